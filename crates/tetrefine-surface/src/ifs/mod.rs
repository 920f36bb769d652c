//! Subdivision curves and surfaces as attractors of iterated function systems
//! (Schaefer, Levin and Goldman, "Subdivision schemes and
//! attractors"), and the Koch curve and Sierpinski gasket as subdivision
//! schemes with movable control points (same paper, §4).
//!
//! ## The construction
//!
//! A stationary subdivision scheme refines `m` control points `P` (rows) by a
//! matrix `S`. Cut `S` into square `m × m` blocks `S_i` (rows of `S`, possibly
//! overlapping) such that the pieces `S_i P` are control polygons of the parts
//! of the limit curve or surface. The paper's maps are
//! `f_i(X) = X P⁻¹ S_i P` on points `X` lifted to `R^m` (extra identity
//! columns and a column of ones make `P` square). This module uses the same
//! maps in the coordinates `w = X P⁻¹`: a point is an affine combination
//! `x = Σ_j w_j P_j` of the control points (`Σ_j w_j = 1`), and
//! `f_i(w) = w S_i`. The two forms are conjugate by the fixed matrix `P`, so
//! they have the same attractor, but the weight form needs no affine basis
//! among the control points (planar and collinear control polygons work).
//! Since every row of `S_i` sums to one, the maps keep `Σ w = 1`.
//!
//! ## Contractivity
//!
//! On the affine plane `Σ w = 1` the linear part of `f_i` is `v ↦ v S_i` on
//! `D = {v : Σ v = 0}`. The paper argues from the eigenvalues of `S_i`; a
//! common norm in which every map contracts is what Barnsley's theorem needs,
//! so [`Ifs::contraction_certificate`] constructs one: find the shortest `L`
//! such that every product `Π` of `L` maps has Euclidean operator norm on `D`
//! at most `γ^L < 1` (bounded above by the Frobenius norm), and set
//!
//! `‖v‖* = max over 0 ≤ j < L and all products Π of j maps of γ^(−j) ‖v Π‖₂`.
//!
//! Then `‖v S_i‖* ≤ γ ‖v‖*` for every map (the terms of length `L` are bounded
//! by `γ^L ‖v‖₂`), so the IFS has a unique attractor and iterating any compact
//! start set converges to it in the Hausdorff metric, at rate `γ`.
//!
//! ## Schemes
//!
//! - [`IfsKind::CubicBSpline`]: uniform cubic B-spline subdivision
//!   (`p_2i = (p_(i−1) + 6 p_i + p_(i+1))/8`, `p_(2i+1) = (p_i + p_(i+1))/2`);
//!   `n ≥ 4` control points, attractor = the curve between knots 1 and
//!   `n − 2` (`n − 3` cubic pieces). Two maps.
//! - [`IfsKind::FourPoint`]: the interpolating four-point scheme
//!   (`p_(2i+1) = (−p_(i−1) + 9 p_i + 9 p_(i+1) − p_(i+2))/16`); `n ≥ 6`
//!   control points, attractor = the curve from `p_2` to `p_(n−3)`. Two maps.
//! - [`IfsKind::Bicubic`]: the tensor product of the cubic B-spline rules on
//!   a `nu × nv` grid (row-major, `nu, nv ≥ 4`), the regular case of
//!   Catmull–Clark. Four maps `S_a ⊗ S_b`, map `2a + b`.
//! - [`IfsKind::Koch`]: five control points, the paper's four Koch matrices
//!   (barycentric rules); with [`koch_control`] the attractor is the Koch
//!   curve, moving a control point deforms it locally.
//! - [`IfsKind::Gasket`]: six control points (corner, edge point, corner, …),
//!   the paper's three gasket matrices (quadratic Lagrange rules on the outer
//!   edges, linear inside); with [`gasket_control`] the attractor is the
//!   Sierpinski gasket.

mod linalg;

use super::error::SurfaceError;
use glam::DVec3;
use linalg::{mat_mul, restricted_frobenius, row_times, solve4};
use tetrefine::SplitMix64;
/// The attractor's writers: the core's point and polyline files.
pub use tetrefine::{
    write_points_csv, write_points_vtp, write_polylines, write_polylines_csv, write_polylines_vtp,
    PolylineFormat,
};

