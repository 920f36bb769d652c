//! `tetrefine refine IN -o OUT [--steps N] [--boundary …] [--opt-passes N]
//! [--stop-after PHASE] [--stats FILE.json] [--histogram FILE]`.

use super::progress::BarProgress;
use super::steps::StepStats;
use std::path::PathBuf;
use std::time::Instant;
use tetrefine::io::indicator::read_indicator;
use tetrefine::refine::marking::{select, MarkStrategy};
use tetrefine::refine::{locate_parents, refine_with, Phase, RefineOptions, Sqrt3Rule};
use tetrefine::report::steps::{step_row, step_table_header};
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
    pub boundary: Sqrt3Rule,
    /// Passes of the optimize phase (edge removal + smoothing); 0 skips it.
    #[arg(long, default_value_t = 3)]
    pub opt_passes: usize,
    /// Minimum-sine quality below which vertices get optimization-based smoothing.
    #[arg(long, default_value_t = 0.3)]
    pub threshold: f64,
    /// How hard the optimize phase works: fast (boundary fixed), default
    /// (boundary vertices move inside their patch and along feature lines),
    /// best (more passes, larger edge-removal rings, a higher bar).
    #[arg(long, default_value = "default")]
    pub effort: tetrefine::improve::Effort,
    /// Hausdorff bound (MMG's -hausd): how far boundary moves may take the
    /// surface from the step's reference surface; default 5 % of the local
    /// edge length.
    #[arg(long)]
    pub hausd: Option<f64>,
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
    /// Per-tet error indicator: a text file (one value per line), CSV
    /// `tet,value` (0-based ids), Medit `.sol` (SolAtTetrahedra or
    /// SolAtVertices) or `FILE.vtu:ARRAY`.
    #[arg(long)]
    pub indicator: Option<String>,
    /// Marking strategy (repeatable; selections combine as a union):
    /// fraction:F, doerfler:θ, max:γ, threshold:X (these need --indicator),
    /// region:ID[,ID…], box:x0,y0,z0,x1,y1,z1, sphere:x,y,z,r.
    #[arg(long = "mark")]
    pub marks: Vec<String>,
    /// Select the tets of these regions (same as --mark region:…).
    #[arg(long)]
    pub region: Option<String>,
    /// Select the tets whose centroid is in this box (same as --mark box:…).
    #[arg(long = "box", allow_hyphen_values = true)]
    pub select_box: Option<String>,
    /// Select the tets whose centroid is in this sphere (same as --mark sphere:…).
    #[arg(long, allow_hyphen_values = true)]
    pub sphere: Option<String>,
    /// With a selection: `refined` (default) lets smoothing and edge removal
    /// touch only the refined zone, so tets sharing no vertex with it come
    /// out bit-identical; `all` optimises everywhere.
    #[arg(long, default_value = "refined")]
    pub smooth: SmoothScope,
    /// Write `new_tet parent_tet` per line (0-based output and input ids), so
    /// a solver can carry its fields over.
    #[arg(long)]
    pub parent_map: Option<PathBuf>,
    /// Refinement rounds already done on this mesh (in an adaptive loop,
    /// the round number): feature edges are kept in odd and trisected in
    /// even global steps.
    #[arg(long, default_value_t = 0)]
    pub step_offset: usize,
    /// Largest memory the refinement may take (bytes, or with K, M, G, T);
    /// default: what /proc/meminfo says is available. Each step's peak is
    /// estimated beforehand and a step that would not fit is refused.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// Accept a selection that matches no tet (the mesh is written unrefined).
    #[arg(long)]
    pub allow_empty: bool,
    /// Accept `--steps 0` (the mesh is written unrefined, with its arrays).
    #[arg(long)]
    pub allow_steps_zero: bool,
    /// MSH variant of a `.msh` output: 2.2, 4.1 or 4.1-binary. Physical
    /// names and every physical tag of the input's entities are written back.
    #[arg(long, default_value = "4.1")]
    pub msh_format: tetrefine::io::gmsh::MshFormat,
}

/// Where the optimize phase may act in adaptive refinement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SmoothScope {
    /// Only the refined zone.
    Refined,
    /// The whole mesh.
    All,
}

