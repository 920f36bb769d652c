//! Vertex moves seen from the ball of the moved vertex.

use super::TetMesh;
use crate::geom::all_positive;
use glam::DVec3;

/// The corners of tet `t` with vertex `v` (if it is one of them) standing at `x`.
#[inline]
pub(crate) fn tet_points_with(mesh: &TetMesh, t: u32, v: u32, x: DVec3) -> [DVec3; 4] {
    let tv = mesh.tet(t);
    let mut p = mesh.tet_points(t);
    for (pi, &vi) in p.iter_mut().zip(&tv) {
        if vi == v {
            *pi = x;
        }
    }
    p
}

/// Whether every tet of `ball` stays positively oriented (exact predicate) with
/// vertex `v` at `x`.
pub fn ball_stays_positive(mesh: &TetMesh, v: u32, ball: &[u32], x: DVec3) -> bool {
    all_positive(ball.iter().map(|&t| tet_points_with(mesh, t, v, x)))
}