/// Which subdivision scheme an [`Ifs`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IfsKind {
    /// Uniform cubic B-spline curve (at least 4 control points).
    CubicBSpline,
    /// Interpolating four-point curve (at least 6 control points).
    FourPoint,
    /// Bicubic B-spline patch on a `nu × nv` row-major grid (both at least 4).
    Bicubic {
        /// Grid points along `u` (rows).
        nu: usize,
        /// Grid points along `v` (columns).
        nv: usize,
    },
    /// Koch curve by subdivision (exactly 5 control points).
    Koch,
    /// Sierpinski gasket by subdivision (exactly 6 control points: corner,
    /// edge point, corner, edge point, corner, edge point).
    Gasket,
}

/// The standard Koch control points: (0,0), (1/3,0), the peak
/// (1/2, √3/6) and (2/3,0), (1,0), in the plane `z = 0`.
pub fn koch_control() -> [DVec3; 5] {
    [
        DVec3::ZERO,
        DVec3::new(1.0 / 3.0, 0.0, 0.0),
        DVec3::new(0.5, 3f64.sqrt() / 6.0, 0.0),
        DVec3::new(2.0 / 3.0, 0.0, 0.0),
        DVec3::X,
    ]
}

/// The standard gasket control points: the corners (0,0), (1,0),
/// (1/2, √3/2) with the edge midpoints between them, in the order corner,
/// midpoint, corner, midpoint, corner, midpoint (plane `z = 0`).
pub fn gasket_control() -> [DVec3; 6] {
    let c = [
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
    ];
    [
        c[0],
        0.5 * (c[0] + c[1]),
        c[1],
        0.5 * (c[1] + c[2]),
        c[2],
        0.5 * (c[2] + c[0]),
    ]
}

/// An iterated function system built from subdivision matrices, acting on
/// affine weights of the control points (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Ifs {
    kind: IfsKind,
    control: Vec<DVec3>,
    m: usize,
    /// Row-major `m × m` subdivision matrices.
    maps: Vec<Vec<f64>>,
}

/// A norm in which every map of an [`Ifs`] is a contraction (see the
/// [module docs](self)): `‖v S_i‖* ≤ factor · ‖v‖*` for every map `i` and
/// every weight difference `v` (`Σ v = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContractionCertificate {
    /// `L`: every product of `L` maps has operator norm at most `factor^L`.
    pub length: usize,
    /// `γ < 1`, the contraction factor of every map in the norm.
    pub factor: f64,
}

impl ContractionCertificate {
    /// `‖v‖* = max over products Π of fewer than `length` maps of
    /// factor^(−|Π|) ‖v Π‖₂`, for `v` with `Σ v = 0`.
    pub fn norm(&self, ifs: &Ifs, v: &[f64]) -> f64 {
        let mut best = 0.0f64;
        let mut frontier = vec![v.to_vec()];
        for j in 0..self.length {
            let scale = self.factor.powi(-(j as i32));
            for w in &frontier {
                best = best.max(scale * w.iter().map(|x| x * x).sum::<f64>().sqrt());
            }
            if j + 1 < self.length {
                frontier = frontier
                    .iter()
                    .flat_map(|w| (0..ifs.map_count()).map(move |i| ifs.apply(i, w)))
                    .collect();
            }
        }
        best
    }
}

/// Most points [`Ifs::for_each_point`] may visit.
const MAX_POINTS: f64 = (1u64 << 28) as f64;

/// Most points [`ifs_attractor`] may return.
const MAX_STORED_POINTS: f64 = (1u64 << 24) as f64;

impl Ifs {
    /// The IFS of `kind` for these control points.
    pub fn new(kind: IfsKind, control: &[DVec3]) -> Result<Ifs, SurfaceError> {
        if let Some(i) = control.iter().position(|p| !p.is_finite()) {
            return Err(SurfaceError::NonFinite { vertex: i });
        }
        let n = control.len();
        let need = |ok: bool, what: &str| {
            if ok {
                Ok(())
            } else {
                Err(SurfaceError::Parameter(format!(
                    "{kind:?} needs {what} control points, got {n}"
                )))
            }
        };
        let maps = match kind {
            IfsKind::CubicBSpline => {
                need(n >= 4, "at least 4")?;
                split_rows(&bspline_refinement(n), n, &[0, n - 3])
            }
            IfsKind::FourPoint => {
                need(n >= 6, "at least 6")?;
                split_rows(&four_point_refinement(n), n, &[0, n - 5])
            }
            IfsKind::Bicubic { nu, nv } => {
                need(
                    nu >= 4 && nv >= 4 && nu.checked_mul(nv) == Some(n),
                    "a grid of at least 4 × 4",
                )?;
                let su = split_rows(&bspline_refinement(nu), nu, &[0, nu - 3]);
                let sv = split_rows(&bspline_refinement(nv), nv, &[0, nv - 3]);
                let mut maps = Vec::new();
                for a in &su {
                    for b in &sv {
                        maps.push(kronecker(a, nu, b, nv));
                    }
                }
                maps
            }
            IfsKind::Koch => {
                need(n == 5, "exactly 5")?;
                KOCH.iter().map(thirds).collect()
            }
            IfsKind::Gasket => {
                need(n == 6, "exactly 6")?;
                GASKET.iter().map(eighths).collect()
            }
        };
        Ok(Ifs {
            kind,
            control: control.to_vec(),
            m: n,
            maps,
        })
    }

