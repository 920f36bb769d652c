//! `tetrefine improve IN -o OUT [--opt-passes N]`: the optimize phase alone,
//! boundary fixed — a mesh clean-up tool.

use std::path::PathBuf;
use tetrefine::MeshStats;
use tetrefine::{improve, ImproveOptions};

/// Arguments of `improve`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Maximum passes of edge removal + smoothing.
    #[arg(long, default_value_t = 5)]
    pub opt_passes: usize,
    /// Largest memory `improve` may take (bytes, or with K, M, G, T);
    /// default: what /proc/meminfo says is available. The peak is estimated
    /// from the tet count and a mesh that would not fit is refused.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
}

/// Runs `improve`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let budget = super::guard::MemoryBudget::new(a.max_memory.as_deref())?;
    let mut mesh = super::load(&a.input)?;
    budget.check_improve(mesh.n_tets() as u64)?;
    let before = MeshStats::compute(&mesh);
    let report = improve(
        &mut mesh,
        &ImproveOptions {
            passes: a.opt_passes,
            ..Default::default()
        },
    );
    let after = MeshStats::compute(&mesh);
    crate::say!(
        "min dihedral worst/avg: {:.2}° / {:.2}° -> {:.2}° / {:.2}°  ({} edges removed, {} Laplacian and {} optimized moves in {} passes)",
        before.min_dihedral_deg.worst,
        before.min_dihedral_deg.avg,
        after.min_dihedral_deg.worst,
        after.min_dihedral_deg.avg,
        report.edges_removed,
        report.laplacian_moves,
        report.optimized_moves,
        report.passes
    );
    super::write_mesh(&a.output, &mesh)
}
