//! Multi-face removal: a set of faces sandwiched between two vertices `u`
//! and `w` goes, and the tets on both sides are replaced by the tets around
//! the new edge `u`–`w`. It is the inverse of edge removal, and a 2-3 flip
//! is its one-face case.
//!
//! ```text
//!               u               a sandwiched face (x, y, z): the tets
//!             / | \             [u, x, y, z] (positive, so x → y → z runs
//!           x---|---z           counterclockwise seen from u) and
//!            \  |  /            [w, z, y, x] both exist. n such faces
//!              \y/              forming a triangulated polygon are 2n tets;
//!               |               each polygon side (a, b), in the order of
//!               w               its face, gives the new tet [u, a, b, w]:
//!                               2n → n + 2.
//! ```
//!
//! The faces that may go together are grown from one face across its
//! edges: the face (b, a, p) across side (a, b) joins when the tets
//! [u, b, a, p] and [w, p, a, b] both exist. These faces form a tree, and
//! the subtree to remove is the one whose worst new tet is best, found by
//! the dynamic programme of Shewchuk ("Two discrete optimization
//! algorithms for the topological improvement of tetrahedral meshes",
//! 2002): the value of a face is the minimum over its sides of the better
//! of stopping there (the side's new tet) and going on into the face
//! behind it (that face's value).
//!
//! Every new tet is checked with the exact predicate before the cavity is
//! replaced. Positive new tets whose boundary is the cavity's fill it
//! exactly once, so a subtree that would close a cycle (a vertex whose
//! faces all go, which would be lost) shows up as a side used in both
//! directions, one of whose tets is inverted: it is never chosen.

use super::{replace_cavity, OpError};
use crate::geom::{is_positive, tet_min_sine};
use crate::mesh::{face_key, FaceKey, TetMesh, NO_ADJ};

/// The vertices `(x, y, z)` of face `f` of tet `t` ordered so that
/// `[t[f], x, y, z]` is an even permutation of `t`, hence positive.
fn face_seen_from_apex(v: [u32; 4], f: usize) -> [u32; 3] {
    match f {
        0 => [v[1], v[2], v[3]],
        1 => [v[2], v[0], v[3]],
        2 => [v[0], v[1], v[3]],
        _ => [v[0], v[2], v[1]],
    }
}

/// A sandwiched face of the growth tree.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// Its vertices, counterclockwise seen from `u`.
    face: [u32; 3],
    /// The tet `[u, face]` and the tet `[w, face reversed]`.
    tu: u32,
    tw: u32,
    /// The side (index into `face`, side `k` = `face[k]`–`face[k+1]`)
    /// shared with the parent; `usize::MAX` at the root.
    up: usize,
    /// The face behind each side, if it may go too.
    child: [u32; 3],
}

const NONE: u32 = u32::MAX;

/// What [`remove_faces`] did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaceRemoval {
    /// The faces removed.
    pub faces: usize,
    /// The tets that went (two per face).
    pub removed: Vec<u32>,
    /// The new tets around the new edge.
    pub created: Vec<u32>,
}

/// Removes interior face `f` of tet `t`, and with it the sandwiched faces
/// next to it that raise the worst new tet, if that worst tet has quality
/// (min sine) strictly above `beat`. At most `max_faces` faces are
/// considered; every tet of the cavity must satisfy `allowed`.
///
/// Refused (mesh unchanged): a boundary or constrained face (between
/// regions, or marked), an edge `u`–`w` already in the mesh, no subtree
/// whose new tets are all positive and beat `beat`
/// ([`OpError::NoImprovement`]; [`OpError::WouldInvert`] when `beat` is
/// −∞). Faces across feature edges or constrained faces are never grown
/// into.
pub fn remove_faces(
    mesh: &mut TetMesh,
    t: u32,
    f: usize,
    beat: f64,
    max_faces: usize,
    allowed: &dyn Fn(u32) -> bool,
) -> Result<FaceRemoval, OpError> {
    let plan = plan_face_removal(
        mesh,
        t,
        f,
        beat,
        max_faces,
        allowed,
        &mut FaceScratch::default(),
    )?;
    apply_face_removal(mesh, &plan)
}

