//! The `optimize` phase (the √3 paper, §3.2, steps 6–7): passes of interior edge
//! removal where it raises the worst tet of the edge's ring (on a ring of
//! three a 3-2 flip, of four a 4-4 flip), multi-face removal at the tets
//! it left bad (one face: a 2-3 flip), then vertex smoothing where a
//! vertex's worst tet is below a threshold — Laplacian first, kept only if
//! it helps, then optimization-based smoothing — repeated until a pass
//! changes nothing or the pass budget is spent.
//!
//! Boundary vertices, vertices on region interfaces or marked faces, feature
//! edges, corners and required vertices never move, and only interior edges
//! and faces (inside one region) are removed, so the domain, its regions
//! and its tags are untouched.

use super::boundary_smooth::FLAT_ONLY;
use super::boundary_smooth::{BoundarySmoothOptions, BoundarySmoothReport, BoundarySmoother};
use super::colour::{colour_balls_except, sequential_levels, Balls};
use super::insertion::{plan_insertion, InsertionScratch};
use super::laplacian::{laplacian_position_in, BallNow};
use super::optimize::{optimize_position_in, OptimizeParams};
use super::ring::canonicalize_ring;
use super::BallPoints;
use crate::geom::tet_min_sine;
use crate::mesh::fasthash::{FastHashMap, FastHashSet};
use crate::mesh::{edge_key, EdgeKey, TetMesh};
use crate::ops::edge_removal::{apply_ring_triangulation, RingTriangulation};
use crate::ops::edge_removal::{best_ring_triangulation_above, RingScratch};
use crate::ops::face_removal::{apply_face_removal, plan_face_removal, FacePlan, FaceScratch};
use crate::ops::{boundary_flip_ring, flip_boundary_edge, BoundaryFlipLimits, TetsAtVertex};
use crate::ops::{is_cap_below, remove_boundary_cap, CapLimits};
use crate::ops::{split_edge, EdgeRing};
use crate::topo::scatter::Shared;
use crate::topo::{EDGE_OF, TET_EDGES};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};

/// Options of [`improve`].
#[derive(Clone, Debug)]
pub struct ImproveOptions {
    /// Maximum number of passes.
    pub passes: usize,
    /// Vertices whose worst incident tet has a min-sine below this are smoothed
    /// (the paper's bar is 0.3, 17.46°; the default 0.35, 20.49°, lifts the
    /// worst of one default step on six of the seven shipped meshes from
    /// 17.5°–18° to about 20.5°, with the step's time within the
    /// run-to-run spread; 0.36 gave 21.1° but 1.1° less average on
    /// mmg_cube).
    pub threshold: f64,
    /// Vertices whose worst incident tet is below this get a Laplacian try
    /// (kept only if it raises their worst tet). The paper triggers smoothing
    /// only below `threshold`; trying the cheap Laplacian move up to 0.7
    /// (≈ 44°) raises the tripod's average minimum dihedral by about 2° after
    /// one step and 3.5° after two, at no cost in the worst angle.
    pub laplacian_threshold: f64,
    /// A Laplacian try may lower its ball's worst tet, down to `threshold`
    /// (and never below `floor` nor the worst tet `improve` was given),
    /// when it raises the ball's mean; `false`:
    /// it must raise the worst. Measured on the seven shipped meshes (one
    /// default step, `threshold` 0.33): the average minimum dihedral angle
    /// rises by 0.9°–1.9° (the holed bar 45.35° → 46.80°, the ladder 43.48°
    /// → 45.06°), the worst stays at the bar, the step takes up to a fifth
    /// longer.
    pub smooth_for_mean: bool,
    /// Edges of tets whose min-sine is below this are tried for removal.
    pub edge_threshold: f64,
    /// Largest ring (tets around an edge) tried for removal.
    pub max_ring: usize,
    /// Per point: may it move? `None`: every vertex not fixed by the rules above.
    pub movable: Option<Vec<bool>>,
    /// Per tet slot: may its edges be removed? `None`: every tet.
    pub tet_allowed: Option<Vec<bool>>,
    /// Vertices smoothed per block (see `smooth_pass`): the balls of a block
    /// are gathered at once, about 90 bytes a vertex, and each block costs a
    /// scan over the tet slots.
    pub smooth_block: usize,
    /// Boundary and interface vertices smoothed inside their patch
    /// ([`BoundarySmoothOptions`]); `None`: the boundary stays fixed.
    pub boundary: Option<BoundarySmoothOptions>,
    /// Insert a vertex on an edge of a tet still below `threshold` after
    /// the flips and contractions of a pass, where that raises the worst tet
    /// of the edge's shell (see `insert_pass`); the tet count grows.
    pub insert_vertices: bool,
    /// The quality (min sine) the passes should leave every tet at or
    /// above: while a tet that may change is below it, passes go on past
    /// `passes`, at most four more, as long as each raises the
    /// worst of them and changes something; those passes work only within
    /// two rings of the tets below it. A refinement step sets it from
    /// its input's worst tet (so that a refined mesh is not worse than its
    /// input); 0: none.
    pub floor: f64,
}

/// The default of [`ImproveOptions::threshold`] (and of `--threshold`).
pub const DEFAULT_THRESHOLD: f64 = 0.35;

/// Passes [`improve`] runs at most past [`ImproveOptions::passes`] while a
/// tet is below [`ImproveOptions::floor`].
const FLOOR_PASSES: usize = 4;

/// A pass past [`ImproveOptions::passes`] looks only at the tets below the
/// floor and what lies within this many rings of them (the dirty flags
/// elsewhere are dropped): the passes before had the whole mesh. A later
/// step's floor is its input's worst, at the smoothing bar, so a few tets
/// just below it used to send up to four more passes over every dirty
/// vertex and tet, for the mean more than for the floor. Measured on two
/// default steps of the shipped meshes (2026-12-06, user time, one run
/// each on a machine whose wall times varied by ±10 %): gmsh_t16 37.7 →
/// 29.6 s, the tripod 10.5 → 7.5–8.5 s, the ladder 9.8 → 7.8 s,
/// tetgen_example 51.4 → 47.9 s, worst angles kept (the ladder 15.34° →
/// 15.67°), averages 0.06°–0.4° lower; one step is unchanged (its floor,
/// the input's worst, is rarely missed). With one ring, gmsh_t16's worst
/// fell from 20.54° to 19.66° and the ladder's to 14.63°.
const FLOOR_PASS_RINGS: usize = 2;

impl Default for ImproveOptions {
    fn default() -> Self {
        ImproveOptions {
            passes: 3,
            threshold: DEFAULT_THRESHOLD,
            laplacian_threshold: 0.7,
            smooth_for_mean: true,
            edge_threshold: 0.5,
            max_ring: 10,
            movable: None,
            tet_allowed: None,
            smooth_block: 1 << 20,
            boundary: Some(BoundarySmoothOptions::default()),
            insert_vertices: true,
            floor: 0.0,
        }
    }
}

/// What [`improve`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ImproveReport {
    /// Passes run.
    pub passes: usize,
    /// Interior edges removed.
    pub edges_removed: usize,
    /// Vertices moved by Laplacian smoothing.
    pub laplacian_moves: usize,
    /// Vertices moved by optimization-based smoothing.
    pub optimized_moves: usize,
    /// Boundary and interface vertices moved inside their patch.
    pub surface_moves: usize,
    /// Feature-line vertices moved along their line.
    pub line_moves: usize,
    /// Boundary sliver caps removed ([`crate::ops::remove_boundary_cap`]).
    pub caps_removed: usize,
    /// Long edges split at their midpoint by a refinement step's long-edge
    /// rounds ([`Effort::long_edge_factor`](super::Effort::long_edge_factor)).
    pub long_edges_split: usize,
    /// Boundary faces those splits cut in two, each adding one boundary
    /// face (two for a boundary edge between two boundary faces).
    pub long_edge_boundary_faces: usize,
    /// Boundary edges flipped ([`crate::ops::flip_boundary_edge`]).
    pub boundary_flips: usize,
    /// Short edges contracted, an interior vertex merged into a neighbour
    /// ([`crate::ops::contract_edge`]).
    pub edges_contracted: usize,
    /// Multi-face removals ([`crate::ops::remove_faces`]; one face is a 2-3
    /// flip).
    pub faces_removed: usize,
    /// Vertices inserted where no flip, contraction or move lifted a tet.
    pub vertices_inserted: usize,
}

