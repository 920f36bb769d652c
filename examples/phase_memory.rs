//! Resident memory per phase of √3 steps (Linux only): before each phase the
//! kernel's peak counter is reset (`/proc/self/clear_refs`), so each line
//! shows the resident set at the phase's start and end and its own peak.
//! `cargo run --release --example phase_memory -- [MESH | cube:N] [steps]`.

use std::path::Path;
use tetrefine::{refine_step_with_progress, Phase, Progress, RefineOptions};

/// A `/proc/self/status` entry in MiB.
fn status_mib(key: &str) -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<u64>().ok())
        .unwrap_or(0)
        >> 10
}

/// Resets the peak resident set counter of this process.
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

struct MemoryLines;

impl Progress for MemoryLines {
    fn phase_start(&self, phase: Phase, tets: u64) {
        reset_peak();
        print!(
            "{:>16} {tets:>10} tets  start {:>6} MiB",
            phase.name(),
            status_mib("VmRSS:")
        );
    }
    fn phase_end(&self) {
        println!(
            "  end {:>6} MiB  peak {:>6} MiB",
            status_mib("VmRSS:"),
            status_mib("VmHWM:")
        );
    }
}

fn main() {
    let arg = std::env::args().nth(1).unwrap_or("cube:37".into());
    let steps: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let mut m = match arg.strip_prefix("cube:") {
        Some(n) => {
            let n = n.parse().expect("cube:N with an integer N");
            tetrefine::TetMesh::from_data(&tetrefine::cube_grid(n))
                .expect("the cube grid is valid")
                .0
        }
        None => {
            tetrefine::io::load_mesh(Path::new(&arg))
                .unwrap_or_else(|e| panic!("{e}"))
                .0
        }
    };
    for step in 1..=steps {
        let r = refine_step_with_progress(&mut m, step, &RefineOptions::default(), &MemoryLines);
        println!("step {step}: {} tets in {:.1} s", m.n_tets(), r.seconds);
    }
    reset_peak();
    let stats = tetrefine::report::MeshStats::compute(&m);
    println!(
        "statistics of {} tets: peak {} MiB",
        stats.tets,
        status_mib("VmHWM:")
    );
}
