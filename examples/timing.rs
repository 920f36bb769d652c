//! Development probe: time of two steps with per-phase checks.
use std::path::Path;
use std::time::Instant;
use tetrefine::refine::{refine_step, RefineOptions};
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let check = std::env::args().nth(2).is_some();
    let mut m = tetrefine::io::load_mesh(Path::new(&path)).unwrap().0;
    for step in 1..=2 {
        let t0 = Instant::now();
        let r = refine_step(
            &mut m,
            step,
            &RefineOptions {
                check_each_phase: check,
                ..Default::default()
            },
        );
        println!(
            "step {step}: {} tets {:.2}s (phases {:?})",
            m.n_tets(),
            t0.elapsed().as_secs_f64(),
            r.phases
                .iter()
                .map(|p| format!("{}:{:.2}", p.name, p.seconds))
                .collect::<Vec<_>>()
        );
    }
}
