//! Long-edge splits: the √3 operations never remove an old interior edge, so
//! after a step the edges of the input stand out among the new ones (on the
//! tripod the longest edge is 3.6 times the mean). An edge much longer than
//! the edges around it is split at its midpoint (or, where that split would
//! leave a poor tet, at a point of the edge off the middle) by the shell
//! split of [`split_edge`](crate::ops::split_edge), the way MMG3D's
//! size-driven remeshing and Rivara's longest-edge bisection split edges;
//! the smoothing and edge removal that follow then even out the new
//! vertex's ball. A very long free interior edge whose split no point of
//! it keeps is split at a lower bar, and those passes lift its halves
//! ([`RELAXED_NEED`]).
//!
//! "Much longer" is relative: an edge `(a, b)` of length `l` is long when
//! `l > factor · (L(a) + L(b)) / 2`, where `L(v)` is the mean length of the
//! edges at `v` as the mesh stands before the pass. A graded mesh keeps its
//! grading (an edge is compared with its neighbours, not with a global
//! size), and a uniform mesh has no long edge. The relative test alone
//! leaves long edges among long neighbours, such as a graded input's
//! coarse part; a cap ([`LengthCap`]) also splits every edge longer than
//! a multiple of the median of the `L(v)`, so the grading a step keeps
//! stays within that multiple.
//!
//! Every edge may be split: a free interior edge, a chord (an interior edge
//! between two fixed vertices, crossing a thin part of the domain; its
//! new point is a free vertex) and an edge of the surface: a boundary edge, a
//! feature edge, an edge of a region interface or a marked face. A surface
//! edge's new point lies on the edge, so on the surface as it stands: the
//! domain, its regions and the feature lines keep their shape, and the split
//! faces and feature edges keep their markers ([`split_shell`]). The next
//! step's boundary rules and crease trisection work on any triangulation of
//! the surface, so they see the new points as any other.
//!
//! Left whole: an edge of a partition face (the rank across would not split
//! it), and an edge between two fixed vertices whose end's ball the walk
//! does not reach whole (a pinch vertex, where a non-manifold edge's fans
//! may lie in separate pieces of the ball and a split of one fan would leave
//! the other's edge whole).
//!
//! Until 2026-12-06 only free interior edges were split. Chords were left
//! because their splits once took a two-step refinement of the tripod along
//! its feature lines to 4.5° (11.7° without); with the optimizer and the
//! step's hold as they are now, the adaptive and uniform guarantees of the
//! library's quality tests pass with chords and surface edges split. On one
//! default step of the shipped meshes this shortens the longest edge of the
//! tripod from 5.70 to 5.14, of the holed bar from 1.33 to 1.13 and of
//! mmg_tinyBoxt (a feature edge) from 0.275 to 0.241.

use super::optimize::{optimize_position_in, OptimizeParams};
use super::BallPoints;
use crate::geom::tet_min_sine;
use crate::mesh::partition::partition_edges;
use crate::mesh::TetMesh;
use crate::ops::edge_split::split_halves;
use crate::ops::edge_split::split_shell;
use crate::ops::TetsAtVertex;
use crate::topo::edge_key;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashSet;

/// Per vertex, the sorted distinct neighbours of `v` (through its ball).
fn neighbours(mesh: &TetMesh, v: u32, ball: &mut Vec<u32>, out: &mut Vec<u32>) {
    mesh.ball(v, ball);
    out.clear();
    for &t in ball.iter() {
        out.extend(mesh.tet(t).into_iter().filter(|&x| x != v));
    }
    out.sort_unstable();
    out.dedup();
}

/// A block of consecutive vertices: per vertex its mean edge length and the
/// end (exclusive) of its run in the third list, the neighbours of higher
/// id with the edge's length.
type NeighbourBlock = (Vec<f64>, Vec<u32>, Vec<(u32, f64)>);

/// Whether the edge `(a, b)` may be split: not when it lies on a partition
/// face (`cut`, [`partition_edges`]). Every other edge may: a free interior
/// edge, a chord, or a surface edge (a feature edge or an edge of a
/// constrained face, [`TetMesh::face_is_constrained`]).
fn is_splittable(a: u32, b: u32, cut: &HashSet<[u32; 2]>) -> bool {
    cut.is_empty() || !cut.contains(&edge_key(a, b))
}

/// A block's long edges and their shells' (slot, generation) pairs.
type LongEdgeBlock = (Vec<LongEdge>, Vec<(u32, u32)>);

/// The length above which [`split_long_edges`] splits an edge whatever
/// its neighbours' lengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LengthCap {
    /// No cap: only the relative test.
    Off,
    /// This multiple of the median, over the points of the zone's tets, of
    /// the mean edge length at a point, as the mesh stands before the pass.
    MedianTimes(f64),
}

/// What [`split_long_edges`] did.
pub(crate) struct LongEdgeSplits {
    /// Edges split.
    pub edges: usize,
    /// Boundary faces cut in two (each split adds one boundary face).
    pub boundary_faces: usize,
    /// The new tets.
    pub new_tets: Vec<u32>,
}

/// A long edge found by [`split_long_edges`].
struct LongEdge {
    length: f64,
    a: u32,
    b: u32,
    /// Whether the walk that found its shell reached every tet at `a`
    /// (see the loop in [`split_long_edges`]).
    whole_ball: bool,
    /// Where its split would put the new point ([`split_point`]).
    at: Option<DVec3>,
    /// Its shell as found: a range of the list of (slot, generation).
    shell: std::ops::Range<usize>,
}

/// Where along `(a, b)` a split is tried when its midpoint is refused:
/// points `SPLIT_STEP` of the edge's length apart on both sides of the
/// middle, out to `SPLIT_REACH` from it.
const SPLIT_STEP: f64 = 0.025;
/// See [`SPLIT_STEP`].
const SPLIT_REACH: f64 = 0.2;
/// How far from the middle the split of an edge whose new point must stay
/// on it (a feature edge, an edge at a crease) is looked for when no point
/// within [`SPLIT_REACH`] passes ([`split_point`]). Searching that far for
/// every edge (out to 0.3, not as a fallback) made mmg_tinyBoxt's one-step
/// longest edge longer, 0.1231 → 0.1385 (2026-12-07): the best point of
/// the wider range leaves thinner halves than a nearer point that passes.
const FAR_REACH: f64 = 0.35;

