//! `tetrefine bisect IN -o OUT [--steps N]`: uniform 1:8 red refinement, the
//! speed-of-light reference for the √3 step.

use std::path::PathBuf;
use std::time::Instant;
use tetrefine::bisect;

/// Arguments of `bisect`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh (.vtu, .mesh, .msh, .node).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of 1:8 steps.
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
    /// Largest memory the bisection may take (bytes, or with K, M, G, T);
    /// default: what /proc/meminfo says is available. Every step's peak is
    /// estimated before any work, and again before the step, and a step
    /// that would not fit is refused.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
}

/// Runs `bisect`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let budget = super::guard::MemoryBudget::new(a.max_memory.as_deref())?;
    let mut mesh = super::load(&a.input)?;
    budget.check_bisect(a.steps, mesh.n_tets() as u64, 1)?;
    for s in 1..=a.steps {
        budget.check_bisect(1, mesh.n_tets() as u64, s)?;
        let t0 = Instant::now();
        let before = mesh.n_tets();
        mesh = bisect(&mesh).map_err(|e| format!("{}: step {s}: {e}", a.input.display()))?;
        let secs = t0.elapsed().as_secs_f64();
        crate::say!(
            "step {s}: {before} -> {} tets, {} points, {secs:.3} s ({:.1} M output tets/s)",
            mesh.n_tets(),
            mesh.n_points(),
            mesh.n_tets() as f64 / secs.max(1e-9) / 1e6
        );
    }
    super::write_mesh(&a.output, &mesh)
}
