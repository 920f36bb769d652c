//! Rings of the optimize phase's edge removal: a canonical form, so that the
//! ring triangulation (the one programme of
//! [`crate::ops::edge_removal::best_ring_triangulation_above`], with the bar
//! set to the ring's worst tet) does not depend on where the ring was
//! gathered from.

use crate::ops::edge_removal::EdgeRing;

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
    let m = (0..r)
        .min_by_key(|&i| ring.tets[i])
        .expect("an edge ring holds at least one tet");
    ring.tets.rotate_left(m);
    ring.verts.rotate_left(m);
}
