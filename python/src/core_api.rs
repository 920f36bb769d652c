//! # CORE API — the one place the Python package touches the `tetrefine` crate.
//!
//! Every `tetrefine::…` path used by the bindings is in this file (and
//! nowhere else in `python/src`), so that a change of the core's public API
//! (module renames, a curated `lib.rs`) is adapted here alone. The functions
//! take and return plain Rust data (vectors, strings of JSON, messages) and
//! know nothing of Python; `lib.rs` does the Python side.
//!
//! What each function does follows the CLI (`src/cli/*.rs`) step by step, so
//! that the package behaves as the command line does.

use std::path::Path;

use tetrefine::io::CellArray;
use tetrefine::refine_with;
use tetrefine::report::Histogram;
use tetrefine::report::DEFAULT_HIST_MAX_DEG;
use tetrefine::MeshData;
use tetrefine::MeshStats;
use tetrefine::{select, MarkStrategy};
use tetrefine::{Phase, Progress, RefineOptions};

/// The core's mesh store.
pub type TetMesh = tetrefine::TetMesh;

/// Default number of histogram bins of `quality --json` (1° bins over 0–71°).
pub const DEFAULT_BINS: usize = tetrefine::report::DEFAULT_BINS;

/// A mesh as plain arrays, 0-based, before validation.
#[derive(Default)]
pub struct Input {
    /// Vertex coordinates.
    pub points: Vec<[f64; 3]>,
    /// Four vertex ids per tet (any orientation).
    pub tets: Vec<[u32; 4]>,
    /// Region per tet (empty: all 0).
    pub regions: Vec<i32>,
    /// Marked triangles with their marker.
    pub faces: Vec<([u32; 3], i32)>,
    /// Feature edges with their marker.
    pub edges: Vec<([u32; 2], i32)>,
    /// Corner vertices.
    pub corners: Vec<u32>,
}

/// What building changed (the notes the CLI prints on stderr).
#[derive(Clone, Debug, Default)]
pub struct BuildNotes {
    /// Negatively oriented tets turned around.
    pub reoriented: usize,
    /// Points no tet uses.
    pub unreferenced_points: usize,
    /// Marked triangles that are no face of any tet (dropped).
    pub dropped_triangles: usize,
    /// Tagged edges that are no edge of any tet (dropped).
    pub dropped_edges: usize,
}

fn notes(r: &tetrefine::BuildReport) -> BuildNotes {
    BuildNotes {
        reoriented: r.reoriented,
        unreferenced_points: r.unreferenced_points,
        dropped_triangles: r.dropped_triangles,
        dropped_edges: r.dropped_edges,
    }
}

/// Why arrays could not be built into a mesh: the library's message, and the
/// 1-based tet it names, if any.
pub struct BuildFailure {
    /// The library's message (the same as the file readers give).
    pub message: String,
    /// 1-based tet number the message refers to.
    pub tet: Option<usize>,
}

/// Builds the store from arrays through the library's own path
/// (`TetMesh::from_data`, as every file reader does), then compacts it so
/// that slot `i` is the `i`-th tet.
pub fn build(input: Input) -> Result<(TetMesh, BuildNotes), BuildFailure> {
    use tetrefine::MeshError as E;
    let data = MeshData {
        points: input.points,
        tets: input.tets,
        tet_regions: input.regions,
        triangles: input.faces,
        edges: input.edges,
        corners: input.corners,
        ..Default::default()
    };
    match TetMesh::from_data(&data) {
        Ok((mut mesh, report)) => {
            drop(data);
            mesh.compact();
            Ok((mesh, notes(&report)))
        }
        Err(e) => {
            let tet = match &e {
                E::IndexOutOfRange { at, .. }
                | E::RepeatedVertex { at, .. }
                | E::ZeroVolume { at }
                | E::DuplicateTet { at, .. }
                | E::NonManifoldFace { at, .. }
                | E::Overlap { at, .. } => Some(at.tet),
                _ => None,
            };
            Err(BuildFailure {
                message: e.to_string(),
                tet,
            })
        }
    }
}

/// Reads a mesh file (format by extension, as the CLI) and compacts it.
pub fn read(path: &Path) -> Result<(TetMesh, BuildNotes), String> {
    let (mut mesh, report) = tetrefine::io::load_mesh(path).map_err(|e| e.to_string())?;
    mesh.compact();
    Ok((mesh, notes(&report)))
}