    /// The scheme.
    pub fn kind(&self) -> IfsKind {
        self.kind
    }

    /// The control points.
    pub fn control(&self) -> &[DVec3] {
        &self.control
    }

    /// `m`, the number of control points (length of a weight vector).
    pub fn dimension(&self) -> usize {
        self.m
    }

    /// Number of maps.
    pub fn map_count(&self) -> usize {
        self.maps.len()
    }

    /// Subdivision matrix `S_i`, row-major `m × m`.
    pub fn map(&self, i: usize) -> &[f64] {
        &self.maps[i]
    }

    /// `f_i(w) = w S_i` (`w` has [`Ifs::dimension`] entries; missing ones
    /// count as 0, extra ones are ignored).
    pub fn apply(&self, i: usize, w: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.m];
        row_times(w, &self.maps[i], self.m, &mut out);
        out
    }

    /// The point `Σ_j w_j P_j`.
    pub fn position(&self, w: &[f64]) -> DVec3 {
        w.iter().zip(&self.control).map(|(&a, &p)| a * p).sum()
    }

    /// `w` shifted by a multiple of `(1, …, 1)` so that its entries sum to 1
    /// (start points must be affine weights).
    pub fn affine(&self, w: &[f64]) -> Vec<f64> {
        let shift = (1.0 - w.iter().sum::<f64>()) / self.m as f64;
        w.iter().map(|a| a + shift).collect()
    }

    /// Affine weights of the point `x`: the least-norm `w` with `Σ w = 1` and
    /// `Σ w_j P_j = x` (least squares in the part of space the control
    /// points do not span). A way to start the iteration from points in space.
    pub fn lift(&self, x: DVec3) -> Vec<f64> {
        // Rows of A: the x, y, z coordinates of the control points and ones.
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|r| {
                self.control
                    .iter()
                    .map(|p| if r < 3 { p[r] } else { 1.0 })
                    .collect()
            })
            .collect();
        let mut g = [[0.0f64; 4]; 4];
        for (i, gi) in g.iter_mut().enumerate() {
            for (j, gij) in gi.iter_mut().enumerate() {
                *gij = rows[i].iter().zip(&rows[j]).map(|(a, b)| a * b).sum();
            }
        }
        let ridge = 1e-12 * (g[0][0] + g[1][1] + g[2][2] + g[3][3]);
        for (i, gi) in g.iter_mut().enumerate() {
            gi[i] += ridge;
        }
        let y = solve4(g, [x.x, x.y, x.z, 1.0]);
        let w: Vec<f64> = (0..self.m)
            .map(|j| (0..4).map(|r| rows[r][j] * y[r]).sum())
            .collect();
        self.affine(&w)
    }

    /// The fixed point of map `i` (its weights), by iterating `f_i`.
    pub fn fixed_point(&self, i: usize) -> Vec<f64> {
        let mut w = vec![1.0 / self.m as f64; self.m];
        let mut next = vec![0.0; self.m];
        for _ in 0..100_000 {
            row_times(&w, &self.maps[i], self.m, &mut next);
            let change = w
                .iter()
                .zip(&next)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            std::mem::swap(&mut w, &mut next);
            if change < 1e-17 {
                break;
            }
        }
        w
    }

    /// `k` rounds of `X ↦ f_0(X) ∪ … ∪ f_(n−1)(X)` from the start set
    /// (weights, each normalised with [`Ifs::affine`]). The result lists
    /// `f_(i1) ∘ … ∘ f_(ik)(x_s)` at index `((i1·n + i2)·n + … + ik)·|X| + s`:
    /// the outermost map is the most significant digit, which orders the
    /// points along a curve.
    pub fn iterate_set(&self, start: &[Vec<f64>], k: usize) -> Vec<Vec<f64>> {
        let mut set: Vec<Vec<f64>> = start.iter().map(|w| self.affine(w)).collect();
        for _ in 0..k {
            set = (0..self.map_count())
                .flat_map(|i| set.iter().map(move |w| (i, w)))
                .map(|(i, w)| self.apply(i, w))
                .collect();
        }
        set
    }

    /// The points of [`Ifs::iterate_set`] (same order and indices) without
    /// storing them: `visit(index, position)` is called in index order.
    /// Fails when there would be more than 2^28 points.
    pub fn for_each_point(
        &self,
        start: &[Vec<f64>],
        k: usize,
        mut visit: impl FnMut(usize, DVec3),
    ) -> Result<(), SurfaceError> {
        if let Some(w) = start.iter().find(|w| w.len() != self.m) {
            return Err(SurfaceError::Parameter(format!(
                "a start point has {} weights; this IFS has {} control points",
                w.len(),
                self.m
            )));
        }
        let n = self.map_count();
        let total = start.len() as f64 * (n as f64).powi(k.min(1000) as i32);
        if total > MAX_POINTS {
            return Err(SurfaceError::TooLarge {
                steps: k,
                estimate: total,
                what: "points",
            });
        }
        // Inner rounds (applied first) as a stored set; outer rounds as
        // matrix products T = S_(i_k1) ⋯ S_(i_1), walked depth first.
        let mut inner = 0;
        while inner < k && (start.len() * n.pow(inner as u32 + 1)) <= 4096 {
            inner += 1;
        }
        let set = self.iterate_set(start, inner);
        let outer = k - inner;
        // Q = S_(i_k1) ⋯ S_(i_1) P, the control points of the piece with that
        // address, carried down the tree (m² work per node).
        let mut stack = vec![self.control.clone()];
        self.walk_prefixes(outer, 0, &mut stack, &mut |prefix, q| {
            for (idx, u) in set.iter().enumerate() {
                let x: DVec3 = u.iter().zip(q).map(|(&a, &p)| a * p).sum();
                visit(prefix * set.len() + idx, x);
            }
        });
        Ok(())
    }

    fn walk_prefixes(
        &self,
        depth: usize,
        prefix: usize,
        stack: &mut Vec<Vec<DVec3>>,
        leaf: &mut impl FnMut(usize, &[DVec3]),
    ) {
        if depth == 0 {
            leaf(
                prefix,
                stack.last().expect("stack holds the control points"),
            );
            return;
        }
        for i in 0..self.map_count() {
            let q = stack.last().expect("stack holds the control points");
            let s = &self.maps[i];
            let next: Vec<DVec3> = (0..self.m)
                .map(|r| {
                    let row = &s[r * self.m..(r + 1) * self.m];
                    row.iter().zip(q).map(|(&a, &p)| a * p).sum()
                })
                .collect();
            stack.push(next);
            self.walk_prefixes(depth - 1, prefix * self.map_count() + i, stack, leaf);
            stack.pop();
        }
    }

    /// The chaos game: from `start`, apply a map chosen uniformly at random
    /// (seeded, reproducible) `skip + count` times and return the last
    /// `count` positions.
    pub fn chaos_game(&self, start: &[f64], count: usize, skip: usize, seed: u64) -> Vec<DVec3> {
        let mut rng = SplitMix64(seed);
        let mut w = self.affine(start);
        let mut next = vec![0.0; self.m];
        let mut out = Vec::with_capacity(count);
        for step in 0..skip + count {
            let i = (rng.next_f64() * self.map_count() as f64) as usize;
            row_times(
                &w,
                &self.maps[i.min(self.map_count() - 1)],
                self.m,
                &mut next,
            );
            std::mem::swap(&mut w, &mut next);
            if step >= skip {
                out.push(self.position(&w));
            }
        }
        out
    }

    /// A norm in which every map contracts (see the [module docs](self)),
    /// trying product lengths `1..=max_length`; `None` if none works or the
    /// search would exceed about 10^9 operations.
    pub fn contraction_certificate(&self, max_length: usize) -> Option<ContractionCertificate> {
        let n = self.map_count();
        let cost = (self.m as f64).powi(3);
        let mut products: Vec<Vec<f64>> = vec![];
        for length in 1..=max_length {
            if (n as f64).powi(length as i32) * cost > 1e9 {
                return None;
            }
            products = if products.is_empty() {
                self.maps.clone()
            } else {
                products
                    .iter()
                    .flat_map(|p| self.maps.iter().map(move |s| mat_mul(p, s, self.m)))
                    .collect()
            };
            let worst = products
                .iter()
                .map(|p| restricted_frobenius(p, self.m))
                .fold(0.0, f64::max);
            if worst < 1.0 {
                return Some(ContractionCertificate {
                    length,
                    factor: worst.powf(1.0 / length as f64),
                });
            }
        }
        None
    }
}

