//! Edge removal: the m tets around an edge are replaced by a triangulation of
//! the ring of their opposite edges, coned to both edge ends.
//!
//! ```text
//!               a                 ring p0 p1 … (tets (a,b,p_i,p_i+1)):
//!            / /|\ \              every triangle (p_i,p_k,p_j) of a
//!          p0-/-|-\-p3            triangulation of the ring gives the
//!           \p1-|-p2/             tets (a,p_i,p_k,p_j) and (b,p_j,p_k,p_i).
//!             \ | /               interior edge: closed ring, m → 2m − 4;
//!               b                 boundary edge: open ring p0 … p_m from one
//!                                 boundary face to the other, m → 2m − 2, and
//!                                 p0–p_m becomes the new boundary edge.
//! ```
//!
//! The triangulation is the one that maximises the worst new tet, found by the
//! O(r³) dynamic programme over the ring polygon of Shewchuk ("Two discrete
//! optimization algorithms for the topological improvement of tetrahedral
//! meshes", 2002) with Klincsek's recurrence: `best(i,j) = max_k min(best(i,k),
//! best(k,j), q(i,k,j))`. For a boundary edge this is the √3 flip of the seed
//! paper §4: the new boundary edge joins the two face barycentres p0 and p_m.

use super::{replace_cavity, OpError};
use crate::geom::{all_positive, tet_min_sine};
use crate::mesh::{TetMesh, NO_ADJ};
use crate::topo::{TET_EDGES, TET_EDGE_OPPOSITE};
use glam::DVec3;

/// The tets around an edge `(a, b)` in rotational order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeRing {
    /// First end of the edge.
    pub a: u32,
    /// Second end of the edge.
    pub b: u32,
    /// Tets `T_i = (a, b, p_i, p_{i+1})`, each positively oriented in that order.
    pub tets: Vec<u32>,
    /// Ring vertices `p_i`: `tets.len()` of them for a closed ring,
    /// `tets.len() + 1` for an open one.
    pub verts: Vec<u32>,
    /// Closed ring (interior edge) or open (boundary edge: `(a,b,p_0)` and
    /// `(a,b,p_last)` are boundary faces).
    pub closed: bool,
}

/// Parity of the permutation `p` of `0..4` (true = even).
fn even_permutation(p: [usize; 4]) -> bool {
    let mut inv = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if p[i] > p[j] {
                inv += 1;
            }
        }
    }
    inv % 2 == 0
}

impl EdgeRing {
    /// Gathers the ring of local edge `e` of tet `t`.
    pub fn gather(mesh: &TetMesh, t: u32, e: usize) -> EdgeRing {
        let mut ring = EdgeRing::default();
        ring.gather_into(mesh, t, e);
        ring
    }

    /// Like [`EdgeRing::gather`], re-using this ring's buffers.
    pub fn gather_into(&mut self, mesh: &TetMesh, t: u32, e: usize) {
        let v = mesh.tet(t);
        let [ia, ib] = TET_EDGES[e];
        let [k, l] = TET_EDGE_OPPOSITE[e];
        let (x, y) = if even_permutation([ia, ib, k, l]) {
            (v[k], v[l])
        } else {
            (v[l], v[k])
        };
        self.a = v[ia];
        self.b = v[ib];
        self.tets.clear();
        self.verts.clear();
        self.tets.push(t);
        self.verts.push(x);
        self.verts.push(y);
        // Forward: leave (a,b,x,y) through the face (a,b,y), i.e. opposite x.
        let mut cur = t;
        let (mut prev_v, mut last_v) = (x, y);
        loop {
            let f = mesh.local_index(cur, prev_v).expect("ring vertex");
            let h = mesh.adj(cur)[f];
            if h == NO_ADJ {
                self.closed = false;
                break;
            }
            let n = h >> 2;
            if n == t {
                self.closed = true;
                self.verts.pop(); // the walk came back to x
                return;
            }
            let nv = mesh.tet(n);
            let z = nv[(h & 3) as usize];
            self.tets.push(n);
            self.verts.push(z);
            prev_v = last_v;
            last_v = z;
            cur = n;
        }
        // Open ring: walk backwards from t through the face (a,b,x) (opposite y)
        // and prepend.
        let mut back_tets = Vec::new();
        let mut back_verts = Vec::new();
        let mut cur = t;
        let (mut next_v, mut first_v) = (y, x);
        loop {
            let f = mesh.local_index(cur, next_v).expect("ring vertex");
            let h = mesh.adj(cur)[f];
            if h == NO_ADJ {
                break;
            }
            let n = h >> 2;
            let z = mesh.tet(n)[(h & 3) as usize];
            back_tets.push(n);
            back_verts.push(z);
            next_v = first_v;
            first_v = z;
            cur = n;
        }
        if !back_tets.is_empty() {
            back_tets.reverse();
            back_verts.reverse();
            back_tets.extend_from_slice(&self.tets);
            back_verts.extend_from_slice(&self.verts);
            self.tets = back_tets;
            self.verts = back_verts;
        }
    }

