//! The phases of one √3 step (see the module docs of [`crate::refine`](mod@crate::refine)).

use super::{InterfaceRule, NoProgress, Phase, PhaseReport, Progress, RefineOptions, StepReport};
use crate::improve::{
    improve, split_long_edges, ImproveOptions, ImproveReport, LengthCap, LongEdgeSplits,
};
use crate::mesh::ball_stays_positive;
use crate::mesh::fasthash::FastHashMap;
use crate::mesh::partition::{canonical_centroid, partition_edges, PartitionMarker};
use crate::mesh::{edge_key, TetMarks, TetMesh, NO_ADJ};
use crate::ops::{
    flip23_bulk, is_selected, make_flips_valid, remove_edge, remove_interface_edge, split14_bulk,
    split_boundary_face, split_interface_face, trisect_edge, EdgeRing, FlipBatch,
};
use crate::stencil::sqrt3_positions_trisecting;
use crate::topo::TET_EDGES;
use glam::DVec3;
use std::collections::HashSet;
use std::time::Instant;

/// Runs `steps` refinement steps; one report per step.
///
/// With a selection (adaptive refinement, the √3 paper's §6), step 1 splits
/// the selected tets and every later step splits their descendants again —
/// the tets whose `level` the previous step raised — so the selected zone is
/// refined `steps` times (the paper's Figure 13).
pub fn refine(mesh: &mut TetMesh, steps: usize, opts: &RefineOptions) -> Vec<StepReport> {
    let mut reports = Vec::with_capacity(steps);
    refine_with(mesh, steps, opts, &NoProgress, |_, _, r| reports.push(r));
    reports
}

/// [`refine`] with progress callbacks and a callback after every step:
/// `on_step(step, mesh, report)` sees the mesh as the 1-based `step` left it
/// (statistics, intermediate files) before the next step begins.
pub fn refine_with(
    mesh: &mut TetMesh,
    steps: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
    on_step: impl FnMut(usize, &TetMesh, StepReport),
) {
    let never = |_: usize, _: &TetMesh, _: u64| Ok::<(), std::convert::Infallible>(());
    let Ok(()) = refine_with_guard(mesh, steps, opts, progress, never, on_step);
}

/// [`refine_with`] with a guard before every step: `before_step(step, mesh,
/// split)` sees the mesh and how many of its tets the step will split, and
/// an `Err` stops the refinement there (the mesh is as the previous step
/// left it) and is returned — e.g. a step whose memory would not fit.
pub fn refine_with_guard<E>(
    mesh: &mut TetMesh,
    steps: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
    mut before_step: impl FnMut(usize, &TetMesh, u64) -> Result<(), E>,
    mut on_step: impl FnMut(usize, &TetMesh, StepReport),
) -> Result<(), E> {
    let mut step_opts = opts.clone();
    // Every step keeps the worst of the mesh the run was given (see
    // [`step_keeping`]); the first finds it itself.
    let keep = (steps > 1).then(|| worst_dihedral(mesh));
    for s in 1..=steps {
        if s > 1 && opts.selection.is_some() {
            step_opts.selection = Some(descendants_of_last_step(mesh, s - 1));
        }
        let sel = step_opts.selection.as_deref();
        let split = (0..mesh.n_tet_slots())
            .filter(|&t| mesh.is_alive(t as u32) && is_selected(sel, t))
            .count();
        before_step(s, mesh, split as u64)?;
        let report = step_keeping(mesh, s, &step_opts, progress, keep.filter(|_| s > 1));
        on_step(s, mesh, report);
    }
    Ok(())
}

/// Per tet slot: was it refined in step `step` (its level is `step`)? With a
/// selection, only refined tets reach the step's level.
pub fn descendants_of_last_step(mesh: &TetMesh, step: usize) -> Vec<bool> {
    (0..mesh.n_tet_slots() as u32)
        .map(|t| mesh.is_alive(t) && usize::from(mesh.level(t)) >= step)
        .collect()
}

/// State carried from phase to phase within one step.
struct StepState {
    /// Points with ids at or above this are the barycentres of this step.
    first_barycentre: u32,
    /// Points with ids at or above this are the face points of this step.
    first_face_point: u32,
    /// Old boundary faces that were split, outward-oriented, with their new point.
    split_faces: Vec<([u32; 3], u32)>,
    /// Old interface faces between two regions that were split, with their
    /// new point, oriented outward from the lower region (one orientation per
    /// interface patch, as the √3 stencils need).
    region_interfaces: Vec<([u32; 3], u32)>,
    /// Old marked faces inside one region that were split, with their new
    /// point (always refined linearly).
    marked_interfaces: Vec<([u32; 3], u32)>,
    /// Old partition faces ([`crate::mesh::partition`]) that were split, with
    /// their new point: linear, never flipped, never moved.
    partition_faces: Vec<([u32; 3], u32)>,
    /// Edges of every old partition face, split or not: never flipped nor
    /// trisected (the other side of the cut could not follow).
    partition_edges: HashSet<[u32; 2]>,
    /// 1-based step number: feature edges are kept in odd steps and trisected
    /// in even ones.
    step: usize,
    /// Feature edges as they were when the step began (the old surface's
    /// creases, which the √3 stencils must see even after trisection).
    creases: HashSet<[u32; 2]>,
    /// Old feature edges trisected in this step.
    trisected: HashSet<[u32; 2]>,
}

/// One √3 step. `step` is 1-based (odd and even steps differ on creases).
pub fn refine_step(mesh: &mut TetMesh, step: usize, opts: &RefineOptions) -> StepReport {
    refine_step_with_progress(mesh, step, opts, &NoProgress)
}

/// [`refine_step`] with progress callbacks.
pub fn refine_step_with_progress(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
) -> StepReport {
    step_keeping(mesh, step, opts, progress, None)
}

