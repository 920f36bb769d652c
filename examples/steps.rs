//! Development probe: quality of the tripod over two steps in every rule.
use std::path::Path;
use tetrefine::refine::{refine_step, BoundaryRule, RefineOptions};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).cloned().unwrap_or("meshes/tripod.mesh".into());
    let passes: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    for rule in [BoundaryRule::Linear, BoundaryRule::Approximating] {
        let mut m = tetrefine::io::load_mesh(Path::new(&path)).unwrap().0;
        for step in 1..=2 {
            let opts = RefineOptions {
                boundary: rule,
                opt_passes: passes,
                ..Default::default()
            };
            let r = refine_step(&mut m, step, &opts);
            m.check().unwrap();
            let s = tetrefine::MeshStats::compute(&m);
            println!("{rule:?} step {step}: {} nodes {} tets worst {:.2} avg {:.2} best {:.2} val {:.2}/{} | {:.2}s refused {} {} moves {}/{}/{} improve {:?}",
                s.nodes, s.tets, s.min_dihedral_deg.worst, s.min_dihedral_deg.avg, s.min_dihedral_deg.best, s.valence.avg, s.valence.max, r.seconds,
                r.refused_flips, r.refused_boundary_flips, r.full_moves, r.shortened_moves, r.skipped_moves, r.improve);
        }
    }
}