impl ImproveReport {
    /// Adds the counts of `other` (a later call on the same mesh).
    pub fn add(&mut self, other: &ImproveReport) {
        self.passes += other.passes;
        self.edges_removed += other.edges_removed;
        self.laplacian_moves += other.laplacian_moves;
        self.optimized_moves += other.optimized_moves;
        self.surface_moves += other.surface_moves;
        self.line_moves += other.line_moves;
        self.caps_removed += other.caps_removed;
        self.long_edges_split += other.long_edges_split;
        self.long_edge_boundary_faces += other.long_edge_boundary_faces;
        self.boundary_flips += other.boundary_flips;
        self.edges_contracted += other.edges_contracted;
        self.faces_removed += other.faces_removed;
        self.vertices_inserted += other.vertices_inserted;
    }
}

/// Work-tracking state of [`improve`]: per-slot quality and dirty flags, so
/// that later passes only revisit what the previous one changed.
struct Tracker {
    /// Min-sine quality per tet slot.
    tq: Vec<f64>,
    /// Tet slots touched since they were last examined for edge removal.
    tet_dirty: Vec<bool>,
    /// Vertices whose ball changed since they were last examined (atomic:
    /// the moves of a colour class are recorded in parallel, and two balls
    /// of a class may share a vertex, which both flag).
    vert_dirty: Vec<AtomicBool>,
    /// Tet slots whose edges may be removed.
    allowed: Option<Vec<bool>>,
    /// Per vertex, the `clock` reading when a tet holding it last changed
    /// (was created, removed, or had a vertex moved); atomic for the same
    /// reason as `vert_dirty`.
    changed_at: Vec<AtomicU64>,
    /// Advanced by [`Tracker::tick`]; changes are stamped with its reading.
    clock: u64,
}

