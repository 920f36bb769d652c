//! Loop and Kobbelt's √3 on the regular triangular lattice, written as IFS
//! maps (Schaefer, Levin and Goldman, "Subdivision schemes and attractors",
//! §3.2–3.3).
//!
//! Lattice point `(i, j)` stands for `i e1 + j e2` with `e1 = (1, 0)` and
//! `e2 = (1/2, √3/2)`; the six neighbours of a point are at the offsets
//! [`N6`]. The patch is the limit surface over the triangle
//! `T = (0,0), (1,0), (0,1)`; its control net is every lattice point within
//! lattice distance `r` of `T` ([`net`]). One IFS level is one Loop step
//! (binary split, 4 sub-triangles) or two √3 steps (which together make a
//! ternary split aligned with the coarse lattice, 9 sub-triangles). The
//! points of a sub-triangle's net at the finer level are affine
//! combinations of the coarse net: those combinations are the rows of the
//! map. The construction checks that every coarse point they use is in the
//! net (the net is closed under the scheme), so the attractor is exactly
//! the limit surface over `T`.

use std::collections::HashMap;

/// A lattice point (or offset) `(i, j)`.
pub(super) type P = [i64; 2];

/// The six neighbour offsets, counter-clockwise from `e1`.
pub(super) const N6: [P; 6] = [[1, 0], [0, 1], [-1, 1], [-1, 0], [0, -1], [1, -1]];

/// An affine combination of coarse lattice points.
type Combo = Vec<(P, f64)>;

/// Lattice (hexagonal) distance between two points.
fn hex_distance(a: P, b: P) -> i64 {
    let (x, y) = (a[0] - b[0], a[1] - b[1]);
    (x.abs() + y.abs() + (x + y).abs()) / 2
}

/// The corners of `T`.
pub(super) const CORNERS: [P; 3] = [[0, 0], [1, 0], [0, 1]];

/// Every lattice point within distance `r` of `T`: the corners of `T`
/// first, then by distance, then by `(j, i)`.
pub(super) fn net(r: i64) -> Vec<P> {
    let mut pts: Vec<(i64, P)> = Vec::new();
    for j in -r - 1..=r + 2 {
        for i in -r - 1..=r + 2 {
            let p = [i, j];
            let d = CORNERS
                .iter()
                .map(|&c| hex_distance(p, c))
                .min()
                .unwrap_or(0);
            if d <= r {
                pts.push((d, p));
            }
        }
    }
    pts.sort_by_key(|&(d, p)| {
        let corner = CORNERS.iter().position(|&c| c == p).unwrap_or(3);
        (d, corner, p[1], p[0])
    });
    pts.into_iter().map(|(_, p)| p).collect()
}

fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}

/// A sub-triangle of `T` at the finer level: `q ↦ sign·q + shift` in fine
/// lattice coordinates (`sign = −1` is the half-turn that maps `T` onto a
/// downward triangle; both keep the orientation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct SubTriangle {
    /// `+1` or `−1`.
    pub sign: i64,
    /// The translation, in fine lattice units.
    pub shift: P,
}

impl SubTriangle {
    fn apply(&self, q: P) -> P {
        [
            self.sign * q[0] + self.shift[0],
            self.sign * q[1] + self.shift[1],
        ]
    }
}

const fn up(i: i64, j: i64) -> SubTriangle {
    SubTriangle {
        sign: 1,
        shift: [i, j],
    }
}

const fn down(i: i64, j: i64) -> SubTriangle {
    SubTriangle {
        sign: -1,
        shift: [i, j],
    }
}

/// Loop's four sub-triangles (fine = coarse × 2): the corners at `T`'s
/// vertices 0, 1, 2, then the centre.
pub(super) const LOOP_SUBS: [SubTriangle; 4] = [up(0, 0), up(1, 0), up(0, 1), down(1, 1)];

/// √3's nine sub-triangles after two steps (fine = coarse × 3): the corners
/// at `T`'s vertices 0, 1, 2; the upward triangles on the middle thirds of
/// the edges 0–1, 1–2, 2–0; the three downward triangles (at vertex 0's,
/// 1's and 2's side of the centre).
pub(super) const SQRT3_SUBS: [SubTriangle; 9] = [
    up(0, 0),
    up(2, 0),
    up(0, 2),
    up(1, 0),
    up(1, 1),
    up(0, 1),
    down(1, 1),
    down(2, 1),
    down(1, 2),
];

/// Loop's regular rules, one step, for the fine point `f` (coarse × 2):
/// vertex `5/8 v + 1/16 Σ neighbours` (Loop's `β = 1/16` at valence 6),
/// edge `3/8 (p + q) + 1/8 (r + s)`.
pub(super) fn loop_fine(f: P) -> Combo {
    let (a, b) = (f[0], f[1]);
    let (p, d, o1, o2) = match (a.rem_euclid(2), b.rem_euclid(2)) {
        (0, 0) => {
            let v = [a / 2, b / 2];
            let mut c = vec![(v, 5.0 / 8.0)];
            c.extend(N6.iter().map(|&n| (add(v, n), 1.0 / 16.0)));
            return c;
        }
        (1, 0) => ([(a - 1) / 2, b / 2], [1, 0], [0, 1], [1, -1]),
        (0, 1) => ([a / 2, (b - 1) / 2], [0, 1], [1, 0], [-1, 1]),
        _ => ([(a - 1) / 2, (b + 1) / 2], [1, -1], [1, 0], [0, -1]),
    };
    vec![
        (p, 3.0 / 8.0),
        (add(p, d), 3.0 / 8.0),
        (add(p, o1), 1.0 / 8.0),
        (add(p, o2), 1.0 / 8.0),
    ]
}