/// [`refine_step_with_progress`], keeping the worst dihedral angle `keep`
/// (radians; `None`: the worst of `mesh` as the step finds it). The
/// optimize phase aims at the step's own input's worst (its floor), but
/// the promise is to the mesh a run was given: in a run of several steps,
/// a later step that ends between the two keeps its result.
fn step_keeping(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
    keep: Option<f64>,
) -> StepReport {
    let start = Instant::now();
    // The input's worst, before the phases change the mesh; only a step
    // that reaches the optimize phase with passes to run needs it.
    let optimizes = opts.opt_passes > 0 && matches!(opts.stop_after, None | Some(Phase::Optimize));
    let worst_in = if optimizes { worst_dihedral(mesh) } else { 0.0 };
    let floor = worst_in.sin().max(0.0);
    // A later step whose input is already below `keep` is held to its
    // input's worst: the tets below `keep` there are not of its making.
    let keep = if optimizes {
        keep.map_or(worst_in, |k| k.min(worst_in))
    } else {
        0.0
    };
    // A worst within the optimizer's reach is kept: if the phases leave a
    // tet below it, the step starts again from its input with the input
    // tets around the fault held back (not split), for up to `HOLD_ROUNDS`
    // rounds while each raises the worst. Not on a part of a distributed
    // mesh, whose neighbour across the cut would split the faces it shares.
    let keeps = keep > 0.0 && keep.sin() <= FLOOR_BAR_CAP && partition_edges(mesh).is_empty();
    let input = keeps.then(|| mesh.clone());
    let mut report = step_phases(mesh, step, opts, progress, floor);
    if let Some(input) = input {
        let selected =
            |t: usize| input.is_alive(t as u32) && is_selected(opts.selection.as_deref(), t);
        let n_selected = (0..input.n_tet_slots()).filter(|&t| selected(t)).count();
        let mut held = vec![false; input.n_tet_slots()];
        // The last attempt, which missed `keep` but had the highest worst
        // so far: holding back can also make things worse.
        let mut best: Option<(f64, TetMesh, StepReport)> = None;
        for round in 0..HOLD_ROUNDS {
            let bad = tets_below(mesh, keep);
            if bad.is_empty() {
                best = None;
                break;
            }
            let worst = worst_dihedral(mesh);
            // A round that did not raise the worst ends the retries.
            if best.as_ref().is_some_and(|b| worst <= b.0) {
                break;
            }
            hold_around(&input, mesh, &bad, round > 0, &mut held);
            let n_held = (0..input.n_tet_slots())
                .filter(|&t| selected(t) && held[t])
                .count();
            // A step that would hold back more than a sliver of its tets
            // refines and misses instead (a one-tet mesh would not refine).
            if n_held > n_selected / HOLD_SHARE {
                break;
            }
            let selection = (0..input.n_tet_slots())
                .map(|t| selected(t) && !held[t])
                .collect();
            let retry = RefineOptions {
                selection: Some(selection),
                ..opts.clone()
            };
            progress.step_again(report.phases.len() as u64);
            let attempt = std::mem::replace(mesh, input.clone());
            best = Some((worst, attempt, report));
            report = step_phases(mesh, step, &retry, progress, floor);
            report.held = n_held;
        }
        if let Some((worst, attempt, attempt_report)) = best {
            if worst_dihedral(mesh) < worst {
                *mesh = attempt;
                report = attempt_report;
            }
        }
    }
    report.seconds = start.elapsed().as_secs_f64();
    report
}

/// Rounds of [`step_keeping`]'s retry. The first holds back
/// only the input tets where the tets below the input's worst lie; later
/// rounds also hold the tets sharing a vertex with them. Measured on the
/// shipped meshes refined and refined again (2026-12-06): one round was
/// enough, holding 2 to 11 input tets; where the fault is not the split
/// (a 69° feature angle, the ladder and the holed bar's second steps run
/// as single steps) no round helped.
const HOLD_ROUNDS: usize = 4;

/// A step holds back at most one in this many of its selected tets.
const HOLD_SHARE: usize = 100;

/// The live tets of `mesh` with a dihedral angle (radians) below `angle`.
fn tets_below(mesh: &TetMesh, angle: f64) -> Vec<u32> {
    use rayon::prelude::*;
    (0..mesh.n_tet_slots() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&t| mesh.is_alive(t) && min_dihedral(mesh, t) < angle)
        .collect()
}

