//! 3-2 edge flip: the three tets around an interior edge become two tets
//! sharing the triangle of the ring. The inverse of the 2-3 flip, and the
//! smallest case of edge removal (m = 3 → 2m − 4 = 2).
//!
//! ```text
//!            a                  before: (a,b,r0,r1) (a,b,r1,r2) (a,b,r2,r0)
//!          / | \                after:  (a,r0,r1,r2) and (b,r2,r1,r0)
//!        r0--|--r2
//!          \ | /   r1 behind
//!            b
//! ```

use super::{edge_removal::remove_edge, OpError};
use crate::mesh::TetMesh;

/// Removes edge `e` of tet `t` when exactly three tets surround it (interior
/// edge); returns the two new tets.
pub fn flip32(mesh: &mut TetMesh, t: u32, e: usize) -> Result<[u32; 2], OpError> {
    let ring = super::EdgeRing::gather(mesh, t, e);
    if !ring.closed || ring.tets.len() != 3 {
        return Err(OpError::NotApplicable(
            "edge does not have exactly three tets around it",
        ));
    }
    let ids = remove_edge(mesh, &ring, f64::NEG_INFINITY)?;
    Ok([ids[0], ids[1]])
}