/// A multi-face removal found on the mesh as it stood
/// ([`plan_face_removal`]), to be applied by [`apply_face_removal`].
#[derive(Clone, Debug)]
pub(crate) struct FacePlan {
    /// The apexes, ends of the new edge.
    u: u32,
    w: u32,
    /// The tets that go, each with its slot generation when planned.
    old: Vec<(u32, u32)>,
    /// The new tets.
    new: Vec<[u32; 4]>,
}

impl FacePlan {
    /// Whether every tet of the cavity is still the one planned on (no
    /// operation since has freed or re-used its slot).
    pub(crate) fn is_current(&self, mesh: &TetMesh) -> bool {
        self.old
            .iter()
            .all(|&(t, g)| mesh.is_alive(t) && mesh.generation(t) == g)
    }
}

/// The search half of [`remove_faces`]: the best removal at face `f` of
/// `t` on the mesh as it stands, without changing it. The edge `u`–`w` is
/// checked when the plan is applied, since a removal made in between may
/// create it.
pub(crate) fn plan_face_removal(
    mesh: &TetMesh,
    t: u32,
    f: usize,
    beat: f64,
    max_faces: usize,
    allowed: &dyn Fn(u32) -> bool,
    scratch: &mut FaceScratch,
) -> Result<FacePlan, OpError> {
    let h = mesh.adj(t)[f];
    if h == NO_ADJ {
        return Err(OpError::NotApplicable("boundary face"));
    }
    let tw = h >> 2;
    let tv = mesh.tet(t);
    let face = face_seen_from_apex(tv, f);
    if mesh.face_is_constrained(t, Some(tw), face) {
        return Err(OpError::NotApplicable("constrained face"));
    }
    if !allowed(t) || !allowed(tw) {
        return Err(OpError::NotApplicable("tet outside the allowed zone"));
    }
    let u = tv[f];
    let w = mesh.tet(tw)[(h & 3) as usize];
    let FaceScratch {
        nodes,
        seen,
        value,
        go_on,
    } = scratch;
    // The root's sides first: a try refused at a side of the root with
    // nothing behind it (below) grows no further. Measured with `perf` on
    // one default step of tetgen_example: the face plans' share of the
    // samples fell from 13 % to 9 %; the tree, and so the output, is the
    // same.
    let mut tree = Tree {
        mesh,
        u,
        w,
        max: max_faces.max(1),
        allowed,
        nodes,
        seen,
        next: 0,
    };
    tree.start(t, tw, face);
    tree.grow(1);
    let (pu, pw) = (mesh.point(u), mesh.point(w));
    // Quality of the new tet of side k of a node, or DEAD if it does not
    // beat the bar. The float orientation goes first: an inverted or flat
    // tet is dead without its normals (a tet the float sign calls flat but
    // the exact predicate positive would be refused too: refusing is
    // safe). The exact predicate only runs on tets that beat the bar.
    let side_q = |n: &Node, k: usize| -> f64 {
        let (a, b) = (n.face[k], n.face[(k + 1) % 3]);
        let p = [pu, mesh.point(a), mesh.point(b), pw];
        if (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) <= 0.0 {
            return DEAD;
        }
        let q = tet_min_sine(&p);
        if q.is_nan() || q <= beat || !is_positive(&p) {
            DEAD
        } else {
            q
        }
    };
    // A side of the root with no face behind it can only stop there: if
    // that tet is dead, so is every subtree (most tries end here).
    let root = tree.nodes[0];
    let mut root_stop = [f64::NAN; 3];
    for (k, stop) in root_stop.iter_mut().enumerate() {
        if root.child[k] == NONE {
            *stop = side_q(&root, k);
            if *stop == DEAD {
                return Err(refusal(beat));
            }
        }
    }
    tree.grow(usize::MAX);
    // Children come after their parent in `nodes`: values bottom-up. A
    // value at or below the bar is DEAD, so a node with one dead side is
    // dead whatever its other sides give, and they are not evaluated.
    value.clear();
    value.resize(nodes.len(), f64::INFINITY);
    go_on.clear();
    go_on.resize(nodes.len(), [false; 3]);
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        let mut v = f64::INFINITY;
        for k in 0..3 {
            if k == n.up {
                continue;
            }
            let stop = if i == 0 && !root_stop[k].is_nan() {
                root_stop[k]
            } else {
                side_q(n, k)
            };
            let deeper = if n.child[k] == NONE {
                DEAD
            } else {
                value[n.child[k] as usize]
            };
            go_on[i][k] = deeper > stop;
            v = v.min(stop.max(deeper));
            if v == DEAD {
                break;
            }
        }
        value[i] = v;
    }
    if value[0] <= beat || value[0] == DEAD {
        return Err(refusal(beat));
    }
    let mut old = Vec::new();
    let mut new = Vec::new();
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        let n = &nodes[i];
        old.push((n.tu, mesh.generation(n.tu)));
        old.push((n.tw, mesh.generation(n.tw)));
        for (k, &deeper) in go_on[i].iter().enumerate() {
            if k == n.up {
                continue;
            }
            if deeper {
                stack.push(n.child[k] as usize);
            } else {
                new.push([u, n.face[k], n.face[(k + 1) % 3], w]);
            }
        }
    }
    debug_assert_eq!(new.len(), old.len() / 2 + 2);
    Ok(FacePlan { u, w, old, new })
}