/// The smallest dihedral angle (radians) of tet `t`.
fn min_dihedral(mesh: &TetMesh, t: u32) -> f64 {
    crate::geom::dihedral_angles(&mesh.tet_points(t))
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// Marks in `held` (per tet slot of `input`, the step's input) the input
/// tets holding a vertex or the centroid of one of `bad` (tets of the
/// step's output `mesh`), located by a visibility walk from the bad tet's
/// `parent`, and with `ring` every input tet sharing a vertex with those.
fn hold_around(input: &TetMesh, mesh: &TetMesh, bad: &[u32], ring: bool, held: &mut [bool]) {
    let Some(first) = input.tet_ids().next() else {
        return;
    };
    let mut near = vec![false; input.n_points()];
    for &t in bad {
        let p = mesh.tet_points(t);
        let hint = mesh.parent(t);
        let mut at = if (hint as usize) < input.n_tet_slots() && input.is_alive(hint) {
            hint
        } else {
            first
        };
        let centroid = (p[0] + p[1] + p[2] + p[3]) * 0.25;
        for x in p.into_iter().chain([centroid]) {
            at = super::parents::walk_to(input, at, x);
            held[at as usize] = true;
            for v in input.tet(at) {
                near[v as usize] = true;
            }
        }
    }
    if ring {
        for t in input.tet_ids() {
            if input.tet(t).iter().any(|&v| near[v as usize]) {
                held[t as usize] = true;
            }
        }
    }
}

/// The phases of one step on `mesh` (see [`refine_step_with_progress`]),
/// the optimize phase keeping `floor` (min sine) where it can.
fn step_phases(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    progress: &dyn Progress,
    floor: f64,
) -> StepReport {
    let mut report = StepReport::default();
    let mut st = StepState {
        first_barycentre: mesh.n_points() as u32,
        first_face_point: u32::MAX,
        split_faces: Vec::new(),
        region_interfaces: Vec::new(),
        marked_interfaces: Vec::new(),
        partition_faces: Vec::new(),
        partition_edges: partition_edges(mesh),
        step: step + opts.step_offset,
        creases: mesh.feature_edges().keys().copied().collect(),
        trisected: HashSet::new(),
    };
    for phase in Phase::ALL {
        let t0 = Instant::now();
        progress.phase_start(phase, mesh.n_tets() as u64);
        match phase {
            Phase::Split => split_phase(mesh, opts, &mut report),
            Phase::Flip => flip_phase(mesh, &st, &mut report),
            Phase::BoundarySplit => boundary_split_phase(mesh, &mut st, &mut report),
            Phase::BoundaryFlip => boundary_flip_phase(
                mesh,
                &mut st,
                opts.boundary == crate::stencil::Sqrt3Rule::Linear,
                opts.interfaces == InterfaceRule::Sqrt3,
                &mut report,
            ),
            Phase::BoundarySmooth => boundary_smooth_phase(mesh, &st, opts, &mut report),
            Phase::Optimize => {
                // The topological phases appended tets and points at the ends
                // of the arrays; bring neighbours together in memory first.
                mesh.reorder_spatially_in_place();
                report.improve = optimize_phase(mesh, step, opts, true, None, floor);
            }
        }
        progress.phase_end();
        if opts.check_each_phase {
            if let Err(e) = mesh.check() {
                report.check_failures.push(format!("{phase}: {e}"));
            }
        }
        report.phases.push(PhaseReport {
            name: phase.name(),
            tets: mesh.n_tets(),
            seconds: t0.elapsed().as_secs_f64(),
        });
        if opts.stop_after == Some(phase) {
            break;
        }
    }
    report
}

/// Phase 6: edge removal and smoothing, then (at the efforts that have them)
/// the long-edge rounds, each with its settling passes, and the outlier
/// round ([`outlier_round`]), over the zone
/// `--smooth` allows. Also run, without the long-edge rounds
/// (`long_edges`) and over the band the cut froze (`zone`: per point, may
/// it move; per tet slot, may its edges go), by the distributed driver once
/// the cut has moved.
pub(crate) fn optimize_phase(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    long_edges: bool,
    zone: Option<(Vec<bool>, Vec<bool>)>,
    floor: f64,
) -> ImproveReport {
    if opts.opt_passes == 0 {
        return ImproveReport::default();
    }
    // The distributed band's long-edge round and rescue (below) need its
    // points and tets after the passes.
    let mut band = zone.clone();
    let (movable, tet_allowed) = match zone {
        Some((verts, tets)) => (Some(verts), Some(tets)),
        None => smoothing_zone(mesh, step, opts),
    };
    let mut io = ImproveOptions {
        movable,
        tet_allowed,
        floor,
        // An input already above the smoothing bar raises it to its worst:
        // the tets between the two get the optimizer too (measured on the
        // shipped meshes refined twice, each step written and read back:
        // mmg_cube 17.60° -> 18.09°, the holed bar 17.59° -> 19.65°, their
        // inputs 17.98° and 19.64°).
        ..opts.effort.improve_options(
            opts.opt_passes,
            opts.threshold.max(floor.min(FLOOR_BAR_CAP)),
            opts.hausd,
        )
    };
    if band.is_some() {
        // The band had only the first passes, without its interface
        // vertices: it gets a higher edge-removal bar than the settling
        // rounds' ([`BAND_EDGE_THRESHOLD`]).
        io.edge_threshold = io.edge_threshold.max(BAND_EDGE_THRESHOLD);
    }
    keep_domain_for(&mut io, opts.boundary);
    let bar = io.threshold;
    // Long edges are split once the passes have evened out the
    // step's new points (split on the raw √3 mesh they gain
    // half as much: tripod 41.6° against 43.4° average), then
    // passes with edge removal up to a higher bar settle the new
    // balls; the effort sets how many such rounds run.
    let mut report = improve(mesh, &io);
    if let Some(factor) = opts.effort.long_edge_factor().filter(|_| long_edges) {
        for round in 0..opts.effort.long_edge_rounds() {
            // Only edges of this step's tets: an adaptive step leaves the
            // rest of the mesh at its size.
            let mut long_edge_zone = descendants_of_last_step(mesh, step);
            // The first round splits what stands out against its
            // neighbours, later rounds also what the cap finds. Capping
            // every round was measured too (one default step, 2026-12-07):
            // the first round's settling of its extra splits left an
            // interior edge of mmg_cube whose split no point keeps, the
            // output's longest at 0.536 against 0.317, for +0.2° to +0.5°
            // of average on mmg_cube, gmsh_t16 and tetgen_example.
            let cap = if round == 0 {
                LengthCap::Off
            } else {
                opts.effort.long_edge_cap()
            };
            let split = split_long_edges(mesh, factor, cap, bar, Some(&mut long_edge_zone), true);
            // The splits appended their points and tets at the ends of the
            // arrays, away from their neighbours: brought together again,
            // the settling passes load balls from fewer cache lines.
            // Measured on one default step (2026-12-06, two pairs of runs
            // of the builds without and with it, back to back):
            // mmg_tinyBoxt 4.69 → 4.29 s and 4.81 → 4.17 s, tetgen_example
            // 2.35 → 2.17 s and 2.45 → 2.26 s, gmsh_t16 1.27 s both and
            // 1.43 → 1.35 s, a 26³ cube grid 5.85 → 5.55 s.
            mesh.reorder_spatially_in_place();
            // The zone is gathered after the split, so it holds the new
            // tets (of this step's level, as the tets they halve) and their
            // points.
            let (movable, tet_allowed) = smoothing_zone(mesh, step, opts);
            report.add(&settle_splits(mesh, &split, &io, movable, tet_allowed));
        }
        if let Some((factor, cap)) = opts.effort.outlier_split().filter(|_| step >= 2) {
            report.add(&outlier_round(mesh, step, opts, &io, (factor, cap)));
        }
    }
    // The distributed driver's band: the whole mesh around it had every
    // round, the band only its first passes, so what they leave below the
    // bar gets the rescue, over the tets whose four vertices are the
    // band's (the passes' flips made new tets of its vertices). Measured
    // on a 2.4M-tet MMG mesh of the tripod, one step on 2 ranks: the band
    // left 18.43° against the serial run's 20.30°.
    if let Some((verts, tets)) = band.as_mut() {
        if let Some(factor) = opts.effort.long_edge_factor() {
            let cap = opts.effort.long_edge_cap();
            report.add(&band_long_edge_round(
                mesh,
                (verts, tets),
                (factor, cap),
                &io,
            ));
        }
        // The serial steps' outlier round, over the band.
        if let Some(outliers) = opts.effort.outlier_split().filter(|_| step >= 2) {
            report.add(&band_long_edge_round(mesh, (verts, tets), outliers, &io));
        }
    }
    if let Some((mut verts, _)) = band {
        verts.resize(mesh.n_points(), false);
        let mut tets = vec![false; mesh.n_tet_slots()];
        for t in mesh.tet_ids() {
            tets[t as usize] = mesh.tet(t).iter().all(|&v| verts[v as usize]);
        }
        if let Some(rescue) = rescue_options(mesh, Some(verts), Some(tets), opts, bar) {
            report.add(&improve(mesh, &rescue));
        }
        return report;
    }
    let target = rescue_target(floor, opts.effort);
    if target > 0.0 {
        let (movable, tet_allowed) = smoothing_zone(mesh, step, opts);
        if let Some(rescue) = rescue_options(mesh, movable, tet_allowed, opts, target) {
            report.add(&improve(mesh, &rescue));
        }
    }
    report
}

/// The rescue round ([`rescue_options`]) of a `default` or `best` step also
/// takes the tets its passes left below this minimum sine (about 17.5°),
/// not only those below the input's worst: the passes lift almost every
/// tet to the bar (0.35), and one left far below it is a sliver their
/// order of moves missed. Measured on MMG's 362k-tet mesh of the tripod,
/// one default step (2026-12-07): one interior tet of 3,370,320 ended at
/// 15.33°, the next at 20.49°; the round lifted it to 20.49° for about
/// 0.8 s of a 25 s run. On the ladder's second step its worst cluster
/// (14.38°, boundary tets at x = −2) stays where it was.
const RESCUE_BELOW: f64 = 0.3;

/// The minimum sine the rescue round lifts tets to, for a step whose input's
/// worst has sine `floor`: that floor up to [`FLOOR_BAR_CAP`] (a floor above
/// it is aimed at, not kept: a Kuhn grid's 45° is out of a √3 step's reach,
/// and a rescue there would take the whole mesh), and at least
/// [`RESCUE_BELOW`] except for `fast`, which keeps the boundary where it is
/// (the rescue moves it). 0 means no rescue.
fn rescue_target(floor: f64, effort: crate::improve::Effort) -> f64 {
    let kept = if floor <= FLOOR_BAR_CAP { floor } else { 0.0 };
    if effort == crate::improve::Effort::Fast {
        kept
    } else {
        kept.max(RESCUE_BELOW)
    }
}

/// The passes that settle the balls of the long-edge splits `split`, with
/// `io`'s options over the zone `movable` / `tet_allowed` (as in
/// [`ImproveOptions`]) and edge removal up to [`SETTLE_EDGE_THRESHOLD`];
/// the report counts the splits too. The boundary stays where the first
/// passes left it, so `--hausd` bounds the whole step's drift (moving it
/// again would measure from the moved surface); this costs 0.1°–0.2° of
/// average.
fn settle_splits(
    mesh: &mut TetMesh,
    split: &LongEdgeSplits,
    io: &ImproveOptions,
    movable: Option<Vec<bool>>,
    tet_allowed: Option<Vec<bool>>,
) -> ImproveReport {
    let mut settled = improve(mesh, &settle_options(io, movable, tet_allowed));
    settled.long_edges_split += split.edges;
    settled.long_edge_boundary_faces += split.boundary_faces;
    settled
}

/// The options of a settling round: `io`'s over the zone `movable` /
/// `tet_allowed` (as in [`ImproveOptions`]), edge removal up to at least
/// [`SETTLE_EDGE_THRESHOLD`], the boundary where it is.
fn settle_options(
    io: &ImproveOptions,
    movable: Option<Vec<bool>>,
    tet_allowed: Option<Vec<bool>>,
) -> ImproveOptions {
    ImproveOptions {
        movable,
        tet_allowed,
        edge_threshold: io.edge_threshold.max(SETTLE_EDGE_THRESHOLD),
        boundary: None,
        ..io.clone()
    }
}

/// The outlier round after the long-edge rounds of a second or later
/// step: the settling passes of the last round lengthen some edges, flip
/// others into being, and the splits themselves lower the means their
/// neighbours are judged by, so a tail of edges stands out again, and a
/// step keeps the tail of the step before. The edges of this step's tets
/// longer than `factor` times the mean at their ends, or than `cap`, whose
/// whole shell is at or above the bar, are split, and
/// [`OUTLIER_SETTLE_PASSES`] passes settle the balls within
/// [`OUTLIER_SETTLE_RINGS`] ring of the new tets (inside the zone
/// `--smooth` allows), the boundary where it is.
///
/// Measured on two default steps (2026-12-07, edge lengths against MMG3D
/// `-hsiz`'s at the same count scaled by the cube root of the count
/// ratio): the 99th-percentile edge of mmg_cube went from 1.261× to
/// 1.236×, of the holed bar from 1.264× to 1.234×, of the tripod from
/// 1.257× to 1.231×, with 4 %–5 % more tets and about 0.25° more average.
/// A first step's tail is short (its 99th percentile is 1.18×–1.24×
/// MMG's), and there the round only moved the results around: with it in
/// every step the ladder's two-step worst went from 14.38° to 13.24° (its
/// first step's output, the second step's input, changed), and the
/// distributed band of mmg_cube on two ranks fell 2.0° short of the serial
/// average. Two steps of tetgen_example took 27 % more wall time with a
/// 2-ring settle and 15 % more with one ring, run back to back with the
/// build without the round (the round in both steps).
fn outlier_round(
    mesh: &mut TetMesh,
    step: usize,
    opts: &RefineOptions,
    io: &ImproveOptions,
    (factor, cap): (f64, LengthCap),
) -> ImproveReport {
    // Only edges whose whole shell is at or above the bar: the keep test of
    // `split_long_edges` (the smaller of the shell's worst and the bar)
    // then asks every new tet to be above the bar, so a round for sizes
    // makes no tet worse than the passes' bar, and the step's worst tets
    // are left to the rounds and passes before. (On the shipped meshes'
    // second steps no outlier's shell was below the bar: the same outputs
    // with and without this filter.)
    let mut zone = descendants_of_last_step(mesh, step);
    {
        use rayon::prelude::*;
        let mesh = &*mesh;
        zone.par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(t, z)| {
                *z = *z
                    && mesh.is_alive(t as u32)
                    && crate::geom::tet_min_sine(&mesh.tet_points(t as u32)) >= io.threshold;
            });
    }
    // Very long edges at the lower bar only in the rounds before, whose
    // full settling passes lift the thin halves: the round's short settle
    // left mmg_tinyBoxt's two-step worst at 17.32° (19.21° without).
    let split = split_long_edges(mesh, factor, cap, io.threshold, Some(&mut zone), false);
    if split.edges == 0 {
        return ImproveReport::default();
    }
    let (movable, tets) = zone_near(
        mesh,
        &split.new_tets,
        OUTLIER_SETTLE_RINGS,
        smoothing_zone(mesh, step, opts),
    );
    let io = ImproveOptions {
        passes: OUTLIER_SETTLE_PASSES,
        ..io.clone()
    };
    settle_splits(mesh, &split, &io, Some(movable), Some(tets))
}

