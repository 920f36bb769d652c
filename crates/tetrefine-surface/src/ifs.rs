//! Subdivision curves and surfaces as attractors of iterated function systems
//! (seed paper `003`: Schaefer, Levin and Goldman, "Subdivision schemes and
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

use super::error::SurfaceError;
use super::vtp;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::file::{write_atomic, IoError};

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

/// File formats for points and polylines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolylineFormat {
    /// VTK XML PolyData `.vtp` (ASCII), for ParaView.
    Vtp,
    /// Comma-separated values `.csv`.
    Csv,
}

impl PolylineFormat {
    /// The format of `path` from its extension.
    pub fn of(path: &Path) -> Result<PolylineFormat, IoError> {
        match super::io::lowercase_extension(path).as_str() {
            "vtp" => Ok(PolylineFormat::Vtp),
            "csv" => Ok(PolylineFormat::Csv),
            _ => Err(IoError::file(
                path,
                "points and polylines are written as .vtp or .csv",
            )),
        }
    }
}

/// Write polylines in the format of the extension of `path`
/// ([`write_polylines_vtp`] or [`write_polylines_csv`]).
pub fn write_polylines(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    match PolylineFormat::of(path)? {
        PolylineFormat::Vtp => write_polylines_vtp(path, polylines),
        PolylineFormat::Csv => write_polylines_csv(path, polylines),
    }
}

/// Write points as CSV (`x,y,z` header, one point a line).
pub fn write_points_csv(path: &Path, points: &[DVec3]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "x,y,z")?;
        for p in points {
            writeln!(w, "{},{},{}", p.x, p.y, p.z)?;
        }
        Ok(())
    })
}

/// Write polylines as CSV (`polyline,point,x,y,z` header, one point a line).
pub fn write_polylines_csv(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "polyline,point,x,y,z")?;
        for (l, line) in polylines.iter().enumerate() {
            for (i, p) in line.iter().enumerate() {
                writeln!(w, "{l},{i},{},{},{}", p.x, p.y, p.z)?;
            }
        }
        Ok(())
    })
}

/// Write points as VTK XML PolyData (`.vtp`, ASCII), one vertex cell each.
pub fn write_points_vtp(path: &Path, points: &[DVec3]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        vtp::write_header(w, points.len(), [points.len(), 0, 0])?;
        vtp::write_points(w, points.iter())?;
        vtp::write_cells(w, "Verts", (0..points.len() as u64).map(std::iter::once))?;
        vtp::write_footer(w)
    })
}

/// Write polylines as VTK XML PolyData (`.vtp`, ASCII) for ParaView:
/// polylines of two or more points become `Lines` cells, single points
/// `Verts` cells. Every polyline has its own points.
pub fn write_polylines_vtp(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    let total: usize = polylines.iter().map(Vec::len).sum();
    // Point ids of each polyline: consecutive, in polyline order.
    let mut first = Vec::with_capacity(polylines.len());
    let mut next = 0u64;
    for l in polylines {
        first.push(next);
        next += l.len() as u64;
    }
    let cells = |single: bool| {
        polylines
            .iter()
            .zip(&first)
            .filter(move |(l, _)| !l.is_empty() && (l.len() == 1) == single)
            .map(|(l, &f)| f..f + l.len() as u64)
    };
    write_atomic(path, |w| {
        vtp::write_header(w, total, [cells(true).count(), cells(false).count(), 0])?;
        vtp::write_points(w, polylines.iter().flatten())?;
        vtp::write_cells(w, "Verts", cells(true))?;
        vtp::write_cells(w, "Lines", cells(false))?;
        vtp::write_footer(w)
    })
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

// ---------------------------------------------------------------------------
// Small dense linear algebra.

/// `out = w A` for a row vector `w` and row-major `m × m` `A`.
fn row_times(w: &[f64], a: &[f64], m: usize, out: &mut [f64]) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for (r, &wr) in w.iter().take(m).enumerate() {
        if wr != 0.0 {
            for (o, &x) in out.iter_mut().zip(&a[r * m..(r + 1) * m]) {
                *o += wr * x;
            }
        }
    }
}

/// `A B` for row-major `m × m` matrices.
fn mat_mul(a: &[f64], b: &[f64], m: usize) -> Vec<f64> {
    let mut out = vec![0.0; m * m];
    for r in 0..m {
        row_times(&a[r * m..(r + 1) * m], b, m, &mut out[r * m..(r + 1) * m]);
    }
    out
}

/// Frobenius norm of `v ↦ v Π` restricted to `{Σ v = 0}`: with
/// `C = I − 11ᵀ/m` it is `‖C Π C‖_F`, and since `Π 1 = 1`,
/// `C Π C = Π − 1 · (column means of Π)`. Bounds the operator norm above.
fn restricted_frobenius(p: &[f64], m: usize) -> f64 {
    let means: Vec<f64> = (0..m)
        .map(|c| (0..m).map(|r| p[r * m + c]).sum::<f64>() / m as f64)
        .collect();
    let mut sum = 0.0;
    for r in 0..m {
        for c in 0..m {
            let x = p[r * m + c] - means[c];
            sum += x * x;
        }
    }
    sum.sqrt()
}