/// Refuses an output extension the writers do not know, before any work.
pub fn check_output_path(path: &Path) -> Result<(), String> {
    tetrefine::io::Format::for_writing(path)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Writes a (compact) mesh; a `.vtu` also carries `level`, `parent` and
/// `marked` cell arrays, as `tetrefine refine` writes them (`parents`
/// replaces the store's own values when given).
pub fn write(
    path: &Path,
    mesh: &TetMesh,
    parents: Option<&[u32]>,
    marked: Option<&[bool]>,
) -> Result<(), String> {
    check_output_path(path)?;
    let is_vtu = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
    if is_vtu {
        let n = mesh.n_tets();
        let level = |i: usize| i32::from(mesh.level(i as u32));
        let parent = |i: usize| match parents {
            Some(p) => p[i] as i32,
            None => mesh.parent(i as u32) as i32,
        };
        let mark = |i: usize| i32::from(marked.is_some_and(|m| m[i]));
        let cells = [
            CellArray::Int32With("level".into(), n, &level),
            CellArray::Int32With("parent".into(), n, &parent),
            CellArray::Int32With("marked".into(), n, &mark),
        ];
        tetrefine::io::write_vtu(path, mesh, None, &cells).map_err(|e| e.to_string())
    } else {
        tetrefine::io::write_mesh(path, mesh).map_err(|e| e.to_string())
    }
}

const _: () = assert!(std::mem::size_of::<glam::DVec3>() == 3 * std::mem::size_of::<f64>());

/// The points of the store as `[x, y, z]` rows, borrowed (no copy).
pub fn points(mesh: &TetMesh) -> &[[f64; 3]] {
    let p = mesh.points();
    // SAFETY: glam's `DVec3` is `#[repr(C)] { x, y, z: f64 }` (size checked
    // above), so a slice of them is a slice of `[f64; 3]`.
    unsafe { std::slice::from_raw_parts(p.as_ptr().cast::<[f64; 3]>(), p.len()) }
}

/// The tets of a compact store, borrowed (no copy; slot `i` is tet `i`).
pub fn tets(mesh: &TetMesh) -> &[[u32; 4]] {
    debug_assert_eq!(mesh.n_tet_slots(), mesh.n_tets());
    mesh.tet_slots()
}

/// Number of tets.
pub fn n_tets(mesh: &TetMesh) -> usize {
    mesh.n_tets()
}

/// Number of points.
pub fn n_points(mesh: &TetMesh) -> usize {
    mesh.n_points()
}

/// Region per tet.
pub fn regions(mesh: &TetMesh) -> Vec<i32> {
    mesh.tet_ids().map(|t| mesh.region(t)).collect()
}

/// Refinement level per tet (0 for input tets).
pub fn levels(mesh: &TetMesh) -> Vec<u8> {
    mesh.tet_ids().map(|t| mesh.level(t)).collect()
}

/// Parent per tet: the input tet holding its centroid after `refine`.
pub fn parents(mesh: &TetMesh) -> Vec<u32> {
    mesh.tet_ids().map(|t| mesh.parent(t)).collect()
}

/// Marked triangles (sorted vertex triples, in sorted order) and markers.
pub fn marked_faces(mesh: &TetMesh) -> Vec<([u32; 3], i32)> {
    let mut v: Vec<([u32; 3], i32)> = mesh.face_markers().iter().map(|(k, &m)| (*k, m)).collect();
    v.sort_unstable();
    v
}

/// Feature edges (sorted pairs, in sorted order) and markers.
pub fn feature_edges(mesh: &TetMesh) -> Vec<([u32; 2], i32)> {
    let mut v: Vec<([u32; 2], i32)> = mesh.feature_edges().iter().map(|(k, &m)| (*k, m)).collect();
    v.sort_unstable();
    v
}

/// Corner vertices, sorted.
pub fn corners(mesh: &TetMesh) -> Vec<u32> {
    let mut v: Vec<u32> = mesh.corners().iter().copied().collect();
    v.sort_unstable();
    v
}

/// `quality --json` of the mesh with `bins` histogram bins over 0–71°.
pub fn quality_json(mesh: &TetMesh, bins: usize) -> String {
    let stats = MeshStats::compute_with(mesh, Histogram::new(0.0, DEFAULT_HIST_MAX_DEG, bins));
    serde_json::to_string(&stats).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
}

/// Per tet: minimum and maximum dihedral angle (degrees), the paper's
/// quality (min sine of the signed dihedral angles) and the signed volume —
/// the cell arrays of the `.vtu` writer.
pub fn tet_quality(mesh: &TetMesh) -> [Vec<f64>; 4] {
    use rayon::prelude::*;
    use tetrefine::geom::{tet_quality, tet_volume};
    let per: Vec<[f64; 4]> = (0..mesh.n_tets() as u32)
        .into_par_iter()
        .map(|t| {
            let p = mesh.tet_points(t);
            let q = tet_quality(&p);
            [
                q.min_dihedral_deg,
                q.max_dihedral_deg,
                q.min_sine,
                tet_volume(&p),
            ]
        })
        .collect();
    [0, 1, 2, 3].map(|k| per.iter().map(|q| q[k]).collect())
}

/// Options of [`refine`], the flags of `tetrefine refine`.
pub struct RefineArgs {
    /// `--steps`.
    pub steps: usize,
    /// `--boundary`.
    pub boundary: String,
    /// `--opt-passes`.
    pub opt_passes: usize,
    /// `--threshold`.
    pub threshold: f64,
    /// `--stop-after`.
    pub stop_after: Option<String>,
    /// `--features auto|none|FILE`.
    pub features: String,
    /// `--feature-angle`.
    pub feature_angle: f64,
    /// The `--mark` specs (already joined with the geometric selections).
    pub marks: Vec<String>,
    /// `--smooth refined` (true) or `all`.
    pub smooth_refined: bool,
    /// `--step-offset`.
    pub step_offset: usize,
    /// Also compute `quality --json` after every step.
    pub stats: bool,
    /// `--allow-empty`: a selection of no tet is not an error.
    pub allow_empty: bool,
    /// `--allow-steps-zero`: `steps = 0` is not an error.
    pub allow_steps_zero: bool,
    /// `--effort fast|default|best`.
    pub effort: String,
    /// `--hausd`.
    pub hausd: Option<f64>,
    /// `--interfaces linear|sqrt3`.
    pub interfaces: String,
    /// `--steps auto` (then `steps` is the cap, [`AUTO_SIZE_PASSES`]).
    pub steps_auto: bool,
    /// `--size` / `--size-array`: components (1 or 6) and values per point.
    pub size: Option<(usize, Vec<f64>)>,
    /// `--hsiz`.
    pub hsiz: Option<f64>,
    /// `--hmax`.
    pub hmax: Option<f64>,
    /// The input's point fields (`--fields`, `.vtu` point data).
    pub point_fields: Vec<FieldIn>,
    /// The input's cell fields, per input tet.
    pub cell_fields: Vec<FieldIn>,
    /// Carry the fields over (`--transfer`; `false`: `--no-transfer`).
    pub transfer: bool,
    /// Compute the vertex parent map (`--parent-map`) even without fields.
    pub vertex_parents: bool,
}

/// Size passes of `steps="auto"` at most (the CLI's `--steps auto` cap).
pub const AUTO_SIZE_PASSES: usize = tetrefine::AUTO_SIZE_PASSES;

/// A named field: `components` values per entry, entry after entry.
#[derive(Clone, Debug)]
pub struct FieldIn {
    /// The field's name.
    pub name: String,
    /// Values per entry.
    pub components: usize,
    /// The values.
    pub values: Vec<f64>,
}

/// The vertex parent map (the CLI's `--parent-map` points section and
/// `.vtu` arrays `parent_tet`, `parent_vertices`, `parent_bary`,
/// `parent_outside`), per output point.
#[derive(Clone, Debug, Default)]
pub struct VertexParents {
    /// The input tet holding the point (or nearest to it).
    pub tet: Vec<u32>,
    /// That tet's four vertices.
    pub vertices: Vec<[u32; 4]>,
    /// The point's barycentric coordinates for them.
    pub bary: Vec<[f64; 4]>,
    /// The point lies outside the input; `bary` give the nearest input
    /// boundary point.
    pub outside: Vec<bool>,
}

/// What went wrong in [`refine`]: bad options (a `ValueError`) or a file.
pub enum RefineError {
    /// An option or the indicator is invalid.
    Value(String),
    /// A feature-edge file could not be read.
    File(String),
}

/// The result of [`refine`].
pub struct Refined {
    /// The refined mesh, compact; its `parent` values are the library's
    /// nearby-tet hints until [`locate`] places them.
    pub mesh: TetMesh,
    /// Per input tet: was it selected? (`None`: uniform refinement.)
    pub selection: Option<Vec<bool>>,
    /// Per step: the step report as JSON (phases, counts, seconds), with the
    /// `quality --json` fields when asked for.
    pub steps: Vec<String>,
    /// Wall seconds of the work around the steps, as JSON: copy of the
    /// input, feature detection, the steps, parent location, compaction and
    /// the `marked` array.
    pub timings: String,
    /// The parents and marked flags, when the transfer located them already.
    pub located: Option<(Vec<u32>, Vec<bool>)>,
    /// The point fields carried over (empty without transfer).
    pub point_fields: Vec<FieldIn>,
    /// The cell fields carried over.
    pub cell_fields: Vec<FieldIn>,
    /// The vertex parent map, when fields were carried over or it was asked for.
    pub vertex_parents: Option<VertexParents>,
}

/// Checks the fields against the mesh: `n` entries of finite values each.
fn check_fields(fields: &[FieldIn], n: usize, what: &str, arg: &str) -> Result<(), String> {
    for f in fields {
        if f.components == 0 || f.values.len() != n * f.components {
            return Err(format!(
                "{arg}[{:?}] has {} rows but the mesh has {n} {what}",
                f.name,
                f.values.len() / f.components.max(1)
            ));
        }
        if let Some(i) = f.values.iter().position(|x| !x.is_finite()) {
            return Err(format!(
                "{arg}[{:?}]: value {} at row {} is not a finite number",
                f.name,
                f.values[i],
                i / f.components
            ));
        }
    }
    Ok(())
}

/// The size map of `size=` / `hsiz=` / `hmax=` over the points of `input`
/// (the CLI's `--size-array`, `--hsiz`, `--hmax`: the library's
/// [`tetrefine::SizeMap::from_values`] and [`tetrefine::SizeMap::cap`]).
fn size_map(a: &RefineArgs, input: &TetMesh) -> Result<Option<tetrefine::SizeMap>, String> {
    use tetrefine::SizeMap;
    for (name, h) in [("hsiz", a.hsiz), ("hmax", a.hmax)] {
        if let Some(h) = h {
            if !(h > 0.0 && h.is_finite()) {
                return Err(format!("{name}={h} must be a positive length"));
            }
        }
    }
    if a.size.is_some() && a.hsiz.is_some() {
        return Err("give one size: size=... or hsiz=... (hmax caps either)".into());
    }
    let n = input.n_points();
    let mut map = match &a.size {
        Some((components, values)) => {
            if values.len() != n * components {
                return Err(format!(
                    "size has {} rows but the mesh has {n} points",
                    values.len() / components.max(&1)
                ));
            }
            Some(SizeMap::from_values(*components, values).map_err(|e| format!("size: {e}"))?)
        }
        None => a.hsiz.map(|h| SizeMap::Iso(vec![h; n])),
    };
    if let Some(h) = a.hmax {
        match map.as_mut() {
            Some(m) => m.cap(h),
            None => map = Some(SizeMap::Iso(vec![h; n])),
        }
    }
    Ok(map)
}

/// Called at the start of every phase with (1-based step, phase name, live
/// tets). It may unwind (`std::panic::resume_unwind`) to cancel the run.
pub type PhaseHook<'a> = dyn Fn(usize, &str, u64) + Sync + 'a;

struct HookProgress<'a> {
    hook: &'a PhaseHook<'a>,
    step: std::sync::atomic::AtomicUsize,
}

