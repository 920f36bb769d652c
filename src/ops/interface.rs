//! Operations on faces and edges inside the mesh that must survive refinement:
//! faces between two regions (material interfaces) and marked interior faces.
//! They are refined like the boundary — a 1-3 split on both sides (2 → 6
//! tets) and the √3 flip of an interface edge, done as two boundary edge
//! removals that share the new interface edge.
//!
//! ```text
//!   2-6 split of face (a,b,c):              interface edge removal of (a,b):
//!            d (apex of t)                    ring m1 p1 … m2 … back to m1,
//!          / | \                              cut by the chord m1–m2 into the
//!        a --m-- c   (m on the face)          polygon of each side; each side is
//!          \ | /                              triangulated by the DP and coned to
//!            e (apex of the neighbour)        a and b; the chord becomes the new
//!   (b,a,m,d) (c,b,m,d) (a,c,m,d)             interface edge, (a,m1,m2) and
//!   (a,b,m,e) (b,c,m,e) (c,a,m,e)             (b,m2,m1) the new interface faces.
//! ```

use super::edge_removal::{best_ring_triangulation, EdgeRing};
use super::{replace_cavity_raw, OpError};
use crate::mesh::{TetMesh, NO_ADJ};
use crate::topo::TET_FACES;
use glam::DVec3;

/// Splits interior face `f` of tet `t` at `p`, splitting both tets in three;
/// each new tet keeps the region of its old tet and the face's marker moves to
/// the three new faces. Returns the new vertex.
pub fn split_interface_face(
    mesh: &mut TetMesh,
    t: u32,
    f: usize,
    p: DVec3,
) -> Result<u32, OpError> {
    let h = mesh.adj(t)[f];
    if h == NO_ADJ {
        return Err(OpError::NotApplicable(
            "boundary face: use split_boundary_face",
        ));
    }
    let (u, g) = TetMesh::half_face(h);
    let v = mesh.tet(t);
    let l = TET_FACES[f];
    let (a, b, c, d) = (v[l[0]], v[l[1]], v[l[2]], v[f]);
    let e = mesh.tet(u)[g];
    let marker = mesh.face_marker([a, b, c]);
    let m = mesh.add_point(p);
    let new = [
        [b, a, m, d],
        [c, b, m, d],
        [a, c, m, d],
        [a, b, m, e],
        [b, c, m, e],
        [c, a, m, e],
    ];
    match replace_cavity_raw(mesh, &[t, u], &new, &[0, 0, 0, 1, 1, 1]) {
        Ok(_) => {
            if marker.is_some() {
                mesh.set_face_marker([a, b, c], None);
                for (x, y) in [(a, b), (b, c), (c, a)] {
                    mesh.set_face_marker([x, y, m], marker);
                }
            }
            Ok(m)
        }
        Err(err) => {
            mesh.pop_unused_point(m);
            Err(err)
        }
    }
}

/// Removes the interior edge of the closed `ring` whose ring vertices `m1` and
/// `m2` lie on the interface through the edge: the tets from `m1` to `m2` form
/// one side, the rest the other; each side must lie in one region. The new
/// edge `m1–m2` and the faces `(a,m1,m2)`, `(b,m2,m1)` carry the interface on
/// (with the marker of the removed faces `(a,b,m1)`, `(a,b,m2)` if equal).
pub fn remove_interface_edge(
    mesh: &mut TetMesh,
    ring: &EdgeRing,
    m1: u32,
    m2: u32,
) -> Result<(), OpError> {
    if !ring.closed {
        return Err(OpError::NotApplicable("interface edge ring must be closed"));
    }
    let r = ring.verts.len();
    let i1 = ring
        .verts
        .iter()
        .position(|&x| x == m1)
        .ok_or(OpError::NotApplicable("m1 not on the ring"))?;
    let i2 = ring
        .verts
        .iter()
        .position(|&x| x == m2)
        .ok_or(OpError::NotApplicable("m2 not on the ring"))?;
    let mut new = Vec::new();
    let mut origin = Vec::new();
    for (from, to) in [(i1, i2), (i2, i1)] {
        // Side from `from` to `to` walking forward: tets T_from … T_{to-1}.
        let count = (to + r - from) % r;
        if count == 0 {
            return Err(OpError::NotApplicable("m1 and m2 coincide"));
        }
        let tets: Vec<u32> = (0..count).map(|k| ring.tets[(from + k) % r]).collect();
        let verts: Vec<u32> = (0..=count).map(|k| ring.verts[(from + k) % r]).collect();
        let region = mesh.region(tets[0]);
        if tets.iter().any(|&t| mesh.region(t) != region) {
            return Err(OpError::NotApplicable(
                "one side of the interface spans two regions",
            ));
        }
        let side = EdgeRing {
            a: ring.a,
            b: ring.b,
            tets,
            verts,
            closed: false,
        };
        let tri = best_ring_triangulation(mesh, &side);
        if tri.quality == f64::NEG_INFINITY {
            return Err(OpError::WouldInvert);
        }
        let o = ring
            .tets
            .iter()
            .position(|&t| t == side.tets[0])
            .unwrap_or(0);
        for &[i, k, j] in &tri.triangles {
            new.push([ring.a, side.verts[i], side.verts[k], side.verts[j]]);
            new.push([ring.b, side.verts[j], side.verts[k], side.verts[i]]);
            origin.extend([o, o]);
        }
    }
    let (ma, mb) = (
        mesh.face_marker([ring.a, ring.b, m1]),
        mesh.face_marker([ring.a, ring.b, m2]),
    );
    replace_cavity_raw(mesh, &ring.tets, &new, &origin)?;
    if ma.is_some() || mb.is_some() {
        mesh.set_face_marker([ring.a, ring.b, m1], None);
        mesh.set_face_marker([ring.a, ring.b, m2], None);
        let m = if ma == mb { ma } else { ma.or(mb) };
        mesh.set_face_marker([ring.a, m1, m2], m);
        mesh.set_face_marker([ring.b, m2, m1], m);
    }
    Ok(())
}
