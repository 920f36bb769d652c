//! Interior edge removal for the optimize phase, with the ring triangulation
//! searched only among triangulations that beat a given quality.
//!
//! The search is the dynamic programme of [`crate::ops::edge_removal`]
//! (Shewchuk, "Two discrete optimization algorithms for the topological
//! improvement of tetrahedral meshes", 2002, with Klincsek's recurrence
//! `best(i,j) = max_k min(best(i,k), best(k,j), q(i,k,j))`), with one change:
//! a triangle whose worst tet does not beat the bar counts as invalid. Since
//! `x ↦ (x > bar ? x : −∞)` commutes with `min` and `max`, every sub-polygon
//! value above the bar, and every choice made among such values, is the one
//! of the plain programme: when a triangulation beats the bar it is the same
//! triangulation. But sub-polygons that cannot beat the bar are settled after
//! one tet quality, and the exact orientation predicate (slow on the nearly
//! coplanar ring vertices of structured meshes) only runs on triangles that
//! already beat the bar. Most rings tried by the optimize phase cannot be
//! improved, so this is where the phase used to spend a third of its time.

use crate::geom::{orient3d, tet_min_sine};
use crate::mesh::TetMesh;
use crate::ops::edge_removal::{EdgeRing, RingTriangulation};
use glam::DVec3;

/// Reusable buffers of [`improving_ring_triangulation`].
#[derive(Default)]
pub struct RingScratch {
    p: Vec<DVec3>,
    best: Vec<f64>,
    arg: Vec<usize>,
    stack: Vec<(usize, usize)>,
}

/// The triangulation of the ring of `ring` whose worst new tet (each triangle
/// coned to both edge ends) is best, if that worst tet's min-sine quality is
/// strictly above `beat` and every new tet is positively oriented (exact
/// predicate); `None` otherwise. When it exists it is exactly the one
/// [`crate::ops::edge_removal::best_ring_triangulation`] returns.
pub fn improving_ring_triangulation(
    mesh: &TetMesh,
    ring: &EdgeRing,
    beat: f64,
    s: &mut RingScratch,
) -> Option<RingTriangulation> {
    let r = ring.verts.len();
    if r < 3 {
        return None;
    }
    let pa = mesh.point(ring.a);
    let pb = mesh.point(ring.b);
    s.p.clear();
    s.p.extend(ring.verts.iter().map(|&v| mesh.point(v)));
    let p = &s.p;
    if ring.closed && ring_bound_fails(pa, pb, p, beat) {
        return None;
    }
    // Worst quality of the two tets of triangle (i, k, j) if it beats the
    // bar and both are positive, else −∞.
    let tri_q = |i: usize, k: usize, j: usize| -> f64 {
        let ta = [pa, p[i], p[k], p[j]];
        let qa = tet_min_sine(&ta);
        if qa.is_nan() || qa <= beat {
            return f64::NEG_INFINITY;
        }
        let tb = [pb, p[j], p[k], p[i]];
        let q = qa.min(tet_min_sine(&tb));
        if q.is_nan() || q <= beat {
            return f64::NEG_INFINITY;
        }
        if orient3d(ta[0], ta[1], ta[2], ta[3]) <= 0.0
            || orient3d(tb[0], tb[1], tb[2], tb[3]) <= 0.0
        {
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
    if quality <= beat {
        return None;
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
    Some(RingTriangulation { quality, triangles })
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

/// Puts a closed ring in a form that does not depend on the tet it was
/// gathered from: `a < b`, and the ring starting at its lowest tet slot.
/// (Swapping the edge's ends reverses the ring's direction: tet
/// `(a, b, p_i, p_i+1)` is `(b, a, p_i+1, p_i)`.) The dynamic programme then
/// sees the same polygon, and picks the same triangulation, from any start.
pub fn canonicalize_ring(ring: &mut EdgeRing) {
    let r = ring.tets.len();
    if r == 0 || ring.verts.len() != r {
        return;
    }
    if ring.a > ring.b {
        std::mem::swap(&mut ring.a, &mut ring.b);
        ring.tets.reverse();
        ring.verts[1..].reverse();
    }
    let m = (0..r).min_by_key(|&i| ring.tets[i]).unwrap_or(0);
    ring.tets.rotate_left(m);
    ring.verts.rotate_left(m);
}
