//! Vertex insertion for the slivers that flips, contractions and smoothing
//! leave: a new vertex on one of the bad tet's edges splits the edge's shell
//! ([`crate::ops::split_edge`]) and is placed where the worst of the new tets
//! is best, found by the same optimisation-based smoothing that moves
//! existing vertices.
//!
//! A sliver `(a, b, c, d)` with its diagonals `ab` and `cd` nearly crossing
//! becomes the halves `(m, b, c, d)` and `(a, m, c, d)`; with `m` lifted off
//! the sliver's plane above the crossing, both are fat. Klingner and
//! Shewchuk ("Aggressive tetrahedral mesh improvement", IMR 2007) found
//! insertion the operation that lifts the slivers the others cannot; MMG3D
//! inserts on edges too. Here the insertion is judged before anything
//! changes: the candidate's ball is loaded with the new vertex as a
//! placeholder, the position optimised, and the split made only when the
//! ball's worst beats the worst of the shell it replaces.

use super::optimize::{optimize_position_in, OptimizeParams};
use super::BallPoints;
use crate::mesh::TetMesh;
use crate::ops::EdgeRing;
use glam::DVec3;

/// The optimiser's tuning here: more iterations than a vertex move, as the
/// new vertex starts on the edge (or at the shell's centroid), far from
/// where it ends.
const PARAMS: OptimizeParams = OptimizeParams {
    iterations: 40,
    active_tol: 1e-3,
    halvings: 10,
};

/// A split that raises the worst tet of an edge's shell.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct InsertionPlan {
    /// First end of the edge.
    pub a: u32,
    /// Second end of the edge.
    pub b: u32,
    /// The tets around the edge, which the split replaces.
    pub shell: Vec<u32>,
    /// Where the new vertex goes.
    pub x: DVec3,
    /// The worst min-sine of the new tets there.
    pub quality: f64,
}

/// Scratch reused between searches.
#[derive(Default)]
pub(crate) struct InsertionScratch {
    ring: EdgeRing,
    ball: BallPoints,
    qualities: Vec<f64>,
    trial: Vec<f64>,
    /// The vertices the last [`plan_insertion`] read: the tet's and its
    /// edges' ring vertices, with repeats.
    pub read: Vec<u32>,
}