/// The value of a side or subtree whose worst new tet does not beat the
/// bar, or is not positive.
const DEAD: f64 = f64::NEG_INFINITY;

/// Why no subtree was found: below a finite bar, an invalid subtree and
/// one that does not beat it look the same (the exact predicate was
/// skipped).
fn refusal(beat: f64) -> OpError {
    if beat == f64::NEG_INFINITY {
        OpError::WouldInvert
    } else {
        OpError::NoImprovement
    }
}

/// Reusable buffers of [`plan_face_removal`] (one per thread of a sweep).
#[derive(Default)]
pub(crate) struct FaceScratch {
    /// The growth tree.
    nodes: Vec<Node>,
    /// Its faces' keys.
    seen: Vec<FaceKey>,
    /// Per node: the worst new tet of its best subtree, or [`DEAD`].
    value: Vec<f64>,
    /// Per node and side: the best subtree goes on into the child.
    go_on: Vec<[bool; 3]>,
}

/// Applies a plan whose cavity is current ([`FacePlan::is_current`]):
/// refused if the edge `u`–`w` exists by now, or by the checks of
/// [`replace_cavity`].
pub(crate) fn apply_face_removal(
    mesh: &mut TetMesh,
    plan: &FacePlan,
) -> Result<FaceRemoval, OpError> {
    debug_assert!(plan.is_current(mesh));
    // The walk sees only the piece of u's ball its first tet is in (at a
    // pinch, where pieces of the domain touch at u, not the others). That
    // is enough: the new tets all hold u–w and close around it, so the
    // open segment u–w lies inside the cavity, which no tet of another
    // piece overlaps; an edge u–w there would cross a cavity tet. The
    // walk is a guard, as cheap as one ball.
    let mut ball = Vec::new();
    mesh.ball(plan.u, &mut ball);
    if ball.iter().any(|&b| mesh.tet(b).contains(&plan.w)) {
        return Err(OpError::NotApplicable("the apexes already share an edge"));
    }
    let old: Vec<u32> = plan.old.iter().map(|&(t, _)| t).collect();
    let created = replace_cavity(mesh, &old, &plan.new)?;
    Ok(FaceRemoval {
        faces: old.len() / 2,
        removed: old,
        created,
    })
}

/// The tree of faces sandwiched between `u` and `w`, grown breadth first
/// from a root face, at most `max` of them, into `nodes` (`seen` holds
/// their keys). Growing in two calls, up to a node and then on, gives the
/// tree one call would.
struct Tree<'a> {
    mesh: &'a TetMesh,
    u: u32,
    w: u32,
    max: usize,
    allowed: &'a dyn Fn(u32) -> bool,
    nodes: &'a mut Vec<Node>,
    seen: &'a mut Vec<FaceKey>,
    /// The first node whose sides are not yet looked behind.
    next: usize,
}

