//! Optimization-based smoothing: move a vertex to raise the minimum quality of
//! its ball (the non-smooth max–min problem of Freitag, Jones and Plassmann,
//! "An efficient parallel algorithm for mesh smoothing", 1995, and Freitag's
//! thesis 1997).
//!
//! Each iteration takes the tets whose quality is within a small tolerance of
//! the minimum (the active set), estimates their quality gradients with
//! respect to the vertex by central differences, and searches along the
//! direction that raises all of them (the minimum-norm point of the convex hull
//! of the active gradients, found by a few Frank–Wolfe/Gilbert steps). A step
//! is accepted only if the ball's minimum rises and no tet inverts (exact
//! predicate); otherwise it is halved, a few times, and then the search stops.

use super::BallPoints;
use glam::DVec3;

/// Tuning of the optimiser.
#[derive(Clone, Copy, Debug)]
pub struct OptimizeParams {
    /// Outer iterations.
    pub iterations: usize,
    /// Qualities within this of the minimum are active.
    pub active_tol: f64,
    /// Halvings of a rejected step before giving up.
    pub halvings: usize,
}

impl Default for OptimizeParams {
    fn default() -> Self {
        OptimizeParams {
            iterations: 12,
            active_tol: 1e-3,
            halvings: 10,
        }
    }
}

/// Minimum-norm point of the convex hull of `g` (a few Gilbert iterations):
/// a direction along which all active qualities rise, if one exists.
pub(crate) fn min_norm_in_hull(g: &[DVec3]) -> DVec3 {
    let mut x = g[0];
    for _ in 0..32 {
        // Vertex minimising <x, g_i>.
        let (mut best, mut bi) = (f64::INFINITY, 0);
        for (i, gi) in g.iter().enumerate() {
            let d = x.dot(*gi);
            if d < best {
                best = d;
                bi = i;
            }
        }
        let d = g[bi] - x;
        let dd = d.length_squared();
        // The hull point only picks a search direction; the thresholds end
        // the iteration when it no longer moves in double precision. Any
        // direction is safe, because every trial position is judged again
        // below by its exact ball qualities and orientation.
        if dd < 1e-30 {
            break;
        }
        let step = (-x.dot(d) / dd).clamp(0.0, 1.0);
        if step <= 1e-12 {
            break;
        }
        x += step * d;
    }
    x
}

/// Where the optimiser would move the vertex whose ball's corners are loaded
/// in `bp` if it stood at `x0`, without moving it: the optimised position and
/// the ball's new minimum quality, if that is above the minimum at `x0`. On success
/// `qs` holds the ball's qualities at the new position, in ball order; `trial`
/// is scratch.
pub fn optimize_position_in(
    bp: &BallPoints,
    x0: DVec3,
    params: &OptimizeParams,
    qs: &mut Vec<f64>,
    trial: &mut Vec<f64>,
) -> Option<(DVec3, f64)> {
    // A length scale for differences and steps: mean distance to the ball's
    // other vertices.
    let mut scale = 0.0;
    let mut n = 0;
    for i in 0..bp.len() {
        for u in bp.others(i) {
            scale += (u - x0).length();
            n += 1;
        }
    }
    if n == 0 {
        return None;
    }
    scale /= n as f64;
    // Central differences with h = 1e-6 of the mean edge length: truncation
    // error O(h²) ≈ 1e-12 and rounding ≈ ε/h ≈ 1e-10, relative — ample for a
    // search direction. Validity never rests on the gradient: a move is kept
    // only if the recomputed qualities rise and the ball stays positive.
    let h = 1e-6 * scale;
    let mut x = x0;
    qs.clear();
    qs.extend((0..bp.len()).map(|i| bp.quality(i, x)));
    let mut q = qs.iter().copied().fold(f64::INFINITY, f64::min);
    let start = q;
    let mut grads: Vec<DVec3> = Vec::new();
    for _ in 0..params.iterations {
        grads.clear();
        for (i, &qi) in qs.iter().enumerate() {
            if qi > q + params.active_tol {
                continue;
            }
            let mut g = DVec3::ZERO;
            for axis in 0..3 {
                let mut e = DVec3::ZERO;
                e[axis] = h;
                g[axis] = (bp.quality(i, x + e) - bp.quality(i, x - e)) / (2.0 * h);
            }
            grads.push(g);
        }
        if grads.is_empty() {
            break;
        }
        let d = min_norm_in_hull(&grads);
        let dn = d.length();
        // Below the gradient's own error (about 1e-10 relative, see `h`).
        if dn < 1e-12 {
            break; // stationary: no direction raises all active tets
        }
        // First guess: the step at which the linear model of the worst active tet
        // reaches the next-worst inactive one, capped at a fraction of the scale.
        let next = qs
            .iter()
            .copied()
            .filter(|&qi| qi > q + params.active_tol)
            .fold(f64::INFINITY, f64::min);
        let mut alpha = if next.is_finite() {
            (next - q) / (dn * dn)
        } else {
            0.1 * scale / dn
        };
        alpha = alpha.min(0.2 * scale / dn);
        let mut moved = false;
        for _ in 0..params.halvings {
            let y = x + alpha * d;
            // Accepted only if the ball's minimum rises by more than 1e-12:
            // the first tet at or below that settles a rejection.
            if let Some(qy) = bp.qualities_above(y, q + 1e-12, trial) {
                if bp.stays_positive(y) {
                    x = y;
                    q = qy;
                    std::mem::swap(qs, trial);
                    moved = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !moved {
            break;
        }
    }
    (q > start).then_some((x, q))
}