/// Rings of tets around the outlier round's new tets that its passes may
/// change ([`outlier_round`]): its splits are a small, scattered part of
/// the mesh, and the two long-edge rounds before settled the rest.
const OUTLIER_SETTLE_RINGS: usize = 1;

/// Passes of the outlier round's settle ([`outlier_round`]). One pass left
/// a two-step mmg_cube's longest edge at 0.194 (two: 0.117), made by its
/// flips after the splits.
const OUTLIER_SETTLE_PASSES: usize = 2;

/// The distributed band's long-edge round: the serial step's rounds left
/// the edges of the cut's faces whole ([`split_long_edges`] refuses an edge
/// of a partition face, whose other side the rank across holds); once the
/// cut has moved they are inside a part, so the band's long edges (`factor`
/// against their ends' means, or over `cap`, its median measured over the
/// band) are split (only edges whose whole shell is in the band's tets)
/// and [`BAND_SETTLING_ROUNDS`] settling rounds, `io`'s passes over the
/// band with its new points and tets, even out the new balls; no very
/// long edge is split at the lower bar here (on mmg_cube over two ranks
/// that took the band to 10,391 tets at 43.52° average against the serial
/// step's 7,193 at 47.88°). `verts` and
/// `tets` (the band, per point and per tet slot) take in the new points
/// and tets. One split round, not the effort's count: the edges the serial
/// rounds missed are those of the cut's faces, and the band is around
/// them, though the round splits any band edge that is long against the
/// means at its ends then. Measured on one step on two ranks (2026-12-07,
/// `--boundary linear`, one settling round), average minimum dihedral
/// angle without the round → with it (the serial step's): mmg_cube 45.80°
/// → 46.30° (47.23°), the tripod 48.37° → 48.53° (48.59°), gmsh_t16
/// 49.96° → 50.10° (50.18°); the worst unchanged; tets 5,486 → 6,010
/// (6,027), 33,446 → 34,320 (33,783), 147,205 → 151,592 (147,056).
fn band_long_edge_round(
    mesh: &mut TetMesh,
    (verts, tets): (&mut Vec<bool>, &mut Vec<bool>),
    (factor, cap): (f64, LengthCap),
    io: &ImproveOptions,
) -> ImproveReport {
    let split = split_long_edges(mesh, factor, cap, io.threshold, Some(tets), false);
    if split.edges == 0 {
        return ImproveReport::default();
    }
    let mut report = ImproveReport {
        long_edges_split: split.edges,
        long_edge_boundary_faces: split.boundary_faces,
        ..Default::default()
    };
    for _ in 0..BAND_SETTLING_ROUNDS {
        // The points added since the band was gathered (the splits', and
        // any the passes inserted on an edge of a band tet) lie inside the
        // band: they may move.
        verts.resize(mesh.n_points(), true);
        tets.resize(mesh.n_tet_slots(), false);
        let settle = settle_options(io, Some(verts.clone()), Some(tets.clone()));
        report.add(&improve(mesh, &settle));
    }
    report
}