impl Tree<'_> {
    /// Restarts the tree at `face` (tets `tu`, `tw`).
    fn start(&mut self, tu: u32, tw: u32, face: [u32; 3]) {
        self.nodes.clear();
        self.nodes.push(Node {
            face,
            tu,
            tw,
            up: usize::MAX,
            child: [NONE; 3],
        });
        self.seen.clear();
        self.seen.push(face_key(face));
        self.next = 0;
    }

    /// Looks behind the sides of the nodes before `until` (all of them with
    /// `usize::MAX`), adding the faces found.
    fn grow(&mut self, until: usize) {
        while self.next < self.nodes.len().min(until) {
            let i = self.next;
            let n = self.nodes[i];
            for k in 0..3 {
                if k == n.up || self.nodes.len() >= self.max {
                    continue;
                }
                let (a, b, c) = (n.face[k], n.face[(k + 1) % 3], n.face[(k + 2) % 3]);
                if self.mesh.is_feature_edge(a, b) {
                    continue;
                }
                let Some(next) =
                    behind(self.mesh, n.tu, n.tw, self.u, self.w, a, b, c, self.allowed)
                else {
                    continue;
                };
                let key = face_key(next.face);
                if self.seen.contains(&key) {
                    continue;
                }
                self.seen.push(key);
                self.nodes[i].child[k] = self.nodes.len() as u32;
                self.nodes.push(next);
            }
            self.next += 1;
        }
    }
}