impl Progress for HookProgress<'_> {
    fn phase_start(&self, phase: Phase, total: u64) {
        use std::sync::atomic::Ordering::Relaxed;
        // Every step begins with the split phase.
        if phase == Phase::Split {
            self.step.fetch_add(1, Relaxed);
        }
        let step = self.step.load(Relaxed);
        (self.hook)(step, phase.name(), total);
    }

    fn step_again(&self, _phases: u64) {
        // The retry begins with the split phase again: same step.
        self.step.fetch_sub(1, std::sync::atomic::Ordering::Relaxed);
    }
}

/// The union of the marking specs, or `None` for uniform refinement (the
/// CLI's `mark_strategy`, with the Python argument names).
fn strategy(marks: &[String], have_indicator: bool) -> Result<Option<MarkStrategy>, String> {
    if marks.is_empty() {
        return Ok(None);
    }
    let parts = marks
        .iter()
        .map(|s| {
            s.parse::<MarkStrategy>()
                .map_err(|e| format!("mark={s:?}: {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let st = MarkStrategy::union(parts);
    if st.needs_indicator() && !have_indicator {
        return Err(format!(
            "mark {st} needs an indicator array (indicator=...)"
        ));
    }
    Ok(Some(st))
}

/// `tetrefine refine` on a copy of `input`: the same validation, marking,
/// feature handling, steps, parent location and compaction as the CLI.
pub fn refine(
    input: &TetMesh,
    a: &RefineArgs,
    indicator: Option<&[f64]>,
    hook: &PhaseHook<'_>,
) -> Result<Refined, RefineError> {
    use RefineError::{File, Value};
    let boundary = a
        .boundary
        .parse()
        .map_err(|e| Value(format!("boundary: {e}")))?;
    let interfaces: tetrefine::InterfaceRule = a
        .interfaces
        .parse()
        .map_err(|e| Value(format!("interfaces: {e}")))?;
    let stop_after = match &a.stop_after {
        Some(p) => Some(
            p.parse::<Phase>()
                .map_err(|e| Value(format!("stop_after: {e}")))?,
        ),
        None => None,
    };
    if !(a.threshold > 0.0 && a.threshold < 1.0) {
        return Err(Value(format!(
            "threshold={} must lie in (0, 1) (a sine)",
            a.threshold
        )));
    }
    if !(a.feature_angle > 0.0 && a.feature_angle < 180.0) {
        return Err(Value(format!(
            "feature_angle={} must lie in (0, 180) degrees",
            a.feature_angle
        )));
    }
    if a.steps == 0 && !a.allow_steps_zero {
        return Err(Value(
            "steps=0 refines nothing; give steps >= 1 (or allow_steps_zero=True to get the mesh unrefined)".into(),
        ));
    }
    let size = size_map(a, input).map_err(Value)?;
    if size.is_some() {
        if !a.marks.is_empty() || indicator.is_some() {
            return Err(Value("a size map chooses what to refine itself: drop indicator/mark/region/box/sphere, or the size arguments".into()));
        }
        if stop_after.is_some() {
            return Err(Value(
                "stop_after names a phase of the √3 step; size-driven refinement has none".into(),
            ));
        }
    } else if a.steps_auto {
        return Err(Value("steps='auto' refines until every edge meets a size map: give size=..., hsiz=... or hmax=...".into()));
    }
    check_fields(&a.point_fields, input.n_points(), "points", "point_fields").map_err(Value)?;
    check_fields(&a.cell_fields, input.n_tets(), "tets", "cell_fields").map_err(Value)?;
    let has_fields = !a.point_fields.is_empty() || !a.cell_fields.is_empty();
    if a.transfer && !has_fields {
        return Err(Value(
            "transfer=True: the mesh carries no point or cell field (give point_fields= or cell_fields=)".into(),
        ));
    }
    let st = strategy(&a.marks, indicator.is_some()).map_err(Value)?;
    let selection = match &st {
        Some(st) => {
            let sel = select(st, indicator, input).map_err(|e| Value(format!("mark {st}: {e}")))?;
            if !a.allow_empty && !sel.iter().any(|&x| x) {
                return Err(Value(format!(
                    "mark {st} selects none of the {} tets; nothing would be refined (allow_empty=True returns the mesh unrefined)",
                    input.n_tets()
                )));
            }
            Some(sel)
        }
        None => None,
    };
    // One copy: the input stays as it is (the Python object is immutable)
    // and serves to locate the parents afterwards.
    let clock = std::time::Instant::now();
    let mut lap = {
        let mut last = clock.elapsed();
        move || {
            let now = clock.elapsed();
            let d = (now - last).as_secs_f64();
            last = now;
            d
        }
    };
    let mut mesh = input.clone();
    let t_copy = lap();
    {
        use tetrefine::detect_features_for;
        use tetrefine::io::read_edge_list;
        match a.features.as_str() {
            "none" => mesh.clear_features(),
            "auto" => {
                detect_features_for(&mut mesh, a.feature_angle, interfaces);
            }
            file => {
                read_edge_list(&mut mesh, Path::new(file)).map_err(|e| File(e.to_string()))?;
            }
        }
    }
    let t_features = lap();
    let opts = RefineOptions {
        boundary,
        opt_passes: a.opt_passes,
        threshold: a.threshold,
        stop_after,
        selection: selection.clone(),
        smooth_refined_only: selection.is_some() && a.smooth_refined,
        step_offset: a.step_offset,
        check_each_phase: false,
        effort: a
            .effort
            .parse::<tetrefine::Effort>()
            .map_err(|e| Value(format!("effort={:?}: {e}", a.effort)))?,
        hausd: match a.hausd {
            Some(h) if !(h.is_finite() && h >= 0.0) => {
                return Err(Value(format!("hausd={h} must be a finite distance >= 0")))
            }
            h => h,
        },
        interfaces,
    };
    let progress = HookProgress {
        hook,
        step: std::sync::atomic::AtomicUsize::new(0),
    };
    let mut steps = Vec::with_capacity(a.steps);
    // The library's step loop (the CLI's too): it selects the descendants of
    // the selection for every later step.
    let with_stats = |mut value: serde_json::Value, m: &TetMesh| {
        if a.stats {
            let stats = serde_json::to_value(MeshStats::compute(m)).unwrap_or_default();
            if let (Some(obj), serde_json::Value::Object(q)) = (value.as_object_mut(), stats) {
                obj.insert("quality".into(), serde_json::Value::Object(q));
            }
        }
        value.to_string()
    };
    if let Some(mut size) = size {
        // The CLI's size loop: the floor is each pass's worst tet at its
        // start (in the metric), the optimize phase after each pass; `auto`
        // stops when no edge is long or no split was possible.
        let sopts = tetrefine::SizeOptions {
            quality_floor: None,
            // `effort`, `hausd` and the boundary rule as the √3 step's
            // optimize phase.
            improve: tetrefine::size_improve_options(
                opts.effort,
                a.opt_passes,
                a.threshold,
                opts.hausd,
                opts.boundary,
            ),
        };
        for s in 1..=a.steps {
            hook(s, "size", mesh.n_tets() as u64);
            let t = std::time::Instant::now();
            let r = tetrefine::size_pass(&mut mesh, &mut size, &sopts);
            let value = serde_json::json!({
                "size_pass": s,
                "long_edges": r.long_edges,
                "split": r.split,
                "refused": r.refused,
                "long_after": r.long_after,
                "tets": mesh.n_tets(),
                "seconds": t.elapsed().as_secs_f64(),
            });
            steps.push(with_stats(value, &mesh));
            if a.steps_auto && (r.long_after == 0 || r.split == 0) {
                break;
            }
        }
    } else {
        // The library's step loop (the CLI's too): it selects the descendants of
        // the selection for every later step.
        refine_with(&mut mesh, a.steps, &opts, &progress, |_, m, report| {
            let value = serde_json::to_value(&report).unwrap_or_default();
            steps.push(with_stats(value, m));
        });
    }
    let t_steps = lap();
    mesh.compact();
    let t_compact = lap();
    // The CLI's transfer: parents located, every output point located in
    // the input, point fields interpolated there, cell fields copied from
    // the parents.
    let transfer = has_fields && a.transfer;
    let mut located = None;
    let mut vertex_parents = None;
    let (mut point_fields, mut cell_fields) = (Vec::new(), Vec::new());
    if transfer || a.vertex_parents {
        let (parents, marked) = locate(input, &mesh, selection.as_deref());
        let locs = tetrefine::locate_points(input, &mesh);
        if transfer {
            point_fields = a
                .point_fields
                .iter()
                .map(|f| FieldIn {
                    name: f.name.clone(),
                    components: f.components,
                    values: tetrefine::interpolate_point_field(
                        input.tet_slots(),
                        &locs,
                        &f.values,
                        f.components,
                    ),
                })
                .collect();
            cell_fields = a
                .cell_fields
                .iter()
                .map(|f| FieldIn {
                    name: f.name.clone(),
                    components: f.components,
                    values: tetrefine::copy_cell_field(&parents, &f.values, f.components),
                })
                .collect();
        }
        vertex_parents = Some(VertexParents {
            tet: locs.iter().map(|l| l.tet).collect(),
            vertices: locs.iter().map(|l| input.tet(l.tet)).collect(),
            bary: locs.iter().map(|l| l.bary).collect(),
            outside: locs.iter().map(|l| l.outside).collect(),
        });
        located = Some((parents, marked));
    }
    let t_transfer = lap();
    let mut timings = serde_json::json!({
        "copy": t_copy,
        "features": t_features,
        "steps": t_steps,
        "compact": t_compact,
    });
    if located.is_some() {
        timings["transfer"] = serde_json::json!(t_transfer);
    }
    let timings = timings.to_string();
    Ok(Refined {
        mesh,
        selection,
        steps,
        timings,
        located,
        point_fields,
        cell_fields,
        vertex_parents,
    })
}

/// The parents of a refined mesh (`tetrefine refine`'s `locate_parents`:
/// the input tet holding each tet's centroid, found by the library's walk
/// from the step's hint) and the `marked` flags they give: does the tet
/// descend from a selected input tet. The CLI does this after the steps; the
/// package does it on first use of `parent`, `marked` or a `.vtu` write.
pub fn locate(
    input: &TetMesh,
    mesh: &TetMesh,
    selection: Option<&[bool]>,
) -> (Vec<u32>, Vec<bool>) {
    use rayon::prelude::*;
    use tetrefine::walk_to;
    let first = input.tet_ids().next().unwrap_or(0);
    let parents: Vec<u32> = (0..mesh.n_tets() as u32)
        .into_par_iter()
        .with_min_len(1024)
        .map(|t| {
            let p = mesh.tet_points(t);
            let c = (p[0] + p[1] + p[2] + p[3]) * 0.25;
            let hint = mesh.parent(t);
            let start = if (hint as usize) < input.n_tet_slots() && input.is_alive(hint) {
                hint
            } else {
                first
            };
            walk_to(input, start, c)
        })
        .collect();
    let marked = parents
        .iter()
        .map(|&p| selection.is_none_or(|s| s.get(p as usize).copied().unwrap_or(false)))
        .collect();
    (parents, marked)
}

/// `tetrefine improve`: edge removal and smoothing, boundary fixed, on a
/// copy; the report as JSON.
/// The options of [`improve`], as `tetrefine improve` takes them.
pub struct ImproveArgs {
    /// `--opt-passes`.
    pub passes: usize,
    /// Optimisation bar (min sine).
    pub threshold: f64,
    /// `--effort`.
    pub effort: String,
    /// `--hausd`.
    pub hausd: Option<f64>,
    /// `--features auto|none`.
    pub features: String,
    /// `--feature-angle`.
    pub feature_angle: f64,
}

/// `tetrefine improve`: features as `--features` says, then the optimize
/// phase at the given effort.
pub fn improve(input: &TetMesh, a: &ImproveArgs) -> Result<(TetMesh, String), String> {
    let threshold = a.threshold;
    if !(threshold > 0.0 && threshold < 1.0) {
        return Err(format!("threshold={threshold} must lie in (0, 1) (a sine)"));
    }
    let effort: tetrefine::Effort = a
        .effort
        .parse()
        .map_err(|e| format!("effort={:?}: {e}", a.effort))?;
    if let Some(h) = a.hausd {
        if !(h.is_finite() && h >= 0.0) {
            return Err(format!("hausd={h} must be a finite distance >= 0"));
        }
    }
    let mut mesh = input.clone();
    match a.features.as_str() {
        "none" => mesh.clear_features(),
        "auto" => {
            tetrefine::detect_features(&mut mesh, a.feature_angle);
        }
        other => return Err(format!("features={other:?}: use 'auto' or 'none'")),
    }
    let report = tetrefine::improve(
        &mut mesh,
        &effort.improve_options(a.passes, threshold, a.hausd),
    );
    mesh.compact();
    Ok((mesh, serde_json::to_string(&report).unwrap_or_default()))
}

/// `tetrefine bisect`: `steps` uniform 1:8 red refinements; per step a JSON
/// `{"tets", "points", "seconds"}`.
pub fn bisect(input: &TetMesh, steps: usize) -> Result<(TetMesh, Vec<String>), String> {
    let mut mesh = input.clone();
    let mut reports = Vec::new();
    for s in 1..=steps {
        let t0 = std::time::Instant::now();
        mesh = tetrefine::bisect(&mesh).map_err(|e| format!("step {s}: {e}"))?;
        mesh.compact();
        reports.push(
            serde_json::json!({
                "tets": mesh.n_tets(),
                "points": mesh.n_points(),
                "seconds": t0.elapsed().as_secs_f64(),
            })
            .to_string(),
        );
    }
    Ok((mesh, reports))
}

/// The surface TetGen fills: a file, or points and triangles.
#[cfg(feature = "tetgen")]
pub enum Surface<'a> {
    /// A `.poly`, `.smesh`, `.off`, `.stl` or triangles-only `.mesh` file.
    File(&'a Path),
    /// Points and triangles with facet markers.
    Triangles(Vec<[f64; 3]>, Vec<([u32; 3], i32)>),
}

/// Options of [`mesh_surface`] (the flags of `tetrefine mesh`).
#[cfg(feature = "tetgen")]
pub struct MeshArgs {
    /// `--min-ratio`.
    pub min_ratio: Option<f64>,
    /// `--min-dihedral`.
    pub min_dihedral: Option<f64>,
    /// `--max-volume`.
    pub max_volume: Option<f64>,
    /// `--switches`.
    pub switches: Option<String>,
    /// `--time-limit` in seconds (`None`: no limit).
    pub time_limit: Option<f64>,
}

/// Why [`mesh_surface`] failed, by the Python exception it becomes.
#[cfg(feature = "tetgen")]
pub enum MeshError {
    /// The surface file cannot be read (`OSError`).
    File(String),
    /// A bad option or surface, or a TetGen error (`ValueError`).
    Value(String),
    /// TetGen ran past the time limit and was stopped (`TimeoutError`).
    Timeout(String),
    /// TetGen's process died by a signal, or could not be run (`RuntimeError`).
    Crash(String),
}

/// `tetrefine mesh`: fills a closed surface with TetGen, which runs in a
/// child process (a crash of TetGen is an error, never the end of the
/// interpreter) under the optional time limit. The messages of a timeout or
/// a crash name the surface (its path, or its size for arrays).
#[cfg(feature = "tetgen")]
pub fn mesh_surface(surface: Surface<'_>, a: MeshArgs) -> Result<TetMesh, MeshError> {
    use std::time::Duration;
    use tetrefine::io::Plc;
    use tetrefine::tetgen::{switches, tetrahedralize, Isolation, Options, TetgenError};
    let time_limit = match a.time_limit {
        None => None,
        Some(t) if t.is_finite() && t > 0.0 && t < 1e9 => {
            Some(Duration::from_secs_f64(t).max(Duration::from_nanos(1)))
        }
        Some(t) => {
            return Err(MeshError::Value(format!(
                "time_limit={t}: give a positive number of seconds, or None for no limit"
            )))
        }
    };
    let opts = Options {
        min_ratio: a.min_ratio,
        min_dihedral: a.min_dihedral,
        max_volume: a.max_volume,
        switches: a.switches,
        size_field: None,
        isolation: Isolation::Child { time_limit },
    };
    switches(&opts, false, "").map_err(|e| MeshError::Value(e.to_string()))?;
    let (plc, name) = match surface {
        Surface::File(p) => match Plc::read(p) {
            Ok(plc) => (plc, p.display().to_string()),
            Err(e) => return Err(MeshError::File(e.to_string())),
        },
        Surface::Triangles(points, tris) => {
            let name = format!(
                "the surface of {} points and {} triangles",
                points.len(),
                tris.len()
            );
            (Plc::from_triangles(points, &tris), name)
        }
    };
    let mut mesh = tetrahedralize(&plc, &opts).map_err(|e| match e {
        TetgenError::TimedOut { .. } => MeshError::Timeout(format!(
            "{name}: {e}: time_limit={} (a looser quality bound or a larger maximum volume finishes sooner)",
            a.time_limit.unwrap_or(0.0)
        )),
        TetgenError::Crashed { .. } | TetgenError::Child(_) => {
            MeshError::Crash(format!("{name}: {e}"))
        }
        e => MeshError::Value(e.to_string()),
    })?;
    mesh.compact();
    Ok(mesh)
}
