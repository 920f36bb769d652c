//! Quick timing loop for [`tetrefine::MeshStats::compute`] (a faster
//! alternative to `cargo bench --bench quality` while iterating):
//! `cargo run --release --example stats_speed -- [n] [reps]` on the n³ cube
//! grid (6n³ tets); prints the best time and tets/s. Set
//! `RAYON_NUM_THREADS=1` for the single-core cost per tet. On a busy machine
//! the CPU time per tet (all threads, from Linux's per-thread schedstat) is
//! the steadier figure.
use std::time::Instant;
use tetrefine::cube_grid;
use tetrefine::{MeshStats, TetMesh};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(56);
    let reps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(30);
    let (mesh, _) = TetMesh::from_data(&cube_grid(n)).expect("cube grid builds");
    let tets = mesh.n_tets() as f64;
    // Warm up (the thread pool, the caches).
    let _ = MeshStats::compute(&mesh);
    let cpu0 = cpu_ns();
    let mut best = f64::INFINITY;
    let mut stats = None;
    for _ in 0..reps {
        let t0 = Instant::now();
        let s = MeshStats::compute(std::hint::black_box(&mesh));
        best = best.min(t0.elapsed().as_secs_f64());
        stats = Some(s);
    }
    let cpu = (cpu_ns() - cpu0) as f64 / reps as f64;
    let s = stats.expect("at least one repetition");
    println!(
        "{} tets: best {:.2} ms, {:.1} ns/tet, {:.2} M tets/s; CPU {:.1} ns/tet (edges {}, valence max {}, min avg {:.6})",
        mesh.n_tets(),
        best * 1e3,
        best / tets * 1e9,
        tets / best / 1e6,
        cpu / tets,
        s.edges,
        s.valence.max,
        s.min_dihedral_deg.avg
    );
}

/// On-CPU nanoseconds of all threads of this process so far (0 where
/// /proc is missing).
fn cpu_ns() -> u64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| std::fs::read_to_string(e.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}