/// The sandwiched face across side `(a, b)` of the face `(a, b, c)` with
/// tets `tu` and `tw`, if it may go: the neighbours of `tu` across
/// `(u, a, b)` and of `tw` across `(w, a, b)` share their fourth vertex `p`
/// and the face `(b, a, p)`, lie in the same region as the tets, are
/// allowed, and none of the faces between them is constrained.
#[allow(clippy::too_many_arguments)]
fn behind(
    mesh: &TetMesh,
    tu: u32,
    tw: u32,
    u: u32,
    w: u32,
    a: u32,
    b: u32,
    c: u32,
    allowed: &dyn Fn(u32) -> bool,
) -> Option<Node> {
    let fu = mesh.local_index(tu, c)?;
    let fw = mesh.local_index(tw, c)?;
    let (hu, hw) = (mesh.adj(tu)[fu], mesh.adj(tw)[fw]);
    if hu == NO_ADJ || hw == NO_ADJ {
        return None;
    }
    let (nu, nw) = (hu >> 2, hw >> 2);
    let p = mesh.tet(nu)[(hu & 3) as usize];
    if mesh.tet(nw)[(hw & 3) as usize] != p || p == w {
        return None;
    }
    // nu and nw must meet at (a, b, p): nw's face opposite w leads to nu.
    let lw = mesh.local_index(nw, w)?;
    if mesh.adj(nw)[lw] == NO_ADJ || mesh.adj(nw)[lw] >> 2 != nu {
        return None;
    }
    if !allowed(nu)
        || !allowed(nw)
        || mesh.face_is_constrained(tu, Some(nu), [u, a, b])
        || mesh.face_is_constrained(tw, Some(nw), [w, a, b])
        || mesh.face_is_constrained(nu, Some(nw), [a, b, p])
    {
        return None;
    }
    let face = [b, a, p];
    debug_assert!(is_positive(&[
        mesh.point(u),
        mesh.point(b),
        mesh.point(a),
        mesh.point(p)
    ]));
    Some(Node {
        face,
        tu: nu,
        tw: nw,
        up: 0,
        child: [NONE; 3],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::total_volume as volume;
    use crate::mesh::MeshData;

    /// A bipyramid: the polygon `ring` (counterclockwise seen from +z, in
    /// the plane z = 0) fanned from its first vertex, coned to the apexes
    /// `(axis, ±h)`. Returns the mesh and the apexes above and below.
    fn bipyramid(ring: &[[f64; 3]], axis: [f64; 2], h: f64) -> (TetMesh, u32, u32) {
        let mut points: Vec<[f64; 3]> = ring.to_vec();
        points.push([axis[0], axis[1], h]);
        points.push([axis[0], axis[1], -h]);
        let n = ring.len() as u32;
        let (u, w) = (n, n + 1);
        let mut tets = Vec::new();
        for i in 1..n - 1 {
            tets.push([u, 0, i, i + 1]);
            tets.push([w, i + 1, i, 0]);
        }
        let data = MeshData {
            points,
            tet_regions: vec![1; tets.len()],
            tets,
            ..Default::default()
        };
        let (mesh, _) = TetMesh::from_data(&data).expect("valid bipyramid");
        mesh.check().expect("valid");
        (mesh, u, w)
    }

    fn worst(mesh: &TetMesh) -> f64 {
        mesh.tet_ids()
            .map(|t| tet_min_sine(&mesh.tet_points(t)))
            .fold(f64::INFINITY, f64::min)
    }

    fn has_edge(mesh: &TetMesh, a: u32, b: u32) -> bool {
        mesh.tet_ids().any(|t| {
            let v = mesh.tet(t);
            v.contains(&a) && v.contains(&b)
        })
    }

    /// The regular hexagon of circumradius 1, vertex 0 at (1, 0).
    fn hexagon() -> Vec<[f64; 3]> {
        (0..6)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 6.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect()
    }

    /// The root face: fan triangle (0, 1, 2) in the tet of apex `u`.
    fn root(mesh: &TetMesh, u: u32) -> (u32, usize) {
        let t = mesh
            .tet_ids()
            .find(|&t| {
                let v = mesh.tet(t);
                v.contains(&u) && v.contains(&1) && v.contains(&2)
            })
            .expect("fan tet");
        (t, mesh.local_index(t, u).expect("apex"))
    }

    /// Hexagon area 3√3/2; bipyramid volume area · 2h / 3.
    fn hexagon_bipyramid_volume(h: f64) -> f64 {
        1.5 * 3f64.sqrt() * 2.0 * h / 3.0
    }

    /// One scratch reused over every face of a jittered grid plans what a
    /// fresh scratch plans: no state of one try leaks into the next (a
    /// stale node, value or flag would change a plan or a refusal).
    #[test]
    fn a_reused_scratch_plans_as_a_fresh_one() {
        let mut data = crate::mesh::generate::cube_grid(4);
        let mut rng = crate::rng::SplitMix64(7);
        for p in &mut data.points {
            if p.iter().all(|&c| c > 0.0 && c < 1.0) {
                for c in p.iter_mut() {
                    *c += 0.08 * (rng.next_f64() - 0.5);
                }
            }
        }
        let (mesh, _) = TetMesh::from_data(&data).expect("valid grid");
        let summary = |r: Result<FacePlan, OpError>| match r {
            Ok(p) => Ok((p.u, p.w, p.old, p.new)),
            Err(e) => Err(format!("{e:?}")),
        };
        let mut shared = FaceScratch::default();
        let (mut plans, mut refusals) = (0, 0);
        for t in mesh.tet_ids() {
            let beat = tet_min_sine(&mesh.tet_points(t));
            for f in 0..4 {
                let a = plan_face_removal(&mesh, t, f, beat, 10, &|_| true, &mut shared);
                let b = plan_face_removal(
                    &mesh,
                    t,
                    f,
                    beat,
                    10,
                    &|_| true,
                    &mut FaceScratch::default(),
                );
                let (a, b) = (summary(a), summary(b));
                if a.is_ok() {
                    plans += 1;
                } else {
                    refusals += 1;
                }
                assert_eq!(a, b, "tet {t} face {f}");
            }
        }
        // The fixture must exercise both outcomes.
        assert!(
            plans > 0 && refusals > 0,
            "{plans} plans, {refusals} refusals"
        );
    }

    #[test]
    fn a_fanned_hexagon_whose_axis_pierces_the_last_fan_triangle_loses_every_face() {
        // A new tet [u, a, b, w] is positive iff the axis passes left of
        // the side (a, b): a removed part of the fan (triangles 0..=k from
        // the root (0, 1, 2)) must contain the axis. With the axis in the
        // last triangle (0, 4, 5) only the whole fan does: n − 2 = 4 faces,
        // 2(n − 2) = 8 tets out, n = 6 in.
        let h = 0.15;
        let (mut mesh, u, w) = bipyramid(&hexagon(), [0.3, -0.55], h);
        let before = worst(&mesh);
        let (t, f) = root(&mesh, u);
        let r = remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|_| true).expect("removed");
        assert_eq!((r.faces, r.removed.len(), r.created.len()), (4, 8, 6));
        assert_eq!(mesh.n_tets(), 6);
        mesh.check().expect("valid after the removal");
        assert!(has_edge(&mesh, u, w));
        assert!((volume(&mesh) - hexagon_bipyramid_volume(h)).abs() < 1e-12);
        assert!(worst(&mesh) > before);
    }

    #[test]
    fn a_feature_edge_stops_the_growth() {
        // The diagonal 0–3 is a feature edge: only the fan triangles (0, 1,
        // 2) and (0, 2, 3) may go, and the axis at (0, 0.3) lies in their
        // union but not in (0, 1, 2) alone (it is left of the side 0 → 2),
        // so both go: 2 faces, 4 tets out, 4 in, the diagonal kept.
        let h = 0.4;
        let (mut mesh, u, w) = bipyramid(&hexagon(), [0.0, 0.3], h);
        mesh.set_feature_edge(0, 3, Some(1));
        let (t, f) = root(&mesh, u);
        let r = remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|_| true).expect("removed");
        assert_eq!((r.faces, r.removed.len(), r.created.len()), (2, 4, 4));
        assert_eq!(mesh.n_tets(), 8);
        mesh.check().expect("valid");
        assert!(has_edge(&mesh, u, w) && has_edge(&mesh, 0, 3));
        assert!((volume(&mesh) - hexagon_bipyramid_volume(h)).abs() < 1e-12);
    }

    #[test]
    fn one_face_is_the_two_three_flip() {
        let ring = [[1.0, 0.0, 0.0], [-0.5, 0.8, 0.0], [-0.5, -0.8, 0.0]];
        let (mut mesh, u, w) = bipyramid(&ring, [0.0, 0.0], 0.3);
        let (t, f) = root(&mesh, u);
        let r = remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|_| true).expect("flip");
        assert_eq!((r.faces, r.created.len()), (1, 3));
        mesh.check().expect("valid");
        assert!(has_edge(&mesh, u, w));
    }

    #[test]
    fn an_axis_outside_the_polygon_is_refused() {
        // Every part of the fan misses the axis: some side has it on its
        // right, so no new tet set is positive.
        let (mut mesh, u, _) = bipyramid(&hexagon(), [1.5, 0.0], 0.3);
        let (t, f) = root(&mesh, u);
        let slots = mesh.tet_slots().to_vec();
        assert_eq!(
            remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|_| true),
            Err(OpError::WouldInvert)
        );
        assert_eq!(mesh.tet_slots(), &slots[..]);
    }

    #[test]
    fn refusals_leave_the_mesh_alone() {
        let (mut mesh, u, _) = bipyramid(&hexagon(), [0.3, -0.55], 0.15);
        let (t, f) = root(&mesh, u);
        let slots = mesh.tet_slots().to_vec();
        // A bar no tet can beat (min sine ≤ 1).
        assert_eq!(
            remove_faces(&mut mesh, t, f, 1.0, 64, &|_| true),
            Err(OpError::NoImprovement)
        );
        // A marked root face.
        let face = mesh.face_vertices(t, f);
        mesh.set_face_marker(face, Some(7));
        assert!(matches!(
            remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|_| true),
            Err(OpError::NotApplicable(_))
        ));
        mesh.set_face_marker(face, None);
        // The root tet outside the zone.
        assert!(matches!(
            remove_faces(&mut mesh, t, f, f64::NEG_INFINITY, 64, &|x| x != t),
            Err(OpError::NotApplicable(_))
        ));
        // A boundary face.
        let b = (0..4)
            .find(|&g| mesh.is_boundary_face(t, g))
            .expect("hull face");
        assert!(matches!(
            remove_faces(&mut mesh, t, b, f64::NEG_INFINITY, 64, &|_| true),
            Err(OpError::NotApplicable(_))
        ));
        assert_eq!(mesh.tet_slots(), &slots[..]);
        mesh.check().expect("valid");
    }
}