impl Tracker {
    fn new(mesh: &TetMesh, allowed: Option<Vec<bool>>) -> Tracker {
        let tq = (0..mesh.n_tet_slots() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| {
                if mesh.is_alive(t) {
                    tet_min_sine(&mesh.tet_points(t))
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        Tracker {
            tq,
            tet_dirty: vec![true; mesh.n_tet_slots()],
            vert_dirty: (0..mesh.n_points())
                .into_par_iter()
                .map(|_| AtomicBool::new(true))
                .collect(),
            allowed,
            changed_at: (0..mesh.n_points())
                .into_par_iter()
                .map(|_| AtomicU64::new(0))
                .collect(),
            clock: 1,
        }
    }

    /// A reading of the clock later than every stamp so far and earlier
    /// than every stamp to come: whatever reads only vertices whose stamps
    /// are below it has seen nothing change since.
    fn tick(&mut self) -> u64 {
        self.clock += 2;
        self.clock - 1
    }

    /// Stamps vertex `v` as changed now.
    fn touch(&mut self, v: u32) {
        *self.vert_dirty[v as usize].get_mut() = true;
        *self.changed_at[v as usize].get_mut() = self.clock;
    }

    /// Whether no tet holding a vertex of `verts` changed since `at` (a
    /// reading of [`Tracker::tick`]).
    fn unchanged_since(&self, verts: impl IntoIterator<Item = u32>, at: u64) -> bool {
        verts
            .into_iter()
            .all(|v| self.changed_at[v as usize].load(Ordering::Relaxed) < at)
    }

    fn grow(&mut self, slots: usize) {
        if self.tq.len() < slots {
            self.tq.resize(slots, f64::INFINITY);
            self.tet_dirty.resize(slots, false);
            if let Some(a) = &mut self.allowed {
                a.resize(slots, false);
            }
        }
    }

    /// Records quality `q` for `t` and flags it and its vertices.
    fn set(&mut self, mesh: &TetMesh, t: u32, q: f64) {
        self.tq[t as usize] = q;
        self.tet_dirty[t as usize] = true;
        for v in mesh.tet(t) {
            self.touch(v);
        }
    }

    /// Records that an operation replaced the tets `removed` by `created`:
    /// the freed slots' qualities go, the new tets are allowed and recorded.
    fn replaced(&mut self, mesh: &TetMesh, removed: &[u32], created: &[u32]) {
        self.grow(mesh.n_tet_slots());
        if self.vert_dirty.len() < mesh.n_points() {
            self.vert_dirty
                .resize_with(mesh.n_points(), || AtomicBool::new(true));
            let now = self.clock;
            self.changed_at
                .resize_with(mesh.n_points(), || AtomicU64::new(now));
        }
        for &x in removed {
            self.tq[x as usize] = f64::INFINITY;
        }
        for &n in created {
            if let Some(a) = &mut self.allowed {
                a[n as usize] = true;
            }
            self.set(mesh, n, tet_min_sine(&mesh.tet_points(n)));
        }
    }

    /// Whether vertex `v` is dirty (its ball changed since it was last
    /// looked at).
    fn is_dirty(&self, v: usize) -> bool {
        self.vert_dirty[v].load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Per point, the worst quality of its live tets, for the points
    /// `wanted` names (+∞ for the others, and for a point without tets).
    /// Few wanted points (a small zone in a large mesh: a rescue round, an
    /// adaptive step's `--smooth refined`) walk their balls; many sweep the
    /// tets once. Both take the minimum over the same tets.
    fn worst_at(&self, mesh: &TetMesh, wanted: impl Fn(usize) -> bool) -> Vec<f64> {
        let n = mesh.n_points();
        let mut vq = vec![f64::INFINITY; n];
        let few: Vec<usize> = {
            let mut few = Vec::new();
            for v in 0..n {
                if wanted(v) {
                    few.push(v);
                    if few.len() > n / 32 {
                        break;
                    }
                }
            }
            few
        };
        if few.len() <= n / 32 {
            let mut ball = Vec::new();
            for v in few {
                mesh.ball(v as u32, &mut ball);
                vq[v] = ball
                    .iter()
                    .map(|&t| self.tq[t as usize])
                    .fold(f64::INFINITY, f64::min);
            }
            return vq;
        }
        for (t, tv) in mesh.tet_slots().iter().enumerate() {
            let q = self.tq[t];
            if q.is_finite() && mesh.is_alive(t as u32) {
                for &x in tv {
                    let s = &mut vq[x as usize];
                    *s = s.min(q);
                }
            }
        }
        vq
    }

    /// The worst quality of the live tets, of those that may change only
    /// with `allowed_only` (+∞ if none).
    fn worst(&self, mesh: &TetMesh, allowed_only: bool) -> f64 {
        (0..mesh.n_tet_slots() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&t| mesh.is_alive(t) && (!allowed_only || self.is_allowed(t)))
            .map(|t| self.tq[t as usize])
            .reduce(|| f64::INFINITY, f64::min)
    }

    /// The live tets that may change whose quality is below `bar`, in slot
    /// order.
    fn allowed_below(&self, mesh: &TetMesh, bar: f64) -> Vec<u32> {
        (0..mesh.n_tet_slots() as u32)
            .filter(|&t| mesh.is_alive(t) && self.tq[t as usize] < bar && self.is_allowed(t))
            .collect()
    }

    /// Keeps the dirty flags only on the tets below `bar` that may change
    /// and on the tets and vertices within `rings` rings of them
    /// ([`TetMesh::zone_around_tets`]): what is not dirty is not looked at.
    fn focus_below(&mut self, mesh: &TetMesh, bar: f64, rings: usize) {
        let (verts, tets) = mesh.zone_around_tets(&self.allowed_below(mesh, bar), rings);
        for (d, &z) in self.tet_dirty.iter_mut().zip(&tets) {
            *d &= z;
        }
        for (d, &z) in self.vert_dirty.iter_mut().zip(&verts) {
            *d.get_mut() &= z;
        }
    }

    fn is_allowed(&self, t: u32) -> bool {
        self.allowed
            .as_ref()
            .is_none_or(|a| a.get(t as usize).copied().unwrap_or(false))
    }
}

/// Runs the optimisation passes on `mesh`.
///
/// The edge search and vertex smoothing run in parallel: edges are searched
/// on the mesh as it stands and removed in order (see `EdgeRemoval::pass`),
/// vertices are smoothed by colour classes, independent sets smoothed in
/// parallel (in colour classes). The result does not depend on the
/// number of threads.
pub fn improve(mesh: &mut TetMesh, opts: &ImproveOptions) -> ImproveReport {
    let mut report = ImproveReport::default();
    let fixed = mesh.fixed_vertices();
    // The vertices the caller lets change (`--smooth refined`'s zone).
    let mut zone: Vec<bool> = (0..mesh.n_points())
        .map(|v| {
            opts.movable
                .as_ref()
                .is_none_or(|m| m.get(v).copied().unwrap_or(false))
        })
        .collect();
    let mut movable: Vec<bool> = (0..mesh.n_points()).map(|v| !fixed[v] && zone[v]).collect();
    drop(fixed);
    let mut tr = Tracker::new(mesh, opts.tet_allowed.clone());
    // A Laplacian move for the mean may lower its ball's worst down to the
    // bar, never below the worst of the mesh as it came in (the floor then
    // rises to that worst): on a mesh already above the bar, `improve`
    // would otherwise lower its worst tet.
    let floor = if opts.smooth_for_mean {
        opts.floor.max(tr.worst(mesh, false))
    } else {
        opts.floor
    };
    // What a move for the mean must keep its ball above.
    let keep = if opts.smooth_for_mean {
        opts.threshold.max(floor)
    } else {
        f64::INFINITY
    };
    let mut edges = EdgeRemoval::default();
    let mut refused = FastHashMap::default();
    // Caps go before the smoother takes the boundary as its reference, and
    // again after the passes for those the passes left.
    if let Some(b) = &opts.boundary {
        cap_pass(mesh, &mut tr, b, opts, &mut report);
    }
    let surface = opts
        .boundary
        .as_ref()
        .map(|b| BoundarySmoother::new(mesh, b.clone()));
    // Past `opts.passes`, a pass runs only while a tet is below the floor
    // and, from the second such pass on, the one before raised the worst
    // of those that may change: the first always runs. Checking the last
    // of `opts.passes` too was measured (two default steps, 2026-12-06):
    // 7 % less time on mmg_tinyBoxt's and gmsh_t16's second steps, but
    // 0.2° less average, and mmg_tinyBoxt's worst fell from 17.20° to
    // 16.80° (the passes it skipped, for the mean, helped the rescue).
    // Such a pass works only near the tets below the floor
    // ([`FLOOR_PASS_RINGS`]).
    let mut worst = f64::NEG_INFINITY;
    for pass in 0..opts.passes + FLOOR_PASSES {
        if pass >= opts.passes {
            let now = tr.worst(mesh, true);
            if now >= floor || now <= worst {
                break;
            }
            worst = now;
            tr.focus_below(mesh, floor, FLOOR_PASS_RINGS);
        }
        report.passes += 1;
        let mut changed = edges.pass(mesh, &mut tr, opts, &mut report);
        changed += face_pass(mesh, &mut tr, &edges.examined, &movable, opts, &mut report);
        if pass >= CONTRACT_FROM_PASS {
            changed += contract_pass(mesh, &mut tr, &mut movable, None, opts, &mut report);
        }
        if opts.insert_vertices && pass >= INSERT_FROM_PASS {
            changed += insert_pass(
                mesh,
                &mut tr,
                (&mut movable, &mut zone),
                &mut refused,
                opts,
                &mut report,
            );
        }
        changed += smooth_pass(mesh, &mut tr, &movable, opts, keep, &mut report);
        if let Some(s) = &surface {
            changed += boundary_pass(mesh, &mut tr, s, opts, &mut report);
        }
        if changed == 0 {
            break;
        }
    }
    if let Some(b) = &opts.boundary {
        if opts.passes > 0 {
            // Boundary contractions change the boundary's triangulation, so
            // they wait until the smoother, whose reference it is, is done;
            // one more interior pass then settles the balls they changed.
            let merged = if b.contract_edges {
                contract_pass(mesh, &mut tr, &mut movable, Some(&zone), opts, &mut report)
            } else {
                0
            };
            if merged > 0 {
                edges.pass(mesh, &mut tr, opts, &mut report);
                contract_pass(mesh, &mut tr, &mut movable, None, opts, &mut report);
                smooth_pass(mesh, &mut tr, &movable, opts, keep, &mut report);
            }
            cap_pass(mesh, &mut tr, b, opts, &mut report);
            // Flips go last: before the smoother, a flip's new faces would
            // be its reference surface too, and the smoother undoes them.
            if b.flip_edges {
                boundary_flip_pass(mesh, &mut tr, b, opts, &mut report);
            }
        }
    }
    report
}

/// Multi-face removals ([`crate::ops::remove_faces`]) at the faces of the
/// `candidates` (those the edge removal pass examined) still below
/// `opts.edge_threshold` after it, where the worst new tet beats the tet,
/// over at most `opts.max_ring` faces (the removal that undoes an edge
/// removal of that ring). A face whose two apexes may both not move is
/// left: the new edge would be a chord between two boundary points, which
/// left slivers at the ladder's corners that nothing lifted. Returns the
/// number of removals.
///
/// The result is the one of a sequential sweep in candidate order over
/// the faces of each slot in local order (a slot that a removal re-used
/// for a new tet is tried on at its next face). The
/// search runs in parallel on the mesh as it stands; a removal changes
/// only tets whose vertices are all in its cavity, and every tet a search
/// at a face of `t` reads holds one of that face's apexes: the vertex of
/// `t` opposite it or the one across it. So while none of these eight
/// vertices lies in a cavity re-made earlier in the sweep, the search
/// result of `t` (a plan, or none) is the sequential one; otherwise `t` is
/// searched again on the mesh as it is then.
fn face_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    candidates: &[u32],
    movable: &[bool],
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    // With each search result, the vertices across the faces of `t` as
    // the search saw them (`NO_APEX` across the boundary).
    const NO_APEX: u32 = u32::MAX;
    type Found = (Option<(usize, FacePlan)>, [u32; 4]);
    let found: Vec<Found> = {
        let (mesh, tr) = (&*mesh, &*tr);
        candidates
            .par_iter()
            .with_min_len(256)
            .map_init(FaceScratch::default, |s, &t| {
                let plan = first_face_plan(mesh, tr, t, 0, movable, opts, s);
                let apexes = if mesh.is_alive(t) {
                    mesh.adj(t).map(|h| {
                        if h == crate::mesh::NO_ADJ {
                            NO_APEX
                        } else {
                            mesh.tet(h >> 2)[(h & 3) as usize]
                        }
                    })
                } else {
                    [NO_APEX; 4]
                };
                (plan, apexes)
            })
            .collect()
    };
    let mut touched = vec![false; mesh.n_points()];
    let mut removed = 0;
    let mut scratch = FaceScratch::default();
    for (&t, (plan, apexes)) in candidates.iter().zip(found) {
        if !mesh.is_alive(t) || tr.tq[t as usize] >= opts.edge_threshold {
            continue;
        }
        // While no vertex of `t` is touched, neither is `t` nor a neighbour
        // (a new tet next to `t` shares a face with it, whose vertices are
        // in the new tet's cavity), so the apexes are the search's.
        let stale = mesh.tet(t).iter().any(|&x| touched[x as usize])
            || apexes.iter().any(|&x| x != NO_APEX && touched[x as usize]);
        let mut plan = if stale {
            first_face_plan(mesh, tr, t, 0, movable, opts, &mut scratch)
        } else {
            plan
        };
        while let Some((f, p)) = plan {
            debug_assert!(p.is_current(mesh));
            match apply_face_removal(mesh, &p) {
                Ok(r) => {
                    tr.replaced(mesh, &r.removed, &r.created);
                    for &n in &r.created {
                        for v in mesh.tet(n) {
                            touched[v as usize] = true;
                        }
                    }
                    removed += 1;
                    // The sweep goes on at the next face of slot `t`, which
                    // the removal may have re-used for one of its new tets.
                    plan = if mesh.is_alive(t) && tr.tq[t as usize] < opts.edge_threshold {
                        first_face_plan(mesh, tr, t, f + 1, movable, opts, &mut scratch)
                    } else {
                        None
                    };
                }
                Err(_) => plan = first_face_plan(mesh, tr, t, f + 1, movable, opts, &mut scratch),
            }
        }
    }
    report.faces_removed += removed;
    removed
}

/// The first face of `t` from local face `from` on with a multi-face
/// removal that beats `t` (see [`face_pass`]), and its plan.
fn first_face_plan(
    mesh: &TetMesh,
    tr: &Tracker,
    t: u32,
    from: usize,
    movable: &[bool],
    opts: &ImproveOptions,
    scratch: &mut FaceScratch,
) -> Option<(usize, FacePlan)> {
    // A candidate the edge pass removed (its slot free) or lifted.
    if !mesh.is_alive(t) || tr.tq[t as usize] >= opts.edge_threshold {
        return None;
    }
    // Strictly better by more than the rounding of `tet_min_sine`, as for
    // edge removal, so that passes cannot cycle.
    let beat = tr.tq[t as usize] + 1e-12;
    let allowed = |x: u32| tr.is_allowed(x);
    (from..4).find_map(|f| {
        let h = mesh.adj(t)[f];
        if h == crate::mesh::NO_ADJ
            || (!movable[mesh.tet(t)[f] as usize]
                && !movable[mesh.tet(h >> 2)[(h & 3) as usize] as usize])
        {
            return None;
        }
        plan_face_removal(mesh, t, f, beat, opts.max_ring, &allowed, scratch)
            .ok()
            .map(|p| (f, p))
    })
}

/// The first pass (counted from 0) with interior edge contractions: the
/// second. Measured on the shipped meshes (two default steps): from the
/// first pass they took out 5–20 % of the tets and ended lower in the worst
/// angle on four of seven meshes; from the third, the ladder (15.43°) and
/// mmg_cube (16.71°) end higher after two steps than from the second
/// (10.98°, 14.72°), but mmg_cube lower after one (16.76° against 17.71°)
/// and the ladder at a 69° feature angle below its input's worst (4.01°
/// against 5.34°), which the second keeps above (5.55°).
const CONTRACT_FROM_PASS: usize = 1;

/// Contractions of the short edges of the tets below `opts.threshold`
/// ([`crate::ops::contract_edge`]): for each such tet, in slot order, its
/// edges from the shortest, each end that may move merged into the other,
/// where that raises the worst tet of the merged vertex's ball. A sliver
/// whose short edge joins an interior vertex to one that may not move
/// (after a step, a new point crowded against the boundary) keeps that
/// edge through every flip and smoothing move; only the contraction takes
/// it out. With `boundary_zone` (the vertices the caller lets change) the
/// merged vertices are the fixed ones instead, each along the boundary
/// within one patch ([`crate::ops::contract_boundary_edge`]: a flat star
/// under the linear rule, else within the crease angle and the Hausdorff
/// bound): a sliver with four boundary corners on a plane.
/// Returns the number of contractions.
fn contract_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    movable: &mut [bool],
    boundary_zone: Option<&[bool]>,
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    let candidates = tr.allowed_below(mesh, opts.threshold);
    let mut ball = Vec::new();
    let mut scratch = Vec::new();
    let mut contracted = 0;
    // A boundary vertex where pieces of the domain touch (a pinch) has
    // tets the walk around it does not reach: contracting the piece it
    // sees would retire a point the others still hold. The tets at each
    // vertex are counted to tell; an interior vertex is never a pinch.
    let mut tets_at = boundary_zone.map(|_| TetsAtVertex::new(mesh));
    let mut old = Vec::new();
    for t in candidates {
        if !mesh.is_alive(t) || tr.tq[t as usize] >= opts.threshold {
            continue;
        }
        let tv = mesh.tet(t);
        let p = mesh.tet_points(t);
        let mut order: [usize; 6] = [0, 1, 2, 3, 4, 5];
        let len = |e: usize| p[TET_EDGES[e][0]].distance_squared(p[TET_EDGES[e][1]]);
        order.sort_by(|&a, &b| len(a).total_cmp(&len(b)));
        'edges: for e in order {
            let [i, j] = TET_EDGES[e];
            for (v, u) in [(tv[i], tv[j]), (tv[j], tv[i])] {
                let may = match boundary_zone {
                    None => movable[v as usize],
                    Some(z) => z[v as usize] && !movable[v as usize],
                };
                if !may {
                    continue;
                }
                mesh.ball(v, &mut ball);
                if !ball.iter().all(|&b| tr.is_allowed(b))
                    || tets_at
                        .as_ref()
                        .is_some_and(|c| c.at(v) as usize != ball.len())
                {
                    continue;
                }
                let beat = ball
                    .iter()
                    .map(|&b| tr.tq[b as usize])
                    .fold(f64::INFINITY, f64::min);
                if tets_at.is_some() {
                    old.clear();
                    old.extend(ball.iter().map(|&b| mesh.tet(b)));
                }
                let done = match (boundary_zone, &opts.boundary) {
                    (Some(_), Some(b)) => {
                        let mean_edge = (0..6).map(len).map(f64::sqrt).sum::<f64>() / 6.0;
                        let limits = BoundaryFlipLimits {
                            exact: b.crease_angle <= FLAT_ONLY,
                            hausd: b.hausd.unwrap_or(b.hausd_rel * mean_edge),
                            crease_angle: b.crease_angle,
                        };
                        crate::ops::contract_boundary_edge(mesh, v, u, beat, limits, &mut scratch)
                    }
                    _ => crate::ops::contract_edge(mesh, v, u, beat, &mut scratch),
                };
                if let Ok(new) = done {
                    if let Some(c) = &mut tets_at {
                        c.replaced(&old, &new, mesh);
                    }
                    tr.replaced(mesh, &ball, &new);
                    movable[v as usize] = false;
                    contracted += 1;
                    break 'edges;
                }
            }
        }
    }
    report.edges_contracted += contracted;
    contracted
}

/// The first pass (counting from 0) with vertex insertions. Measured
/// (2026-12-04, two default steps on the seven meshes): from pass 1 the
/// ladder's worst reached 16.83° / 17.05° (steps 1 / 2; 16.38° / 15.46°
/// from pass 2, 11.44° / 13.52° without insertion) and the other meshes'
/// worst and average moved by at most 0.2° between the two, but the ladder
/// at a 69° feature angle (interpolating, step 2) fell to 5.30°, below its
/// input's 5.34°; from pass 2 it is 7.40°. That case's worst tets sit at a
/// corner with a boundary point 0.05 from it on an untagged crease (no
/// contraction may merge it: the boundary bends there beyond the Hausdorff
/// bound), where any change upstream moves the worst between 3° and 7.5° —
/// a knife edge this constant does not remove.
const INSERT_FROM_PASS: usize = 2;

/// A tet where [`plan_insertion`] found no split: what it read, and when.
struct Refusal {
    /// The tet slot's generation then.
    generation: u32,
    /// A [`Tracker::tick`] reading taken just before.
    at: u64,
    /// The vertices the search read.
    read: Vec<u32>,
}

/// Vertex insertions ([`plan_insertion`]) at the tets still below
/// `opts.threshold`, in slot order, each on the edge of the tet whose split,
/// with the new vertex placed by the optimiser, best raises the worst tet of
/// the edge's shell. The new vertices are interior and may move (they join
/// `movable` and `zone`). Returns the number of insertions.
///
/// A tet with no split found is recorded in `refused`, and an earlier
/// pass's record stands in for the search while no tet holding a vertex
/// the search read has changed: the search reads only those vertices'
/// positions, the shells of the tet's edges and those tets' tags and
/// permissions, and every operation that changes the shell of an edge of
/// the tet either removes the tet (its slot's generation moves on) or
/// makes or removes a tet holding the edge's ends, which stamps them. So
/// the result is the one of searching again. Measured on two default
/// steps of mmg_tinyBoxt: 1.9 s less of 77.6 s, the output byte for byte
/// the same; the last round's ten passes searched the same few hundred
/// tets again each time.
fn insert_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    (movable, zone): (&mut Vec<bool>, &mut Vec<bool>),
    refused: &mut FastHashMap<u32, Refusal>,
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    let candidates = tr.allowed_below(mesh, opts.threshold);
    let mut scratch = InsertionScratch::default();
    let mut inserted = 0;
    for t in candidates {
        let q = tr.tq[t as usize];
        if !mesh.is_alive(t) || q >= opts.threshold {
            continue;
        }
        if let Some(r) = refused.get(&t) {
            if r.generation == mesh.generation(t)
                && tr.unchanged_since(r.read.iter().copied(), r.at)
            {
                continue;
            }
        }
        let at = tr.tick();
        let Some(plan) = plan_insertion(mesh, t, q, |x| tr.is_allowed(x), &mut scratch) else {
            let read = std::mem::take(&mut scratch.read);
            refused.insert(
                t,
                Refusal {
                    generation: mesh.generation(t),
                    at,
                    read,
                },
            );
            continue;
        };
        if let Ok((m, new)) = split_edge(mesh, plan.a, plan.b, plan.x) {
            debug_assert_eq!(m as usize, movable.len());
            movable.push(true);
            zone.push(true);
            tr.replaced(mesh, &plan.shell, &new);
            inserted += 1;
        }
    }
    report.vertices_inserted += inserted;
    inserted
}