/// An edge longer than this times the mean edge length at its ends (or
/// than the cap, [`LengthCap`]) is very long: where it is a free interior
/// edge, its split is kept at a lower bar ([`RELAXED_NEED`]).
const VERY_LONG: f64 = 1.8;

/// The share of its usual bar (the smaller of the shell's worst and the
/// pass's bar) that the worst new tet of a very long free interior edge's
/// split must reach ([`VERY_LONG`]). Such an edge is left whole when every
/// point of it cuts a thin half (its shell held at the bar by the
/// smoother, a ring vertex well to one side of the middle): the longest
/// edges a step left were of that kind. Split at the lower bar, its new
/// point is free, and the long-edge rounds' full settling passes move
/// it off the edge and lift the thin halves; the floor passes and the
/// step's rescue keep the worst where it was. Measured on the shipped
/// meshes (2026-12-07, `benches/compare.sh`, against MMG3D `-hsiz`'s
/// longest edge at the same count, before → after): one default step,
/// mmg_tinyBoxt 1.73× → 1.43× and mmg_cube 1.49× → 1.19×, gmsh_t16's
/// output 30 tets more, the other four unchanged; two steps, the tripod
/// 1.72× → 1.20×, the holed bar 1.62× → 1.18×, mmg_cube 1.67× → 1.40×,
/// gmsh_t16 2.51× → 1.48×; worst angles
/// within 0.4°, averages within 0.1°. 0.8 left the tripod's two-step
/// longest at 1.60× (scaled to our count).
const RELAXED_NEED: f64 = 0.6;

/// Where the split of `(a, b)` (shell `sh`) puts its new point: the
/// midpoint where its worst new tet is at least the smaller of the shell's
/// worst and `bar`; else, of the points of the edge [`SPLIT_STEP`] apart
/// within [`SPLIT_REACH`] of the middle, the one whose worst new tet is
/// best, if it passes the same test; else, where no point of the edge
/// passes, a point found by what the edge allows:
///
/// - a free interior edge (its new point is free) that is `very_long`: the
///   best point off the edge ([`off_edge_point`]), or the best point of the
///   edge if that is better, kept at a lower bar ([`RELAXED_NEED`]); a
///   free interior edge that is not very long is left whole;
/// - a surface edge between two faces of one plane: the best point of that
///   plane ([`in_plane_point`]);
/// - any other edge (a feature edge, an edge at a crease or an interface),
///   and a flat surface edge whose plane has no point that passes: the
///   best point of the edge out to [`FAR_REACH`] from the middle.
///
/// `None` where none passes.
///
/// The midpoint's split can be refused where a ring vertex lies well to one
/// side of the plane through the midpoint square to the edge: one half of
/// its tet is then thin. A point of the edge nearer that vertex cuts it
/// more evenly. Measured on one default step (2026-12-06), against
/// midpoints only: the longest edge of mmg_cube fell from 0.72 to 0.34, of
/// mmg_tinyBoxt from 0.241 to 0.156, of the tripod from 5.15 to 4.51 and
/// of tetgen_example from 0.242 to 0.227; mmg_cube's 99th percentile from
/// 0.291 to 0.235, with 23 % more tets (0.7 %–6 % on the other meshes).
/// The best point, not the first that passes nearest the
/// middle: that one leaves its worst new tet just at the bar (the worst
/// rises through the bar as the point moves off the middle), and a second
/// step started from such tets ended lower (two default steps, 2026-12-06:
/// the holed bar 19.98° and gmsh_t16 18.86°, against 20.72° and 20.54° with
/// midpoints only).
///
/// Where no point of the edge passes, the edge's ring lies near one end
/// (an edge from a box's corner into its ball, a surface edge from a
/// feature line across a face): every point of the edge cuts a thin half.
/// The three fallbacks were measured on two default steps of mmg_tinyBoxt
/// (2026-12-08), whose longest edges were of that kind, in two clusters at
/// a corner and on a feature line: the longest edge went from 0.0890 to
/// 0.0460 (against MMG3D `-hsiz`'s longest at the same count, 2.65× →
/// 1.38×), its worst from 19.21° to 20.53°; mmg_cube's two-step worst
/// and average rose from 20.59° / 49.91° to 20.67° / 49.99° (3 % fewer
/// tets), the holed bar's and the tripod's moved by at most 0.03°. The
/// off-edge point for every free interior edge whose on-edge split is
/// refused, not only very long ones, made two steps of the ladder 6 %
/// more tets in three times the time (its average 0.8° lower).
fn split_point(
    mesh: &TetMesh,
    a: u32,
    b: u32,
    bar: f64,
    sh: &[u32],
    very_long: bool,
) -> Option<DVec3> {
    let (pa, pb) = (mesh.point(a), mesh.point(b));
    let need = shell_worst(mesh, sh).min(bar);
    let worst_at = |t: f64| halves_worst(mesh, a, b, pa.lerp(pb, t), sh);
    let middle = worst_at(0.5);
    if middle >= need {
        return Some(pa.lerp(pb, 0.5));
    }
    // The best of `from` and the points `0.5 + k·SPLIT_STEP` for `k` in
    // `ks`: (worst new tet, t).
    let best_of = |ks: &mut dyn Iterator<Item = i32>, from: (f64, f64)| {
        ks.map(|k| {
            let t = 0.5 + k as f64 * SPLIT_STEP;
            (worst_at(t), t)
        })
        .fold(from, |best, x| if x.0 > best.0 { x } else { best })
    };
    let steps = (SPLIT_REACH / SPLIT_STEP).round() as i32;
    let (q, t) = best_of(&mut (-steps..=steps).filter(|&k| k != 0), (middle, 0.5));
    if q >= need {
        return Some(pa.lerp(pb, t));
    }
    if is_free_interior_edge(mesh, a, b, sh) {
        if !very_long {
            return None;
        }
        let on_edge = pa.lerp(pb, t);
        let need = RELAXED_NEED * need;
        return match off_edge_point(mesh, a, b, sh, on_edge) {
            Some((x, q_off)) if q_off >= need && q_off > q => Some(x),
            _ => (q >= need).then_some(on_edge),
        };
    }
    if let Some((x, _)) = flat_surface_sides(mesh, a, b, sh)
        .and_then(|sides| in_plane_point(mesh, a, b, sh, t, sides))
        .filter(|&(_, q_in)| q_in >= need)
    {
        return Some(x);
    }
    let far = steps + 1..=(FAR_REACH / SPLIT_STEP).round() as i32;
    let (q, t) = best_of(&mut far.flat_map(|k| [-k, k]), (f64::NEG_INFINITY, 0.5));
    (q >= need).then(|| pa.lerp(pb, t))
}

