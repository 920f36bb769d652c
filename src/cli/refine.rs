//! `tetrefine refine IN -o OUT [--steps N] [--boundary …] [--opt-passes N]
//! [--stop-after PHASE] [--stats FILE.json] [--histogram FILE]`.

use super::progress::BarProgress;
use std::path::PathBuf;
use std::time::Instant;
use tetrefine::refine::{
    locate_parents, refine_step_with_progress, BoundaryRule, Phase, RefineOptions,
};
use tetrefine::report::steps::{step_row, step_table_header, StepStats};
use tetrefine::MeshStats;

/// The `--stats` file: `{"steps": [input, step 1, …]}`.
#[derive(serde::Serialize)]
struct StatsFile<'a> {
    steps: &'a [StepStats],
}

/// Arguments of `refine`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh.
    pub input: PathBuf,
    /// Output mesh (.vtu, .mesh, .msh, .node).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of √3 steps.
    #[arg(long, default_value_t = 1)]
    pub steps: usize,
    /// Boundary rule: interpolating (Labsik–Greiner), approximating (Kobbelt) or linear.
    #[arg(long, default_value = "interpolating")]
    pub boundary: BoundaryRule,
    /// Passes of the optimize phase (edge removal + smoothing); 0 skips it.
    #[arg(long, default_value_t = 3)]
    pub opt_passes: usize,
    /// Minimum-sine quality below which vertices get optimization-based smoothing.
    #[arg(long, default_value_t = 0.3)]
    pub threshold: f64,
    /// Stop each step after this phase: split, flip, boundary-split,
    /// boundary-flip, boundary-smooth, optimize.
    #[arg(long)]
    pub stop_after: Option<Phase>,
    /// Write per-step statistics (with per-phase times) as JSON.
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Write the final min-dihedral histogram (.csv, .svg or .png).
    #[arg(long)]
    pub histogram: Option<PathBuf>,
    /// Sharp features: `auto` (input tags plus detected creases, patch borders
    /// and interface junctions), `none`, or an edge-list file (`v0 v1` per
    /// line, 0-based) added to the input tags.
    #[arg(long, default_value = "auto")]
    pub features: String,
    /// Normal deviation (degrees) above which a boundary edge is a crease
    /// (with `--features auto`; MMG's ridge angle is 45°).
    #[arg(long, default_value_t = 45.0)]
    pub feature_angle: f64,
    /// Write the output feature edges as polylines (.vtp for ParaView, or .csv).
    #[arg(long)]
    pub features_out: Option<PathBuf>,
}

/// Runs `refine`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    if let Some(h) = &a.histogram {
        super::check_histogram_path(h)?;
    }
    if !(a.threshold > 0.0 && a.threshold < 1.0) {
        return Err(format!(
            "--threshold {} must lie in (0, 1) (a sine)",
            a.threshold
        ));
    }
    if !(a.feature_angle > 0.0 && a.feature_angle < 180.0) {
        return Err(format!(
            "--feature-angle {} must lie in (0, 180) degrees",
            a.feature_angle
        ));
    }
    if let Some(f) = &a.features_out {
        tetrefine::surface::ifs::PolylineFormat::of(f).map_err(|e| e.to_string())?;
    }
    let mut input = super::load(&a.input)?;
    super::apply_feature_option(&mut input, &a.features, a.feature_angle)?;
    let mut mesh = input.clone();
    let opts = RefineOptions {
        boundary: a.boundary,
        opt_passes: a.opt_passes,
        threshold: a.threshold,
        stop_after: a.stop_after,
        selection: None,
        check_each_phase: false,
    };
    let t0 = Instant::now();
    let first = MeshStats::compute(&mesh);
    println!("{}", step_table_header());
    println!("{}", step_row("input", &first, 0.0));
    let mut steps = vec![StepStats::input(first)];
    let progress = BarProgress::new();
    for s in 1..=a.steps {
        let report = refine_step_with_progress(&mut mesh, s, &opts, &progress);
        let stats = MeshStats::compute(&mesh);
        println!("{}", step_row(&format!("step {s}"), &stats, report.seconds));
        if report.refused_flips + report.refused_boundary_flips + report.skipped_moves > 0 {
            eprintln!(
                "note: step {s}: {} interior flips and {} boundary flips refused, {} boundary moves skipped (each would have inverted a tet)",
                report.refused_flips, report.refused_boundary_flips, report.skipped_moves
            );
        }
        steps.push(StepStats::step(stats, &report));
    }
    locate_parents(&input, &mut mesh);
    if let Some(path) = &a.stats {
        let text = serde_json::to_string_pretty(&StatsFile { steps: &steps })
            .map_err(|e| e.to_string())?;
        tetrefine::io::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .map_err(|e| e.to_string())?;
    }
    super::write_refined(&a.output, &mut mesh, Vec::new())?;
    if let Some(f) = &a.features_out {
        super::write_feature_lines(f, &mesh)?;
    }
    if let Some(h) = &a.histogram {
        let last = &steps.last().expect("input entry").stats;
        super::write_histogram(h, last)?;
    }
    eprintln!(
        "wrote {} ({} tets) in {:.2}s",
        a.output.display(),
        mesh.n_tets(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
