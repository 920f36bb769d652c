//! Development probe: per-phase times of two steps.
use std::path::Path;
use tetrefine::refine::{refine_step, RefineOptions};
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("meshes/tripod.mesh".into());
    let mut m = tetrefine::io::load_mesh(Path::new(&path)).unwrap().0;
    for step in 1..=2 {
        let r = refine_step(&mut m, step, &RefineOptions::default());
        for p in &r.phases {
            println!(
                "step {step} {:>16} {:>9} tets {:.3}s  {:.2} Mtets/s",
                p.name,
                p.tets,
                p.seconds,
                p.tets as f64 / p.seconds / 1e6
            );
        }
        println!("improve {:?}", r.improve);
    }
}
