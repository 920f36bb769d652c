//! TEMPORARY placeholder of the shared √3 stencils (replaced by the surface
//! module's implementation on merge): linear and Kobbelt-approximating only.

use glam::DVec3;
use std::collections::HashSet;

/// Boundary rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sqrt3Rule {
    /// Kobbelt.
    Approximating,
    /// Labsik–Greiner.
    Interpolating,
    /// Linear.
    Linear,
}

/// Positions.
#[derive(Clone, Debug, Default)]
pub struct Sqrt3Positions {
    /// Old vertices.
    pub vertices: Vec<DVec3>,
    /// Face points.
    pub faces: Vec<DVec3>,
}

/// Kobbelt's alpha.
pub fn kobbelt_alpha(n: usize) -> f64 {
    (4.0 - 2.0 * (2.0 * std::f64::consts::PI / n as f64).cos()) / 9.0
}

/// Positions after one step.
pub fn sqrt3_positions(
    points: &[DVec3],
    tris: &[[u32; 3]],
    rule: Sqrt3Rule,
    creases: &HashSet<[u32; 2]>,
    corners: &HashSet<u32>,
) -> Sqrt3Positions {
    let faces = tris
        .iter()
        .map(|t| (points[t[0] as usize] + points[t[1] as usize] + points[t[2] as usize]) / 3.0)
        .collect();
    let mut vertices = points.to_vec();
    if rule == Sqrt3Rule::Approximating {
        let mut nb: Vec<Vec<u32>> = vec![Vec::new(); points.len()];
        let mut fixed = vec![false; points.len()];
        for t in tris {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if !nb[a as usize].contains(&b) {
                    nb[a as usize].push(b);
                }
                if !nb[b as usize].contains(&a) {
                    nb[b as usize].push(a);
                }
                if creases.contains(&[a.min(b), a.max(b)]) {
                    fixed[a as usize] = true;
                    fixed[b as usize] = true;
                }
            }
        }
        for (v, n) in nb.iter().enumerate() {
            if n.is_empty() || fixed[v] || corners.contains(&(v as u32)) {
                continue;
            }
            let avg = n.iter().map(|&u| points[u as usize]).sum::<DVec3>() / n.len() as f64;
            let a = kobbelt_alpha(n.len());
            vertices[v] = (1.0 - a) * points[v] + a * avg;
        }
    }
    Sqrt3Positions { vertices, faces }
}
