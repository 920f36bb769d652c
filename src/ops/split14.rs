//! 1-4 split: a new vertex inside a tet, joined to its four vertices.
//!
//! ```text
//!            3                      child i = the tet with vertex i
//!           /|\                     replaced by the new vertex c:
//!          / | \                      child 0 = (c,1,2,3)
//!         /  c  \                     child 1 = (0,c,2,3)
//!        0---|---2                    child 2 = (0,1,c,3)
//!         \  |  /                     child 3 = (0,1,2,c)
//!          \ | /                    child i keeps face i of the parent;
//!            1                      children i and j share (c, the other two)
//! ```
//!
//! Seed paper (Burkhart, Hamann, Umlauf 2010) §3.1: the tetrahedral analogue of
//! the triangle 1-3 split; it leaves every face of the parent intact, which is
//! what makes adaptive refinement conforming.

use super::{replace_cavity, OpError};
use crate::mesh::TetMesh;
use glam::DVec3;

/// Splits tet `t` at `p` (which must lie strictly inside it) and returns the
/// four children, child `i` holding face `i` of the parent.
pub fn split14(mesh: &mut TetMesh, t: u32, p: DVec3) -> Result<[u32; 4], OpError> {
    let v = mesh.tet(t);
    let c = mesh.add_point(p);
    let new = [
        [c, v[1], v[2], v[3]],
        [v[0], c, v[2], v[3]],
        [v[0], v[1], c, v[3]],
        [v[0], v[1], v[2], c],
    ];
    match replace_cavity(mesh, &[t], &new) {
        Ok(ids) => Ok([ids[0], ids[1], ids[2], ids[3]]),
        Err(e) => {
            // The point was appended last and nothing references it: drop it.
            mesh.pop_unused_point(c);
            Err(e)
        }
    }
}
