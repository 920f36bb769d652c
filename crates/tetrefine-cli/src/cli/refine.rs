//! `tetrefine refine IN -o OUT [--steps N] [--boundary …] [--opt-passes N]
//! [--stop-after PHASE] [--stats FILE.json] [--histogram FILE]`.

use super::progress::BarProgress;
use super::steps::StepStats;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tetrefine::io::read_indicator;
use tetrefine::report::{step_row, step_table_header};
use tetrefine::MeshStats;
use tetrefine::{locate_parents, InterfaceRule, Phase, RefineOptions, Sqrt3Rule};
use tetrefine::{select, MarkStrategy};

/// The `--stats` file: `{"steps": [input, step 1, …]}`.
#[derive(serde::Serialize)]
struct StatsFile<'a> {
    steps: &'a [StepStats],
}

/// Arguments of `refine`.
#[derive(clap::Args)]
pub struct Args {
    /// Input mesh. A `.pvtu`'s pieces are joined (shared points by
    /// `GlobalPointIds`, else by coordinates); a distributed run with a
    /// `.pvtu` output reads them per rank, each rank its own pieces.
    pub input: PathBuf,
    /// Output mesh (.vtu, .mesh, .msh, .node).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of √3 steps (default 1); with a size map, of size passes, or
    /// `auto`: passes until no edge is longer than its target (at most 20;
    /// the default with a size map).
    #[arg(long)]
    pub steps: Option<super::size::Steps>,
    /// MMG size map: a Medit `.sol` with SolAtVertices of type 1 (a target
    /// edge length per point) or type 3 (a metric per point, MMG's order
    /// m11 m12 m22 m13 m23 m33). Refines by splitting every edge longer
    /// than its target instead of √3 steps.
    #[arg(long)]
    pub size: Option<PathBuf>,
    /// The size map is this point array of the input (`.vtu` point data or
    /// Gmsh `$NodeData`; 1 component: a length, 6: a metric). A `.pvtu`
    /// read per rank (under `mpirun`, with a `.pvtu` output) takes it from
    /// each rank's own pieces.
    #[arg(long)]
    pub size_array: Option<String>,
    /// A uniform target edge length (MMG's -hsiz).
    #[arg(long)]
    pub hsiz: Option<f64>,
    /// The largest target edge length (MMG's -hmax): caps the size map, or
    /// alone is a uniform target.
    #[arg(long)]
    pub hmax: Option<f64>,
    /// Boundary rule: interpolating (Labsik–Greiner), approximating (Kobbelt) or linear.
    #[arg(long, default_value = "interpolating")]
    pub boundary: Sqrt3Rule,
    /// Material interfaces: linear (split flat, never smoothed: every region
    /// keeps its exact volume; a curved interface stays faceted) or sqrt3
    /// (split, flipped and smoothed on both sides by the --boundary stencil,
    /// creases only where the interface bends by more than --feature-angle).
    #[arg(long, default_value = "linear")]
    pub interfaces: InterfaceRule,
    /// Passes of the optimize phase (edge removal + smoothing); 0 skips it.
    #[arg(long, default_value_t = 3)]
    pub opt_passes: usize,
    /// Minimum-sine quality below which vertices get optimization-based smoothing.
    #[arg(long, default_value_t = tetrefine::DEFAULT_THRESHOLD)]
    pub threshold: f64,
    /// How hard the optimize phase works: fast (boundary fixed, no long-edge
    /// splits), default (boundary vertices move inside their patch and along
    /// feature lines; two rounds split long edges, and from the second step
    /// on a third the edges that still stand out), best (more passes,
    /// larger edge-removal rings, a higher bar, three long-edge rounds
    /// before that third).
    #[arg(long, default_value = "default")]
    pub effort: tetrefine::Effort,
    /// Hausdorff bound (MMG's -hausd): how far boundary moves may take the
    /// surface from the step's reference surface; default 5 % of the local
    /// edge length for vertex moves and 15 % of a sliver cap's mean edge
    /// for its removal.
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
    /// Write `new_tet parent_tet` per line (0-based output and input ids),
    /// then, after a `# points` line, the vertex parent map: per output
    /// point `new_point input_tet v0 v1 v2 v3 b0 b1 b2 b3 outside` (the
    /// input tet holding it, its vertices and the point's barycentric
    /// coordinates), so a solver can carry its fields over. With a `.pvtu`
    /// output (a distributed run) one file per piece, named like the
    /// pieces: `MAP_r.EXT` beside `MAP.EXT`, in piece `r`'s own 0-based
    /// numbering (input ids stay global).
    #[arg(long)]
    pub parent_map: Option<PathBuf>,
    /// Carry the input's fields over (the default when it has any: `.vtu`
    /// point and cell data, Gmsh `$NodeData`, `--fields`): point fields
    /// interpolated linearly in the input tet holding each output point,
    /// cell fields copied from each tet's parent.
    #[arg(long, overrides_with = "no_transfer")]
    pub transfer: bool,
    /// Drop the input's fields instead of carrying them over.
    #[arg(long, overrides_with = "transfer")]
    pub no_transfer: bool,
    /// Point or cell fields of the input from a Medit solution (.sol or
    /// .solb: SolAtVertices → point fields, SolAtTetrahedra → cell fields);
    /// repeatable. Written as `.vtu` point/cell data, Gmsh
    /// `$NodeData`/`$ElementData`, or `OUT.sol` (points) and `OUT.tets.sol`
    /// (tets) beside a `.mesh` output.
    #[arg(long)]
    pub fields: Vec<PathBuf>,
    /// Refinement rounds already done on this mesh (in an adaptive loop,
    /// the round number): feature edges are kept in odd and trisected in
    /// even global steps. Default: for a `.vtu` written by tetrefine, the
    /// largest value of its `level` array (the steps it has had), else 0.
    #[arg(long)]
    pub step_offset: Option<usize>,
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
    pub msh_format: tetrefine::io::MshFormat,
}

