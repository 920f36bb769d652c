//! Laplacian smoothing: the vertex goes to the centroid of its neighbours
//! (Field 1988), kept only if the worst tet of its ball improves.

use super::BallPoints;
use crate::mesh::TetMesh;
use glam::DVec3;

/// The ball of a vertex as it stands, for [`laplacian_position_in`].
#[derive(Clone, Copy, Debug)]
pub struct BallNow {
    /// Its worst tet quality.
    pub worst: f64,
    /// Its mean tet quality.
    pub mean: f64,
    /// Position in the ball of a tet to check first (the worst one; any
    /// position works, one past the end for none).
    pub first: usize,
}

/// Where the Laplacian move would take `v`, without moving it (the ball's
/// corners loaded in `bp`): the Laplacian target and the ball's new worst
/// quality, if the target raises the worst quality above `now.worst` without
/// lowering the mean below `now.mean` or inverting anything. On success
/// `qualities` holds the ball's tet qualities at the target, in `ball` order.
pub fn laplacian_position_in(
    mesh: &TetMesh,
    v: u32,
    ball: &[u32],
    bp: &BallPoints,
    now: BallNow,
    qualities: &mut Vec<f64>,
) -> Option<(DVec3, f64)> {
    let (current, current_mean, first) = (now.worst, now.mean, now.first);
    let x = bp
        .neighbour_centroid(mesh.n_points(), v)
        .unwrap_or_else(|| mesh.point(v));
    // Every tet must end above `current`; any tet at or below it settles the
    // answer, and the likeliest one to be is the one `first` (the caller's
    // worst tet), so it is tried before the others.
    let quality = |i: usize| bp.quality(i, x);
    let head = (first < bp.len()).then(|| quality(first));
    if head.is_some_and(|s| s.is_nan() || s <= current) {
        return None;
    }
    qualities.clear();
    let mut q = f64::INFINITY;
    let mut sum = 0.0;
    for i in 0..bp.len() {
        let s = match head {
            Some(h) if i == first => h,
            _ => quality(i),
        };
        if s.is_nan() || s <= current {
            return None;
        }
        q = q.min(s);
        sum += s;
        qualities.push(s);
    }
    let mean = sum / ball.len().max(1) as f64;
    (mean >= current_mean && bp.stays_positive(x)).then_some((x, q))
}