/// The best split of an edge of tet `t` whose new vertex raises the worst
/// of the new tets above `beat`. Callers pass `t`'s own quality: every
/// shell holds `t`, so its worst is at most that and the split raises it.
/// Only edges inside one region are tried: a closed
/// shell, no marked face holding the edge, no feature tag, every shell tet
/// allowed by `allowed` — so the new vertex is an interior vertex and the
/// domain, interfaces and tags stay as they are.
pub(crate) fn plan_insertion(
    mesh: &TetMesh,
    t: u32,
    beat: f64,
    allowed: impl Fn(u32) -> bool,
    s: &mut InsertionScratch,
) -> Option<InsertionPlan> {
    let mut best: Option<InsertionPlan> = None;
    let region = mesh.region(t);
    s.read.clear();
    s.read.extend(mesh.tet(t));
    for e in 0..6 {
        s.ring.gather_into(mesh, t, e);
        let ring = &s.ring;
        s.read.extend(&ring.verts);
        if !ring.closed
            || mesh.feature_edge(ring.a, ring.b).is_some()
            || ring
                .tets
                .iter()
                .any(|&x| mesh.region(x) != region || !allowed(x))
            || ring
                .verts
                .iter()
                .any(|&p| mesh.face_marker([ring.a, ring.b, p]).is_some())
        {
            continue;
        }
        let bar = beat.max(best.as_ref().map_or(f64::NEG_INFINITY, |b| b.quality));
        s.ball.load_edge_split(mesh, ring.a, ring.b, &ring.tets);
        // Two starts: the edge's midpoint, and the centroid of the shell's
        // vertices (the Laplacian position, which for a sliver's diagonal
        // already stands off the sliver's plane).
        let (pa, pb) = (mesh.point(ring.a), mesh.point(ring.b));
        let centroid = (ring.verts.iter().map(|&v| mesh.point(v)).sum::<DVec3>() + pa + pb)
            / (ring.verts.len() + 2) as f64;
        let mut found = (DVec3::ZERO, f64::NEG_INFINITY);
        for x0 in [0.5 * (pa + pb), centroid] {
            let at_start = s.ball.worst(x0);
            let (x, q) = optimize_position_in(&s.ball, x0, &PARAMS, &mut s.qualities, &mut s.trial)
                .unwrap_or((x0, at_start));
            if q > found.1 {
                found = (x, q);
            }
        }
        let (x, q) = found;
        if q > bar && s.ball.stays_positive(x) {
            best = Some(InsertionPlan {
                a: ring.a,
                b: ring.b,
                shell: ring.tets.clone(),
                x,
                quality: q,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{tet_min_sine, tet_volume};
    use crate::mesh::generate::cube_grid;
    use crate::ops::split_edge;
    use crate::topo::{TET_EDGES, TET_FACES};

    /// Whether `v` lies inside the unit cube (not on its boundary).
    fn inside(m: &TetMesh, v: u32) -> bool {
        let p = m.point(v);
        [p.x, p.y, p.z].iter().all(|&x| x > 0.0 && x < 1.0)
    }

    /// The unit cube in 3×3×3 cells, one vertex of a tet of the middle cell
    /// (whose corners are all interior) pushed 98 % of the way to the
    /// centroid of the tet's far face: that tet becomes a flat sliver whose
    /// edges are all interior. Returns the mesh and the sliver.
    fn cube_with_a_sliver() -> (TetMesh, u32) {
        let mut m = TetMesh::from_data(&cube_grid(3)).expect("a cube").0;
        let t = m
            .tet_ids()
            .find(|&t| m.tet(t).iter().all(|&v| inside(&m, v)))
            .expect("a tet of the middle cell");
        let c = m.tet(t)[0];
        let far = TET_FACES[0].map(|k| m.point(m.tet(t)[k]));
        let target = (far[0] + far[1] + far[2]) / 3.0;
        m.set_point(c, m.point(c) + 0.98 * (target - m.point(c)));
        m.check().expect("still valid");
        (m, t)
    }

    fn qualities(m: &TetMesh) -> Vec<f64> {
        let mut q = vec![f64::INFINITY; m.n_tet_slots()];
        for t in m.tet_ids() {
            q[t as usize] = tet_min_sine(&m.tet_points(t));
        }
        q
    }

    #[test]
    fn a_split_with_the_vertex_lifted_beats_the_sliver() {
        let (mut m, t) = cube_with_a_sliver();
        let tq = qualities(&m);
        assert!(tq[t as usize] < 0.1, "a sliver: {}", tq[t as usize]);
        let mut s = InsertionScratch::default();
        let plan = plan_insertion(&m, t, tq[t as usize], |_| true, &mut s).expect("an insertion");
        assert!(m.tet(t).contains(&plan.a) && m.tet(t).contains(&plan.b));
        let mut shell = Vec::new();
        m.ball(plan.a, &mut shell);
        shell.retain(|&x| m.tet(x).contains(&plan.b));
        // The plan's shell is the edge's, found through the ball of `a`.
        let mut planned = plan.shell.clone();
        planned.sort_unstable();
        shell.sort_unstable();
        assert_eq!(planned, shell);
        let shell_worst = shell
            .iter()
            .map(|&x| tq[x as usize])
            .fold(f64::INFINITY, f64::min);
        let n = m.n_tets();
        let (_, new) = split_edge(&mut m, plan.a, plan.b, plan.x).expect("applies");
        // k shell tets become 2k; the cube keeps its volume.
        assert_eq!(new.len(), 2 * shell.len());
        assert_eq!(m.n_tets(), n + shell.len());
        let volume: f64 = m.tet_ids().map(|t| tet_volume(&m.tet_points(t))).sum();
        assert!((volume - 1.0).abs() < 1e-12, "{volume}");
        m.check().expect("valid after the split");
        // The new tets are what the plan promised, and better than the shell.
        let worst_new = new
            .iter()
            .map(|&x| tet_min_sine(&m.tet_points(x)))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(worst_new, plan.quality);
        assert!(
            worst_new > shell_worst + 0.1,
            "{worst_new} vs {shell_worst}"
        );
    }

    #[test]
    fn tagged_edges_refused_shells_and_interfaces_are_not_split() {
        let (m, t) = cube_with_a_sliver();
        let tq = qualities(&m);
        let mut s = InsertionScratch::default();
        let q = tq[t as usize];
        assert!(plan_insertion(&m, t, q, |_| true, &mut s).is_some());
        let tv = m.tet(t);
        // A shell holding a tet the caller refuses.
        assert_eq!(plan_insertion(&m, t, q, |x| x != t, &mut s), None);
        // Feature edges.
        let mut f = m.clone();
        for [i, j] in TET_EDGES {
            f.set_feature_edge(tv[i], tv[j], Some(1));
        }
        assert_eq!(plan_insertion(&f, t, q, |_| true, &mut s), None);
        // A marked face on each edge (an embedded surface).
        let mut f = m.clone();
        for face in TET_FACES {
            f.set_face_marker(face.map(|k| tv[k]), Some(3));
        }
        assert_eq!(plan_insertion(&f, t, q, |_| true, &mut s), None);
        // Another region around the sliver: every shell crosses an interface.
        let mut f = m.clone();
        for x in m.tet_ids().filter(|&x| x != t) {
            f.set_region(x, 7);
        }
        assert_eq!(plan_insertion(&f, t, q, |_| true, &mut s), None);
    }
}