/// The optimiser's tuning for [`off_edge_point`]: as for an insertion
/// ([`super::insertion`]), the new point starts on the edge, far from
/// where it ends.
const OFF_EDGE_PARAMS: OptimizeParams = OptimizeParams {
    iterations: 40,
    active_tol: 1e-3,
    halvings: 10,
};

/// Where the new point of a free interior edge's split `(a, b)` (shell
/// `sh`) raises the worst of its halves most, off the edge, and that
/// worst: the optimisation-based smoothing of the new point's ball
/// ([`optimize_position_in`]) started at `start`, a point of the edge.
/// `None` where the optimiser finds no better point or the halves would
/// not all stay positive there.
///
/// An edge from a fixed vertex whose ring lies near that end is split
/// thinly at every point of the edge (the half on the far side of the
/// ring is flat); off the edge, towards the ring's side, the halves are
/// fat. The new point is free, so it may stand anywhere in the shell.
fn off_edge_point(
    mesh: &TetMesh,
    a: u32,
    b: u32,
    sh: &[u32],
    start: DVec3,
) -> Option<(DVec3, f64)> {
    let mut ball = BallPoints::default();
    ball.load_edge_split(mesh, a, b, sh);
    let (mut qs, mut trial) = (Vec::new(), Vec::new());
    let (x, q) = optimize_position_in(&ball, start, &OFF_EDGE_PARAMS, &mut qs, &mut trial)?;
    ball.stays_positive(x).then_some((x, q))
}

/// The third corners `c`, `d` of the two boundary faces at the surface
/// edge `(a, b)` (shell `sh`) when they are the only constrained faces
/// there ([`TetMesh::face_is_constrained`]), carry the same marker, the
/// edge is not a feature edge, and `a, b, c, d` are coplanar within
/// [`FLAT_TOLERANCE`]: a new point in that plane inside `a c b d` leaves
/// the domain as it is (up to that tolerance). `None` otherwise.
fn flat_surface_sides(mesh: &TetMesh, a: u32, b: u32, sh: &[u32]) -> Option<[u32; 2]> {
    if mesh.is_feature_edge(a, b) {
        return None;
    }
    let mut sides = Vec::with_capacity(2);
    for &t in sh {
        let v = mesh.tet(t);
        for f in 0..4 {
            if v[f] == a || v[f] == b {
                continue;
            }
            if mesh.is_interface_face(t, f) {
                return None;
            }
            if mesh.is_boundary_face(t, f) {
                // The face's third corner: neither `a`, `b` nor `v[f]`.
                let c = (0..4)
                    .map(|k| v[k])
                    .find(|&x| x != a && x != b && x != v[f])?;
                sides.push(c);
            }
        }
    }
    let [c, d] = sides[..] else { return None };
    let (pa, pb, pc, pd) = (mesh.point(a), mesh.point(b), mesh.point(c), mesh.point(d));
    let (normal_c, normal_d) = ((pb - pa).cross(pc - pa), (pb - pa).cross(pd - pa));
    // `d`'s distance from the plane of `a, b, c`, and `c`'s from that of
    // `a, b, d`, within FLAT_TOLERANCE of the edge's length.
    let off = |p: DVec3, q: DVec3, n: DVec3| {
        (q - p).dot(n).abs() <= FLAT_TOLERANCE * n.length() * (pb - pa).length()
    };
    (mesh.face_marker([a, b, c]) == mesh.face_marker([a, b, d])
        && off(pa, pd, normal_c)
        && off(pa, pc, normal_d))
    .then_some([c, d])
}

/// How far, relative to the edge's length, a corner of the two boundary
/// faces at an edge may stand off the other face's plane for the faces
/// to count as one plane ([`flat_surface_sides`]). The boundary rules and
/// the boundary smoother compute points of a planar patch by affine
/// combinations and projections, which leave them an ulp or two off the
/// plane (mmg_tinyBoxt's box faces after two steps: `y = 1 - 2⁻⁵²`); the
/// exact `orient3d` then says "not coplanar". 1e-12 is thousands of ulps
/// above that and a million times below any `--hausd` (a fraction of the
/// local edge length): a new point on such a plane moves the domain by at
/// most that much.
const FLAT_TOLERANCE: f64 = 1e-12;

/// Pattern-search steps of [`in_plane_point`] (each halves the step on
/// failure).
const IN_PLANE_ITERATIONS: usize = 24;

/// Where, in the plane of the flat surface edge `(a, b)`'s two boundary
/// faces (third corners `sides`, [`flat_surface_sides`]), the new point of
/// its split raises the worst of its halves most, and that worst: a
/// compass search over the edge's direction and the plane's direction
/// square to it, started at the point `t` of the edge. Each coordinate on
/// which the four corners agree (within [`FLAT_TOLERANCE`]) is set to
/// `a`'s (an axis-aligned face stays on its plane to the bit); on other
/// planes the point is within rounding of it. `None` where the halves at
/// the point found would not all be positive.
///
/// A surface edge ending at a box's corner is split thinly at every point
/// of it where the ring's far vertex lies near one end; moved sideways in
/// the plane, towards the side face that is wider, the halves are fat.
fn in_plane_point(
    mesh: &TetMesh,
    a: u32,
    b: u32,
    sh: &[u32],
    t: f64,
    [c, d]: [u32; 2],
) -> Option<(DVec3, f64)> {
    let (pa, pb, pc, pd) = (mesh.point(a), mesh.point(b), mesh.point(c), mesh.point(d));
    let along = pb - pa;
    let across = along.cross(pc - pa).cross(along).normalize_or_zero() * along.length();
    let mut ball = BallPoints::default();
    ball.load_edge_split(mesh, a, b, sh);
    let snap = |mut x: DVec3| {
        for k in 0..3 {
            let (lo, hi) = [pb[k], pc[k], pd[k]]
                .into_iter()
                .fold((pa[k], pa[k]), |(lo, hi), v| (lo.min(v), hi.max(v)));
            if hi - lo <= FLAT_TOLERANCE * along.length() {
                x[k] = pa[k];
            }
        }
        x
    };
    let mut x = snap(pa.lerp(pb, t));
    let mut q = ball.worst(x);
    let mut h = 0.1;
    for _ in 0..IN_PLANE_ITERATIONS {
        let best = [along, -along, across, -across]
            .into_iter()
            .map(|dir| {
                let y = snap(x + h * dir);
                (ball.worst(y), y)
            })
            .fold((q, x), |best, y| if y.0 > best.0 { y } else { best });
        if best.0 > q {
            (q, x) = best;
        } else {
            h *= 0.5;
        }
    }
    ball.stays_positive(x).then_some((x, q))
}