    /// The worst (smallest) min-sine quality among the ring's tets.
    pub fn worst_quality(&self, mesh: &TetMesh) -> f64 {
        self.tets
            .iter()
            .map(|&t| tet_min_sine(&mesh.tet_points(t)))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The best triangulation of a ring: its worst tet quality and the triangles
/// `(i, k, j)` as indices into the ring vertices.
#[derive(Clone, Debug, Default)]
pub struct RingTriangulation {
    /// Smallest min-sine over the 2·(triangles) new tets (−∞ if none is valid).
    pub quality: f64,
    /// The triangles, as ring vertex positions `i < k < j`.
    pub triangles: Vec<[usize; 3]>,
}

/// Reusable buffers of [`best_ring_triangulation_above`].
#[derive(Default)]
pub struct RingScratch {
    p: Vec<DVec3>,
    best: Vec<f64>,
    arg: Vec<usize>,
    stack: Vec<(usize, usize)>,
}

/// Shewchuk's dynamic programme over the ring polygon: the triangulation whose
/// worst tet (coned to `a` and to `b`) is best. Triangles producing a flat or
/// inverted tet (exact predicate) are excluded. Its quality is −∞ (and it has
/// no triangles) when no triangulation is valid.
pub fn best_ring_triangulation(mesh: &TetMesh, ring: &EdgeRing) -> RingTriangulation {
    best_ring_triangulation_above(mesh, ring, f64::NEG_INFINITY, &mut RingScratch::default())
}

/// The programme of [`best_ring_triangulation`] with a bar: a triangle whose
/// worst tet does not beat `bar` counts as invalid. Since
/// `x ↦ (x > bar ? x : −∞)` commutes with `min` and `max`, every sub-polygon
/// value above the bar, and every choice made among such values, is the one
/// of the plain programme: when a triangulation beats the bar it is the same
/// triangulation (with `bar = −∞` this *is* the plain programme). But
/// sub-polygons that cannot beat the bar are settled after one tet quality,
/// and the exact orientation predicate (slow on the nearly coplanar ring
/// vertices of structured meshes) only runs on triangles that already beat
/// the bar. Returns quality −∞ and no triangles when nothing beats the bar.
pub fn best_ring_triangulation_above(
    mesh: &TetMesh,
    ring: &EdgeRing,
    bar: f64,
    s: &mut RingScratch,
) -> RingTriangulation {
    let none = RingTriangulation {
        quality: f64::NEG_INFINITY,
        triangles: Vec::new(),
    };
    let r = ring.verts.len();
    if r < 3 {
        return none;
    }
    let pa = mesh.point(ring.a);
    let pb = mesh.point(ring.b);
    s.p.clear();
    s.p.extend(ring.verts.iter().map(|&v| mesh.point(v)));
    let p = &s.p;
    if ring.closed && ring_bound_fails(pa, pb, p, bar) {
        return none;
    }
    // Worst quality of the two tets of triangle (i, k, j) if it beats the
    // bar and both are positive, else −∞.
    let tri_q = |i: usize, k: usize, j: usize| -> f64 {
        let ta = [pa, p[i], p[k], p[j]];
        let qa = tet_min_sine(&ta);
        if qa.is_nan() || qa <= bar {
            return f64::NEG_INFINITY;
        }
        let tb = [pb, p[j], p[k], p[i]];
        let q = qa.min(tet_min_sine(&tb));
        if q.is_nan() || q <= bar || !all_positive([ta, tb]) {
            return f64::NEG_INFINITY;
        }
        q
    };
    s.best.clear();
    s.best.resize(r * r, f64::INFINITY);
    s.arg.clear();
    s.arg.resize(r * r, usize::MAX);
    for len in 2..r {
        for i in 0..r - len {
            let j = i + len;
            let mut b = f64::NEG_INFINITY;
            let mut bk = usize::MAX;
            for k in i + 1..j {
                let cand = s.best[i * r + k].min(s.best[k * r + j]);
                if cand <= b {
                    continue;
                }
                let q = cand.min(tri_q(i, k, j));
                if q > b {
                    b = q;
                    bk = k;
                }
            }
            s.best[i * r + j] = b;
            s.arg[i * r + j] = bk;
        }
    }
    let quality = s.best[r - 1];
    if quality <= bar {
        return none;
    }
    let mut triangles = Vec::with_capacity(r - 2);
    s.stack.clear();
    s.stack.push((0, r - 1));
    while let Some((i, j)) = s.stack.pop() {
        if j < i + 2 {
            continue;
        }
        let k = s.arg[i * r + j];
        triangles.push([i, k, j]);
        s.stack.push((i, k));
        s.stack.push((k, j));
    }
    RingTriangulation { quality, triangles }
}

/// Whether a quick upper bound already rules out beating `beat` on a closed
/// ring with edge ends `pa`, `pb` and ring points `p`.
///
/// Each side `(p_i, p_i+1)` of the ring polygon lies in one triangle
/// `(p_i, p_i+1, p_k)` of any triangulation, and its two new tets (coned to
/// `a` and to `b`) split the dihedral angle θ of the old tet
/// `(a, b, p_i, p_i+1)` at that side between them (both positive means the
/// triangle's half-plane lies inside the old wedge). One of the two has an
/// angle of at most θ/2 < 90°, so no triangulation beats `sin(θ/2)`. The test
/// `sin²(θ/2) = (1 − cos θ)/2 ≤ beat²` keeps a margin, so that it only rules
/// out what the full programme would reject too.
fn ring_bound_fails(pa: DVec3, pb: DVec3, p: &[DVec3], beat: f64) -> bool {
    if beat <= 0.0 {
        return false;
    }
    let r = p.len();
    // The margin (1e-9 in units of sin²) is a million times the rounding of
    // the cosines below (a few ulps of 1), so a ring this test rules out
    // misses the bar by more than rounding: the exact programme would reject
    // it too. Safe in the only direction that matters: it never prunes a
    // ring that could pass.
    let limit = 2.0 * beat * beat - 1e-9;
    for i in 0..r {
        let (p0, p1) = (p[i], p[(i + 1) % r]);
        let u = p1 - p0;
        let na = u.cross(pa - p0);
        let nb = u.cross(pb - p0);
        let d = (na.length_squared() * nb.length_squared()).sqrt();
        if d > 0.0 && 1.0 - na.dot(nb) / d <= limit {
            return true;
        }
    }
    false
}

/// Removes the edge of `ring` if the best triangulation's worst tet has
/// quality strictly above `beat` (pass `f64::NEG_INFINITY` to force any valid
/// one). Returns the new tets. The edge must not be a feature edge and no
/// removed face may carry a marker (checked by the caller / `replace_cavity`).
pub fn remove_edge(mesh: &mut TetMesh, ring: &EdgeRing, beat: f64) -> Result<Vec<u32>, OpError> {
    let tri = best_ring_triangulation(mesh, ring);
    if tri.quality == f64::NEG_INFINITY {
        return Err(OpError::WouldInvert);
    }
    if tri.quality <= beat {
        return Err(OpError::NoImprovement);
    }
    apply_ring_triangulation(mesh, ring, &tri)
}

/// Replaces the ring's tets by the tets of a given triangulation.
pub fn apply_ring_triangulation(
    mesh: &mut TetMesh,
    ring: &EdgeRing,
    tri: &RingTriangulation,
) -> Result<Vec<u32>, OpError> {
    let p = &ring.verts;
    let mut new = Vec::with_capacity(2 * tri.triangles.len());
    for &[i, k, j] in &tri.triangles {
        new.push([ring.a, p[i], p[k], p[j]]);
        new.push([ring.b, p[j], p[k], p[i]]);
    }
    replace_cavity(mesh, &ring.tets, &new)
}
