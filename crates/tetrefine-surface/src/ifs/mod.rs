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
//! - [`IfsKind::ClampedCubicBSpline`]: the cubic B-spline with knots of
//!   multiplicity 4 at both ends (`0,0,0,0,1,…,L,L,L,L`, `L = n − 3`), which
//!   starts at the first and ends at the last control point (the paper's
//!   §2.1 example is `n = 5`). Its maps are the two halves by knot insertion
//!   (every half-integer once, the midpoint `L/2` up to multiplicity 3):
//!   each half is again a clamped spline with `L` uniform spans. Two maps.
//! - [`IfsKind::Bezier`]: the Bézier curve of degree `n − 1` (`n ≥ 2`) as the
//!   union of its two halves by de Casteljau's split at `t = 1/2` (Goldman;
//!   the paper's §2.2). Two maps.
//! - [`IfsKind::Loop`]: the regular (valence 6) Loop surface (three-direction
//!   quartic box spline) over one triangle of a triangular net, 12 control
//!   points (see [`triangle_net`]); four maps: the corner sub-triangles at
//!   the triangle's vertices 0, 1, 2 and the centre (paper §3.2).
//! - [`IfsKind::Sqrt3`]: the regular Kobbelt √3 surface over one triangle,
//!   the 27 control points within lattice distance 2 (see [`triangle_net`]);
//!   one map per sub-triangle of two √3 steps, which together split the
//!   triangle into thirds: nine maps (paper §3.3; see [`triangle_net`] for
//!   their order).
//!
//! ## Subsets and start sets
//!
//! Keeping only some maps ([`Ifs::subset`], `--maps` in the CLI) gives a
//! fractal that lies on the curve or surface: if `G ⊂ F` then the attractor of
//! `G` is a subset of the attractor of `F` (paper §3.3, figure 9). After `k`
//! levels with `q` kept maps there are `q^k` pieces. Iterating the maps on
//! any compact start set converges to the attractor; [`ifs_shape`] starts
//! from points on the attractor (exact limit points) or from a point, a
//! segment, a triangle or a mesh ([`IfsStart`]).

mod lattice;
mod linalg;

use super::error::SurfaceError;
use super::polymesh::PolyMesh;
use glam::DVec3;
use linalg::{mat_mul, restricted_frobenius, row_times, solve4};
use std::collections::HashMap;
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
    /// End-interpolating cubic B-spline curve (knots of multiplicity 4 at the
    /// ends; at least 4 control points).
    ClampedCubicBSpline,
    /// Bézier curve of degree `n − 1` (at least 2 control points).
    Bezier,
    /// Regular Loop surface over one triangle (exactly 12 control points in
    /// the order of [`triangle_net`]).
    Loop,
    /// Regular √3 surface over one triangle (exactly 27 control points in the
    /// order of [`triangle_net`]).
    Sqrt3,
}

impl IfsKind {
    /// Whether the attractor is a surface over a triangle or a square
    /// (Loop, √3, bicubic), written as a triangle mesh.
    pub fn is_surface(self) -> bool {
        matches!(
            self,
            IfsKind::Loop | IfsKind::Sqrt3 | IfsKind::Bicubic { .. }
        )
    }

    /// Whether the attractor is a curve whose maps follow each other along
    /// it (map `i + 1`'s piece starts where map `i`'s ends).
    pub fn is_curve(self) -> bool {
        matches!(
            self,
            IfsKind::CubicBSpline
                | IfsKind::FourPoint
                | IfsKind::Koch
                | IfsKind::ClampedCubicBSpline
                | IfsKind::Bezier
        )
    }
}

/// Lattice distance of the √3 control net from its triangle.
const SQRT3_NET_RADIUS: i64 = 2;