/// Whether `(a, b)` (shell `sh`) is neither a feature edge nor an edge of
/// a constrained face ([`TetMesh::face_is_constrained`]: the boundary, a
/// region interface, a marked face): its new point would be free.
fn is_free_interior_edge(mesh: &TetMesh, a: u32, b: u32, sh: &[u32]) -> bool {
    !mesh.is_feature_edge(a, b)
        && sh.iter().all(|&t| {
            let v = mesh.tet(t);
            // The faces of `t` at the edge: those opposite its other two
            // corners.
            (0..4).all(|f| {
                v[f] == a
                    || v[f] == b
                    || !(mesh.is_boundary_face(t, f) || mesh.is_interface_face(t, f))
            })
        })
}

/// The median, over the points of the tets `in_zone` says yes to, of
/// `mean_len` (per point); 0 when there is none.
fn median_mean_length(mesh: &TetMesh, mean_len: &[f64], in_zone: impl Fn(u32) -> bool) -> f64 {
    let mut seen = vec![false; mesh.n_points()];
    for t in mesh.tet_ids() {
        if in_zone(t) {
            for v in mesh.tet(t) {
                seen[v as usize] = true;
            }
        }
    }
    let mut lengths: Vec<f64> = (0..mesh.n_points())
        .filter(|&v| seen[v])
        .map(|v| mean_len[v])
        .collect();
    if lengths.is_empty() {
        return 0.0;
    }
    let mid = lengths.len() / 2;
    *lengths.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Worst quality (min sine) of the tets `sh`.
fn shell_worst(mesh: &TetMesh, sh: &[u32]) -> f64 {
    sh.iter()
        .map(|&t| tet_min_sine(&mesh.tet_points(t)))
        .fold(f64::INFINITY, f64::min)
}

/// Worst quality (min sine) of the halves of the shell `sh` of `(a, b)`
/// when the edge is split at `p` ([`split_halves`]).
fn halves_worst(mesh: &TetMesh, a: u32, b: u32, p: glam::DVec3, sh: &[u32]) -> f64 {
    let mut new = f64::INFINITY;
    for &t in sh {
        for half in split_halves(mesh.tet(t), a, b, u32::MAX) {
            let q = half.map(|x| if x == u32::MAX { p } else { mesh.point(x) });
            new = new.min(tet_min_sine(&q));
        }
    }
    new
}

/// Splits every edge not on a partition face (nor, between two fixed
/// vertices, at a pinch; see the module doc) longer than `factor` times the
/// mean edge length at its two ends or longer than `cap`, longest first,
/// at its midpoint or the point near it that [`split_point`] finds. An
/// edge is split only when every tet of its shell is in `zone` (per tet
/// slot; `None`: every tet; the new tets join it) and when the worst of the
/// new tets is at least the smaller of the shell's worst and `bar` (min
/// sine), so the pass never lowers the worst tet below `bar` — but for a
/// very long free interior edge ([`VERY_LONG`]), whose split is kept at
/// [`RELAXED_NEED`] of that where `relax` says so: its halves may be below
/// `bar`, and the passes that follow lift them (the new point is free).
///
/// The candidates are found in parallel, with their shells and where
/// their splits would be kept, and split in one fixed order (length, then
/// vertex ids), so the result does not depend on the number of threads;
/// only a candidate whose shell an earlier split changed is looked at
/// again. On a 26³ cube grid's step this halved the pass (0.53 → 0.28 s).
pub(crate) fn split_long_edges(
    mesh: &mut TetMesh,
    factor: f64,
    cap: LengthCap,
    bar: f64,
    mut zone: Option<&mut Vec<bool>>,
    relax: bool,
) -> LongEdgeSplits {
    fn in_zone(zone: &Option<&mut Vec<bool>>, t: u32) -> bool {
        zone.as_ref()
            .is_none_or(|z| z.get(t as usize).copied().unwrap_or(false))
    }
    let n = mesh.n_points() as u32;
    let fixed = mesh.fixed_vertices();
    let tets_at = TetsAtVertex::new(mesh);
    let cut = partition_edges(mesh);
    // Not on a distributed rank's part: the passes there leave the cut's
    // vertices where they are, and the halves near it stayed thin (mmg_cube
    // on two ranks: 8,662 tets at 45.29° average against the serial
    // step's 7,193 at 47.88°).
    let relax = relax && cut.is_empty();
    // One ball walk per vertex: its mean edge length, and its neighbours of
    // higher id with the edge's length (each edge once, at its lower end),
    // by blocks of vertices so that the lists stay in a few flat arrays.
    const BLOCK: u32 = 1024;
    let blocks: Vec<NeighbourBlock> = {
        let mesh = &*mesh;
        (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(ball, nb), k| {
                    let vs = k * BLOCK..((k + 1) * BLOCK).min(n);
                    let mut means = Vec::with_capacity(vs.len());
                    let mut ends = Vec::with_capacity(vs.len());
                    let mut upper = Vec::new();
                    for v in vs {
                        neighbours(mesh, v, ball, nb);
                        let p = mesh.point(v);
                        let mut sum = 0.0;
                        for &u in nb.iter() {
                            let l = p.distance(mesh.point(u));
                            sum += l;
                            if u > v {
                                upper.push((u, l));
                            }
                        }
                        means.push(if nb.is_empty() {
                            0.0
                        } else {
                            sum / nb.len() as f64
                        });
                        ends.push(upper.len() as u32);
                    }
                    (means, ends, upper)
                },
            )
            .collect()
    };
    let mean_len: Vec<f64> = blocks.iter().flat_map(|b| b.0.iter().copied()).collect();
    let cap = match cap {
        LengthCap::Off => f64::INFINITY,
        LengthCap::MedianTimes(k) => k * median_mean_length(mesh, &mean_len, |t| in_zone(&zone, t)),
    };
    // Whether the edge `(a, b)` of length `l` is split at the lower bar
    // ([`VERY_LONG`]).
    let very_long = |a: u32, b: u32, l: f64| {
        let local = 0.5 * (mean_len[a as usize] + mean_len[b as usize]);
        relax && (l > VERY_LONG * local || l > cap)
    };
    // The long edges, each with its shell as found (slot and generation of
    // each tet) and whether the split would be kept; per block, then in
    // one list.
    let found: Vec<LongEdgeBlock> = {
        let mesh = &*mesh;
        let mean_len = &mean_len;
        let zone = &zone;
        let fixed = &fixed;
        let tets_at = &tets_at;
        let cut = &cut;
        blocks
            .par_iter()
            .enumerate()
            .map_init(Vec::new, |sh, (k, (_, ends, upper))| {
                let mut found = Vec::new();
                let mut shells = Vec::new();
                let mut from = 0;
                for (i, &end) in ends.iter().enumerate() {
                    let a = k as u32 * BLOCK + i as u32;
                    for &(b, l) in &upper[from..end as usize] {
                        let local = 0.5 * (mean_len[a as usize] + mean_len[b as usize]);
                        if l > factor * local || l > cap {
                            let both_fixed = fixed[a as usize] && fixed[b as usize];
                            let walked = mesh.edge_shell(a, b, sh);
                            let whole_ball = walked == tets_at.at(a) as usize;
                            if sh.iter().all(|&t| in_zone(zone, t))
                                && (whole_ball || !both_fixed)
                                && is_splittable(a, b, cut)
                            {
                                let start = shells.len();
                                shells.extend(sh.iter().map(|&t| (t, mesh.generation(t))));
                                found.push(LongEdge {
                                    length: l,
                                    a,
                                    b,
                                    whole_ball,
                                    at: split_point(mesh, a, b, bar, sh, very_long(a, b, l)),
                                    shell: start..shells.len(),
                                });
                            }
                        }
                    }
                    from = end as usize;
                }
                (found, shells)
            })
            .collect()
    };
    drop(blocks);
    let mut long = Vec::new();
    let mut shells = Vec::new();
    for (found, block_shells) in found {
        let base = shells.len();
        long.extend(found.into_iter().map(|e| LongEdge {
            shell: base + e.shell.start..base + e.shell.end,
            ..e
        }));
        shells.extend(block_shells);
    }
    long.sort_unstable_by(|x, y| {
        y.length
            .total_cmp(&x.length)
            .then((x.a, x.b).cmp(&(y.a, y.b)))
    });
    let mut done = LongEdgeSplits {
        edges: 0,
        boundary_faces: 0,
        new_tets: Vec::new(),
    };
    let mut sh = Vec::new();
    for e in long {
        let (a, b) = (e.a, e.b);
        // A shell whose tets are all still there is the edge's shell now
        // (a tet holding `a` and `b` made by an earlier split is a half of
        // one that held them, so one of these would be gone), and the
        // decision made on it stands. Otherwise an earlier split took the
        // edge or changed its shell: gather it again.
        //
        // At a pinch vertex the walk around `a` from its current tet may not
        // reach the shell at all, and then the edge is left, as the walk
        // alone decides: that case is always walked again. (A split keeps
        // the pieces of every ball as they were, so a ball found whole
        // stays whole.)
        let found = &shells[e.shell];
        // Where the new point goes (see `split_point`).
        let p = if e.whole_ball
            && found
                .iter()
                .all(|&(t, g)| mesh.is_alive(t) && mesh.generation(t) == g)
        {
            let Some(at) = e.at else { continue };
            sh.clear();
            sh.extend(found.iter().map(|&(t, _)| t));
            at
        } else {
            mesh.edge_shell(a, b, &mut sh);
            if sh.is_empty() || !sh.iter().all(|&t| in_zone(&zone, t)) {
                continue;
            }
            let Some(at) = split_point(mesh, a, b, bar, &sh, very_long(a, b, e.length)) else {
                continue;
            };
            at
        };
        let boundary_faces: usize = sh
            .iter()
            .map(|&t| {
                let v = mesh.tet(t);
                (0..4)
                    .filter(|&f| v[f] != a && v[f] != b && mesh.is_boundary_face(t, f))
                    .count()
            })
            .sum();
        if let Ok((_, tets)) = split_shell(mesh, a, b, p, &sh) {
            if let Some(z) = zone.as_deref_mut() {
                z.resize(mesh.n_tet_slots().max(z.len()), false);
                for &t in &tets {
                    z[t as usize] = true;
                }
            }
            done.new_tets.extend(tets);
            done.edges += 1;
            done.boundary_faces += boundary_faces;
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::boundary_face_count;
    use crate::mesh::generate::total_volume as volume;
    use crate::mesh::MeshData;

    /// A bipyramid with caps: the axis `a = (0,0,-3)`, `b = (0,0,3)`
    /// (length 6) and a ring of six points on the unit circle make six tets
    /// around the axis, and two apexes `(0,0,∓4)` cap them with six tets
    /// each, so `a` and `b` are interior and the axis is a free edge. By
    /// hand: the mean edge length is (6 + 1 + 6·√10)/8 ≈ 3.247 at `a` and
    /// `b`, (1 + 6·√17)/7 ≈ 3.677 at an apex and (2·√10 + 2·√17 + 2)/6 ≈
    /// 2.762 at a ring point, so with factor 1.4 only the axis is long
    /// (6 > 4.55; a spoke √10 ≈ 3.16 < 1.4·3.00; an apex edge √17 ≈ 4.12 <
    /// 1.4·3.22; a ring edge 1), and the axis stands 6/3.247 ≈ 1.85 times
    /// over its local mean.
    fn bipyramid() -> TetMesh {
        let mut points = vec![[0.0, 0.0, -3.0], [0.0, 0.0, 3.0]];
        for i in 0..6 {
            let t = std::f64::consts::PI / 3.0 * i as f64;
            points.push([t.cos(), t.sin(), 0.0]);
        }
        points.extend([[0.0, 0.0, -4.0], [0.0, 0.0, 4.0]]);
        let ring = |i: u32| 2 + i % 6;
        let mut tets: Vec<[u32; 4]> = (0..6u32).map(|i| [0, 1, ring(i), ring(i + 1)]).collect();
        tets.extend((0..6u32).map(|i| [8, 0, ring(i), ring(i + 1)]));
        tets.extend((0..6u32).map(|i| [1, 9, ring(i), ring(i + 1)]));
        let data = MeshData {
            points,
            tets,
            ..Default::default()
        };
        TetMesh::from_data(&data)
            .expect("a valid capped bipyramid")
            .0
    }

    #[test]
    fn the_one_long_edge_is_split_at_its_midpoint() {
        let mut m = bipyramid();
        // The hexagon (six triangles of area √3/4) times the heights
        // 6 + 1 + 1, over three.
        let exact = 6.0 * 3f64.sqrt() / 4.0 * 8.0 / 3.0;
        assert!((volume(&m) - exact).abs() < 1e-12);
        let done = split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true);
        assert_eq!((done.edges, done.boundary_faces), (1, 0));
        let new = done.new_tets;
        // Every tet of the six-tet shell becomes two.
        assert_eq!(new.len(), 12);
        assert_eq!(m.n_tets(), 24);
        assert_eq!(m.n_points(), 11);
        assert_eq!(m.point(10), glam::DVec3::ZERO);
        assert!((volume(&m) - exact).abs() < 1e-12);
        m.check().expect("a valid mesh after the split");
        // Nothing is long any more at 1.4: a half axis, 3, against
        // 1.4·(2.872 + 1.5)/2 ≈ 3.06 (the means at `a` and at the midpoint).
        assert_eq!(
            split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true).edges,
            0
        );
    }

    /// One tet `a = (0,0,0)`, `b = (2,0,0)`, `p = (0.7,1.2,0)`, `q =
    /// (0.7,0,1.2)`: `(a, b)` is 2 against means of about 1.593 at `a` and
    /// 1.846 at `b` (ratio 1.163; every other edge below 1.1 times its
    /// ends' means). The ring vertices lie at x = 0.7, so the plane through
    /// the midpoint (1,0,0), `p` and `q` cuts a thin half. Worst half, in
    /// degrees of minimum dihedral angle, computed apart with numpy (volume
    /// times edge length over the two face areas): 37.40 at t = 0.5, 43.60
    /// at 0.45, 46.84 at 0.425 (the best of the points tried), 46.24 at 0.4,
    /// 42.89 at 0.375; the tet itself 53.69. With the bar at 43° the first
    /// point from the middle to pass would be 0.45; the split goes at the
    /// best, t = 0.425, x = 0.85.
    #[test]
    fn a_split_refused_at_the_midpoint_goes_to_the_best_point_off_it() {
        let points = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.7, 1.2, 0.0],
            [0.7, 0.0, 1.2],
        ];
        let corners = std::array::from_fn(|i| glam::DVec3::from_array(points[i]));
        let tet = if crate::geom::tet_volume(&corners) > 0.0 {
            [0, 1, 2, 3]
        } else {
            [1, 0, 2, 3]
        };
        let data = MeshData {
            points,
            tets: vec![tet],
            ..Default::default()
        };
        let mut m = TetMesh::from_data(&data).expect("one tet").0;
        let bar = 43f64.to_radians().sin();
        let done = split_long_edges(&mut m, 1.1, LengthCap::Off, bar, None, true);
        assert_eq!((done.edges, done.boundary_faces), (1, 2));
        m.check().expect("a valid mesh after the split");
        let x = m.point(m.n_points() as u32 - 1);
        assert!(x.distance(glam::DVec3::new(0.85, 0.0, 0.0)) < 1e-12, "{x}");
        // Volume: base triangle a, b, p (area 1.2) times q's height 1.2 / 3.
        assert!((volume(&m) - 1.2 * 1.2 / 3.0).abs() < 1e-12);
        let worst = m
            .tet_ids()
            .map(|t| tet_min_sine(&m.tet_points(t)))
            .fold(f64::INFINITY, f64::min);
        assert!((worst.asin().to_degrees() - 46.842).abs() < 1e-3, "{worst}");
    }

    #[test]
    fn an_edge_with_a_tet_outside_the_zone_stays() {
        let mut m = bipyramid();
        let mut zone = vec![true; m.n_tet_slots()];
        zone[3] = false;
        assert_eq!(
            split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, Some(&mut zone), true).edges,
            0
        );
        assert_eq!(m.n_tets(), 18);
        let mut zone = vec![true; m.n_tet_slots()];
        let done = split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, Some(&mut zone), true);
        assert_eq!(done.edges, 1);
        let new = done.new_tets;
        assert!(new.iter().all(|&t| zone[t as usize]));
    }

    #[test]
    fn a_higher_factor_splits_nothing() {
        // The axis is 1.85 times its local mean.
        let mut m = bipyramid();
        assert_eq!(
            split_long_edges(&mut m, 1.9, LengthCap::Off, 0.3, None, true).edges,
            0
        );
        assert_eq!(
            split_long_edges(&mut m, 1.8, LengthCap::Off, 0.3, None, true).edges,
            1
        );
    }

    /// The bipyramid's points with only its tets `ids` (slots of
    /// [`bipyramid`]).
    fn bipyramid_part(ids: std::ops::Range<u32>) -> TetMesh {
        let m = bipyramid();
        let data = MeshData {
            points: m.points().iter().map(|p| p.to_array()).collect(),
            tets: ids.map(|t| m.tet(t)).collect(),
            ..Default::default()
        };
        TetMesh::from_data(&data)
            .expect("a part of the bipyramid")
            .0
    }

    /// The capped bipyramid without the axis tet `(a, b, r0, r1)`: the axis
    /// now lies on the boundary, between the boundary faces `(a, b, r0)`
    /// and `(a, b, r1)`, with a shell of five tets. Every edge of the capped
    /// bipyramid is still there (the removed tet's other edges are held by
    /// its neighbours), so the means and the factor of [`bipyramid`] hold.
    fn notched() -> TetMesh {
        bipyramid_part(1..18)
    }

    #[test]
    fn a_long_boundary_edge_is_split_with_its_faces_markers_and_feature_tag() {
        let mut m = notched();
        // The full bipyramid's volume less the removed tet's (a sixth of
        // the hexagon's area times the axis, over three).
        let exact = 6.0 * 3f64.sqrt() / 4.0 * (8.0 - 6.0 / 6.0) / 3.0;
        assert!((volume(&m) - exact).abs() < 1e-12);
        // The caps' twelve outer faces and the removed tet's four.
        assert_eq!(boundary_face_count(&m), 12 + 4);
        for q in [2, 3] {
            m.set_face_marker([0, 1, q], Some(5));
        }
        m.set_feature_edge(0, 1, Some(9));
        let done = split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true);
        assert_eq!((done.edges, done.boundary_faces), (1, 2));
        let new = done.new_tets;
        assert_eq!(new.len(), 10, "five shell tets, two halves each");
        m.check().expect("a valid mesh after the split");
        let mid = m.n_points() as u32 - 1;
        assert_eq!(m.point(mid), glam::DVec3::ZERO);
        // The domain is unchanged: the same volume, each boundary face on
        // the axis split in two.
        assert!((volume(&m) - exact).abs() < 1e-12);
        assert_eq!(boundary_face_count(&m), 16 + 2);
        assert_eq!(m.feature_edge(0, mid), Some(9));
        assert_eq!(m.feature_edge(mid, 1), Some(9));
        assert!(!m.is_feature_edge(0, 1));
        for q in [2, 3] {
            assert_eq!(m.face_marker([0, mid, q]), Some(5));
            assert_eq!(m.face_marker([mid, 1, q]), Some(5));
        }
    }

    #[test]
    fn an_edge_of_a_partition_face_stays() {
        let mut m = notched();
        let cut = crate::mesh::partition::partition_marker(1);
        m.set_face_marker([0, 1, 2], Some(cut));
        assert_eq!(
            split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true).edges,
            0
        );
        assert_eq!(m.n_tets(), 17);
    }

    #[test]
    fn a_chord_between_boundary_points_is_split() {
        // Without its caps the axis joins two boundary points through the
        // inside.
        let mut m = bipyramid_part(0..6);
        // Means 6/7 + 6/7 at a and b ((6 + 6·√10)/7 ≈ 3.568), so the axis
        // stands 6/3.568 ≈ 1.68 times over them.
        assert_eq!(
            split_long_edges(&mut m, 1.7, LengthCap::Off, 0.3, None, true).edges,
            0
        );
        assert_eq!(
            split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true).edges,
            1
        );
        assert_eq!(m.n_tets(), 12);
        m.check().expect("a valid mesh after the split");
        assert!(
            !m.fixed_vertices()[m.n_points() - 1],
            "the midpoint is inside"
        );
    }

    /// `cube_grid(2)`: edges of 0.5 (along the axes), √2/2 (face
    /// diagonals) and √3/2 (the eight cube diagonals, each inside its cube
    /// with a shell of six tets). Computed apart with numpy: the median over
    /// the 27 points of the mean edge length at a point is 0.61945, and no
    /// edge is more than 1.3936 times the mean of its ends' means, so the
    /// relative test at 1.4 finds nothing, a cap of 1.4 times the median
    /// (0.86722) is above √3/2 = 0.86603, and one of 1.3 times (0.80528)
    /// is below it and above √2/2.
    #[test]
    fn the_cap_splits_the_cube_diagonals_the_relative_test_leaves() {
        let data = crate::mesh::generate::cube_grid(2);
        let mut m = TetMesh::from_data(&data).expect("a cube grid").0;
        assert_eq!(
            split_long_edges(&mut m, 1.4, LengthCap::Off, 0.3, None, true).edges,
            0
        );
        let above = LengthCap::MedianTimes(1.4);
        assert_eq!(
            split_long_edges(&mut m, 1.4, above, 0.3, None, true).edges,
            0
        );
        let done = split_long_edges(&mut m, 1.4, LengthCap::MedianTimes(1.3), 0.3, None, true);
        assert_eq!((done.edges, done.boundary_faces), (8, 0));
        // Each cube's six tets become twelve around its centre.
        assert_eq!(m.n_tets(), 8 * 12);
        assert_eq!(m.n_points(), 27 + 8);
        let mut centres: Vec<[f64; 3]> = (27..35).map(|v| m.point(v).to_array()).collect();
        centres.sort_by(|x, y| x.partial_cmp(y).expect("finite"));
        let mut expect = Vec::new();
        for x in [0.25, 0.75] {
            for y in [0.25, 0.75] {
                for z in [0.25, 0.75] {
                    expect.push([x, y, z]);
                }
            }
        }
        assert_eq!(centres, expect);
        assert!((volume(&m) - 1.0).abs() < 1e-12);
        m.check().expect("a valid mesh after the splits");
    }

    /// The median over the zone's points only: in `cube_grid(2)` the
    /// corners of the first cube (its six tets, slots 0 to 5) have mean
    /// edge lengths 0.61945 (three of them), 0.62342 (three) and 0.64105
    /// (two), computed apart with numpy; their median, the upper of the two
    /// middle values, is 0.62342, against 0.61945 over the whole grid. At
    /// 1.394 times the median the cap is 0.86905 over the zone, above the
    /// cube diagonal √3/2 = 0.86603, and 0.86349 over the whole grid, below
    /// it.
    #[test]
    fn the_cap_takes_its_median_over_the_zone() {
        let data = crate::mesh::generate::cube_grid(2);
        let mut m = TetMesh::from_data(&data).expect("a cube grid").0;
        for t in 0..6 {
            assert!(m.tet_points(t).iter().all(|p| p.max_element() <= 0.5));
        }
        let mut zone = vec![false; m.n_tet_slots()];
        zone[..6].fill(true);
        let cap = LengthCap::MedianTimes(1.394);
        let in_zone = split_long_edges(&mut m, 1.4, cap, 0.3, Some(&mut zone), true);
        assert_eq!(in_zone.edges, 0);
        assert_eq!(split_long_edges(&mut m, 1.4, cap, 0.3, None, true).edges, 8);
    }
}