/// The offsets (coarse × 3) from a coarse vertex to the centroids of its
/// six triangles: its neighbours after one √3 step.
const OFF1: [P; 6] = [[1, 1], [-1, 2], [-2, 1], [-1, -1], [1, -2], [2, -1]];

/// Kobbelt's relaxed old vertex at valence 6:
/// `(1 − α) v + α/6 Σ neighbours`, `α = (4 − 2 cos(2π/6))/9 = 1/3`.
fn relaxed(v: P) -> Combo {
    let mut c = vec![(v, 2.0 / 3.0)];
    c.extend(N6.iter().map(|&n| (add(v, n), 1.0 / 18.0)));
    c
}

/// The centroid at `g` (coarse × 3) of a coarse triangle, as the mean of its
/// corners.
fn centroid(g: P) -> Combo {
    let corners = if g[0].rem_euclid(3) == 1 {
        let (i, j) = ((g[0] - 1) / 3, (g[1] - 1) / 3);
        [[i, j], [i + 1, j], [i, j + 1]]
    } else {
        let (i, j) = ((g[0] - 2) / 3, (g[1] - 2) / 3);
        [[i + 1, j], [i, j + 1], [i + 1, j + 1]]
    };
    corners.iter().map(|&c| (c, 1.0 / 3.0)).collect()
}

/// The point at `g` (coarse × 3) after one √3 step: a relaxed old vertex or
/// a new centroid.
fn sqrt3_level1(g: P) -> Combo {
    if g[0].rem_euclid(3) == 0 && g[1].rem_euclid(3) == 0 {
        relaxed([g[0] / 3, g[1] / 3])
    } else {
        centroid(g)
    }
}

fn scaled(c: Combo, s: f64) -> impl Iterator<Item = (P, f64)> {
    c.into_iter().map(move |(p, w)| (p, w * s))
}

/// Two of Kobbelt's √3 steps for the fine point `f` (coarse × 3):
/// - at an old vertex: relaxed again with its six centroids as neighbours;
/// - at an old centroid: relaxed with its three (relaxed) corners and the
///   three neighbouring centroids as neighbours;
/// - at a third of an old edge: the centroid of the step-one triangle formed
///   by the nearer end (relaxed) and the centroids on both sides of the edge.
pub(super) fn sqrt3_fine(f: P) -> Combo {
    let r = [f[0].rem_euclid(3), f[1].rem_euclid(3)];
    if r == [0, 0] || r == [1, 1] || r == [2, 2] {
        let mut c: Combo = scaled(sqrt3_level1(f), 2.0 / 3.0).collect();
        for o in OFF1 {
            c.extend(scaled(sqrt3_level1(add(f, o)), 1.0 / 18.0));
        }
        return c;
    }
    for d in N6 {
        let v3 = [f[0] - d[0], f[1] - d[1]];
        if v3[0].rem_euclid(3) != 0 || v3[1].rem_euclid(3) != 0 {
            continue;
        }
        for (x, &a) in OFF1.iter().enumerate() {
            for &b in &OFF1[x + 1..] {
                if add(a, b) == [3 * d[0], 3 * d[1]] {
                    let mut c: Combo = scaled(relaxed([v3[0] / 3, v3[1] / 3]), 1.0 / 3.0).collect();
                    c.extend(scaled(centroid(add(v3, a)), 1.0 / 3.0));
                    c.extend(scaled(centroid(add(v3, b)), 1.0 / 3.0));
                    return c;
                }
            }
        }
    }
    unreachable!("every point of the fine lattice is a vertex, centroid or edge third")
}

/// The maps `S_i` (row-major `m × m`, `m = net.len()`): row `r` of map `i`
/// holds the fine point at `subs[i](net[r])` as a combination of the net.
/// `Err` names a coarse point the rules need outside the net.
pub(super) fn lattice_maps(
    net: &[P],
    subs: &[SubTriangle],
    fine: impl Fn(P) -> Combo,
) -> Result<Vec<Vec<f64>>, P> {
    let index: HashMap<P, usize> = net.iter().enumerate().map(|(k, &p)| (p, k)).collect();
    let m = net.len();
    subs.iter()
        .map(|s| {
            let mut map = vec![0.0; m * m];
            for (r, &q) in net.iter().enumerate() {
                for (p, w) in fine(s.apply(q)) {
                    let c = *index.get(&p).ok_or(p)?;
                    map[r * m + c] += w;
                }
            }
            Ok(map)
        })
        .collect()
}