/// Points of the attractor of `kind` for these control points after
/// `iterations` rounds of every map, as polylines, starting from points on
/// the attractor (fixed points of the maps), so every point returned lies on
/// the limit curve or surface:
///
/// - curves (B-spline, four-point, Koch): one polyline through the limit
///   points at the `map_count^iterations + 1` uniform parameters;
/// - gasket: one closed triangle per piece (`3^iterations` polylines);
/// - bicubic: the `(2^k + 1)²` grid of patch points at uniform parameters,
///   as its rows and then its columns.
pub fn ifs_attractor(
    kind: IfsKind,
    control: &[DVec3],
    iterations: usize,
) -> Result<Vec<Vec<DVec3>>, SurfaceError> {
    let ifs = Ifs::new(kind, control)?;
    let n = ifs.map_count();
    let estimate = 4.0 * (n as f64).powi(iterations.min(1000) as i32);
    if estimate > MAX_STORED_POINTS {
        return Err(SurfaceError::TooLarge {
            steps: iterations,
            estimate,
            what: "points",
        });
    }
    match kind {
        IfsKind::CubicBSpline | IfsKind::FourPoint | IfsKind::Koch => {
            let ends = [ifs.fixed_point(0), ifs.fixed_point(n - 1)];
            let mut line = Vec::new();
            let mut last = DVec3::ZERO;
            ifs.for_each_point(&ends, iterations, |idx, x| {
                if idx % 2 == 0 {
                    line.push(x);
                } else {
                    last = x;
                }
            })?;
            line.push(last);
            Ok(vec![line])
        }
        IfsKind::Gasket => {
            let c: Vec<Vec<f64>> = (0..3).map(|i| ifs.fixed_point(i)).collect();
            let start = [c[0].clone(), c[1].clone(), c[2].clone(), c[0].clone()];
            let mut lines = Vec::new();
            ifs.for_each_point(&start, iterations, |idx, x| {
                if idx % 4 == 0 {
                    lines.push(Vec::with_capacity(4));
                }
                if let Some(l) = lines.last_mut() {
                    l.push(x);
                }
            })?;
            Ok(lines)
        }
        IfsKind::Bicubic { .. } => {
            // Map 2a + b has the patch corner (u, v) = (a, b) as fixed point.
            let corners: Vec<Vec<f64>> = (0..4).map(|i| ifs.fixed_point(i)).collect();
            let side = 1usize << iterations.min(30);
            let stride = side + 1;
            let mut grid = vec![DVec3::ZERO; stride * stride];
            ifs.for_each_point(&corners, iterations, |idx, x| {
                let (mut address, corner) = (idx / 4, idx % 4);
                let (mut u, mut v) = (corner >> 1, corner & 1);
                for bit in 0..iterations {
                    let digit = address % 4;
                    address /= 4;
                    u += (digit >> 1) << bit;
                    v += (digit & 1) << bit;
                }
                grid[u * stride + v] = x;
            })?;
            let rows = (0..stride).map(|u| grid[u * stride..(u + 1) * stride].to_vec());
            let cols = (0..stride).map(|v| (0..stride).map(|u| grid[u * stride + v]).collect());
            Ok(rows.chain(cols).collect())
        }
    }
}

