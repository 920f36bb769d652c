//! Laplacian smoothing: the vertex goes to the centroid of its neighbours
//! (Field 1988), kept only if the worst tet of its ball improves.

use super::{ball_min_mean_at, ball_stays_positive, vertex_neighbours};
use crate::mesh::TetMesh;
use glam::DVec3;

/// Centroid of the neighbours of `v`.
pub fn laplacian_target(mesh: &TetMesh, v: u32, ball: &[u32], scratch: &mut Vec<u32>) -> DVec3 {
    vertex_neighbours(mesh, v, ball, scratch);
    if scratch.is_empty() {
        return mesh.point(v);
    }
    scratch.iter().map(|&u| mesh.point(u)).sum::<DVec3>() / scratch.len() as f64
}

/// Moves `v` to its Laplacian target if that raises the ball's worst quality
/// above `current` without lowering the ball's mean quality or inverting
/// anything. Returns the new worst quality if it moved.
pub fn laplacian_smooth(
    mesh: &mut TetMesh,
    v: u32,
    ball: &[u32],
    current: f64,
    scratch: &mut Vec<u32>,
) -> Option<f64> {
    let x = laplacian_target(mesh, v, ball, scratch);
    let (q, mean) = ball_min_mean_at(mesh, v, ball, x);
    if q > current
        && mean >= ball_min_mean_at(mesh, v, ball, mesh.point(v)).1
        && ball_stays_positive(mesh, v, ball, x)
    {
        mesh.set_point(v, x);
        Some(q)
    } else {
        None
    }
}
