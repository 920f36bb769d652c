//! Per-phase times and output tets/s of one or two √3 steps (a quick
//! alternative to `cargo bench --bench refine`): `cargo run --release
//! --example phases -- [MESH | cube:N] [steps]`.
use std::path::Path;
use tetrefine::{refine_step, RefineOptions};
fn main() {
    let arg = std::env::args().nth(1).unwrap_or("cube:37".into());
    let steps: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let mut m = match arg.strip_prefix("cube:") {
        Some(n) => {
            tetrefine::TetMesh::from_data(&tetrefine::cube_grid(n.parse().unwrap()))
                .unwrap()
                .0
        }
        None => tetrefine::io::load_mesh(Path::new(&arg)).unwrap().0,
    };
    println!("input: {} tets", m.n_tets());
    for step in 1..=steps {
        let r = refine_step(&mut m, step, &RefineOptions::default());
        for p in &r.phases {
            println!(
                "step {step} {:>16} {:>10} tets {:>8.3}s {:>7.2} M output tets/s",
                p.name,
                p.tets,
                p.seconds,
                p.tets as f64 / p.seconds / 1e6
            );
        }
        println!(
            "step {step} total {:.3}s, {:.2} M output tets/s",
            r.seconds,
            m.n_tets() as f64 / r.seconds / 1e6
        );
    }
}
