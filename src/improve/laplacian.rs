//! Laplacian smoothing: the vertex goes to the centroid of its neighbours
//! (Field 1988), kept only if its ball gets better: a higher worst tet, or,
//! where the caller allows it, a higher mean with the worst kept above a
//! bar (the "smart" Laplacian of Freitag, 1997, judges a move by its ball's
//! quality in the same way).

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
    /// The worst may fall to just above this (never below `worst` if that is
    /// lower) for a higher mean; `f64::INFINITY`: the worst must rise.
    pub keep: f64,
}

/// Where the Laplacian move would take `v`, without moving it (the ball's
/// corners loaded in `bp`): the Laplacian target, or the point halfway to
/// it if the target is refused, and the ball's new worst quality, if
/// there every tet is above `min(now.worst, now.keep)`,
/// nothing inverts, and the mean rises (or stays while the worst rises). On
/// success `qualities` holds the ball's tet qualities at the position, in
/// `ball` order.
pub fn laplacian_position_in(
    mesh: &TetMesh,
    v: u32,
    ball: &[u32],
    bp: &BallPoints,
    now: BallNow,
    qualities: &mut Vec<f64>,
) -> Option<(DVec3, f64)> {
    let target = bp
        .neighbour_centroid(mesh.n_points(), v)
        .unwrap_or_else(|| mesh.point(v));
    // Halfway there when the centroid itself is refused: measured on the
    // seven shipped meshes (one default step), the average minimum dihedral
    // rises by another 0.15°–0.9° (mmg_cube 43.0° → 43.9°) at no cost in
    // time that shows.
    let x0 = mesh.point(v);
    judge_position(target, bp, now, qualities, ball.len())
        .or_else(|| judge_position(x0 + 0.5 * (target - x0), bp, now, qualities, ball.len()))
}

/// The ball's new worst quality if `v` stood at `x` and the move is kept
/// by the rule of [`laplacian_position_in`] (`n` tets in the ball).
fn judge_position(
    x: DVec3,
    bp: &BallPoints,
    now: BallNow,
    qualities: &mut Vec<f64>,
    n: usize,
) -> Option<(DVec3, f64)> {
    let (current_mean, first) = (now.mean, now.first);
    let current = now.worst.min(now.keep);
    // Every tet must end above `current`; any tet at or below it settles the
    // answer, and the likeliest one to be is the one `first` (the caller's
    // worst tet), so it is tried before the others. With `keep` at infinity
    // every tet above the worst means the worst rises, so the test below is
    // the mean's alone.
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
    let mean = sum / n.max(1) as f64;
    let better = mean > current_mean || (mean >= current_mean && q > now.worst);
    (better && bp.stays_positive(x)).then_some((x, q))
}