/// Settling rounds after the band's long-edge splits: two, as the serial
/// step's balls had two rounds. Measured on mmg_cube, one step on two ranks
/// (2026-12-07, `--boundary linear`): average 46.03° with one, 46.25° with
/// two, 46.34° with three (serial 47.49°); the tripod 48.59° → 48.65°
/// (48.51°).
const BAND_SETTLING_ROUNDS: usize = 2;

/// Options for a last, local round where the passes left a tet below the
/// input's worst (`floor`): the `best` effort's options (a higher bar, larger
/// edge-removal rings, boundary moves up to a higher bar) over the tets below
/// the floor and the tets sharing a vertex with them, inside the zone `io`
/// allows (`movable`, `tet_allowed` as in [`ImproveOptions`]). `None` when
/// no tet is below the floor. Measured with the bar at 0.33: the holed bar
/// refined twice left one wedge at 17.86° against its input's 19.34° (a
/// corner vertex and three boundary vertices, two short opposite edges);
/// the round lifted it to 18.18°, not to the floor, and the ladder's
/// second step from 15.18° to 15.54°, above its input's 15.51°.
fn rescue_options(
    mesh: &TetMesh,
    zone_movable: Option<Vec<bool>>,
    zone_tets: Option<Vec<bool>>,
    opts: &RefineOptions,
    floor: f64,
) -> Option<ImproveOptions> {
    let allowed = |t: u32| zone_tets.as_ref().is_none_or(|a| a[t as usize]);
    let bad: Vec<u32> = {
        use rayon::prelude::*;
        (0..mesh.n_tet_slots() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&t| {
                mesh.is_alive(t)
                    && allowed(t)
                    && crate::geom::tet_min_sine(&mesh.tet_points(t)) < floor
            })
            .collect()
    };
    if bad.is_empty() {
        return None;
    }
    // The bad tets' vertices, then every tet and vertex of their balls.
    let (movable, tets) = zone_near(mesh, &bad, 1, (zone_movable, zone_tets));
    let mut rescue = ImproveOptions {
        movable: Some(movable),
        tet_allowed: Some(tets),
        floor,
        ..crate::improve::Effort::Best.improve_options(
            opts.opt_passes,
            opts.threshold.max(floor),
            opts.hausd,
        )
    };
    keep_domain_for(&mut rescue, opts.boundary);
    Some(rescue)
}

/// The vertices (per point) and tets (per tet slot) within `rings` rings
/// of `tets` ([`TetMesh::zone_around_tets`], grown through any tet), then
/// limited to the zone `--smooth` allows (`zone`: per point, may it move;
/// per tet slot, may it change; `None`: no limit).
fn zone_near(
    mesh: &TetMesh,
    tets: &[u32],
    rings: usize,
    zone: (Option<Vec<bool>>, Option<Vec<bool>>),
) -> (Vec<bool>, Vec<bool>) {
    let (mut verts, mut near) = mesh.zone_around_tets(tets, rings);
    if let Some(z) = zone.0 {
        verts.iter_mut().zip(z).for_each(|(v, z)| *v &= z);
    }
    if let Some(z) = zone.1 {
        near.iter_mut().zip(z).for_each(|(t, z)| *t &= z);
    }
    (verts, near)
}

/// The linear rule promises the input's domain: a boundary vertex moves
/// only inside a flat star, so no crease, however shallow, is cut, and no
/// cap is removed. The other rules leave `io` as it is.
pub(crate) fn keep_domain_for(io: &mut ImproveOptions, rule: crate::stencil::Sqrt3Rule) {
    if matches!(rule, crate::stencil::Sqrt3Rule::Linear) {
        if let Some(b) = &mut io.boundary {
            b.crease_angle = crate::improve::boundary_smooth::FLAT_ONLY;
            b.remove_caps = false;
        }
    }
}

/// The highest smoothing bar (min sine, about 21°) an input's worst tet
/// sets: above it, most of a mesh would go through the optimizer.
const FLOOR_BAR_CAP: f64 = 0.36;

/// The smallest dihedral angle (radians) of `mesh`'s tets (0 for an empty
/// mesh). Its sine is the optimize phase's floor, so that a step does not
/// leave a tet worse than its input's worst: a tet whose min sine is at
/// least that has no dihedral angle below the input's smallest.
fn worst_dihedral(mesh: &TetMesh) -> f64 {
    use rayon::prelude::*;
    let worst = (0..mesh.n_tet_slots() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&t| mesh.is_alive(t))
        .map(|t| min_dihedral(mesh, t))
        .reduce(|| f64::INFINITY, f64::min);
    if worst.is_finite() {
        worst
    } else {
        0.0
    }
}

/// Edge removal bar (min sine) of the passes after the long-edge splits.
/// Against the first passes' 0.5, a higher bar raises the average minimum
/// dihedral angle at the cost of time: measured on one default step of the
/// seven shipped meshes (2026-12-07, one run each, against 0.7): 0.6
/// (36.9°) takes 4 %–25 % less wall time (tetgen_example 2.36 → 1.92 s,
/// gmsh_t16 1.76 → 1.46 s) for 0.16°–0.31° less average, with the same
/// 99th-percentile edge within 0.5 %; 0.55 saved 4 %–8 % more but cost
/// 0.4°–0.8° of average and 4.7° of the ladder's worst. With 0.6 the
/// average stays above MMG3D's at the same count on all seven (by
/// 0.2°–2.9°, `benches/compare.sh`), while the time is 2–3 times short of
/// issue 14's 1/8 of MMG's: the trade goes to time.
const SETTLE_EDGE_THRESHOLD: f64 = 0.6;

/// Edge removal bar (min sine) of the distributed band's passes after the
/// cut has moved: the band missed the serial rounds, and it is a small part
/// of the mesh, so it keeps the settling rounds' earlier bar. Measured on
/// mmg_cube, one step on two ranks against the serial step (2026-12-07,
/// `--boundary linear`): with 0.6 here too the average was 45.87° against
/// 47.49°.
const BAND_EDGE_THRESHOLD: f64 = 0.7;

/// What the optimize phase may touch: with `--smooth refined` the zone of
/// [`refined_zone`], otherwise everything (`None`, `None`).
#[allow(clippy::type_complexity)]
fn smoothing_zone(
    mesh: &TetMesh,
    step: usize,
    opts: &RefineOptions,
) -> (Option<Vec<bool>>, Option<Vec<bool>>) {
    if opts.smooth_refined_only {
        refined_zone(mesh, step)
    } else {
        (None, None)
    }
}

/// The tets refined in this step (their level reached `step`) and their
/// vertices: what `--smooth refined` lets the optimize phase touch.
#[allow(clippy::type_complexity)]
fn refined_zone(mesh: &TetMesh, step: usize) -> (Option<Vec<bool>>, Option<Vec<bool>>) {
    let tets = descendants_of_last_step(mesh, step);
    let mut verts = vec![false; mesh.n_points()];
    for t in mesh.tet_ids() {
        if tets[t as usize] {
            for v in mesh.tet(t) {
                verts[v as usize] = true;
            }
        }
    }
    (Some(verts), Some(tets))
}