// ---------------------------------------------------------------------------
// Subdivision matrices.

/// Global refinement of an open cubic B-spline polygon of `n` points:
/// `2n − 3` rows `e_0, v_1, e_1, …, v_(n−2), e_(n−2)` (edge and vertex rules).
fn bspline_refinement(n: usize) -> Vec<Vec<f64>> {
    let mut rows = Vec::with_capacity(2 * n - 3);
    for i in 0..n - 1 {
        let mut e = vec![0.0; n];
        e[i] = 0.5;
        e[i + 1] = 0.5;
        rows.push(e);
        if i + 2 < n {
            let mut v = vec![0.0; n];
            v[i] = 0.125;
            v[i + 1] = 0.75;
            v[i + 2] = 0.125;
            rows.push(v);
        }
    }
    rows
}

/// Global refinement of an open four-point polygon of `n` points: the `2n − 5`
/// rows `p_1, q_1, p_2, …, q_(n−3), p_(n−2)` where `q_i` is inserted between
/// `p_i` and `p_(i+1)`.
fn four_point_refinement(n: usize) -> Vec<Vec<f64>> {
    let mut rows = Vec::with_capacity(2 * n - 5);
    for i in 1..n - 2 {
        let mut p = vec![0.0; n];
        p[i] = 1.0;
        rows.push(p);
        let mut q = vec![0.0; n];
        q[i - 1] = -1.0 / 16.0;
        q[i] = 9.0 / 16.0;
        q[i + 1] = 9.0 / 16.0;
        q[i + 2] = -1.0 / 16.0;
        rows.push(q);
    }
    let mut last = vec![0.0; n];
    last[n - 2] = 1.0;
    rows.push(last);
    rows
}

