//! Writes a structured cube mesh of `6 n³` tets (Freudenthal–Kuhn cells) for benchmarks:
//! `cargo run --release --example cube_mesh -- N OUT.mesh`.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(n), Some(out)) = (
        args.first().and_then(|s| s.parse::<usize>().ok()),
        args.get(1),
    ) else {
        eprintln!("usage: cube_mesh N OUT  (6 N³ tets; N ≥ 1)");
        return ExitCode::FAILURE;
    };
    if n == 0 {
        eprintln!("error: N must be at least 1");
        return ExitCode::FAILURE;
    }
    let mesh = tetrefine::TetMesh::from_data(&tetrefine::cube_grid(n))
        .expect("the cube grid is a valid mesh")
        .0;
    match tetrefine::io::write_mesh(&PathBuf::from(out), &mesh) {
        Ok(()) => {
            println!("{out}: {} tets, {} points", mesh.n_tets(), mesh.n_points());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