/// Phase 1: 1-4 split of every selected tet at its barycentre, in bulk
/// ([`split14_bulk`]).
fn split_phase(mesh: &mut TetMesh, opts: &RefineOptions, report: &mut StepReport) {
    report.split += split14_bulk(mesh, opts.selection.as_deref());
}

/// Phase 2: 2-3 flip of each old interior face whose two tets were both split:
/// the children holding it have the two barycentres as apexes. Validity is
/// decided in parallel, the rare invalid flips are repaired by moving their
/// barycentres ([`make_flips_valid`]), then all valid flips are done in bulk
/// ([`flip23_bulk`]).
fn flip_phase(mesh: &mut TetMesh, st: &StepState, report: &mut StepReport) {
    let mut batch = FlipBatch::barycentre_faces(mesh, st.first_barycentre);
    report.moved_barycentres += make_flips_valid(mesh, &mut batch);
    let n = batch.len();
    let flipped = flip23_bulk(mesh, batch);
    report.flipped += flipped;
    report.refused_flips += n - flipped;
}

/// The partition marker of face `fv`, if it has one.
fn partition_of(mesh: &TetMesh, fv: [u32; 3]) -> Option<PartitionMarker> {
    if mesh.face_markers().is_empty() {
        return None;
    }
    mesh.face_marker(fv).and_then(PartitionMarker::decode)
}

/// Where phase 3 splits face `fv`: its centroid (a partition face's in the
/// canonical order), or `None` for a held partition face.
fn face_split_point(
    mesh: &TetMesh,
    fv: [u32; 3],
    partition: Option<PartitionMarker>,
) -> Option<DVec3> {
    let p = fv.map(|x| mesh.point(x));
    match partition {
        Some(pm) if pm.hold => None,
        Some(_) => Some(canonical_centroid(p)),
        None => Some((p[0] + p[1] + p[2]) / 3.0),
    }
}

/// Phase 3: 1-3 split of every boundary face of a split tet at its
/// barycentre, and the 2-6 split of every interface face whose two tets were
/// split. Partition faces are split at their canonical centroid unless held.
fn boundary_split_phase(mesh: &mut TetMesh, st: &mut StepState, report: &mut StepReport) {
    let first = st.first_barycentre;
    st.first_face_point = mesh.n_points() as u32;
    let mut faces = Vec::new();
    let mut interfaces = Vec::new();
    for t in mesh.tet_ids() {
        let v = mesh.tet(t);
        for f in 0..4 {
            if v[f] < first || !(0..4).all(|j| j == f || v[j] < first) {
                continue;
            }
            if mesh.is_boundary_face(t, f) {
                faces.push((t, f));
            } else if mesh.is_interface_face(t, f) {
                let (u, g) = TetMesh::half_face(mesh.adj(t)[f]);
                let w = mesh.tet(u);
                if u > t && w[g] >= first && (0..4).all(|j| j == g || w[j] < first) {
                    interfaces.push((t, f));
                }
            }
        }
    }
    for (t, f) in faces {
        let fv = mesh.face_vertices(t, f);
        let partition = partition_of(mesh, fv);
        let Some(c) = face_split_point(mesh, fv, partition) else {
            continue;
        };
        if let Ok((m, _)) = split_boundary_face(mesh, t, f, c) {
            if partition.is_some() {
                st.partition_faces.push((fv, m));
            } else {
                st.split_faces.push((fv, m));
            }
            report.boundary_split += 1;
        }
    }
    for (t, f) in interfaces {
        let fv = mesh.face_vertices(t, f);
        let partition = partition_of(mesh, fv);
        let Some(c) = face_split_point(mesh, fv, partition) else {
            continue;
        };
        let (rt, ru) = (mesh.region(t), mesh.region(mesh.adj(t)[f] >> 2));
        if let Ok(m) = split_interface_face(mesh, t, f, c) {
            if partition.is_some() {
                // A serial run with the cut marked: the step the two ranks
                // do together, one 1-3 split each.
                st.partition_faces.push((fv, m));
            } else if rt == ru {
                st.marked_interfaces.push((fv, m));
            } else {
                // `fv` is seen from `t`, outward: reversed when `t` is on the
                // higher side.
                let oriented = if rt < ru { fv } else { [fv[0], fv[2], fv[1]] };
                st.region_interfaces.push((oriented, m));
            }
            report.interface_split += 1;
        }
    }
}

/// A tet holding the edge `(a, b)` and its local edge index, searched in the
/// ball of `near` (a vertex known to share a tet with the edge).
fn tet_with_edge(
    mesh: &TetMesh,
    near: u32,
    a: u32,
    b: u32,
    ball: &mut Vec<u32>,
) -> Option<(u32, usize)> {
    mesh.ball(near, ball);
    ball.iter().find_map(|&t| {
        let v = mesh.tet(t);
        let ia = v.iter().position(|&x| x == a)?;
        let ib = v.iter().position(|&x| x == b)?;
        let e = TET_EDGES
            .iter()
            .position(|&[i, j]| (i == ia && j == ib) || (i == ib && j == ia))?;
        Some((t, e))
    })
}

/// Ring vertices `p` of `ring` whose face `(a, b, p)` is constrained (boundary
/// ends of an open ring, region changes, marked faces).
fn constrained_ring_vertices(mesh: &TetMesh, ring: &EdgeRing) -> Vec<u32> {
    let r = ring.verts.len();
    let mut out = Vec::new();
    if !ring.closed {
        out.push(ring.verts[0]);
        out.push(ring.verts[r - 1]);
    }
    let n = ring.tets.len();
    let inner = if ring.closed { 0..n } else { 1..n };
    for i in inner {
        // Face (a, b, verts[i]) lies between tets i-1 and i.
        let (t0, t1) = (ring.tets[(i + n - 1) % n], ring.tets[i]);
        let p = ring.verts[i];
        if mesh.face_is_constrained(t0, Some(t1), [ring.a, ring.b, p]) {
            out.push(p);
        }
    }
    out
}

/// Whether `a`, `b`, `m1`, `m2` lie in one plane up to rounding: the volume
/// of the tet they span is below 1e-10 of the product of its edge lengths
/// from `a`.
fn flat_enough(mesh: &TetMesh, a: u32, b: u32, m1: u32, m2: u32) -> bool {
    let [pa, pb, p1, p2] = [a, b, m1, m2].map(|v| mesh.point(v));
    let det = crate::geom::orient3d(pa, pb, p1, p2).abs();
    det <= 1e-10 * (pb - pa).length() * (p1 - pa).length() * (p2 - pa).length()
}

