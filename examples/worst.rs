//! Development probe: where the worst tets are after refinement.
use std::path::Path;
use tetrefine::refine::{refine_step, BoundaryRule, RefineOptions};
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("meshes/tripod.mesh".into());
    let rule: BoundaryRule = std::env::args()
        .nth(2)
        .unwrap_or("interpolating".into())
        .parse()
        .unwrap();
    let mut m = tetrefine::io::load_mesh(Path::new(&path)).unwrap().0;
    for step in 1..=2 {
        refine_step(
            &mut m,
            step,
            &RefineOptions {
                boundary: rule,
                ..Default::default()
            },
        );
        let fixed = tetrefine::smooth::fixed_vertices(&m);
        let mut q: Vec<(f64, u32)> = m
            .tet_ids()
            .map(|t| {
                (
                    tetrefine::geom::tet_quality(&m.tet_points(t)).min_dihedral_deg,
                    t,
                )
            })
            .collect();
        q.sort_by(|a, b| a.0.total_cmp(&b.0));
        println!("step {step}");
        for &(a, t) in q.iter().take(8) {
            let nb = m.tet(t).iter().filter(|&&v| fixed[v as usize]).count();
            let nbf = (0..4).filter(|&f| m.is_boundary_face(t, f)).count();
            println!(
                "  {a:.2}° fixed verts {nb} boundary faces {nbf} level {}",
                m.level(t)
            );
        }
        let below: usize = q.iter().filter(|x| x.0 < 10.0).count();
        println!("  below 10°: {below}");
    }
}
