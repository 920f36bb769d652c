//! Boundary 1-3 split: a new vertex on a boundary face splits its tet in three.
//!
//! ```text
//!              c                  boundary face (a,b,c) of tet (a,b,c,d),
//!             /|\                 apex d inside; m on the face:
//!            / | \                  (a,b,m,d) (b,c,m,d) (c,a,m,d)
//!           /  m  \               the three new boundary faces (a,b,m),
//!          / /   \ \              (b,c,m), (c,a,m) keep the face's marker.
//!         a---------b
//! ```
//!
//! Seed paper §4 ("tetrahedral 1-3 split", its Figure 7b): the boundary half of
//! Kobbelt's √3 1-3 split.

use super::{replace_cavity, OpError};
use crate::mesh::TetMesh;
use crate::topo::TET_FACES;
use glam::DVec3;

/// Splits boundary face `f` of tet `t` at `p` (on or near the face) and
/// returns the new vertex and the three new tets.
pub fn split_boundary_face(
    mesh: &mut TetMesh,
    t: u32,
    f: usize,
    p: DVec3,
) -> Result<(u32, [u32; 3]), OpError> {
    if !mesh.is_boundary_face(t, f) {
        return Err(OpError::NotApplicable("face is not on the boundary"));
    }
    let v = mesh.tet(t);
    let l = TET_FACES[f];
    let (a, b, c, d) = (v[l[0]], v[l[1]], v[l[2]], v[f]);
    let m = mesh.add_point(p);
    // (a,b,c) is outward, so (a,b,c,d) is negative and (a,b,m,d) etc. with m on
    // the face are negative too: list them as (b,a,m,d) to get positive tets.
    let new = [[b, a, m, d], [c, b, m, d], [a, c, m, d]];
    match replace_cavity(mesh, &[t], &new) {
        Ok(ids) => Ok((m, [ids[0], ids[1], ids[2]])),
        Err(e) => {
            mesh.pop_unused_point(m);
            Err(e)
        }
    }
}
