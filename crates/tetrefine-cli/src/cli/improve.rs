//! `tetrefine improve IN -o OUT [--opt-passes N] [--effort E] [--hausd D]`:
//! the optimize phase alone — a mesh clean-up tool; boundary vertices move
//! inside their patches (corners and feature lines kept) unless `--effort fast`.

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
    /// fast (boundary fixed), default (boundary vertices move inside their
    /// patch and along feature lines), best.
    #[arg(long, default_value = "default")]
    pub effort: tetrefine::Effort,
    /// Hausdorff bound of boundary moves (MMG's -hausd); default 5 % of
    /// the local edge length.
    #[arg(long)]
    pub hausd: Option<f64>,
    /// Sharp features: auto (input tags plus detected creases and patch
    /// borders, kept in place), none, or an edge-list file.
    #[arg(long, default_value = "auto")]
    pub features: String,
    /// Crease angle for --features auto (degrees).
    #[arg(long, default_value_t = 45.0)]
    pub feature_angle: f64,
}

/// Runs `improve`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    let budget = super::guard::MemoryBudget::new(a.max_memory.as_deref())?;
    let mut mesh = super::load(&a.input)?;
    budget.check_improve(mesh.n_tets() as u64)?;
    super::apply_feature_option(
        &mut mesh,
        &a.features,
        a.feature_angle,
        tetrefine::InterfaceRule::Linear,
    )?;
    let before = MeshStats::compute(&mesh);
    let report = improve(
        &mut mesh,
        &a.effort
            .improve_options(a.opt_passes, ImproveOptions::default().threshold, a.hausd),
    );
    let after = MeshStats::compute(&mesh);
    crate::say!(
        "min dihedral worst/avg: {:.2}° / {:.2}° -> {:.2}° / {:.2}°  ({} edges removed, {} Laplacian and {} optimized moves, {} boundary and {} feature-line moves, {} boundary caps removed, {} edges contracted, {} multi-face removals, {} vertices inserted, in {} passes)",
        before.min_dihedral_deg.worst,
        before.min_dihedral_deg.avg,
        after.min_dihedral_deg.worst,
        after.min_dihedral_deg.avg,
        report.edges_removed,
        report.laplacian_moves,
        report.optimized_moves,
        report.surface_moves,
        report.line_moves,
        report.caps_removed,
        report.edges_contracted,
        report.faces_removed,
        report.vertices_inserted,
        report.passes
    );
    super::write_mesh(&a.output, &mesh)
}