/// The control net of [`IfsKind::Loop`] and [`IfsKind::Sqrt3`] as lattice
/// points `(i, j)`, in the order the control points are expected: the point
/// `(i, j)` of a regular triangular net is the one at `i e1 + j e2` with
/// `e1 = (1, 0)`, `e2 = (1/2, √3/2)` in the plane of the net (any affine
/// image of the lattice, or any surface net with this connectivity, works).
/// The first three are the patch triangle `(0,0), (1,0), (0,1)`; then every
/// lattice point within distance 1 (Loop: the 12-point net of the regular
/// box-spline patch) or 2 (√3, 27 points) of it, by distance, then by `j`,
/// then by `i`. `None` for the other kinds. (√3 needs the larger net: after
/// two steps a corner sub-triangle's 12-point net holds centroids of
/// neighbouring coarse triangles, whose rules reach distance 2.)
///
/// Map order: Loop — corner sub-triangles at vertices 0, 1, 2, then the
/// centre. √3 (two steps, a split into thirds) — the corners at vertices 0,
/// 1, 2; the upward triangles on the middle thirds of the edges 0–1, 1–2,
/// 2–0; the three downward triangles nearest vertex 0, 1, 2.
pub fn triangle_net(kind: IfsKind) -> Option<Vec<[i64; 2]>> {
    match kind {
        IfsKind::Loop => Some(lattice::net(1)),
        IfsKind::Sqrt3 => Some(lattice::net(SQRT3_NET_RADIUS)),
        _ => None,
    }
}

/// The regular planar net of [`triangle_net`] with unit edges in the plane
/// `z = 0` (the patch triangle is `(0,0), (1,0), (1/2, √3/2)`).
pub fn regular_net(kind: IfsKind) -> Option<Vec<DVec3>> {
    let h = 3f64.sqrt() / 2.0;
    triangle_net(kind).map(|net| {
        net.iter()
            .map(|&[i, j]| DVec3::new(i as f64 + 0.5 * j as f64, h * j as f64, 0.0))
            .collect()
    })
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
    /// The index of each map in the scheme's full list (see [`Ifs::subset`]).
    labels: Vec<usize>,
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
            IfsKind::ClampedCubicBSpline => {
                need(n >= 4, "at least 4")?;
                clamped_halves(n)
            }
            IfsKind::Bezier => {
                need(n >= 2, "at least 2")?;
                bezier_halves(n)
            }
            IfsKind::Loop | IfsKind::Sqrt3 => {
                let net = triangle_net(kind).unwrap_or_default();
                need(
                    n == net.len(),
                    if kind == IfsKind::Loop {
                        "exactly 12"
                    } else {
                        "exactly 27"
                    },
                )?;
                let built = if kind == IfsKind::Loop {
                    lattice::lattice_maps(&net, &lattice::LOOP_SUBS, lattice::loop_fine)
                } else {
                    lattice::lattice_maps(&net, &lattice::SQRT3_SUBS, lattice::sqrt3_fine)
                };
                built.map_err(|p| {
                    SurfaceError::Parameter(format!(
                        "internal: the {kind:?} rules need lattice point {p:?} outside the net"
                    ))
                })?
            }
        };
        Ok(Ifs {
            kind,
            control: control.to_vec(),
            m: n,
            labels: (0..maps.len()).collect(),
            maps,
        })
    }

    /// The IFS of the maps `keep` only (indices into this IFS's maps; any
    /// order, each at most once, at least one). Its attractor is a subset of
    /// this one's: a fractal on the curve or surface. The kept maps are in
    /// increasing order of their original index.
    pub fn subset(&self, keep: &[usize]) -> Result<Ifs, SurfaceError> {
        let n = self.map_count();
        if keep.is_empty() {
            return Err(SurfaceError::Parameter("keep at least one map".into()));
        }
        let mut sorted = keep.to_vec();
        sorted.sort_unstable();
        if let Some(&bad) = sorted.iter().find(|&&i| i >= n) {
            return Err(SurfaceError::Parameter(format!(
                "map {bad} does not exist: {:?} has maps 0 to {}",
                self.kind,
                n - 1
            )));
        }
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(SurfaceError::Parameter(format!(
                "map {} is given twice",
                w[0]
            )));
        }
        Ok(Ifs {
            kind: self.kind,
            control: self.control.clone(),
            m: self.m,
            maps: sorted.iter().map(|&i| self.maps[i].clone()).collect(),
            labels: sorted.iter().map(|&i| self.labels[i]).collect(),
        })
    }

    /// The index in the scheme's full list of each map (`0..map_count()`
    /// unless this IFS is a [`Ifs::subset`]).
    pub fn labels(&self) -> &[usize] {
        &self.labels
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
///   as its rows and then its columns;
/// - Loop and √3: the triangles of [`ifs_shape`]'s mesh as closed polylines.
///
/// [`ifs_shape`] gives surfaces as triangle meshes, map subsets and other
/// start sets.
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
        IfsKind::Loop | IfsKind::Sqrt3 => {
            match ifs_shape(kind, control, iterations, &IfsOptions::default())? {
                IfsShape::Surface(mesh) => Ok(mesh
                    .faces
                    .iter()
                    .map(|f| {
                        let mut l: Vec<DVec3> =
                            f.iter().map(|&v| mesh.points[v as usize]).collect();
                        l.push(mesh.points[f[0] as usize]);
                        l
                    })
                    .collect()),
                _ => Ok(Vec::new()),
            }
        }
        IfsKind::CubicBSpline
        | IfsKind::FourPoint
        | IfsKind::Koch
        | IfsKind::ClampedCubicBSpline
        | IfsKind::Bezier => {
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

/// The initial set the maps are applied to (see [`ifs_shape`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum IfsStart {
    /// Points on the attractor: the fixed points of the maps at the ends of
    /// a curve or the corners of a surface patch (or gasket), so every point
    /// written is a limit point. Curves become polylines, surfaces triangle
    /// meshes over the parameter grid (shared vertices).
    #[default]
    Attractor,
    /// The first control point: `q^k` points.
    Point,
    /// The segment from the first to the last control point: `q^k`
    /// two-point polylines.
    Segment,
    /// The triangle of the first, the middle (`⌊n/2⌋`) and the last control
    /// point: `q^k` triangles (a triangle soup).
    Triangle,
    /// Any mesh (its points lifted to weights with [`Ifs::lift`]): `q^k`
    /// copies of it; without faces, `q^k` copies of its points.
    Mesh(PolyMesh),
}

/// Options of [`ifs_shape`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IfsOptions {
    /// Keep only these maps (see [`Ifs::subset`]); `None` keeps all.
    pub maps: Option<Vec<usize>>,
    /// The start set.
    pub start: IfsStart,
}