/// Where the optimize phase may act in adaptive refinement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SmoothScope {
    /// Only the refined zone.
    Refined,
    /// The whole mesh.
    All,
}

impl Args {
    /// The output files the options name, each with its option (for
    /// [`super::outputs::refuse_shared_paths`]).
    pub fn named_outputs(&self) -> [(&'static str, Option<&Path>); 5] {
        [
            ("-o", Some(self.output.as_path())),
            ("--stats", self.stats.as_deref()),
            ("--histogram", self.histogram.as_deref()),
            ("--features-out", self.features_out.as_deref()),
            ("--parent-map", self.parent_map.as_deref()),
        ]
    }
}

/// The union of every selection option, or `None` for uniform refinement.
pub fn mark_strategy(a: &Args) -> Result<Option<MarkStrategy>, String> {
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

/// The selection of `strategy` on `input` (with `--indicator`), or `None`
/// for uniform refinement; tells the user how many tets it selects.
pub fn selection_of(
    a: &Args,
    strategy: Option<&MarkStrategy>,
    input: &tetrefine::TetMesh,
) -> Result<Option<Vec<bool>>, String> {
    Ok(match strategy {
        Some(st) => {
            let values = match &a.indicator {
                Some(spec) => {
                    let v = read_indicator(spec, input).map_err(|e| e.to_string())?;
                    if spec.to_ascii_lowercase().ends_with(".sol") {
                        eprintln!("note: --indicator {spec}: read as an error indicator (larger = refine; SolAtVertices: a tet takes the maximum of its vertices); an MMG size map (target edge lengths) is --size FILE.sol");
                    }
                    Some(v)
                }
                None => None,
            };
            super::guard::check_selection(st, input)?;
            let sel =
                select(st, values.as_deref(), input).map_err(|e| format!("--mark {st}: {e}"))?;
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
    })
}

/// `--threshold`, `--feature-angle` and `--hausd` within their ranges.
pub fn check_numbers(a: &Args) -> super::CliResult {
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
    if let Some(h) = a.hausd {
        if !(h >= 0.0 && h.is_finite()) {
            return Err(format!("--hausd {h} must be a finite distance >= 0"));
        }
    }
    Ok(())
}

/// Runs `refine`.
pub fn run(a: Args) -> super::CliResult {
    #[cfg(feature = "mpi")]
    if super::distributed::wanted(&a) {
        return super::distributed::run(a);
    }
    #[cfg(not(feature = "mpi"))]
    if super::pvtu_merge::is_pvtu(&a.output) {
        return Err(format!(
            "{}: a .pvtu is written by distributed runs: build with `--features mpi` and run under mpirun",
            a.output.display()
        ));
    }
    tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?;
    super::outputs::refuse_shared_paths(&a.named_outputs())?;
    let plan = super::size::plan(&a)?;
    let (size_given, n_steps, auto) = (plan.size_given, plan.n_steps, plan.auto);
    let budget = super::guard::MemoryBudget::new(a.max_memory.as_deref())?;
    if let Some(h) = &a.histogram {
        super::check_histogram_path(h)?;
    }
    check_numbers(&a)?;
    if let Some(f) = &a.features_out {
        tetrefine::PolylineFormat::of(f).map_err(|e| e.to_string())?;
    }
    let strategy = mark_strategy(&a)?;
    let (mut input, mut meta) = super::load_with_meta(&a.input)?;
    let transfer = load_fields(&a, &input, &mut meta)?;
    let selection = selection_of(&a, strategy.as_ref(), &input)?;
    let selected = selection
        .as_ref()
        .map_or(input.n_tets(), |s| s.iter().filter(|&&x| x).count()) as u64;
    budget.check_plan(
        if size_given { 1 } else { n_steps },
        input.n_tets() as u64,
        selected,
        input.n_tets() as u64,
    )?;
    super::apply_feature_option(&mut input, &a.features, a.feature_angle, a.interfaces)?;
    let size = super::size::size_map_of(&a, &input, &meta)?;
    let mut mesh = input.clone();
    let opts = RefineOptions {
        boundary: a.boundary,
        opt_passes: a.opt_passes,
        threshold: a.threshold,
        stop_after: a.stop_after,
        selection: selection.clone(),
        smooth_refined_only: selection.is_some() && a.smooth == SmoothScope::Refined,
        step_offset: step_offset(&a),
        check_each_phase: false,
        effort: a.effort,
        hausd: a.hausd,
        interfaces: a.interfaces,
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
    if let Some(mut size) = size {
        // The floor: each pass's worst tet at its start (in the metric for
        // an anisotropic map), so the worst never drops below the input's.
        let sopts = tetrefine::SizeOptions {
            quality_floor: None,
            // The size loop's optimize phase honours --effort and --hausd
            // as the √3 step's does.
            improve: super::size::improve_options_of(&a),
        };
        let mut last = None;
        for s in 1..=n_steps {
            let t = Instant::now();
            let r = tetrefine::size_pass(&mut mesh, &mut size, &sopts);
            let stats = MeshStats::compute(&mesh);
            let secs = t.elapsed().as_secs_f64();
            crate::say!("{}", step_row(&format!("size {s}"), &stats, secs));
            eprintln!(
                "size pass {s}: {} long edges, {} split, {} refused (would invert a tet or fall below the worst quality so far, measured in the metric), {} still long",
                r.long_edges, r.split, r.refused, r.long_after
            );
            let report = tetrefine::StepReport {
                seconds: secs,
                ..tetrefine::StepReport::default()
            };
            steps.push(StepStats::step(stats, &report));
            let done = r.long_after == 0 || r.split == 0;
            last = Some(r);
            if done && auto {
                break;
            }
        }
        if let Some(r) = last {
            super::size::note_still_long(r.long_after as u64, r.split == 0, &plan);
        }
    } else {
        let progress = BarProgress::new(n_steps, phases_per_step);
        // The plan above projected every step; before each step its real tet
        // counts are held against the budget again (a step of a mesh that grew
        // more than projected is refused, naming it, with nothing written).
        let kept = input.n_tets() as u64;
        let before_step = |s: usize, mesh: &tetrefine::TetMesh, split: u64| {
            budget.check_step(s, mesh.n_tets() as u64, split, kept)
        };
        tetrefine::refine_with_guard(
            &mut mesh,
            n_steps,
            &opts,
            &progress,
            before_step,
            |s, mesh, report| {
                let stats = MeshStats::compute(mesh);
                progress.suspend(|| {
            crate::say!("{}", step_row(&format!("step {s}"), &stats, report.seconds));
            if report.refused_flips + report.refused_boundary_flips + report.skipped_moves > 0 {
                eprintln!(
                    "note: step {s}: {} interior flips and {} boundary flips refused, {} boundary moves skipped (each would have inverted a tet)",
                    report.refused_flips, report.refused_boundary_flips, report.skipped_moves
                );
            }
            if report.held > 0 {
                eprintln!(
                    "note: step {s}: {} input tets left unsplit, where splitting them left a tet below the input's worst dihedral angle",
                    report.held
                );
            }
        });
                steps.push(StepStats::step(stats, &report));
            },
        )?;
        progress.finish();
    }
    if let Some(path) = &a.stats {
        let text = serde_json::to_string_pretty(&StatsFile { steps: &steps })
            .map_err(|e| e.to_string())?;
        tetrefine::io::write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
            .map_err(|e| e.to_string())?;
    }
    write_output(&a, &input, &mut mesh, meta, transfer, selection.as_deref())?;
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

/// `--step-offset`, or when it is not given the steps a `.vtu` input
/// written by tetrefine has had (the largest value of its `level` array,
/// said in a note), so that refining a refined mesh again continues the
/// global step count: its feature edges are then trisected in the even
/// steps instead of staying whole in every run (tripod refined twice, each
/// run from the other's file: worst 17.35° with the count restarted,
/// 17.96° continued, input 17.82°). A `.vtu` without a usable `level`
/// array starts at 0.
pub(super) fn step_offset(a: &Args) -> usize {
    if let Some(k) = a.step_offset {
        return k;
    }
    let steps = if is_vtu_or_pvtu(&a.input) {
        steps_done(&a.input)
    } else {
        0
    };
    note_steps_done(&a.input, steps);
    steps
}

/// Whether `p` names a `.vtu` or a `.pvtu`.
pub(super) fn is_vtu_or_pvtu(p: &std::path::Path) -> bool {
    super::pvtu_merge::is_pvtu(p)
        || p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("vtu"))
}

/// The largest value of the `level` cell array of the `.vtu` (or every
/// piece of the `.pvtu`) at `path`: the steps tetrefine has made on it. 0
/// without such an array or with one that is not whole numbers in 0–255.
pub(super) fn steps_done(path: &std::path::Path) -> usize {
    if super::pvtu_merge::is_pvtu(path) {
        // The cell-array reader reads one `.vtu`: the pieces one by one.
        let pieces = tetrefine::io::read_pvtu_pieces(path).unwrap_or_default();
        return pieces.iter().map(|p| steps_done(p)).max().unwrap_or(0);
    }
    let Ok(level) = tetrefine::io::read_tet_cell_array(path, "level") else {
        return 0;
    };
    let usable = level
        .values
        .iter()
        .all(|&l| l.is_finite() && l >= 0.0 && l.fract() == 0.0 && l <= 255.0);
    if usable {
        level.values.iter().fold(0.0f64, |m, &l| m.max(l)) as usize
    } else {
        0
    }
}

/// Says that the step count goes on from `steps` (when there are any).
pub(super) fn note_steps_done(input: &std::path::Path, steps: usize) {
    if steps > 0 {
        eprintln!(
            "note: {} has had {steps} refinement step{} (its `level` array): the steps go on from there (--step-offset 0 starts the count over)",
            input.display(),
            if steps == 1 { "" } else { "s" }
        );
    }
}

/// Adds `--fields` to the input's `meta`, checks `--transfer` against what
/// the input carries and the output paths the fields would be written to,
/// and says what will be carried over. Returns whether fields are
/// transferred.
pub(super) fn load_fields(
    a: &Args,
    input: &tetrefine::TetMesh,
    meta: &mut tetrefine::io::MeshMeta,
) -> Result<bool, String> {
    for f in &a.fields {
        tetrefine::io::add_sol_fields(f, meta, input.n_points(), input.n_tets())
            .map_err(|e| e.to_string())?;
    }
    let has_fields = !meta.point_fields.is_empty() || !meta.cell_fields.is_empty();
    if a.transfer && !a.no_transfer && !has_fields {
        return Err(format!(
            "--transfer: {} carries no point or cell field (give one with --fields FILE.sol)",
            a.input.display()
        ));
    }
    let transfer = has_fields && !a.no_transfer;
    if transfer {
        let beside = tetrefine::io::fields_beside(&a.output);
        let mut outputs = a.named_outputs().to_vec();
        outputs.extend([
            (
                "the point fields beside -o",
                beside.as_ref().map(|b| b.0.as_path()),
            ),
            (
                "the cell fields beside -o",
                beside.as_ref().map(|b| b.1.as_path()),
            ),
        ]);
        super::outputs::refuse_shared_paths(&outputs)?;
        eprintln!(
            "transfer: {} point and {} cell fields of the input",
            meta.point_fields.len(),
            meta.cell_fields.len()
        );
    }
    Ok(transfer)
}

/// Writes the refined `mesh` to `-o` as the serial command does, for it and
/// for a distributed run gathered on rank 0: `parent` set to the input tet
/// holding each centroid, the mesh compacted, the point locations in the
/// input (for `.vtu` arrays, `--parent-map` and the transfer), the input's
/// fields carried over when `transfer`, and the `marked` array from
/// `selection` (per input tet).
pub(super) fn write_output(
    a: &Args,
    input: &tetrefine::TetMesh,
    mesh: &mut tetrefine::TetMesh,
    mut meta: tetrefine::io::MeshMeta,
    transfer: bool,
    selection: Option<&[bool]>,
) -> super::CliResult {
    locate_parents(input, mesh);
    mesh.compact();
    let is_vtu = tetrefine::io::Format::for_writing(&a.output).map_err(|e| e.to_string())?
        == tetrefine::io::Format::Vtu;
    let locations = (transfer || is_vtu || a.parent_map.is_some())
        .then(|| tetrefine::locate_points(input, mesh));
    if let (Some(path), Some(locs)) = (&a.parent_map, &locations) {
        super::transfer::write_parent_map(path, &|i| input.tet(locs[i].tet), mesh, locs)?;
    }
    // Whether the tet descends from a selected input tet (all do without a
    // selection).
    let sel = selection;
    let marked = |m: &tetrefine::TetMesh, t: u32| {
        let p = m.parent(t) as usize;
        i32::from(sel.is_none_or(|s| s.get(p).copied().unwrap_or(false)))
    };
    let options = tetrefine::io::WriteOptions {
        msh_format: a.msh_format,
    };
    // Names and tag lists stay valid through refinement (every child keeps its
    // parent's region and markers); the fields are carried over or dropped.
    let (point_fields, cell_fields) = match (&locations, transfer) {
        (Some(locs), true) => super::transfer::transfer_fields(input, mesh, &meta, locs),
        _ => (Vec::new(), Vec::new()),
    };
    let arrays = if is_vtu {
        let locs = locations.as_deref().unwrap_or(&[]);
        super::transfer::vtu_arrays(
            &|i| input.tet(locs[i].tet),
            locations.as_deref(),
            &point_fields,
            &cell_fields,
        )
    } else {
        (Vec::new(), Vec::new())
    };
    meta.point_fields = point_fields;
    meta.cell_fields = cell_fields;
    super::write_refined(
        &a.output,
        mesh,
        &[("marked", &marked)],
        &meta,
        &options,
        arrays,
    )?;
    Ok(())
}