/// Phase 4: every old boundary or interface edge whose constrained faces were
/// all split is flipped (boundary: edge removal, m → 2m − 2; interface: the
/// two-sided removal of [`remove_interface_edge`]), so that the new edge joins
/// two face points. Feature edges are kept in odd steps and trisected in even
/// steps (the √3 paper, §5).
///
/// With the linear rule (`linear`), which promises to keep the domain
/// exactly, a boundary edge is flipped only where its two old faces are
/// exactly coplanar (exact `orient3d` of the edge and their opposite
/// corners is zero): across any bend, however slight, the new edge between
/// the face points would cut the domain. Interface edges likewise, unless
/// `sqrt3_interfaces`: then an edge between two regions is flipped however
/// its interface bends (the stencils of phase 5 then move both sides).
fn boundary_flip_phase(
    mesh: &mut TetMesh,
    st: &mut StepState,
    linear: bool,
    sqrt3_interfaces: bool,
    report: &mut StepReport,
) {
    let fp = st.first_face_point;
    // The old corners opposite each old edge in the split faces.
    let mut opposite: FastHashMap<[u32; 2], Vec<u32>> = FastHashMap::default();
    if linear {
        for &(f, _) in &st.split_faces {
            for i in 0..3 {
                opposite
                    .entry(edge_key(f[i], f[(i + 1) % 3]))
                    .or_default()
                    .push(f[(i + 2) % 3]);
            }
        }
    }
    // Old edges seen from the split faces, with how often and one face point.
    let mut seen: FastHashMap<[u32; 2], (u32, u8)> =
        FastHashMap::with_capacity_and_hasher(3 * st.split_faces.len() / 2, Default::default());
    let split = st.split_faces.iter().chain(&st.region_interfaces);
    for &(f, m) in split.chain(&st.marked_interfaces) {
        for i in 0..3 {
            let k = edge_key(f[i], f[(i + 1) % 3]);
            seen.entry(k).and_modify(|e| e.1 += 1).or_insert((m, 1));
        }
    }
    let mut edges: Vec<([u32; 2], u32)> = seen.iter().map(|(k, (m, _))| (*k, *m)).collect();
    let seen_count: FastHashMap<[u32; 2], u8> = seen.iter().map(|(k, (_, n))| (*k, *n)).collect();
    edges.sort_unstable();
    let even = st.step % 2 == 0;
    let mut ball = Vec::new();
    let mut marks = TetMarks::default();
    if even {
        trisect_interior_features(mesh, st, &seen_count, report);
    }
    let mut ring = EdgeRing::default();
    for ([a, b], m) in edges {
        if st.partition_edges.contains(&[a, b]) {
            // Both sides of a cut would have to flip together.
            report.refused_boundary_flips += 1;
            continue;
        }
        let is_feature = mesh.is_feature_edge(a, b);
        if is_feature && !even {
            report.kept_feature_edges += 1;
            continue;
        }
        let Some((t, e)) = tet_with_edge(mesh, m, a, b, &mut ball) else {
            report.refused_boundary_flips += 1;
            continue;
        };
        ring.gather_into(mesh, t, e);
        let cons = constrained_ring_vertices(mesh, &ring);
        // Every constrained face around the edge must have been split.
        if cons.iter().any(|&p| p < fp) {
            report.refused_boundary_flips += 1;
            continue;
        }
        if is_feature {
            // Every tet holding the edge, over all its fans.
            tets_of_edge(mesh, [a, b], Some(t), &mut ball, &mut marks);
            trisect_at_thirds(mesh, st, [a, b], &ball, report);
            continue;
        }
        if cons.len() != 2 || seen_count[&[a, b]] != 2 {
            // Three or more constrained faces meet here (or the domain touches
            // itself along the edge) but the edge is not tagged: flipping
            // would break the junction.
            report.refused_boundary_flips += 1;
            continue;
        }
        let result = if ring.closed {
            // Only a flat interface may be flipped under the linear rule:
            // across a bend, the new edge would cut a chord from one region
            // into the other. A marked face inside one region stays linear
            // under both rules.
            let between_regions = {
                let r0 = mesh.region(ring.tets[0]);
                ring.tets.iter().any(|&u| mesh.region(u) != r0)
            };
            let smooth = sqrt3_interfaces && between_regions;
            if !smooth && !flat_enough(mesh, a, b, cons[0], cons[1]) {
                report.refused_boundary_flips += 1;
                continue;
            }
            remove_interface_edge(mesh, &ring, cons[0], cons[1])
        } else {
            let same_marker =
                mesh.face_marker([a, b, cons[0]]) == mesh.face_marker([a, b, cons[1]]);
            if !same_marker {
                report.refused_boundary_flips += 1;
                continue;
            }
            if linear {
                let coplanar = match opposite.get(&[a, b]).map(Vec::as_slice) {
                    Some(&[c1, c2]) => {
                        let [pa, pb, p1, p2] = [a, b, c1, c2].map(|v| mesh.point(v));
                        crate::geom::orient3d(pa, pb, p1, p2) == 0.0
                    }
                    _ => false,
                };
                if !coplanar {
                    report.refused_boundary_flips += 1;
                    continue;
                }
            }
            remove_edge(mesh, &ring, f64::NEG_INFINITY).map(|_| ())
        };
        match result {
            Ok(()) => report.boundary_flipped += 1,
            Err(_) => report.refused_boundary_flips += 1,
        }
    }
}

/// The interior half of phase 4 in even steps: every feature edge on no
/// constrained face (a tagged edge inside a region, a feature line running
/// from the boundary through the interior) whose tets were all refined in
/// this step is trisected at exact thirds, as the boundary's creases are
/// (the √3 paper, §5, treats tagged interior edges the same way). The √3
/// split and flip keep every old edge, so such an edge is still there; in an
/// adaptive step, an edge with an unrefined tet around it is kept until its
/// whole ball is refined.
fn trisect_interior_features(
    mesh: &mut TetMesh,
    st: &mut StepState,
    on_constrained_faces: &FastHashMap<[u32; 2], u8>,
    report: &mut StepReport,
) {
    let mut edges: Vec<[u32; 2]> = mesh
        .feature_edges()
        .keys()
        .filter(|k| !on_constrained_faces.contains_key(*k) && !st.partition_edges.contains(*k))
        .copied()
        .collect();
    edges.sort_unstable();
    let (mut ball, mut marks) = (Vec::new(), TetMarks::default());
    for [a, b] in edges {
        tets_of_edge(mesh, [a, b], None, &mut ball, &mut marks);
        let refined = |u: &u32| mesh.tet(*u).iter().any(|&v| v >= st.first_barycentre);
        if ball.is_empty() || !ball.iter().all(refined) {
            report.kept_feature_edges += 1;
            continue;
        }
        trisect_at_thirds(mesh, st, [a, b], &ball, report);
    }
}

