//! Edge trisection: two new vertices on an edge split every tet around it in
//! three (seed paper §5, its Figure 7a — the crease rule of even steps).
//!
//! ```text
//!        a ---- x1 ---- x2 ---- b        each ring tet (a,b,p,q) becomes
//!         \     |       |      /           (a,x1,p,q) (x1,x2,p,q) (x2,b,p,q)
//!          \    |       |     /          faces (a,b,p) become (a,x1,p),
//!           `-- p ----- q --´             (x1,x2,p), (x2,b,p) with its marker;
//!                                        the edge's feature tag goes to the
//!                                        three pieces.
//! ```

use super::{replace_cavity_raw, EdgeRing, OpError};
use crate::mesh::TetMesh;
use glam::DVec3;

/// Trisects the edge of `ring` with new vertices at `x1` (next to `ring.a`)
/// and `x2` (next to `ring.b`). Works for open and closed rings and for rings
/// whose tets lie in several regions (each new tet keeps its old tet's
/// region). Returns the two new vertex ids.
pub fn trisect_edge(
    mesh: &mut TetMesh,
    ring: &EdgeRing,
    x1: DVec3,
    x2: DVec3,
) -> Result<(u32, u32), OpError> {
    let (a, b) = (ring.a, ring.b);
    let n = ring.tets.len();
    let v1 = mesh.add_point(x1);
    let v2 = mesh.add_point(x2);
    let r = ring.verts.len();
    let mut new = Vec::with_capacity(3 * n);
    let mut origin = Vec::with_capacity(3 * n);
    for i in 0..n {
        let (p, q) = (ring.verts[i], ring.verts[(i + 1) % r]);
        new.push([a, v1, p, q]);
        new.push([v1, v2, p, q]);
        new.push([v2, b, p, q]);
        origin.extend([i, i, i]);
    }
    let face_markers: Vec<(u32, Option<i32>)> = ring
        .verts
        .iter()
        .map(|&p| (p, mesh.face_marker([a, b, p])))
        .collect();
    let edge_marker = mesh.feature_edge(a, b);
    match replace_cavity_raw(mesh, &ring.tets, &new, &origin) {
        Ok(_) => {
            for (p, m) in face_markers {
                if m.is_some() {
                    mesh.set_face_marker([a, b, p], None);
                    for (x, y) in [(a, v1), (v1, v2), (v2, b)] {
                        mesh.set_face_marker([x, y, p], m);
                    }
                }
            }
            if edge_marker.is_some() {
                mesh.set_feature_edge(a, b, None);
                for (x, y) in [(a, v1), (v1, v2), (v2, b)] {
                    mesh.set_feature_edge(x, y, edge_marker);
                }
            }
            Ok((v1, v2))
        }
        Err(e) => {
            mesh.pop_unused_point(v2);
            mesh.pop_unused_point(v1);
            Err(e)
        }
    }
}
