//! Edge trisection: two new vertices on an edge split every tet around it in
//! three (the √3 paper, §5, its Figure 7a — the crease rule of even steps).
//!
//! ```text
//!        a ---- x1 ---- x2 ---- b        each ring tet (a,b,p,q) becomes
//!         \     |       |      /           (a,x1,p,q) (x1,x2,p,q) (x2,b,p,q)
//!          \    |       |     /          faces (a,b,p) become (a,x1,p),
//!           `-- p ----- q --´             (x1,x2,p), (x2,b,p) with its marker;
//!                                        the edge's feature tag goes to the
//!                                        three pieces.
//! ```

use super::{replace_cavity_raw, OpError};
use crate::mesh::TetMesh;
use glam::DVec3;

/// Trisects the edge `(a, b)` with new vertices at `x1` (next to `a`) and
/// `x2` (next to `b`). `around` must list every tet holding the edge (any
/// order; several fans where the domain touches itself along the edge). Each
/// tet is cut in three by substituting the new points along the edge, which
/// keeps its orientation; each piece keeps its tet's region. Returns the two
/// new vertex ids.
pub fn trisect_edge(
    mesh: &mut TetMesh,
    a: u32,
    b: u32,
    around: &[u32],
    x1: DVec3,
    x2: DVec3,
) -> Result<(u32, u32), OpError> {
    if around.is_empty() {
        return Err(OpError::NotApplicable("no tet holds the edge"));
    }
    let v1 = mesh.add_point(x1);
    let v2 = mesh.add_point(x2);
    let mut new = Vec::with_capacity(3 * around.len());
    let mut origin = Vec::with_capacity(3 * around.len());
    let mut others: Vec<u32> = Vec::new();
    for (i, &t) in around.iter().enumerate() {
        let v = mesh.tet(t);
        let (Some(ia), Some(ib)) = (
            v.iter().position(|&x| x == a),
            v.iter().position(|&x| x == b),
        ) else {
            mesh.pop_unused_point(v2);
            mesh.pop_unused_point(v1);
            return Err(OpError::NotApplicable(
                "a listed tet does not hold the edge",
            ));
        };
        let mut t1 = v;
        t1[ib] = v1;
        let mut t2 = v;
        t2[ia] = v1;
        t2[ib] = v2;
        let mut t3 = v;
        t3[ia] = v2;
        new.extend([t1, t2, t3]);
        origin.extend([i, i, i]);
        others.extend(v.iter().copied().filter(|&x| x != a && x != b));
    }
    others.sort_unstable();
    others.dedup();
    let face_markers: Vec<(u32, Option<i32>)> = others
        .iter()
        .map(|&p| (p, mesh.face_marker([a, b, p])))
        .collect();
    let edge_marker = mesh.feature_edge(a, b);
    match replace_cavity_raw(mesh, around, &new, &origin) {
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