/// 2-2 (and m → 2m − 2) flips of boundary edges ([`flip_boundary_edge`]) of
/// the tets below `b.threshold` with a boundary face, where the flip raises
/// the worst tet of the edge's ring and the two faces are one patch within
/// the Hausdorff bound of `b` (absolute, or relative to the faces' mean edge
/// length; exactly coplanar faces only when `b` allows flat stars only, as
/// for the linear rule). One sweep in slot order. Returns the number of
/// flips.
fn boundary_flip_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    b: &BoundarySmoothOptions,
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    let bar = b.threshold.max(opts.threshold);
    let candidates: Vec<u32> = (0..mesh.n_tet_slots() as u32)
        .filter(|&t| {
            mesh.is_alive(t)
                && tr.tq[t as usize] < bar
                && tr.is_allowed(t)
                && mesh.adj(t).contains(&crate::mesh::NO_ADJ)
        })
        .collect();
    let mut counts = TetsAtVertex::new(mesh);
    let mut flipped = 0;
    for t in candidates {
        'faces: for f in 0..4 {
            if !mesh.is_alive(t) || tr.tq[t as usize] >= bar {
                break;
            }
            if !mesh.is_boundary_face(t, f) {
                continue;
            }
            let p = mesh.tet_points(t);
            for (e, [i, j]) in TET_EDGES.iter().enumerate() {
                if *i == f || *j == f {
                    continue;
                }
                // The face's third corner: local ids sum to 0+1+2+3 = 6.
                let k = 6 - f - i - j;
                let mean_edge =
                    (p[*i].distance(p[*j]) + p[*i].distance(p[k]) + p[*j].distance(p[k])) / 3.0;
                let limits = BoundaryFlipLimits {
                    exact: b.crease_angle <= FLAT_ONLY,
                    hausd: b.hausd.unwrap_or(b.hausd_rel * mean_edge),
                    crease_angle: b.crease_angle,
                };
                let Ok(ring) = boundary_flip_ring(mesh, t, e, limits, &counts) else {
                    continue;
                };
                if !ring.tets.iter().all(|&u| tr.is_allowed(u)) {
                    continue;
                }
                let beat = ring
                    .tets
                    .iter()
                    .map(|&u| tr.tq[u as usize])
                    .fold(f64::INFINITY, f64::min);
                let old = ring.tets.clone();
                if let Ok(new) = flip_boundary_edge(mesh, t, e, limits, beat, &mut counts) {
                    tr.replaced(mesh, &old, &new);
                    flipped += 1;
                    break 'faces;
                }
            }
        }
    }
    report.boundary_flips += flipped;
    flipped
}