/// The fallbacks of [`split_point`] on two shells taken from mmg_tinyBoxt
/// after two default steps with the build before them (2026-12-07), near
/// the box's corner (5, 1, 1) and the feature line y = z = 1, where every
/// point of the edge cut a thin half. Coordinates as written by the
/// `.mesh` writer (shortest round-trip form).
#[cfg(test)]
mod fallback_tests {
    use super::*;
    use crate::geom::tet_volume;
    use crate::mesh::generate::total_volume;
    use crate::mesh::MeshData;

    /// The mesh of `tets` over `points`, each tet turned positive.
    fn mesh_of(points: &[[f64; 3]], tets: &[[u32; 4]]) -> TetMesh {
        let tets = tets
            .iter()
            .map(|&t| {
                let c = t.map(|i| DVec3::from_array(points[i as usize]));
                if tet_volume(&c) > 0.0 {
                    t
                } else {
                    [t[1], t[0], t[2], t[3]]
                }
            })
            .collect();
        let data = MeshData {
            points: points.to_vec(),
            tets,
            ..Default::default()
        };
        TetMesh::from_data(&data).expect("a valid shell").0
    }

    /// The worst min-sine and the smallest volume of the tets made by
    /// putting `p` in place of `a`, and in place of `b`, in each tet of
    /// the shell of `(a, b)`: the halves of its split at `p`, built here
    /// by hand.
    fn halves_at(m: &TetMesh, a: u32, b: u32, p: DVec3) -> (f64, f64) {
        let mut sh = Vec::new();
        m.edge_shell(a, b, &mut sh);
        let (mut worst, mut volume) = (f64::INFINITY, f64::INFINITY);
        for &t in &sh {
            for end in [a, b] {
                let c = m.tet(t).map(|x| if x == end { p } else { m.point(x) });
                worst = worst.min(tet_min_sine(&c));
                volume = volume.min(tet_volume(&c));
            }
        }
        (worst, volume)
    }