/// Solve the 4 × 4 system `g y = b` by Gaussian elimination with partial
/// pivoting (a zero pivot leaves that unknown at 0).
fn solve4(mut g: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| g[i][col].abs().total_cmp(&g[j][col].abs()))
            .unwrap_or(col);
        g.swap(col, pivot);
        b.swap(col, pivot);
        if g[col][col] == 0.0 {
            continue;
        }
        for r in col + 1..4 {
            let f = g[r][col] / g[col][col];
            let pivot_row = g[col];
            for (x, p) in g[r][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut y = [0.0; 4];
    for r in (0..4).rev() {
        if g[r][r] != 0.0 {
            let s: f64 = (r + 1..4).map(|c| g[r][c] * y[c]).sum();
            y[r] = (b[r] - s) / g[r][r];
        }
    }
    y
}

/// SplitMix64 (Steele, Lea and Flood): a small seeded generator for the chaos
/// game.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_weights(rng: &mut SplitMix64, m: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..m).map(|_| lo + (hi - lo) * rng.next_f64()).collect()
    }

    /// Uniform cubic B-spline curve in closed form, `t ∈ [0, n − 3]`
    /// (piece `j` uses `p_j … p_(j+3)`).
    fn bspline_curve(p: &[DVec3], t: f64) -> DVec3 {
        let j = (t.floor().max(0.0) as usize).min(p.len() - 4);
        let s = t - j as f64;
        let (s2, s3, r) = (s * s, s * s * s, 1.0 - s);
        let b0 = r * r * r / 6.0;
        let b1 = (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0;
        let b2 = (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0;
        let b3 = s3 / 6.0;
        b0 * p[j] + b1 * p[j + 1] + b2 * p[j + 2] + b3 * p[j + 3]
    }

    /// One round of the plain four-point rule on an open polygon whose points
    /// carry consecutive integer parameters (units of the current level):
    /// keeps `p_1 … p_(len−2)`, inserts `q_i` between `p_i` and `p_(i+1)`.
    fn four_point_round(p: &[DVec3], par: &[i64]) -> (Vec<DVec3>, Vec<i64>) {
        let mut out = Vec::with_capacity(2 * p.len());
        let mut op = Vec::with_capacity(2 * p.len());
        for i in 1..p.len() - 2 {
            out.push(p[i]);
            op.push(2 * par[i]);
            out.push((-p[i - 1] + 9.0 * p[i] + 9.0 * p[i + 1] - p[i + 2]) / 16.0);
            op.push(2 * par[i] + 1);
        }
        out.push(p[p.len() - 2]);
        op.push(2 * par[p.len() - 2]);
        (out, op)
    }

    /// Points of the plain four-point subdivision at `level`, parameters
    /// `lo ..= hi` (in units of 2^-level), refined from the level-`base` polygon
    /// by windows with three ghost points on each side.
    fn four_point_points(
        base: &(Vec<DVec3>, Vec<i64>),
        base_level: u32,
        level: u32,
        lo: i64,
        hi: i64,
    ) -> Vec<DVec3> {
        let window = |p: &[DVec3], par: &[i64], l: u32| {
            let scale = 1i64 << (level - l);
            let (a, b) = (
                lo.div_euclid(scale) - 3,
                (hi + scale - 1).div_euclid(scale) + 3,
            );
            let keep: Vec<usize> = (0..p.len())
                .filter(|&i| par[i] >= a && par[i] <= b)
                .collect();
            (
                keep.iter().map(|&i| p[i]).collect::<Vec<_>>(),
                keep.iter().map(|&i| par[i]).collect::<Vec<_>>(),
            )
        };
        let (mut p, mut par) = window(&base.0, &base.1, base_level);
        for l in base_level..level {
            let (np, npar) = four_point_round(&p, &par);
            (p, par) = window(&np, &npar, l + 1);
        }
        let out: Vec<DVec3> = (0..p.len())
            .filter(|&i| par[i] >= lo && par[i] <= hi)
            .map(|i| p[i])
            .collect();
        assert_eq!(out.len() as i64, hi - lo + 1, "reference window too small");
        out
    }

    /// Distance from `x` to the nearest entry of `seq` found by walking
    /// downhill from `guess`, then scanning ±`scan` around the walk's end:
    /// an upper bound on the distance to the set.
    fn local_min(seq: &[DVec3], guess: usize, x: DVec3, scan: usize) -> f64 {
        let mut i = guess.min(seq.len() - 1);
        let mut d = seq[i].distance_squared(x);
        loop {
            let left = if i > 0 {
                seq[i - 1].distance_squared(x)
            } else {
                f64::INFINITY
            };
            let right = seq
                .get(i + 1)
                .map_or(f64::INFINITY, |q| q.distance_squared(x));
            if left < d && left <= right {
                (i, d) = (i - 1, left);
            } else if right < d {
                (i, d) = (i + 1, right);
            } else {
                break;
            }
        }
        let (a, b) = (i.saturating_sub(scan), (i + scan + 1).min(seq.len()));
        seq[a..b]
            .iter()
            .map(|q| q.distance_squared(x))
            .fold(d, f64::min)
            .sqrt()
    }

    /// Upper bounds `(points → curve, curve samples → points)` for the points
    /// of `k` rounds of the IFS from `start`. `refs(lo, hi)` returns exact
    /// curve points at `r` uniform parameters per level-`k` piece over pieces
    /// `lo .. hi` (`(hi − lo) r + 1` points).
    fn hausdorff_sides(
        ifs: &Ifs,
        start: &[Vec<f64>],
        k: usize,
        r: usize,
        mut refs: impl FnMut(usize, usize) -> Vec<DVec3>,
    ) -> (f64, f64) {
        let s = start.len();
        let pieces = 1usize << k;
        let chunk = 1usize << 10;
        let margin = 2;
        let (mut side1, mut side2) = (0.0f64, 0.0f64);
        let mut buf = Vec::with_capacity(chunk * s);
        let mut process = |q: usize, leaves: &[DVec3]| {
            let first = q * chunk;
            let lo = first.saturating_sub(margin);
            let hi = (first + chunk + margin).min(pieces);
            let curve = refs(lo, hi);
            assert_eq!(curve.len(), (hi - lo) * r + 1);
            for (i, &x) in leaves.iter().enumerate() {
                let guess = (first + i / s - lo) * r + r / 2;
                side1 = side1.max(local_min(&curve, guess, x, 2));
            }
            let own = (first - lo) * r..=(first + chunk - lo) * r;
            for (j, &c) in curve
                .iter()
                .enumerate()
                .take(*own.end() + 1)
                .skip(*own.start())
            {
                let along = (j as f64 / r as f64 + lo as f64 - first as f64).max(0.0);
                let guess = (along * s as f64) as usize;
                side2 = side2.max(local_min(leaves, guess, c, 2 * s));
            }
        };
        ifs.for_each_point(start, k, |idx, x| {
            buf.push(x);
            if buf.len() == chunk * s {
                process(idx / (chunk * s), &buf);
                buf.clear();
            }
        })
        .expect("iterate");
        (side1, side2)
    }

    #[test]
    fn bspline_attractor_from_a_random_start_is_the_closed_form_curve() {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.6, 0.8, 0.2),
            DVec3::new(1.2, -0.3, 0.5),
            DVec3::new(1.9, 0.4, 0.0),
            DVec3::new(2.5, 0.0, 0.8),
        ];
        let ifs = Ifs::new(IfsKind::CubicBSpline, &p).expect("ifs");
        let mut rng = SplitMix64(7);
        let start = vec![
            random_weights(&mut rng, 5, -1.0, 2.0),
            random_weights(&mut rng, 5, -1.0, 2.0),
        ];
        let (k, r) = (22, 4);
        let span = (p.len() - 3) as f64;
        let (side1, side2) = hausdorff_sides(&ifs, &start, k, r, |lo, hi| {
            (0..=(hi - lo) * r)
                .map(|j| {
                    let t = span * (lo as f64 + j as f64 / r as f64) / (1u64 << k) as f64;
                    bspline_curve(&p, t)
                })
                .collect()
        });
        // Between two curve samples h apart in t, a curve point is within
        // M1·h of a sample, M1 = max |p_(j+1) − p_j| bounding |c'|.
        let m1 = p
            .windows(2)
            .map(|w| w[0].distance(w[1]))
            .fold(0.0, f64::max);
        let slack = m1 * span / (r as f64 * (1u64 << k) as f64);
        let hausdorff = side1.max(side2 + slack);
        assert!(
            hausdorff < 1e-6,
            "Hausdorff bound {hausdorff} ({side1}, {side2}, {slack})"
        );
    }

    #[test]
    fn four_point_attractor_from_a_random_start_is_the_subdivision_limit() {
        let p = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.8, 0.6, 0.1),
            DVec3::new(1.6, -0.2, 0.4),
            DVec3::new(2.4, 0.7, 0.0),
            DVec3::new(3.2, 0.1, 0.6),
            DVec3::new(4.0, 0.8, 0.2),
            DVec3::new(4.8, 0.0, 0.0),
        ];
        let ifs = Ifs::new(IfsKind::FourPoint, &p).expect("ifs");
        let mut rng = SplitMix64(11);
        let start = vec![
            random_weights(&mut rng, 7, -1.0, 2.0),
            random_weights(&mut rng, 7, -1.0, 2.0),
        ];
        // The attractor is the curve from p_2 to p_4; a level-k piece is 2^(1−k)
        // long in the polygon's parameter, so r = 4 samples per piece are the
        // plain subdivision points of level k + 1.
        let (k, r) = (22usize, 4usize);
        let level = k as u32 + 1;
        let base_level = 12;
        let mut base = (p.clone(), (0..p.len() as i64).collect::<Vec<_>>());
        for _ in 0..base_level {
            base = four_point_round(&base.0, &base.1);
        }
        let origin = 2i64 << level;
        let mut max_gap = 0.0f64;
        let (side1, side2) = hausdorff_sides(&ifs, &start, k, r, |lo, hi| {
            let pts = four_point_points(
                &base,
                base_level,
                level,
                origin + (r * lo) as i64,
                origin + (r * hi) as i64,
            );
            for w in pts.windows(2) {
                max_gap = max_gap.max(w[0].distance(w[1]));
            }
            pts
        });
        // Subdivision points are on the limit curve; the arc between two
        // neighbours is taken to stay within twice their distance.
        let hausdorff = side1.max(side2 + 2.0 * max_gap);
        assert!(
            hausdorff < 1e-6,
            "Hausdorff bound {hausdorff} ({side1}, {side2}, {max_gap})"
        );
    }

    #[test]
    fn attractor_polylines_are_the_limit_points() {
        // B-spline: the returned points are the closed form at t = j/2^k·(n−3).
        let p: Vec<DVec3> = (0..7)
            .map(|i| DVec3::new(i as f64, ((i * i) % 5) as f64 * 0.3, (i % 2) as f64))
            .collect();
        let k = 6;
        let line = &ifs_attractor(IfsKind::CubicBSpline, &p, k).expect("ok")[0];
        assert_eq!(line.len(), (1 << k) + 1);
        for (j, x) in line.iter().enumerate() {
            let t = 4.0 * j as f64 / (1 << k) as f64;
            assert!(x.distance(bspline_curve(&p, t)) < 1e-12, "t = {t}");
        }
        // Four-point: the attractor runs from p_2 to p_4 (two spans), so its
        // 2^k pieces are the spans of k − 1 plain subdivision rounds.
        let p = &p[..7];
        let line = &ifs_attractor(IfsKind::FourPoint, p, k).expect("ok")[0];
        let mut plain = (p.to_vec(), (0..p.len() as i64).collect::<Vec<_>>());
        for _ in 0..k - 1 {
            plain = four_point_round(&plain.0, &plain.1);
        }
        let want: Vec<DVec3> = (0..plain.0.len())
            .filter(|&i| plain.1[i] >= 2 << (k - 1) && plain.1[i] <= 4 << (k - 1))
            .map(|i| plain.0[i])
            .collect();
        assert_eq!(line.len(), want.len());
        for (a, b) in line.iter().zip(&want) {
            assert!(a.distance(*b) < 1e-12);
        }
    }

    #[test]
    fn maps_are_contractive() {
        let grid = |nu: usize, nv: usize| -> Vec<DVec3> {
            (0..nu * nv)
                .map(|i| {
                    let (u, v) = ((i / nv) as f64, (i % nv) as f64);
                    DVec3::new(u, v, (u * 0.7).sin() * (v * 0.5).cos())
                })
                .collect()
        };
        let curve: Vec<DVec3> = (0..9)
            .map(|i| DVec3::new(i as f64, (i as f64).sin(), 0.0))
            .collect();
        let cases: Vec<(IfsKind, Vec<DVec3>)> = vec![
            (IfsKind::CubicBSpline, curve[..5].to_vec()),
            (IfsKind::CubicBSpline, curve.clone()),
            (IfsKind::FourPoint, curve[..7].to_vec()),
            (IfsKind::FourPoint, curve.clone()),
            (IfsKind::Bicubic { nu: 4, nv: 4 }, grid(4, 4)),
            (IfsKind::Bicubic { nu: 5, nv: 4 }, grid(5, 4)),
            (IfsKind::Koch, koch_control().to_vec()),
            (IfsKind::Gasket, gasket_control().to_vec()),
        ];
        let mut rng = SplitMix64(3);
        for (kind, control) in cases {
            let ifs = Ifs::new(kind, &control).expect("ifs");
            let cert = ifs
                .contraction_certificate(8)
                .unwrap_or_else(|| panic!("{kind:?}: no certificate"));
            assert!(cert.factor < 1.0, "{kind:?}: {cert:?}");
            // The contraction inequality in the certificate's norm, on random
            // weight differences.
            for _ in 0..50 {
                let mut v = random_weights(&mut rng, ifs.dimension(), -1.0, 1.0);
                let mean = v.iter().sum::<f64>() / v.len() as f64;
                v.iter_mut().for_each(|x| *x -= mean);
                let before = cert.norm(&ifs, &v);
                for i in 0..ifs.map_count() {
                    let after = cert.norm(&ifs, &ifs.apply(i, &v));
                    assert!(
                        after <= cert.factor * before * (1.0 + 1e-12),
                        "{kind:?} map {i}"
                    );
                }
            }
        }
    }

    /// The affine maps of the plane that the IFS induces on positions (fitted
    /// on three control points, checked on all), and their singular values.
    fn plane_maps(ifs: &Ifs, fit: [usize; 3]) -> Vec<(f64, f64)> {
        let p = ifs.control();
        let (a, b, c) = (p[fit[0]], p[fit[1]], p[fit[2]]);
        let det = (b - a).x * (c - a).y - (b - a).y * (c - a).x;
        (0..ifs.map_count())
            .map(|i| {
                let q: Vec<DVec3> = (0..ifs.dimension())
                    .map(|j| {
                        let mut e = vec![0.0; ifs.dimension()];
                        e[j] = 1.0;
                        ifs.position(&ifs.apply(i, &e))
                    })
                    .collect();
                let (qa, qb, qc) = (q[fit[0]], q[fit[1]], q[fit[2]]);
                // Linear part M with M(b − a) = qb − qa, M(c − a) = qc − qa.
                let (u, v) = (b - a, c - a);
                let (du, dv) = (qb - qa, qc - qa);
                let m = [
                    [
                        (du.x * v.y - dv.x * u.y) / det,
                        (dv.x * u.x - du.x * v.x) / det,
                    ],
                    [
                        (du.y * v.y - dv.y * u.y) / det,
                        (dv.y * u.x - du.y * v.x) / det,
                    ],
                ];
                for (j, pj) in p.iter().enumerate() {
                    let d = *pj - a;
                    let image = qa
                        + DVec3::new(
                            m[0][0] * d.x + m[0][1] * d.y,
                            m[1][0] * d.x + m[1][1] * d.y,
                            0.0,
                        );
                    assert!(
                        image.distance(q[j]) < 1e-12,
                        "map {i} is not affine on the plane"
                    );
                }
                // Singular values of the 2 × 2 matrix.
                let (p2, q2) = (
                    m[0][0].powi(2) + m[0][1].powi(2) + m[1][0].powi(2) + m[1][1].powi(2),
                    (m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs(),
                );
                let root = (p2 * p2 - 4.0 * q2 * q2).max(0.0).sqrt();
                (((p2 + root) / 2.0).sqrt(), ((p2 - root) / 2.0).sqrt())
            })
            .collect()
    }

    /// Solve Σ r_i^D = 1 (Moran's equation) by bisection.
    fn similarity_dimension(ratios: &[f64]) -> f64 {
        let (mut lo, mut hi) = (0.0, 10.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if ratios.iter().map(|r| r.powf(mid)).sum::<f64>() > 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    #[test]
    fn koch_curve_endpoints_and_dimension() {
        let control = koch_control();
        let ifs = Ifs::new(IfsKind::Koch, &control).expect("ifs");
        let line = &ifs_attractor(IfsKind::Koch, &control, 5).expect("ok")[0];
        assert_eq!(line.len(), 4usize.pow(5) + 1);
        assert!(line[0].distance(DVec3::ZERO) < 1e-15);
        assert!(line.last().expect("points").distance(DVec3::X) < 1e-15);
        assert!(ifs.position(&ifs.fixed_point(0)).distance(DVec3::ZERO) < 1e-15);
        assert!(ifs.position(&ifs.fixed_point(3)).distance(DVec3::X) < 1e-15);
        let height = 3f64.sqrt() / 6.0;
        for x in line {
            assert!(x.x >= -1e-15 && x.x <= 1.0 + 1e-15 && x.y >= -1e-15 && x.y <= height + 1e-15);
        }
        // Each map is a similarity of ratio 1/3: dimension log 4 / log 3.
        let sv = plane_maps(&ifs, [0, 2, 4]);
        for &(a, b) in &sv {
            assert!((a - 1.0 / 3.0).abs() < 1e-12 && (b - 1.0 / 3.0).abs() < 1e-12);
        }
        let ratios: Vec<f64> = sv.iter().map(|s| s.0).collect();
        let d = similarity_dimension(&ratios);
        assert!((d - 4f64.ln() / 3f64.ln()).abs() < 1e-10, "{d}");
    }

    #[test]
    fn moving_a_koch_control_point_deforms_only_its_side() {
        let control = koch_control();
        let mut moved = control;
        moved[1] += DVec3::new(0.0, 0.1, 0.05);
        let a = Ifs::new(IfsKind::Koch, &control).expect("ifs");
        let b = Ifs::new(IfsKind::Koch, &moved).expect("ifs");
        let mut rng = SplitMix64(5);
        let start = vec![random_weights(&mut rng, 5, 0.0, 1.0)];
        let k = 5;
        let collect = |ifs: &Ifs| {
            let mut pts = Vec::new();
            ifs.for_each_point(&start, k, |_, x| pts.push(x))
                .expect("ok");
            pts
        };
        let (pa, pb) = (collect(&a), collect(&b));
        let quarter = 4usize.pow(k as u32 - 1);
        // Maps 3 and 4 use only P2, P3, P4: the right half is unchanged.
        assert_eq!(pa[2 * quarter..], pb[2 * quarter..]);
        assert!(pa[..2 * quarter]
            .iter()
            .zip(&pb[..2 * quarter])
            .any(|(x, y)| x != y));
    }

    #[test]
    fn gasket_points_lie_in_the_triangle() {
        let control = gasket_control();
        let ifs = Ifs::new(IfsKind::Gasket, &control).expect("ifs");
        let (c0, c1, c2) = (control[0], control[2], control[4]);
        // Distance outside the triangle (0 inside), for points in its plane.
        let outside = |x: DVec3| -> f64 {
            let edges = [(c0, c1), (c1, c2), (c2, c0)];
            let n = (c1 - c0).cross(c2 - c0).normalize();
            let inside = edges
                .iter()
                .all(|&(a, b)| (b - a).cross(x - a).dot(n) >= 0.0);
            if inside {
                return 0.0;
            }
            edges
                .iter()
                .map(|&(a, b)| {
                    let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    x.distance(a + t * (b - a))
                })
                .fold(f64::INFINITY, f64::min)
        };
        let mut rng = SplitMix64(9);
        let k = 9;
        // A start inside (convex weights) stays inside.
        let inside_start = vec![random_weights(&mut rng, 6, 0.0, 1.0)];
        ifs.for_each_point(&inside_start, k, |_, x| {
            assert!(outside(x) < 1e-14, "{x}");
        })
        .expect("ok");
        // A start far outside is pulled in at ratio 1/2 per round.
        let far = vec![ifs.lift(DVec3::new(-3.0, 4.0, 0.0))];
        let d0 = outside(ifs.position(&far[0]));
        assert!(d0 > 3.0);
        let bound = d0 / (1u64 << k) as f64 + 1e-14;
        ifs.for_each_point(&far, k, |_, x| assert!(outside(x) <= bound))
            .expect("ok");
        // Three similarities of ratio 1/2: dimension log 3 / log 2.
        let sv = plane_maps(&ifs, [0, 2, 4]);
        assert!(sv
            .iter()
            .all(|&(a, b)| (a - 0.5).abs() < 1e-12 && (b - 0.5).abs() < 1e-12));
        let d = similarity_dimension(&sv.iter().map(|s| s.0).collect::<Vec<_>>());
        assert!((d - 3f64.ln() / 2f64.ln()).abs() < 1e-10);
        // The polylines: 3^k closed triangles, all in the triangle.
        let lines = ifs_attractor(IfsKind::Gasket, &control, 4).expect("ok");
        assert_eq!(lines.len(), 81);
        assert!(lines.iter().all(|l| l.len() == 4 && l[0] == l[3]));
        assert!(lines.iter().flatten().all(|&x| outside(x) < 1e-14));
    }

    #[test]
    fn moved_gasket_edges_are_the_quadratics_through_their_control_points() {
        let mut control = gasket_control();
        control[1] += DVec3::new(0.05, -0.2, 0.1);
        control[3] += DVec3::new(0.1, 0.1, 0.0);
        let ifs = Ifs::new(IfsKind::Gasket, &control).expect("ifs");
        // All six control points lie on the attractor: corners are fixed
        // points, edge points images of corners.
        for (map, corner, edge) in [(0, 2, 1), (1, 4, 3), (2, 0, 5)] {
            let mut e = vec![0.0; 6];
            e[corner] = 1.0;
            assert!(ifs.position(&ifs.apply(map, &e)).distance(control[edge]) < 1e-15);
        }
        // Edge P0–P1–P2 is generated by maps 0 and 1 from P0: the points at
        // dyadic t are the quadratic through P0, P1, P2 at t = 0, 1/2, 1.
        let mut edge = ifs.clone();
        edge.maps.truncate(2);
        let k = 8;
        let mut e0 = vec![0.0; 6];
        e0[0] = 1.0;
        let (p0, p1, p2) = (control[0], control[1], control[2]);
        edge.for_each_point(&[e0], k, |idx, x| {
            let t = idx as f64 / (1u64 << k) as f64;
            let q = 2.0 * (t - 0.5) * (t - 1.0) * p0 - 4.0 * t * (t - 1.0) * p1
                + 2.0 * t * (t - 0.5) * p2;
            assert!(x.distance(q) < 1e-12, "t = {t}");
        })
        .expect("ok");
    }

    /// Uniform bicubic B-spline patch in closed form, `u ∈ [0, nu − 3]`,
    /// `v ∈ [0, nv − 3]`.
    fn bicubic_patch(p: &[DVec3], nu: usize, nv: usize, u: f64, v: f64) -> DVec3 {
        let rows: Vec<DVec3> = (0..nu)
            .map(|i| bspline_curve(&p[i * nv..(i + 1) * nv], v))
            .collect();
        bspline_curve(&rows, u)
    }

    #[test]
    fn bicubic_attractor_is_the_tensor_product_patch() {
        let (nu, nv) = (5, 6);
        let p: Vec<DVec3> = (0..nu * nv)
            .map(|i| {
                let (u, v) = ((i / nv) as f64, (i % nv) as f64);
                DVec3::new(u, v, 0.3 * (u * 1.3).sin() + 0.2 * (v * 0.9).cos())
            })
            .collect();
        let k = 4;
        let lines = ifs_attractor(IfsKind::Bicubic { nu, nv }, &p, k).expect("ok");
        let side = (1 << k) + 1;
        assert_eq!(lines.len(), 2 * side);
        for (i, row) in lines[..side].iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                let u = (nu - 3) as f64 * i as f64 / (side - 1) as f64;
                let v = (nv - 3) as f64 * j as f64 / (side - 1) as f64;
                assert!(x.distance(bicubic_patch(&p, nu, nv, u, v)) < 1e-12);
                assert_eq!(lines[side + j][i], *x);
            }
        }
        // From a random start the points approach the patch, about halving
        // the distance per round.
        let ifs = Ifs::new(IfsKind::Bicubic { nu, nv }, &p).expect("ifs");
        let mut rng = SplitMix64(13);
        let start = vec![random_weights(&mut rng, nu * nv, -1.0, 2.0)];
        let mut worst = Vec::new();
        for k in [3usize, 4, 5, 6] {
            let mut w = 0.0f64;
            let n = 1usize << k;
            ifs.for_each_point(&start, k, |idx, x| {
                let (mut a, mut u, mut v) = (idx, 0, 0);
                for bit in (0..k).rev() {
                    let digit = a % 4;
                    a /= 4;
                    let _ = bit;
                    u = (u >> 1) | ((digit >> 1) << (k - 1));
                    v = (v >> 1) | ((digit & 1) << (k - 1));
                }
                // Nearest of 13 × 13 samples on the piece and its neighbours.
                let mut best = f64::INFINITY;
                for su in 0..=12 {
                    for sv in 0..=12 {
                        let uu = (u as f64 - 1.0 + su as f64 / 4.0).clamp(0.0, n as f64) / n as f64;
                        let vv = (v as f64 - 1.0 + sv as f64 / 4.0).clamp(0.0, n as f64) / n as f64;
                        let q =
                            bicubic_patch(&p, nu, nv, uu * (nu - 3) as f64, vv * (nv - 3) as f64);
                        best = best.min(q.distance(x));
                    }
                }
                w = w.max(best);
            })
            .expect("ok");
            worst.push(w);
        }
        for w in worst.windows(2) {
            assert!(w[1] < 0.6 * w[0], "{worst:?}");
        }
        assert!(worst[3] < 0.1, "{worst:?}");
    }

    #[test]
    fn chaos_game_points_lie_on_the_curve() {
        let p: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, (i as f64 * 1.7).sin(), (i as f64 * 0.4).cos()))
            .collect();
        let ifs = Ifs::new(IfsKind::CubicBSpline, &p).expect("ifs");
        let mut rng = SplitMix64(21);
        let start = random_weights(&mut rng, 6, -1.0, 2.0);
        let pts = ifs.chaos_game(&start, 2000, 100, 42);
        assert_eq!(pts, ifs.chaos_game(&start, 2000, 100, 42), "seeded");
        let samples: Vec<DVec3> = (0..=3000)
            .map(|j| bspline_curve(&p, 3.0 * j as f64 / 3000.0))
            .collect();
        for x in &pts {
            let j = (0..samples.len())
                .min_by(|&a, &b| samples[a].distance(*x).total_cmp(&samples[b].distance(*x)))
                .expect("samples");
            // Ternary search around the nearest sample.
            let (mut a, mut b) = (
                (j as f64 - 1.0).max(0.0) / 1000.0,
                (j as f64 + 1.0).min(3000.0) / 1000.0,
            );
            for _ in 0..200 {
                let (m1, m2) = (a + (b - a) / 3.0, b - (b - a) / 3.0);
                if bspline_curve(&p, m1).distance(*x) < bspline_curve(&p, m2).distance(*x) {
                    b = m2;
                } else {
                    a = m1;
                }
            }
            let d = bspline_curve(&p, 0.5 * (a + b)).distance(*x);
            assert!(d < 1e-9, "{x} is {d} from the curve");
        }
    }

    #[test]
    fn lift_gives_weights_of_the_point() {
        let p: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(i as f64, (i * i % 4) as f64, (i % 3) as f64))
            .collect();
        let ifs = Ifs::new(IfsKind::CubicBSpline, &p).expect("ifs");
        let x = DVec3::new(0.3, -2.0, 5.0);
        let w = ifs.lift(x);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(ifs.position(&w).distance(x) < 1e-8);
        // Planar control points: points in their plane are reproduced.
        let koch = Ifs::new(IfsKind::Koch, &koch_control()).expect("ifs");
        let y = DVec3::new(0.25, 0.7, 0.0);
        assert!(koch.position(&koch.lift(y)).distance(y) < 1e-8);
    }

    #[test]
    fn writers_produce_files_that_readers_accept() {
        let dir = tempfile::tempdir().expect("tempdir");
        let lines = vec![
            vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.5, 0.25)],
            vec![DVec3::new(2.0, 0.0, 0.0)],
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        ];
        let vtp = dir.path().join("curve.vtp");
        write_polylines_vtp(&vtp, &lines).expect("write vtp");
        let vtk = vtkio::Vtk::import(&vtp).expect("vtkio reads the file");
        let piece = match vtk.data {
            vtkio::model::DataSet::PolyData { pieces, .. } => match pieces.into_iter().next() {
                Some(vtkio::model::Piece::Inline(p)) => *p,
                _ => panic!("inline piece expected"),
            },
            _ => panic!("PolyData expected"),
        };
        assert_eq!(piece.num_points(), 7);
        let cells = |v: Option<vtkio::model::VertexNumbers>| -> (Vec<u64>, Vec<u64>) {
            match v.expect("cells") {
                vtkio::model::VertexNumbers::XML {
                    connectivity,
                    offsets,
                } => (connectivity, offsets),
                other => panic!("XML cells expected, got {other:?}"),
            }
        };
        assert_eq!(cells(piece.verts), (vec![2], vec![1]));
        assert_eq!(cells(piece.lines), (vec![0, 1, 3, 4, 5, 6], vec![2, 6]));
        let coords: Vec<f64> = piece.points.cast_into().expect("f64 points");
        assert_eq!(&coords[3..6], &[1.0, 0.5, 0.25]);

        let csv = dir.path().join("curve.csv");
        write_polylines_csv(&csv, &lines).expect("write csv");
        let text = std::fs::read_to_string(&csv).expect("read");
        let rows: Vec<&str> = text.lines().collect();
        assert_eq!(rows.len(), 8);
        assert_eq!(rows[0], "polyline,point,x,y,z");
        assert_eq!(rows[2], "0,1,1,0.5,0.25");
        let pts = dir.path().join("points.csv");
        write_points_csv(&pts, &lines[2]).expect("write");
        assert_eq!(
            std::fs::read_to_string(&pts).expect("read").lines().count(),
            5
        );
        let pvtp = dir.path().join("points.vtp");
        write_points_vtp(&pvtp, &lines[2]).expect("write");
        assert!(vtkio::Vtk::import(&pvtp).is_ok());

        // A directory that does not exist: an error naming the file, no output.
        let bad = dir.path().join("missing").join("x.vtp");
        let err = write_polylines_vtp(&bad, &lines).unwrap_err();
        assert_eq!(err.path, bad);
        assert!(!bad.exists());
    }

    #[test]
    fn bad_control_points_are_refused() {
        let four = vec![DVec3::ZERO; 4];
        assert!(matches!(
            Ifs::new(IfsKind::FourPoint, &four),
            Err(SurfaceError::Parameter(_))
        ));
        assert!(matches!(
            Ifs::new(IfsKind::Koch, &four),
            Err(SurfaceError::Parameter(_))
        ));
        assert!(matches!(
            Ifs::new(IfsKind::Bicubic { nu: 4, nv: 4 }, &four),
            Err(SurfaceError::Parameter(_))
        ));
        assert!(matches!(
            Ifs::new(
                IfsKind::CubicBSpline,
                &[DVec3::ZERO, DVec3::X, DVec3::NAN, DVec3::Y]
            ),
            Err(SurfaceError::NonFinite { vertex: 2 })
        ));
        assert!(matches!(
            ifs_attractor(IfsKind::Koch, &koch_control(), 40),
            Err(SurfaceError::TooLarge { .. })
        ));
        let koch = Ifs::new(IfsKind::Koch, &koch_control()).expect("ifs");
        assert!(matches!(
            koch.for_each_point(&[vec![1.0; 3]], 2, |_, _| {}),
            Err(SurfaceError::Parameter(_))
        ));
        assert_eq!(koch.apply(0, &[1.0; 9]), koch.apply(0, &[1.0; 5]));
        let msg = Ifs::new(IfsKind::FourPoint, &four).unwrap_err().to_string();
        assert_eq!(msg, "FourPoint needs at least 6 control points, got 4");
    }
}