/// Removes the boundary caps (tets with two boundary faces) below
/// `opts.threshold` that may go under the Hausdorff bound of `b` (absolute,
/// or relative to the cap's mean edge length), one by one in slot order.
/// Returns the number removed.
fn cap_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    b: &BoundarySmoothOptions,
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    if !b.remove_caps {
        return 0;
    }
    let candidates: Vec<u32> = (0..mesh.n_tet_slots() as u32)
        .filter(|&t| {
            mesh.is_alive(t)
                && tr.tq[t as usize] < opts.threshold
                && tr.is_allowed(t)
                && is_cap_below(mesh, t, opts.threshold)
        })
        .collect();
    let mut removed = 0;
    for t in candidates {
        let p = mesh.tet_points(t);
        let mean_edge = crate::topo::TET_EDGES
            .iter()
            .map(|e| p[e[0]].distance(p[e[1]]))
            .sum::<f64>()
            / 6.0;
        let limits = CapLimits {
            hausd: b.hausd.unwrap_or(b.cap_hausd_rel * mean_edge),
            crease_angle: b.crease_angle,
        };
        let verts = mesh.tet(t);
        if remove_boundary_cap(mesh, t, limits).is_ok() {
            tr.tq[t as usize] = f64::INFINITY;
            for v in verts {
                tr.touch(v);
            }
            removed += 1;
        }
    }
    report.caps_removed += removed;
    removed
}