    /// The best worst half over the points of the edge `0.5 ± k·0.025`
    /// for `k` up to `reach` steps.
    fn best_on_edge(m: &TetMesh, reach: i32) -> f64 {
        let (pa, pb) = (m.point(0), m.point(1));
        (-reach..=reach)
            .map(|k| halves_at(m, 0, 1, pa.lerp(pb, 0.5 + k as f64 * 0.025)).0)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Distance of `x` from the line through points 0 and 1, over their
    /// distance.
    fn off_line(m: &TetMesh, x: DVec3) -> f64 {
        let (pa, pb) = (m.point(0), m.point(1));
        let t = (x - pa).dot(pb - pa) / (pb - pa).length_squared();
        pa.lerp(pb, t).distance(x) / pa.distance(pb)
    }

    /// Splits the edge (0, 1) at `x` and checks the mesh and its volume.
    fn split_and_check(m: &mut TetMesh, x: DVec3) {
        let before = total_volume(m);
        let mut sh = Vec::new();
        m.edge_shell(0, 1, &mut sh);
        let (_, new) = split_shell(m, 0, 1, x, &sh).expect("the split is made");
        assert_eq!(new.len(), 2 * sh.len());
        m.check().expect("a valid mesh after the split");
        let after = total_volume(m);
        assert!((after - before).abs() <= 1e-12 * before, "{before} {after}");
    }

    /// An edge from a point inside the box to its corner (5, 1, 1), whose
    /// ring of six lies near the inner end: no point of the edge, out to
    /// ±0.35 of it, gives halves at the lower bar of very long edges; a
    /// point off the edge does.
    #[test]
    fn a_very_long_free_edge_no_point_of_which_splits_well_is_split_off_it() {
        let points = [
            [4.911174298152882, 0.9968813146689889, 0.9955211113897702],
            [5.0, 1.0, 1.0],
            [4.922719025000532, 1.0, 0.9952507813507827],
            [4.936576634065602, 0.9948900707095202, 1.0],
            [4.949839206614152, 1.0, 1.0],
            [4.971047771548676, 0.9953483427425339, 0.9955974941631384],
            [4.950003035679668, 0.995975398335145, 0.9922204078453402],
            [4.94388935620968, 0.9983916541097334, 0.9925674224076461],
        ];
        let tets = [
            [0, 1, 4, 3],
            [0, 1, 5, 6],
            [1, 4, 2, 0],
            [0, 5, 1, 3],
            [1, 7, 0, 2],
            [0, 7, 1, 6],
        ];
        let mut m = mesh_of(&points, &tets);
        let mut sh = Vec::new();
        m.edge_shell(0, 1, &mut sh);
        assert_eq!(sh.len(), 6);
        let need = m
            .tet_ids()
            .map(|t| tet_min_sine(&m.tet_points(t)))
            .fold(0.35, f64::min);
        assert!(best_on_edge(&m, 14) < RELAXED_NEED * need);
        // Not very long: left whole.
        assert_eq!(split_point(&m, 0, 1, 0.35, &sh, false), None);
        let x = split_point(&m, 0, 1, 0.35, &sh, true).expect("a point off the edge");
        assert!(off_line(&m, x) > 1e-3, "{x}");
        let (worst, volume) = halves_at(&m, 0, 1, x);
        assert!(
            worst >= RELAXED_NEED * need && volume > 0.0,
            "{worst} {volume}"
        );
        split_and_check(&mut m, x);
    }

    /// A surface edge from the feature line y = z = 1 across the face
    /// y = 1 (one ring point stands an ulp off it, as the boundary rules
    /// leave it): within ±0.2 of its middle no point of the edge passes
    /// the bar; the best point of the face's plane does, better than any
    /// point of the edge out to ±0.35, and lies on y = 1 exactly.
    #[test]
    fn a_flat_surface_edge_is_split_at_the_best_point_of_its_plane() {
        let points = [
            [0.16896533199851982, 1.0, 0.9940035842527635],
            [0.24155355735181644, 1.0, 1.0],
            [0.17912992759288132, 0.9970539918804403, 0.9963120692475165],
            [0.19087575931640627, 1.0, 1.0],
            [0.202365200176345, 0.9960252304227388, 0.9922909927126888],
            [0.19624647591882305, 0.9999999999999999, 0.991696786539015],
        ];
        let mut m = mesh_of(&points, &[[1, 3, 0, 2], [1, 5, 4, 0], [1, 4, 2, 0]]);
        let mut sh = Vec::new();
        m.edge_shell(0, 1, &mut sh);
        let need = m
            .tet_ids()
            .map(|t| tet_min_sine(&m.tet_points(t)))
            .fold(0.35, f64::min);
        assert!(best_on_edge(&m, 8) < need);
        let x = split_point(&m, 0, 1, 0.35, &sh, false).expect("a point of the plane");
        assert_eq!(x.y, 1.0);
        assert!(off_line(&m, x) > 1e-3, "{x}");
        let (worst, volume) = halves_at(&m, 0, 1, x);
        assert!(worst >= need && worst > best_on_edge(&m, 14) && volume > 0.0);
        split_and_check(&mut m, x);
    }
}