/// Every tet holding the edge `(a, b)`, over all its fans, into `out`: the
/// tets at `a` or `b` reached across faces at `a` or `b` from `known` (a tet
/// holding the edge, when the caller has one) and from the tets `a` and `b`
/// are stored with, kept when they hold both.
///
/// The ball of `a` alone, walked from its stored tet, is not enough where
/// the domain touches itself at `a` (its tets fall into groups that share
/// no face): the walk stays in one group, which may not hold the edge. A
/// rank's part touches itself so wherever the cut, once moved, meets
/// itself at a point, though the union of the parts does not.
fn tets_of_edge(
    mesh: &TetMesh,
    [a, b]: [u32; 2],
    known: Option<u32>,
    out: &mut Vec<u32>,
    marks: &mut TetMarks,
) {
    out.clear();
    marks.begin(mesh.n_tet_slots());
    for t in [known, mesh.tet_of_vertex(a), mesh.tet_of_vertex(b)]
        .into_iter()
        .flatten()
    {
        if marks.mark(t) {
            out.push(t);
        }
    }
    let mut i = 0;
    while i < out.len() {
        let (v, adj) = (mesh.tet(out[i]), mesh.adj(out[i]));
        i += 1;
        for f in 0..4 {
            // Face `f` (opposite `v[f]`) holds `a` or `b`.
            let at_end = [a, b].iter().any(|&x| v[f] != x && v.contains(&x));
            if at_end && adj[f] != NO_ADJ && marks.mark(adj[f] >> 2) {
                out.push(adj[f] >> 2);
            }
        }
    }
    out.retain(|&u| {
        let v = mesh.tet(u);
        v.contains(&a) && v.contains(&b)
    });
}

/// Trisects the feature edge `[a, b]` (its tets `around`) with new points at
/// exactly 1/3 and 2/3, and records it in the step and the report.
fn trisect_at_thirds(
    mesh: &mut TetMesh,
    st: &mut StepState,
    [a, b]: [u32; 2],
    around: &[u32],
    report: &mut StepReport,
) {
    let (pa, pb) = (mesh.point(a), mesh.point(b));
    let (x1, x2) = (pa + (pb - pa) / 3.0, pa + (pb - pa) * (2.0 / 3.0));
    match trisect_edge(mesh, a, b, around, x1, x2) {
        Ok(_) => {
            report.trisected_feature_edges += 1;
            st.trisected.insert([a, b]);
        }
        Err(_) => report.refused_boundary_flips += 1,
    }
}

/// Phase 5: the √3 stencils on the old boundary points and the new face
/// points (and, with `--interfaces sqrt3`, on the interfaces between regions,
/// each seen from its lower region); each move is checked against inversion
/// and halved (up to six times) or skipped.
fn boundary_smooth_phase(
    mesh: &mut TetMesh,
    st: &StepState,
    opts: &RefineOptions,
    report: &mut StepReport,
) {
    let sqrt3_interfaces = opts.interfaces == InterfaceRule::Sqrt3;
    if st.split_faces.is_empty() && (!sqrt3_interfaces || st.region_interfaces.is_empty()) {
        return;
    }
    let creases = &st.creases;
    let corners: HashSet<u32> = mesh
        .corners()
        .iter()
        .chain(mesh.required_vertices())
        .copied()
        .collect();
    // Points that never move here: on a feature edge, corners, required
    // vertices, and every point of a linear interface (so that each region
    // stays exactly what it was).
    let mut pinned: HashSet<u32> = corners.clone();
    for e in creases.iter().chain(mesh.feature_edges().keys()) {
        pinned.insert(e[0]);
        pinned.insert(e[1]);
    }
    // Marked faces inside one region always stay linear; interfaces between
    // regions too, unless `--interfaces sqrt3`.
    let linear_regions: &[([u32; 3], u32)] = if sqrt3_interfaces {
        &[]
    } else {
        &st.region_interfaces
    };
    for (f, m) in st
        .marked_interfaces
        .iter()
        .chain(linear_regions)
        .chain(&st.partition_faces)
    {
        pinned.extend(f.iter().copied());
        pinned.insert(*m);
    }
    // Every point of a partition face, split or held.
    pinned.extend(st.partition_edges.iter().flatten().copied());
    if sqrt3_interfaces {
        // A point on both the boundary and an interface (a junction even
        // where no feature is tagged, `--features none`) would get two
        // targets.
        let on_boundary: HashSet<u32> = st.split_faces.iter().flat_map(|(f, _)| *f).collect();
        for (f, _) in &st.region_interfaces {
            pinned.extend(f.iter().filter(|v| on_boundary.contains(v)));
        }
    }
    let mut targets = stencil_targets(mesh, &st.split_faces, st, opts, &corners);
    if sqrt3_interfaces {
        targets.extend(stencil_targets(
            mesh,
            &st.region_interfaces,
            st,
            opts,
            &corners,
        ));
    }
    let mut ball = Vec::new();
    for (v, target) in targets {
        let from = mesh.point(v);
        if target == from || pinned.contains(&v) {
            continue;
        }
        mesh.ball(v, &mut ball);
        let mut t = 1.0;
        let mut moved = false;
        for attempt in 0..7 {
            let x = from + (target - from) * t;
            if ball_stays_positive(mesh, v, &ball, x) {
                mesh.set_point(v, x);
                if attempt == 0 {
                    report.full_moves += 1;
                } else {
                    report.shortened_moves += 1;
                }
                moved = true;
                break;
            }
            t *= 0.5;
        }
        if !moved {
            report.skipped_moves += 1;
        }
    }
}

/// Where the √3 stencil of `opts.boundary` sends the old points of the split
/// faces `split` (old triangle, its new point) and their new points: old
/// points first (each once), then the face points.
fn stencil_targets(
    mesh: &TetMesh,
    split: &[([u32; 3], u32)],
    st: &StepState,
    opts: &RefineOptions,
    corners: &HashSet<u32>,
) -> Vec<(u32, DVec3)> {
    if split.is_empty() {
        return Vec::new();
    }
    let tris: Vec<[u32; 3]> = split.iter().map(|(f, _)| *f).collect();
    // The trisected variant places the face points of faces along a
    // trisected crease as the surface scheme would; the crease points
    // themselves stay where trisection put them (linear, on the segment).
    let pos = sqrt3_positions_trisecting(
        mesh.points(),
        &tris,
        opts.boundary,
        &st.creases,
        corners,
        &st.trisected,
    )
    .positions;
    let mut old: Vec<u32> = tris.iter().flatten().copied().collect();
    old.sort_unstable();
    old.dedup();
    let mut targets: Vec<(u32, DVec3)> = old
        .into_iter()
        .map(|v| (v, pos.vertices[v as usize]))
        .collect();
    for (i, &(_, m)) in split.iter().enumerate() {
        targets.push((m, pos.faces[i]));
    }
    targets
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::improve::Effort;

    #[test]
    fn the_rescue_keeps_the_floor_up_to_its_cap_and_lifts_slivers_below_0_3() {
        // An input worst below the second target: the rescue lifts to 0.3.
        assert_eq!(rescue_target(0.1, Effort::Default), 0.3);
        assert_eq!(rescue_target(0.0, Effort::Best), 0.3);
        // Between the target and the cap: the input's worst is kept.
        assert_eq!(rescue_target(0.33, Effort::Default), 0.33);
        assert_eq!(rescue_target(0.36, Effort::Default), 0.36);
        // Above the cap the floor is aimed at, not kept; slivers still go.
        assert_eq!(rescue_target(0.5, Effort::Default), 0.3);
        // `fast` rescues only below the kept floor.
        assert_eq!(rescue_target(0.1, Effort::Fast), 0.1);
        assert_eq!(rescue_target(0.5, Effort::Fast), 0.0);
    }
}