/// Boundary smoothing of the dirty surface and line vertices (allowed by
/// `opts.movable`) whose worst tet is below the Laplacian bar, by colour
/// classes ([`BoundarySmoother::pass`]). Returns the number of vertices
/// moved.
fn boundary_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    s: &BoundarySmoother,
    opts: &ImproveOptions,
    report: &mut ImproveReport,
) -> usize {
    let bar = opts.threshold.max(opts.laplacian_threshold);
    let may = |v: usize| {
        opts.movable
            .as_ref()
            .is_none_or(|m| m.get(v).copied().unwrap_or(false))
    };
    let vq = tr.worst_at(mesh, |v| s.is_movable(v as u32) && tr.is_dirty(v) && may(v));
    let verts: Vec<u32> = s
        .movable_vertices()
        .into_iter()
        .filter(|&v| {
            let dirty = tr.vert_dirty[v as usize].get_mut();
            let take = *dirty && vq[v as usize] < bar && may(v as usize);
            if take {
                *dirty = false;
            }
            take
        })
        .collect();
    let mut r = BoundarySmoothReport::default();
    let changed = s.pass(mesh, &verts, &mut r);
    for (t, q) in changed {
        tr.set(mesh, t, q);
    }
    report.surface_moves += r.surface_moves;
    report.line_moves += r.line_moves;
    r.surface_moves + r.line_moves
}

/// A removable edge found by the search half of an edge removal pass: the
/// edge and the triangles of its canonical ring's best triangulation, as
/// ring positions (the ring itself is gathered again when it is removed, so
/// that the records stay small).
struct Removable {
    key: EdgeKey,
    triangles: Box<[[u8; 3]]>,
}

impl Removable {
    fn new(ring: &EdgeRing, tri: &RingTriangulation) -> Removable {
        Removable {
            key: edge_key(ring.a, ring.b),
            triangles: tri
                .triangles
                .iter()
                .map(|&[i, k, j]| [i as u8, k as u8, j as u8])
                .collect(),
        }
    }

    fn triangulation(&self) -> RingTriangulation {
        RingTriangulation {
            quality: f64::NAN,
            triangles: self
                .triangles
                .iter()
                .map(|&[i, k, j]| [i as usize, k as usize, j as usize])
                .collect(),
        }
    }
}

/// Buffers of the edge removal passes.
#[derive(Default)]
struct EdgeRemoval {
    /// Per tet slot, bit `e`: local edge `e` was tried in this pass.
    tried: Vec<AtomicU8>,
    /// Per tet slot: in the ring of a recorded removable edge.
    has_found: Vec<bool>,
    /// Per tet slot: created by a removal of this pass (so not seen by the
    /// search).
    born: Vec<bool>,
    /// Per point: a vertex of a cavity re-triangulated in this pass.
    touched: Vec<bool>,
    /// The candidate tets of the last pass (dirty and below the edge
    /// threshold), for the face removals that follow it.
    examined: Vec<u32>,
}

/// Per-thread buffers of the edge search.
#[derive(Default)]
struct EdgeScratch {
    ring: EdgeRing,
    dp: RingScratch,
}

impl EdgeRemoval {
    /// Interior edge removal on the edges of dirty low-quality tets, each edge
    /// tried once per pass. Returns the number of edges removed.
    ///
    /// The search runs in parallel on the mesh as it stands: every edge of a
    /// candidate tet whose closed ring can be re-triangulated with a better
    /// worst tet (see [`best_ring_triangulation_above`]) is recorded with its
    /// triangulation. Whichever thread finds an edge, its ring is put in
    /// canonical form first ([`canonicalize_ring`]), so the records do not
    /// depend on the threads. The removals are then made one by one, visiting
    /// the candidates' edges in order as a sequential pass would, with the
    /// records standing in for the search wherever no earlier removal of the
    /// pass can have changed the edge's ring.
    fn pass(
        &mut self,
        mesh: &mut TetMesh,
        tr: &mut Tracker,
        opts: &ImproveOptions,
        report: &mut ImproveReport,
    ) -> usize {
        let candidates: Vec<u32> = (0..mesh.n_tet_slots() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&t| {
                let i = t as usize;
                tr.tet_dirty[i]
                    && tr.tq[i] < opts.edge_threshold
                    && mesh.is_alive(t)
                    && tr.is_allowed(t)
            })
            .collect();
        for &t in &candidates {
            tr.tet_dirty[t as usize] = false;
        }
        self.tried.clear();
        self.tried
            .resize_with(mesh.n_tet_slots(), || AtomicU8::new(0));
        let (found, found_tets): (Vec<Removable>, Vec<u32>) = {
            let mesh = &*mesh;
            let tr = &*tr;
            let tried = &self.tried;
            let parts: Vec<(Vec<Removable>, Vec<u32>)> = candidates
                .par_chunks(256)
                .map_init(EdgeScratch::default, |s, chunk| {
                    let mut found = Vec::new();
                    let mut tets = Vec::new();
                    for &t in chunk {
                        search_tet(mesh, tr, tried, opts, t, s, &mut found, &mut tets);
                    }
                    (found, tets)
                })
                .collect();
            let mut found = Vec::new();
            let mut tets = Vec::new();
            for (f, t) in parts {
                found.extend(f);
                tets.extend(t);
            }
            (found, tets)
        };
        // The records by edge; two threads may have found the same edge at
        // once (same record). `has_found` flags the tets of their rings.
        self.has_found.clear();
        self.has_found.resize(mesh.n_tet_slots(), false);
        let mut by_edge: FastHashMap<EdgeKey, Removable> =
            FastHashMap::with_capacity_and_hasher(found.len(), Default::default());
        for f in found {
            by_edge.insert(f.key, f);
        }
        for &t in &found_tets {
            self.has_found[t as usize] = true;
        }
        drop(found_tets);
        // Apply, visiting the candidates' edges in order as a sequential pass
        // would. Removing an edge changes only tets whose vertices are all in
        // its cavity, so the ring of an edge with an end outside every cavity
        // so far is still the one the search saw: its record (or the lack of
        // one) stands. An edge with both ends touched may have a new ring:
        // it is gathered again, and searched again only if a tet of its ring
        // was created in this pass (otherwise the ring, its points and its
        // qualities are the ones the search saw, and so is the verdict).
        self.touched.clear();
        self.touched.resize(mesh.n_points(), false);
        self.born.clear();
        self.born.resize(mesh.n_tet_slots(), false);
        let mut retried: FastHashSet<EdgeKey> = FastHashSet::default();
        let mut removed = 0;
        let mut scratch = EdgeScratch::default();
        for &t in &candidates {
            if !mesh.is_alive(t) || tr.tq[t as usize] >= opts.edge_threshold {
                continue;
            }
            let v = mesh.tet(t);
            for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
                let key = edge_key(v[i], v[j]);
                let both_touched = self.touched[v[i] as usize] && self.touched[v[j] as usize];
                let tri = if both_touched && {
                    if !retried.insert(key) || mesh.is_feature_edge(v[i], v[j]) {
                        continue;
                    }
                    scratch.ring.gather_into(mesh, t, e);
                    let born = &self.born;
                    scratch
                        .ring
                        .tets
                        .iter()
                        .any(|&u| born.get(u as usize).copied().unwrap_or(false))
                } {
                    judge_ring(mesh, tr, opts, &mut scratch)
                } else if (t as usize) < self.has_found.len() && self.has_found[t as usize] {
                    by_edge.remove(&key).map(|f| {
                        // The ring is the one the search saw: gather it again.
                        scratch.ring.gather_into(mesh, t, e);
                        canonicalize_ring(&mut scratch.ring);
                        f.triangulation()
                    })
                } else {
                    None
                };
                let Some(tri) = tri else { continue };
                let ring = &scratch.ring;
                // Room for the new tets in small exact steps: a `Vec` doubling
                // of every per-slot array for a few extra slots would stay
                // with the mesh.
                let need = 2 * tri.triangles.len();
                if mesh.free.len() < need && mesh.tets.capacity() - mesh.tets.len() < need {
                    mesh.reserve_tets_exact((mesh.n_tet_slots() / 256).max(need));
                }
                let Ok(new) = apply_ring_triangulation(mesh, ring, &tri) else {
                    continue;
                };
                removed += 1;
                let slots = mesh.n_tet_slots();
                tr.grow(slots);
                for &x in ring.verts.iter().chain([&ring.a, &ring.b]) {
                    self.touched[x as usize] = true;
                }
                if self.born.len() < slots {
                    self.born.resize(slots, false);
                }
                for n in new {
                    self.born[n as usize] = true;
                    let q = tet_min_sine(&mesh.tet_points(n));
                    tr.set(mesh, n, q);
                    if let Some(a) = &mut tr.allowed {
                        a[n as usize] = true;
                    }
                }
                break; // t is gone
            }
        }
        report.edges_removed += removed;
        // Per-slot and per-point buffers are not kept between passes (the
        // smoothing half needs the room).
        *self = EdgeRemoval {
            examined: candidates,
            ..EdgeRemoval::default()
        };
        removed
    }
}

