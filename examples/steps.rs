//! Development probe: quality of a mesh over two steps.
use std::path::Path;
use tetrefine::refine::{features::detect_features, refine_step, BoundaryRule, RefineOptions};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).cloned().unwrap_or("meshes/tripod.mesh".into());
    let passes: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let feat: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(-1.0);
    for rule in [BoundaryRule::Linear, BoundaryRule::Approximating] {
        let mut m = tetrefine::io::load_mesh(Path::new(&path)).unwrap().0;
        if feat > 0.0 {
            let r = detect_features(&mut m, feat);
            println!("features {r:?}");
        }
        let s = tetrefine::MeshStats::compute(&m);
        println!(
            "input: {} tets vol {} regions {:?}",
            s.tets, s.volume, s.regions
        );
        for step in 1..=2 {
            let opts = RefineOptions {
                boundary: rule,
                opt_passes: passes,
                ..Default::default()
            };
            let r = refine_step(&mut m, step, &opts);
            m.check().unwrap();
            let s = tetrefine::MeshStats::compute(&m);
            println!("{rule:?} step {step}: {} nodes {} tets worst {:.2} avg {:.2} vol {} | {:.2}s refused {} {} kept {} tris {} iface {} moves {}/{}/{}",
                s.nodes, s.tets, s.min_dihedral_deg.worst, s.min_dihedral_deg.avg, s.volume, r.seconds,
                r.refused_flips, r.refused_boundary_flips, r.kept_feature_edges, r.trisected_feature_edges, r.interface_split, r.full_moves, r.shortened_moves, r.skipped_moves);
        }
    }
}
