//! One tet step's boundary equals `surface::sqrt3` applied to the input's
//! boundary (tripod, no features, approximating rule): the same points and
//! the same triangles, except around moves the tet step had to shorten (it
//! counts them) — one implementation of the stencils, two topologies.

use glam::DVec3;
use std::collections::HashSet;
use tetrefine::io::load_mesh;
use tetrefine::TetMesh;
use tetrefine::{refine_step, RefineOptions, Sqrt3Rule};
use tetrefine_surface::sqrt3::{sqrt3, Sqrt3Options};
use tetrefine_surface::PolyMesh;

fn boundary(m: &TetMesh) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let tris: Vec<[u32; 3]> = m
        .tet_ids()
        .flat_map(|t| {
            (0..4)
                .filter(move |&f| m.is_boundary_face(t, f))
                .map(move |f| (t, f))
        })
        .map(|(t, f)| m.face_vertices(t, f))
        .collect();
    (m.points().to_vec(), tris)
}

/// Index of the point of `pts` within `tol` of `p` (points sorted by x).
fn find(sorted: &[(f64, usize)], pts: &[DVec3], p: DVec3, tol: f64) -> Option<usize> {
    let lo = sorted.partition_point(|&(x, _)| x < p.x - tol);
    sorted[lo..]
        .iter()
        .take_while(|&&(x, _)| x <= p.x + tol)
        .map(|&(_, i)| i)
        .find(|&i| (pts[i] - p).length() <= tol)
}

#[test]
fn tet_step_boundary_is_the_surface_scheme() {
    let (input, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    let (pts0, tris0) = boundary(&input);
    let surface_in = PolyMesh {
        points: pts0,
        faces: tris0.iter().map(|t| t.to_vec()).collect(),
    };
    let surf = sqrt3(
        &surface_in,
        Sqrt3Rule::Approximating,
        1,
        &Sqrt3Options::default(),
    )
    .unwrap();

    let mut m = input.clone();
    let r = refine_step(
        &mut m,
        1,
        &RefineOptions {
            boundary: Sqrt3Rule::Approximating,
            // The stencils of the step against the surface scheme: `fast`
            // keeps the optimize phase from moving boundary points inside
            // their patch afterwards (boundary smoothing, issue 14).
            effort: tetrefine::Effort::Fast,
            ..Default::default()
        },
    );
    assert_eq!(r.refused_boundary_flips, 0);
    let (pts, tris) = boundary(&m);
    assert_eq!(tris.len(), surf.faces.len());

    let scale = 100.0; // the tripod spans about 100 units
    let tol = 1e-9 * scale;
    let mut sorted: Vec<(f64, usize)> = surf
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| (p.x, i))
        .collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let used: HashSet<u32> = tris.iter().flatten().copied().collect();
    let mut map = std::collections::HashMap::new();
    let mut unmatched = 0;
    for &v in &used {
        match find(&sorted, &surf.points, pts[v as usize], tol) {
            Some(i) => {
                map.insert(v, i);
            }
            None => unmatched += 1,
        }
    }
    // Only points whose move was shortened (and, through the stencils, none
    // other) may differ.
    assert!(
        unmatched <= r.shortened_moves + r.skipped_moves,
        "{unmatched} points differ, {} moves shortened",
        r.shortened_moves
    );
    let surf_tris: HashSet<[usize; 3]> = surf
        .faces
        .iter()
        .map(|f| {
            let mut k = [f[0] as usize, f[1] as usize, f[2] as usize];
            k.sort_unstable();
            k
        })
        .collect();
    let mut different = 0;
    for t in &tris {
        let k: Option<Vec<usize>> = t.iter().map(|v| map.get(v).copied()).collect();
        match k {
            Some(mut k) => {
                k.sort_unstable();
                if !surf_tris.contains(&[k[0], k[1], k[2]]) {
                    different += 1;
                }
            }
            None => different += 1,
        }
    }
    eprintln!(
        "{unmatched} points and {different} of {} triangles differ; {} moves shortened",
        tris.len(),
        r.shortened_moves
    );
    // Triangles differ only where they touch a shortened move (at most the
    // valence of such a point, a few dozen each).
    assert!(different <= 40 * unmatched, "{different} triangles differ");
    if unmatched == 0 {
        assert_eq!(different, 0);
    }
}