/// Gathers the ring of local edge `e` of `t` into `s.ring` and, if it is a
/// closed ring of allowed tets that can be re-triangulated with a better worst
/// tet, leaves it there in canonical form and returns its triangulation.
fn search_edge(
    mesh: &TetMesh,
    tr: &Tracker,
    opts: &ImproveOptions,
    t: u32,
    e: usize,
    s: &mut EdgeScratch,
) -> Option<RingTriangulation> {
    s.ring.gather_into(mesh, t, e);
    judge_ring(mesh, tr, opts, s)
}

/// The verdict of [`search_edge`] on the ring already gathered in `s.ring`.
fn judge_ring(
    mesh: &TetMesh,
    tr: &Tracker,
    opts: &ImproveOptions,
    s: &mut EdgeScratch,
) -> Option<RingTriangulation> {
    let ring = &mut s.ring;
    if !ring.closed
        || ring.tets.len() > opts.max_ring.min(255) // ring positions are kept as u8
        || !ring.tets.iter().all(|&u| tr.is_allowed(u))
    {
        return None;
    }
    let worst = ring
        .tets
        .iter()
        .map(|&u| tr.tq[u as usize])
        .fold(f64::INFINITY, f64::min);
    canonicalize_ring(ring);
    // Strictly better by more than the rounding of `tet_min_sine` (a few
    // ulps of a value ≤ 1), so that a retriangulation of equal quality is
    // never taken and passes cannot cycle between two of them.
    let bar = worst + 1e-12;
    let tri = best_ring_triangulation_above(mesh, ring, bar, &mut s.dp);
    (tri.quality > bar).then_some(tri)
}

/// The search half of [`EdgeRemoval::pass`] for the edges of candidate tet
/// `t` not tried yet: appends the removable ones to `found` and their rings'
/// tets to `found_tets`.
#[allow(clippy::too_many_arguments)]
fn search_tet(
    mesh: &TetMesh,
    tr: &Tracker,
    tried: &[AtomicU8],
    opts: &ImproveOptions,
    t: u32,
    s: &mut EdgeScratch,
    found: &mut Vec<Removable>,
    found_tets: &mut Vec<u32>,
) {
    let v = mesh.tet(t);
    for (e, &[i, j]) in TET_EDGES.iter().enumerate() {
        if tried[t as usize].fetch_or(1 << e, Ordering::Relaxed) & (1 << e) != 0
            || mesh.is_feature_edge(v[i], v[j])
        {
            continue;
        }
        let rec = search_edge(mesh, tr, opts, t, e, s);
        // Every tet of the ring holds the edge: it is tried now.
        for &u in &s.ring.tets {
            let uv = mesh.tet(u);
            let ia = uv
                .iter()
                .position(|&x| x == s.ring.a)
                .expect("every tet of the ring holds the edge's end a");
            let ib = uv
                .iter()
                .position(|&x| x == s.ring.b)
                .expect("every tet of the ring holds the edge's end b");
            let k = EDGE_OF[ia][ib];
            if k < 6 {
                tried[u as usize].fetch_or(1 << k, Ordering::Relaxed);
            }
        }
        if let Some(tri) = rec {
            found.push(Removable::new(&s.ring, &tri));
            found_tets.extend_from_slice(&s.ring.tets);
        }
    }
}

/// Per-thread buffers of vertex smoothing.
#[derive(Default)]
struct SmoothScratch {
    qualities: Vec<f64>,
    trial: Vec<f64>,
    ball: BallPoints,
}

/// A vertex move decided by [`smooth_vertex`].
struct VertexMove {
    /// New position.
    x: DVec3,
    /// Moved by Laplacian smoothing.
    laplacian: bool,
    /// Moved by optimization-based smoothing.
    optimized: bool,
    /// Qualities of the ball's tets at `x`, in ball order.
    qualities: Vec<f64>,
}

/// The move of `v` (ball `ball`, per-slot qualities `tq`): a Laplacian try
/// kept only if it raises the worst tet and keeps the mean, then
/// optimization-based smoothing if the worst tet is still below the
/// threshold. Reads only the ball's points and qualities.
fn smooth_vertex(
    mesh: &TetMesh,
    tq: &[f64],
    v: u32,
    ball: &[u32],
    opts: &ImproveOptions,
    keep: f64,
    s: &mut SmoothScratch,
) -> Option<VertexMove> {
    let mut q = f64::INFINITY;
    let mut worst = 0;
    let mut sum = 0.0;
    for (i, &t) in ball.iter().enumerate() {
        let qt = tq[t as usize];
        if qt < q {
            q = qt;
            worst = i;
        }
        sum += qt;
    }
    let mean = sum / ball.len().max(1) as f64;
    let mut x = mesh.point(v);
    let mut laplacian = false;
    let now = BallNow {
        worst: q,
        mean,
        first: worst,
        keep,
    };
    s.ball.load(mesh, v, ball);
    if let Some((x2, q2)) = laplacian_position_in(mesh, v, ball, &s.ball, now, &mut s.qualities) {
        x = x2;
        q = q2;
        laplacian = true;
    }
    let mut optimized = false;
    if q < opts.threshold {
        if let Some((x3, _)) = optimize_position_in(
            &s.ball,
            x,
            &OptimizeParams::default(),
            &mut s.qualities,
            &mut s.trial,
        ) {
            x = x3;
            optimized = true;
        }
    }
    if !(laplacian || optimized) {
        return None;
    }
    // After a Laplacian move or a successful optimization, `s.qualities`
    // holds the ball's qualities at `x`.
    let qualities = s.qualities.clone();
    Some(VertexMove {
        x,
        laplacian,
        optimized,
        qualities,
    })
}