/// Square blocks of `n` consecutive rows starting at each of `starts`.
fn split_rows(rows: &[Vec<f64>], n: usize, starts: &[usize]) -> Vec<Vec<f64>> {
    starts
        .iter()
        .map(|&s| rows[s..s + n].iter().flatten().copied().collect())
        .collect()
}

/// `A ⊗ B` for row-major square `A` (`na × na`) and `B` (`nb × nb`), acting on
/// row-major `na × nb` grids.
fn kronecker(a: &[f64], na: usize, b: &[f64], nb: usize) -> Vec<f64> {
    let m = na * nb;
    let mut out = vec![0.0; m * m];
    for r1 in 0..na {
        for r2 in 0..nb {
            for c1 in 0..na {
                for c2 in 0..nb {
                    out[(r1 * nb + r2) * m + c1 * nb + c2] = a[r1 * na + c1] * b[r2 * nb + c2];
                }
            }
        }
    }
    out
}

/// The paper's Koch matrices, in thirds.
const KOCH: [[[i8; 5]; 5]; 4] = [
    [
        [3, 0, 0, 0, 0],
        [2, 1, 0, 0, 0],
        [2, 0, 1, 0, 0],
        [1, 2, 0, 0, 0],
        [0, 3, 0, 0, 0],
    ],
    [
        [0, 3, 0, 0, 0],
        [0, 2, 1, 0, 0],
        [1, 0, 2, 0, 0],
        [0, 1, 2, 0, 0],
        [0, 0, 3, 0, 0],
    ],
    [
        [0, 0, 3, 0, 0],
        [0, 0, 2, 1, 0],
        [0, 0, 2, 0, 1],
        [0, 0, 1, 2, 0],
        [0, 0, 0, 3, 0],
    ],
    [
        [0, 0, 0, 3, 0],
        [0, 0, 0, 2, 1],
        [0, 0, 1, 0, 2],
        [0, 0, 0, 1, 2],
        [0, 0, 0, 0, 3],
    ],
];

/// The paper's gasket matrices, in eighths.
const GASKET: [[[i8; 6]; 6]; 3] = [
    [
        [8, 0, 0, 0, 0, 0],
        [3, 6, -1, 0, 0, 0],
        [0, 8, 0, 0, 0, 0],
        [0, 4, 0, 0, 0, 4],
        [0, 0, 0, 0, 0, 8],
        [3, 0, 0, 0, -1, 6],
    ],
    [
        [0, 8, 0, 0, 0, 0],
        [-1, 6, 3, 0, 0, 0],
        [0, 0, 8, 0, 0, 0],
        [0, 0, 3, 6, -1, 0],
        [0, 0, 0, 8, 0, 0],
        [0, 4, 0, 4, 0, 0],
    ],
    [
        [0, 0, 0, 0, 0, 8],
        [0, 0, 0, 4, 0, 4],
        [0, 0, 0, 8, 0, 0],
        [0, 0, -1, 6, 3, 0],
        [0, 0, 0, 0, 8, 0],
        [-1, 0, 0, 0, 3, 6],
    ],
];

fn thirds(s: &[[i8; 5]; 5]) -> Vec<f64> {
    s.iter().flatten().map(|&x| x as f64 / 3.0).collect()
}

fn eighths(s: &[[i8; 6]; 6]) -> Vec<f64> {
    s.iter().flatten().map(|&x| x as f64 / 8.0).collect()
}

#[cfg(test)]
mod tests;