/// The union of every selection option, or `None` for uniform refinement.
fn mark_strategy(a: &Args) -> Result<Option<MarkStrategy>, String> {
    let mut specs: Vec<String> = a.marks.clone();
    if let Some(r) = &a.region {
        specs.push(format!("region:{r}"));
    }
    if let Some(b) = &a.select_box {
        specs.push(format!("box:{b}"));
    }
    if let Some(s) = &a.sphere {
        specs.push(format!("sphere:{s}"));
    }
    if specs.is_empty() {
        if a.indicator.is_some() {
            return Err("--indicator needs a marking strategy: --mark fraction:F, doerfler:θ, max:γ or threshold:X".into());
        }
        return Ok(None);
    }
    let parts = specs
        .iter()
        .map(|s| {
            s.parse::<MarkStrategy>()
                .map_err(|e| format!("--mark {s}: {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let strategy = MarkStrategy::union(parts);
    if strategy.needs_indicator() && a.indicator.is_none() {
        return Err(format!("--mark {strategy} needs --indicator FILE"));
    }
    Ok(Some(strategy))
}

/// Runs `refine`.
pub fn run(a: Args) -> super::CliResult {
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    super::outputs::refuse_shared_paths(&[
        ("-o", Some(a.output.as_path())),
        ("--stats", a.stats.as_deref()),
        ("--histogram", a.histogram.as_deref()),
        ("--features-out", a.features_out.as_deref()),
        ("--parent-map", a.parent_map.as_deref()),
    ])?;
    if a.steps == 0 && !a.allow_steps_zero {
        return Err("--steps 0 refines nothing; give --steps N ≥ 1 (or --allow-steps-zero to write the mesh unrefined)".into());
    }
    let budget = super::guard::MemoryBudget::new(a.max_memory.as_deref())?;
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
        tetrefine::polyline::PolylineFormat::of(f).map_err(|e| e.to_string())?;
    }
    if let Some(h) = a.hausd {
        if !(h >= 0.0 && h.is_finite()) {
            return Err(format!("--hausd {h} must be a finite distance >= 0"));
        }
    }
    let strategy = mark_strategy(&a)?;
    let (mut input, meta) = super::load_with_meta(&a.input)?;
    let selection = match &strategy {
        Some(st) => {
            let values = match &a.indicator {
                Some(spec) => Some(read_indicator(spec, &input).map_err(|e| e.to_string())?),
                None => None,
            };
            super::guard::check_selection(st, &input)?;
            let sel =
                select(st, values.as_deref(), &input).map_err(|e| format!("--mark {st}: {e}"))?;
            let count = sel.iter().filter(|&&x| x).count();
            if count == 0 && !a.allow_empty {
                return Err(format!(
                    "--mark {st} selects none of the {} tets; nothing would be refined (--allow-empty writes the mesh unrefined)",
                    input.n_tets()
                ));
            }
            eprintln!("selected {count} of {} tets ({st})", input.n_tets());
            Some(sel)
        }
        None => None,
    };
    let selected = selection
        .as_ref()
        .map_or(input.n_tets(), |s| s.iter().filter(|&&x| x).count()) as u64;
    budget.check_plan(
        a.steps,
        input.n_tets() as u64,
        selected,
        input.n_tets() as u64,
    )?;
    super::apply_feature_option(&mut input, &a.features, a.feature_angle)?;
    let mut mesh = input.clone();
    let opts = RefineOptions {
        boundary: a.boundary,
        opt_passes: a.opt_passes,
        threshold: a.threshold,
        stop_after: a.stop_after,
        selection: selection.clone(),
        smooth_refined_only: selection.is_some() && a.smooth == SmoothScope::Refined,
        step_offset: a.step_offset,
        check_each_phase: false,
        effort: a.effort,
        hausd: a.hausd,
    };
    let t0 = Instant::now();
    let first = MeshStats::compute(&mesh);
    crate::say!("{}", step_table_header());
    crate::say!("{}", step_row("input", &first, 0.0));
    let mut steps = vec![StepStats::input(first)];
    let phases_per_step = match a.stop_after {
        Some(p) => Phase::ALL
            .iter()
            .position(|&q| q == p)
            .map_or(Phase::ALL.len(), |i| i + 1),
        None => Phase::ALL.len(),
    };
    let progress = BarProgress::new(a.steps, phases_per_step);
    refine_with(&mut mesh, a.steps, &opts, &progress, |s, mesh, report| {
        let stats = MeshStats::compute(mesh);
        progress.suspend(|| {
            crate::say!("{}", step_row(&format!("step {s}"), &stats, report.seconds));
            if report.refused_flips + report.refused_boundary_flips + report.skipped_moves > 0 {
                eprintln!(
                    "note: step {s}: {} interior flips and {} boundary flips refused, {} boundary moves skipped (each would have inverted a tet)",
                    report.refused_flips, report.refused_boundary_flips, report.skipped_moves
                );
            }
        });
        steps.push(StepStats::step(stats, &report));
    });
    progress.finish();
    locate_parents(&input, &mut mesh);
    if let Some(path) = &a.stats {
        let text = serde_json::to_string_pretty(&StatsFile { steps: &steps })
            .map_err(|e| e.to_string())?;
        tetrefine::io::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .map_err(|e| e.to_string())?;
    }
    mesh.compact();
    if let Some(path) = &a.parent_map {
        let ids: Vec<u32> = mesh.tet_ids().collect();
        tetrefine::io::write_atomic(path, |w| {
            use std::io::Write;
            writeln!(
                w,
                "# new_tet parent_tet (0-based; parent = input tet holding the centroid)"
            )?;
            for (i, &t) in ids.iter().enumerate() {
                writeln!(w, "{i} {}", mesh.parent(t))?;
            }
            Ok(())
        })
        .map_err(|e| e.to_string())?;
    }
    // Whether the tet descends from a selected input tet (all do without a
    // selection).
    let sel = selection.as_deref();
    let marked = |m: &tetrefine::TetMesh, t: u32| {
        let p = m.parent(t) as usize;
        i32::from(sel.is_none_or(|s| s.get(p).copied().unwrap_or(false)))
    };
    let options = tetrefine::io::WriteOptions {
        msh_format: a.msh_format,
    };
    // Names and tag lists stay valid through refinement (every child keeps its
    // parent's region and markers); the input's fields do not.
    let mut meta = meta;
    meta.point_fields.clear();
    meta.cell_fields.clear();
    super::write_refined(
        &a.output,
        &mut mesh,
        &[("marked", &marked)],
        &meta,
        &options,
    )?;
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