/// Vertex smoothing of dirty movable vertices whose worst tet is poor, in
/// blocks of `opts.smooth_block` consecutive vertices (neighbours in space
/// after the spatial reordering), each block colour class by colour class.
/// Blocks bound the memory of the balls: gathering all of them at once took
/// a quarter of a gigabyte on a 14M-tet mesh. Returns the number of vertices
/// moved.
fn smooth_pass(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    movable: &[bool],
    opts: &ImproveOptions,
    keep: f64,
    report: &mut ImproveReport,
) -> usize {
    let vq = tr.worst_at(mesh, |v| tr.is_dirty(v) && movable[v]);
    let bar = opts.threshold.max(opts.laplacian_threshold);
    let mut verts = Vec::new();
    let mut alone = Vec::new();
    for v in 0..mesh.n_points() {
        let dirty = tr.vert_dirty[v].get_mut();
        if !*dirty || !movable[v] {
            continue;
        }
        *dirty = false;
        if vq[v] < bar {
            verts.push(v as u32);
            alone.push(vq[v] < opts.threshold);
        }
    }
    drop(vq);
    let mut moved = 0;
    let mut scratch = SmoothScratch::default();
    let mut level = Vec::new();
    let size = opts.smooth_block.max(1);
    for (block, alone) in verts.chunks(size).zip(alone.chunks(size)) {
        let balls = Balls::gather(mesh, block);
        // The vertices bad enough for optimization-based smoothing are few,
        // and the worst tets hinge on them: they are smoothed one by one in
        // vertex order before and after the colour classes (smoothing them
        // only in colour order lost up to 4.5° of the tripod's worst angle).
        let mut classes = colour_balls_except(mesh, &balls, block, |i| alone[i]);
        // Runs of one-vertex classes are smoothed one by one, in order, or
        // exactly as if, by dependency levels.
        let mut groups: Vec<Vec<u32>> = Vec::new();
        let mut c = 0;
        while c < classes.len() {
            if classes[c].len() == 1 {
                let end = (c..classes.len())
                    .find(|&k| classes[k].len() != 1)
                    .unwrap_or(classes.len());
                let seq: Vec<u32> = classes[c..end].iter().map(|k| k[0]).collect();
                c = end;
                groups.extend(sequential_levels(mesh, &balls, block, &seq, &mut level));
            } else {
                groups.push(std::mem::take(&mut classes[c]));
                c += 1;
            }
        }
        drop(classes);
        for group in &groups {
            let moves = decide_moves(
                mesh,
                &tr.tq,
                &balls,
                block,
                group,
                (opts, keep),
                &mut scratch,
            );
            moved += apply_moves(mesh, tr, &balls, block, group, moves, report);
        }
    }
    moved
}

/// Moves the vertices of `group` (balls no two of which share a tet) as
/// `moves` says and records their balls' new qualities; returns the number
/// of moves. For a large group the records are made in parallel: each tet
/// slot is in one ball only, so its quality and flag have one writer, and a
/// vertex flagged from two balls is flagged either way, so the result is
/// that of recording the moves one by one.
fn apply_moves(
    mesh: &mut TetMesh,
    tr: &mut Tracker,
    balls: &Balls,
    verts: &[u32],
    group: &[u32],
    moves: Vec<Option<VertexMove>>,
    report: &mut ImproveReport,
) -> usize {
    let mut n = 0;
    for (&i, m) in group.iter().zip(&moves) {
        if let Some(m) = m {
            mesh.set_point(verts[i as usize], m.x);
            report.laplacian_moves += m.laplacian as usize;
            report.optimized_moves += m.optimized as usize;
            n += 1;
        }
    }
    if group.len() < 64 {
        // Not worth a trip through the thread pool.
        for (&i, m) in group.iter().zip(&moves) {
            let Some(m) = m else { continue };
            for (&t, &q) in balls.ball(i as usize).iter().zip(&m.qualities) {
                tr.set(mesh, t, q);
            }
        }
        return n;
    }
    let mesh = &*mesh;
    let tq = Shared::new(&mut tr.tq);
    let tet_dirty = Shared::new(&mut tr.tet_dirty);
    let (vert_dirty, changed_at, now) = (&tr.vert_dirty, &tr.changed_at, tr.clock);
    group
        .par_iter()
        .zip(moves.par_iter())
        .with_min_len(32)
        .for_each(|(&i, m)| {
            let Some(m) = m else { return };
            for (&t, &q) in balls.ball(i as usize).iter().zip(&m.qualities) {
                // The balls of a class share no tet slot: one writer each.
                tq.set(t as usize, q);
                tet_dirty.set(t as usize, true);
                for v in mesh.tet(t) {
                    vert_dirty[v as usize].store(true, Ordering::Relaxed);
                    changed_at[v as usize].store(now, Ordering::Relaxed);
                }
            }
        });
    n
}

/// The moves [`smooth_vertex`] decides for the vertices of balls `group`
/// (no two sharing a tet), in parallel if there are enough of them; a
/// move for the mean keeps its ball above `keep`.
fn decide_moves(
    mesh: &TetMesh,
    tq: &[f64],
    balls: &Balls,
    verts: &[u32],
    group: &[u32],
    (opts, keep): (&ImproveOptions, f64),
    scratch: &mut SmoothScratch,
) -> Vec<Option<VertexMove>> {
    let one = |s: &mut SmoothScratch, i: u32| {
        let ball = balls.ball(i as usize);
        if ball.is_empty() {
            return None;
        }
        smooth_vertex(mesh, tq, verts[i as usize], ball, opts, keep, s)
    };
    if group.len() < 64 {
        // Not worth a trip through the thread pool.
        group.iter().map(|&i| one(scratch, i)).collect()
    } else {
        group
            .par_iter()
            .with_min_len(32)
            .map_init(SmoothScratch::default, |s, &i| one(s, i))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::pinched_pyramids;
    use crate::mesh::generate::total_volume as volume;

    #[test]
    fn a_pinch_vertex_is_not_contracted() {
        // Two pyramids touching at `v` = (0.9, 0.9, 0) only
        // ([`pinched_pyramids`]): `v` sits near the lower base's corner
        // `a0` (point 3), so the two tets at the short edge `v`–`a0` are
        // slivers. Each piece's boundary star at `v` is a flat disk, so
        // contracting `v` into `a0` is a valid boundary contraction for the
        // lower piece alone, which is all the walk around `v` sees.
        let data = pinched_pyramids([0.9, 0.9, 0.0], 3.0, 2.0);
        let mut m = TetMesh::from_data(&data).expect("two pyramids").0;
        // Base areas 4 and 18, heights 2: (4 · 2 + 18 · 2) / 3.
        let exact = 44.0 / 3.0;
        assert!((volume(&m) - exact).abs() < 1e-12);
        assert!(m.tet_ids().all(|t| tet_min_sine(&m.tet_points(t)) > 0.0));
        let mut ball = Vec::new();
        m.ball(0, &mut ball);
        assert_eq!(ball.len(), 4, "the walk sees one pyramid");
        crate::refine::features::detect_features(&mut m, 45.0);
        assert!(!m.is_corner(0));
        let report = improve(&mut m, &ImproveOptions::default());
        m.check().expect("a valid mesh");
        assert!((volume(&m) - exact).abs() < 1e-12, "volume {}", volume(&m));
        assert!(m.tet_ids().any(|t| m.tet(t).contains(&0)));
        assert_eq!(report.edges_contracted, 0, "{report:?}");
        assert!(m.tet_of_vertex(0).is_some_and(|t| m.tet(t).contains(&0)));
        m.compact();
        m.check().expect("a valid mesh after compaction");
        assert!((volume(&m) - exact).abs() < 1e-12, "volume {}", volume(&m));
    }

    #[test]
    fn the_tracker_stamps_the_corners_of_what_changes_after_a_tick() {
        // A Kuhn grid of 2×2×2 cells: 27 points, 48 tets.
        let m = TetMesh::from_data(&crate::mesh::generate::cube_grid(2))
            .expect("a cube")
            .0;
        assert_eq!((m.n_points(), m.n_tets()), (27, 48));
        let mut tr = Tracker::new(&m, None);
        let all = || 0..m.n_points() as u32;
        let at = tr.tick();
        assert!(tr.unchanged_since(all(), at), "nothing changed yet");
        let t = m.tet_ids().next().expect("a tet");
        let q = tr.tq[t as usize];
        tr.set(&m, t, q);
        let corners = m.tet(t);
        for v in all() {
            assert_eq!(
                tr.unchanged_since([v], at),
                !corners.contains(&v),
                "point {v}"
            );
        }
        // A later reading sees the change as past.
        let later = tr.tick();
        assert!(tr.unchanged_since(all(), later));
        assert!(!tr.unchanged_since(corners, at));
    }
}
