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
}

/// Runs `improve`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let mut mesh = super::load(&a.input)?;
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
