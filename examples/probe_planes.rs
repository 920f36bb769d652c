//! Development probe: which boundary points leave the input planes.
use glam::DVec3;
use std::path::Path;
use tetrefine::refine::{features::detect_features, refine_step, BoundaryRule, RefineOptions};
fn main() {
    let mut m = tetrefine::io::load_mesh(Path::new("meshes/mmg_cube.mesh"))
        .unwrap()
        .0;
    detect_features(&mut m, 45.0);
    for step in 1..=2 {
        let np0 = m.n_points();
        refine_step(
            &mut m,
            step,
            &RefineOptions {
                boundary: BoundaryRule::Interpolating,
                opt_passes: 0,
                ..Default::default()
            },
        );
        let s = tetrefine::MeshStats::compute(&m);
        println!("step {step} vol {}", s.volume);
        let mut bad = 0;
        for t in m.tet_ids() {
            for f in 0..4 {
                if m.is_boundary_face(t, f) {
                    for v in m.face_vertices(t, f) {
                        let p: DVec3 = m.point(v);
                        let on = [p.x, p.y, p.z]
                            .iter()
                            .any(|&c| c.abs() < 1e-9 || (c - 1.0).abs() < 1e-9);
                        if !on && bad < 5 {
                            bad += 1;
                            println!(
                                "  off-plane {v} {p} (new: {}) feature {}",
                                v as usize >= np0,
                                m.feature_edges().keys().any(|e| e.contains(&v))
                            );
                        }
                    }
                }
            }
        }
    }
}