/// What [`ifs_shape`] makes.
#[derive(Clone, Debug, PartialEq)]
pub enum IfsShape {
    /// A point set.
    Points(Vec<DVec3>),
    /// Polylines (curves, segments, gasket triangles).
    Polylines(Vec<Vec<DVec3>>),
    /// A surface mesh (triangles).
    Surface(PolyMesh),
}

/// The attractor of `kind` for these control points after `iterations`
/// rounds of the (kept) maps applied to the start set:
///
/// - [`IfsStart::Attractor`]: curves as polylines through the limit points at
///   the piece ends (one polyline per run of adjacent pieces; with every map
///   kept, one polyline of `2^k + 1` points, `4^k + 1` for Koch); the gasket as
///   `q^k` closed triangles; Loop, √3 and bicubic as triangle meshes whose
///   vertices are the limit points at the corners of the `q^k` pieces,
///   shared between pieces: with every map kept, Loop has
///   `(2^k + 1)(2^k + 2)/2` vertices and `4^k` triangles, √3
///   `(3^k + 1)(3^k + 2)/2` and `9^k`, bicubic `(2^k + 1)²` and `2·4^k`;
/// - the other starts: `q^k` images of the start set (see [`IfsStart`]).
pub fn ifs_shape(
    kind: IfsKind,
    control: &[DVec3],
    iterations: usize,
    options: &IfsOptions,
) -> Result<IfsShape, SurfaceError> {
    let full = Ifs::new(kind, control)?;
    let ifs = match &options.maps {
        Some(keep) => full.subset(keep)?,
        None => full.clone(),
    };
    let n = control.len();
    let unit = |j: usize| -> Vec<f64> { (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect() };
    let (start, faces): (Vec<Vec<f64>>, Vec<Vec<u32>>) = match &options.start {
        IfsStart::Attractor => return attractor_shape(&full, &ifs, iterations),
        IfsStart::Point => (vec![unit(0)], vec![]),
        IfsStart::Segment => (vec![unit(0), unit(n - 1)], vec![]),
        IfsStart::Triangle => (vec![unit(0), unit(n / 2), unit(n - 1)], vec![vec![0, 1, 2]]),
        IfsStart::Mesh(mesh) => {
            if mesh.points.is_empty() {
                return Err(SurfaceError::Parameter(
                    "the start mesh has no points".into(),
                ));
            }
            if let Some(i) = mesh.points.iter().position(|p| !p.is_finite()) {
                return Err(SurfaceError::NonFinite { vertex: i });
            }
            for (f, face) in mesh.faces.iter().enumerate() {
                if let Some(&v) = face.iter().find(|&&v| v as usize >= mesh.points.len()) {
                    return Err(SurfaceError::VertexOutOfRange {
                        face: f,
                        vertex: v,
                        count: mesh.points.len(),
                    });
                }
            }
            (
                mesh.points.iter().map(|&x| ifs.lift(x)).collect(),
                mesh.faces.clone(),
            )
        }
    };
    check_size(&ifs, start.len(), iterations)?;
    let mut points = Vec::new();
    ifs.for_each_point(&start, iterations, |_, x| points.push(x))?;
    let s = start.len();
    Ok(match &options.start {
        IfsStart::Segment => IfsShape::Polylines(points.chunks(2).map(|c| c.to_vec()).collect()),
        _ if faces.is_empty() => IfsShape::Points(points),
        _ => {
            let pieces = points.len() / s;
            let mut all = Vec::with_capacity(pieces * faces.len());
            for p in 0..pieces {
                let base = (p * s) as u32;
                all.extend(faces.iter().map(|f| f.iter().map(|&v| v + base).collect()));
            }
            IfsShape::Surface(PolyMesh::new(points, all))
        }
    })
}

/// Refuses runs that would store more than [`MAX_STORED_POINTS`] points.
fn check_size(ifs: &Ifs, start: usize, iterations: usize) -> Result<(), SurfaceError> {
    let estimate = start as f64 * (ifs.map_count() as f64).powi(iterations.min(1000) as i32);
    if estimate > MAX_STORED_POINTS {
        return Err(SurfaceError::TooLarge {
            steps: iterations,
            estimate,
            what: "points",
        });
    }
    Ok(())
}

/// The parameter-space action of a map of a surface scheme:
/// `x ↦ (sign·x + shift)/scale` on integer lattice (or grid) coordinates.
#[derive(Clone, Copy)]
struct ParamMap {
    sign: i64,
    shift: [i64; 2],
}

/// The parameter domain of a surface scheme.
struct SurfaceLayout {
    /// Corners of the domain (integer coordinates).
    corners: Vec<[i64; 2]>,
    /// The map whose fixed point each corner is.
    fixing: Vec<usize>,
    /// The triangles of one piece, over the corners.
    tris: Vec<[usize; 3]>,
    /// The maps' common scale factor.
    scale: i64,
    /// Each map in parameters.
    params: Vec<ParamMap>,
}

/// [`IfsStart::Attractor`] for `ifs`, a subset of `full`.
fn attractor_shape(full: &Ifs, ifs: &Ifs, k: usize) -> Result<IfsShape, SurfaceError> {
    let nfull = full.map_count();
    let labels = ifs.labels();
    match full.kind() {
        IfsKind::Gasket => {
            check_size(ifs, 4, k)?;
            let c: Vec<Vec<f64>> = (0..3).map(|i| full.fixed_point(i)).collect();
            let start = [c[0].clone(), c[1].clone(), c[2].clone(), c[0].clone()];
            let mut lines: Vec<Vec<DVec3>> = Vec::new();
            ifs.for_each_point(&start, k, |idx, x| {
                if idx % 4 == 0 {
                    lines.push(Vec::with_capacity(4));
                }
                if let Some(l) = lines.last_mut() {
                    l.push(x);
                }
            })?;
            Ok(IfsShape::Polylines(lines))
        }
        kind if kind.is_curve() => {
            check_size(ifs, 2, k)?;
            let m = full.dimension();
            let ends = if matches!(kind, IfsKind::ClampedCubicBSpline | IfsKind::Bezier) {
                // These curves interpolate their end control points: the
                // fixed points are exactly the unit weights.
                let unit = |j: usize| (0..m).map(|i| f64::from(u8::from(i == j))).collect();
                [unit(0), unit(m - 1)]
            } else {
                [full.fixed_point(0), full.fixed_point(nfull - 1)]
            };
            let q = ifs.map_count();
            let mut lines: Vec<Vec<DVec3>> = Vec::new();
            let mut previous: Option<u128> = None;
            let mut first = DVec3::ZERO;
            ifs.for_each_point(&ends, k, |idx, x| {
                if idx % 2 == 0 {
                    first = x;
                    return;
                }
                // The piece's index among all nfull^k pieces, in curve order.
                let mut piece = idx / 2;
                let mut place = 1u128;
                let mut index = 0u128;
                for _ in 0..k {
                    index += labels[piece % q] as u128 * place;
                    place *= nfull as u128;
                    piece /= q;
                }
                match (previous, lines.last_mut()) {
                    (Some(p), Some(l)) if p + 1 == index => l.push(x),
                    _ => lines.push(vec![first, x]),
                }
                previous = Some(index);
            })?;
            Ok(IfsShape::Polylines(lines))
        }
        kind => {
            // Surfaces: corners of the parameter domain with their fixed
            // points, the triangles of one piece, the maps in parameters.
            let SurfaceLayout {
                corners,
                fixing,
                tris,
                scale,
                params,
            } = match kind {
                IfsKind::Loop | IfsKind::Sqrt3 => {
                    // Maps 0, 1, 2 are the corner sub-triangles, fixing the
                    // corners 0, 1, 2.
                    let (subs, scale): (&[lattice::SubTriangle], i64) = if kind == IfsKind::Loop {
                        (&lattice::LOOP_SUBS, 2)
                    } else {
                        (&lattice::SQRT3_SUBS, 3)
                    };
                    SurfaceLayout {
                        corners: lattice::CORNERS.to_vec(),
                        fixing: vec![0, 1, 2],
                        tris: vec![[0, 1, 2]],
                        scale,
                        params: subs
                            .iter()
                            .map(|s| ParamMap {
                                sign: s.sign,
                                shift: s.shift,
                            })
                            .collect(),
                    }
                }
                // Bicubic: (u, v) with map 2a + b ↦ ((u + a)/2, (v + b)/2).
                _ => SurfaceLayout {
                    corners: vec![[0, 0], [1, 0], [1, 1], [0, 1]],
                    fixing: vec![0, 2, 3, 1],
                    tris: vec![[0, 1, 2], [0, 2, 3]],
                    scale: 2,
                    params: (0..4)
                        .map(|i| ParamMap {
                            sign: 1,
                            shift: [(i >> 1) as i64, (i & 1) as i64],
                        })
                        .collect(),
                },
            };
            check_size(ifs, corners.len(), k)?;
            if k > 30 {
                return Err(SurfaceError::TooLarge {
                    steps: k,
                    estimate: (ifs.map_count() as f64).powi(k.min(1000) as i32),
                    what: "faces",
                });
            }
            let start: Vec<Vec<f64>> = fixing.iter().map(|&i| full.fixed_point(i)).collect();
            let c = corners.len();
            let q = ifs.map_count();
            let mut index: HashMap<[i64; 2], u32> = HashMap::new();
            let mut points = Vec::new();
            let mut faces = Vec::new();
            let mut piece_vertices = vec![0u32; c];
            let powers: Vec<i64> = (0..k).map(|j| scale.pow(j as u32)).collect();
            ifs.for_each_point(&start, k, |idx, x| {
                let (piece, corner) = (idx / c, idx % c);
                // Digits of the piece, innermost map (least significant) first.
                let mut y = corners[corner];
                let mut rest = piece;
                for power in &powers {
                    let pm = params[labels[rest % q]];
                    rest /= q;
                    y = [
                        pm.sign * y[0] + pm.shift[0] * power,
                        pm.sign * y[1] + pm.shift[1] * power,
                    ];
                }
                let v = *index.entry(y).or_insert_with(|| {
                    points.push(x);
                    (points.len() - 1) as u32
                });
                piece_vertices[corner] = v;
                if corner + 1 == c {
                    faces.extend(
                        tris.iter()
                            .map(|t| t.iter().map(|&i| piece_vertices[i]).collect::<Vec<u32>>()),
                    );
                }
            })?;
            Ok(IfsShape::Surface(PolyMesh::new(points, faces)))
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

/// Inserts knot `t` into the cubic B-spline with knot vector `knots` (full,
/// `rows.len() + 4` entries) and control rows `rows` (Boehm's algorithm).
fn insert_knot(knots: &mut Vec<f64>, rows: &mut Vec<Vec<f64>>, t: f64) {
    let k = knots
        .iter()
        .rposition(|&u| u <= t)
        .unwrap_or(0)
        .min(rows.len() - 1);
    let mut out = Vec::with_capacity(rows.len() + 1);
    for i in 0..=rows.len() {
        if i + 3 <= k {
            out.push(rows[i].clone());
        } else if i > k {
            out.push(rows[i - 1].clone());
        } else {
            let a = (t - knots[i]) / (knots[i + 3] - knots[i]);
            out.push(
                rows[i - 1]
                    .iter()
                    .zip(&rows[i])
                    .map(|(p, q)| (1.0 - a) * p + a * q)
                    .collect(),
            );
        }
    }
    knots.insert(k + 1, t);
    *rows = out;
}

/// The two maps of the clamped cubic B-spline of `n` control points (knots
/// `0,0,0,0,1,…,L,L,L,L`, `L = n − 3`): insert every half-integer once and
/// `L/2` up to multiplicity 3, so the curve splits at `L/2` into two clamped
/// splines of `L` spans each; their `n` control points are the first and the
/// last `n` of the `2n − 1` refined ones.
fn clamped_halves(n: usize) -> Vec<Vec<f64>> {
    let l = (n - 3) as f64;
    let mut knots: Vec<f64> = [0.0; 4].to_vec();
    knots.extend((1..n - 3).map(|i| i as f64));
    knots.extend([l; 4]);
    let mut rows: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    for i in 0..n - 3 {
        insert_knot(&mut knots, &mut rows, i as f64 + 0.5);
    }
    let mid = 0.5 * l;
    while knots.iter().filter(|&&u| u == mid).count() < 3 {
        insert_knot(&mut knots, &mut rows, mid);
    }
    debug_assert_eq!(rows.len(), 2 * n - 1);
    let first: Vec<f64> = rows[..n].iter().flatten().copied().collect();
    let last: Vec<f64> = rows[n - 1..].iter().flatten().copied().collect();
    vec![first, last]
}

/// De Casteljau's split at `t = 1/2` of a Bézier curve of degree
/// `d = n − 1`: left row `i` is `Σ_(j≤i) C(i, j)/2^i P_j`, right row `i` is
/// `Σ_(j≥i) C(d − i, j − i)/2^(d−i) P_j`.
fn bezier_halves(n: usize) -> Vec<Vec<f64>> {
    let d = n - 1;
    // Pascal's triangle up to d.
    let mut pascal = vec![vec![1.0f64]];
    for r in 1..=d {
        let prev = &pascal[r - 1];
        let row: Vec<f64> = (0..=r)
            .map(|j| {
                let a = if j > 0 { prev[j - 1] } else { 0.0 };
                let b = prev.get(j).copied().unwrap_or(0.0);
                a + b
            })
            .collect();
        pascal.push(row);
    }
    let mut left = vec![0.0; n * n];
    let mut right = vec![0.0; n * n];
    for i in 0..n {
        let scale = 0.5f64.powi(i as i32);
        for j in 0..=i {
            left[i * n + j] = pascal[i][j] * scale;
        }
        let scale = 0.5f64.powi((d - i) as i32);
        for j in i..n {
            right[i * n + j] = pascal[d - i][j - i] * scale;
        }
    }
    vec![left, right]
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
