//! Doo–Sabin subdivision of polygon meshes (D. Doo, M. Sabin, "Behaviour of
//! recursive division surfaces near extraordinary points", CAD 10(6), 1978).
//!
//! Every corner k of a face of n vertices becomes a new point
//! Σⱼ αₖⱼ pⱼ with αₖₖ = (n + 5)/(4n) and αₖⱼ = (3 + 2 cos(2π(k − j)/n))/(4n)
//! (the Doo–Sabin weights; for quads 9/16, 3/16, 3/16, 1/16, the tensor
//! product of Chaikin's corner cutting). The new faces are: one *F-face* per
//! old face (its corner points), one quad *E-face* per interior edge and one
//! *V-face* per interior vertex (the corner points around it). On a regular
//! quad mesh the limit surface is the uniform biquadratic B-spline.
//!
//! Every F-face keeps the centroid of its old face (the weights of each old
//! vertex over the n corners sum to 1), so the limit point of a face is its
//! centroid.
//!
//! Boundaries: edges and vertices on an open boundary get no E- or V-face,
//! so the boundary recedes (the simple, common treatment); tagged creases
//! are not supported by this scheme.
//!
//! Counts per step on a closed mesh: V' = Σ|f| = 2E, F' = F + E + V,
//! E' = 4E. Output order: F-faces (old face order), E-faces (edge order of
//! [`super::polymesh::HalfEdges::edges`]), V-faces (vertex order); new point
//! ids are the half-edge ids of the corners.

use super::features::SubdivisionError;
use super::polymesh::{PolyMesh, NO_TWIN};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The Doo–Sabin weight of vertex j for the corner k of an n-gon, with
/// d = (k − j) mod n.
pub fn doo_sabin_weight(n: usize, d: usize) -> f64 {
    let nf = n as f64;
    if d % n == 0 {
        (nf + 5.0) / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (2.0 * PI * d as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// `steps` Doo–Sabin steps.
pub fn doo_sabin(mesh: &PolyMesh, steps: usize) -> Result<PolyMesh, SubdivisionError> {
    let mut cur = mesh.clone();
    for _ in 0..steps {
        cur = doo_sabin_step(&cur)?;
    }
    if steps == 0 {
        mesh.validate()?;
    }
    Ok(cur)
}

fn doo_sabin_step(mesh: &PolyMesh) -> Result<PolyMesh, SubdivisionError> {
    let he = mesh.half_edges()?;
    let p = &mesh.points;
    let corner_pts: Vec<Vec<DVec3>> = mesh
        .faces
        .par_iter()
        .map(|f| {
            let n = f.len();
            let w: Vec<f64> = (0..n).map(|d| doo_sabin_weight(n, d)).collect();
            (0..n)
                .map(|k| {
                    let mut q = DVec3::ZERO;
                    for (j, &v) in f.iter().enumerate() {
                        q += p[v as usize] * w[(k + n - j) % n];
                    }
                    q
                })
                .collect()
        })
        .collect();
    let points: Vec<DVec3> = corner_pts.into_iter().flatten().collect();
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(mesh.faces.len() + he.edges.len() + p.len());
    for f in 0..mesh.faces.len() {
        faces.push((he.face_start[f]..he.face_start[f + 1]).collect());
    }
    for &h in &he.edge_half {
        let t = he.twin[h as usize];
        if t == NO_TWIN {
            continue;
        }
        // h: u→w in f, t: w→u in g; corner ids are half-edge ids.
        faces.push(vec![he.next(h), h, he.next(t), t]);
    }
    for v in 0..p.len() as u32 {
        if he.vertex_out[v as usize] == NO_TWIN || he.is_boundary_vertex(v) {
            continue;
        }
        faces.push(he.outgoing(v));
    }
    Ok(PolyMesh { points, faces })
}
