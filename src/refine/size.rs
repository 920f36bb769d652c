//! Size-driven refinement: split every edge longer than its target, as MMG
//! reads a size map.
//!
//! A size map gives, per point, either a target edge length `h` (isotropic;
//! MMG's scalar `SolAtVertices`) or a symmetric positive-definite metric `M`
//! (anisotropic; MMG's 6-component tensor `m11 m12 m22 m13 m23 m33`): the
//! length of an edge `e` in the metric is `sqrt(eᵀ M e)`, and `M = I / h²`
//! is the isotropic case. An edge `(a, b)` is long when the mean of its
//! lengths in the metrics of `a` and `b` exceeds [`SPLIT_ABOVE`].
//!
//! One [`size_pass`] splits the long edges at their midpoints
//! ([`crate::ops::split_edge`]), longest first, the new point's metric the
//! mean of the two ends' (a mean of positive-definite matrices is positive
//! definite); a split that would create a tet worse than the quality floor
//! (by default the worst tet when the pass begins; for a metric, quality is
//! measured after mapping the tet by the metric's Cholesky factor, since an
//! anisotropic mesh is meant to be well shaped in the metric, not in x, y,
//! z) is refused, so quality never drops below it. The optimize phase ([`crate::improve::improve`]) runs after each pass.
//! The √3 operations never remove an old interior edge, which is why the
//! size loop needs these splits.
//!
//! The splits are applied one after the other, longest first (ties by the
//! edge's vertex ids), so the result does not depend on the thread count.

use crate::geom::tet_min_sine;
use crate::improve::{improve, ImproveOptions};
use crate::mesh::TetMesh;
use crate::ops::split_edge;
use glam::{DMat3, DVec3};

/// Metric length above which an edge is split. Splitting an edge of length
/// `L > √2` leaves two of `L/2 > 0.71`, the balance MMG strikes too, and
/// every edge of the result is at most `√2 ≈ 1.41` times its target.
pub const SPLIT_ABOVE: f64 = std::f64::consts::SQRT_2;

/// Size passes a loop "until every edge meets the map" runs at most (the
/// CLI's `--steps auto`, the Python package's `steps="auto"`).
pub const AUTO_SIZE_PASSES: usize = 20;

/// A size map over the points of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum SizeMap {
    /// A target edge length per point.
    Iso(Vec<f64>),
    /// A metric per point, `m11 m12 m22 m13 m23 m33` (MMG's order).
    Aniso(Vec<[f64; 6]>),
}

impl SizeMap {
    /// A size map from `components` values per point, point after point:
    /// 1 (a target edge length, positive and finite) or 6 (a metric
    /// `m11 m12 m22 m13 m23 m33`, positive definite). The error names the
    /// first bad point (1-based, as mesh files count) and its value.
    pub fn from_values(components: usize, values: &[f64]) -> Result<SizeMap, String> {
        if components != 1 && components != 6 {
            return Err(format!(
                "{components} components; a size is 1 (length) or 6 (metric m11 m12 m22 m13 m23 m33)"
            ));
        }
        if values.len() % components != 0 {
            return Err(format!(
                "{} values are no whole number of {components}-component entries",
                values.len()
            ));
        }
        for (k, e) in values.chunks_exact(components).enumerate() {
            let ok = match e {
                [h] => *h > 0.0 && h.is_finite(),
                _ => is_positive_definite(&[e[0], e[1], e[2], e[3], e[4], e[5]]),
            };
            if !ok {
                return Err(format!(
                    "the value of point {} ({e:?}) is not a positive size or a positive-definite metric",
                    k + 1
                ));
            }
        }
        Ok(match components {
            1 => SizeMap::Iso(values.to_vec()),
            _ => SizeMap::Aniso(
                values
                    .chunks_exact(6)
                    .map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]])
                    .collect(),
            ),
        })
    }

    /// Number of points the map covers.
    pub fn len(&self) -> usize {
        match self {
            SizeMap::Iso(v) => v.len(),
            SizeMap::Aniso(v) => v.len(),
        }
    }

    /// Whether the map covers no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Caps every target length at `hmax` (MMG's `-hmax`): an isotropic
    /// size becomes `min(h, hmax)`; a metric's eigenvalues are raised to at
    /// least `1/hmax²` (done by adding the missing part along the whole
    /// identity when the smallest eigenvalue is too small, a cheap bound
    /// that keeps the metric positive definite and its lengths ≥ `1/hmax`
    /// per unit).
    pub fn cap(&mut self, hmax: f64) {
        match self {
            SizeMap::Iso(v) => v.iter_mut().for_each(|h| *h = h.min(hmax)),
            SizeMap::Aniso(v) => {
                let floor = 1.0 / (hmax * hmax);
                for m in v.iter_mut() {
                    let low = min_eigenvalue(m);
                    if low < floor {
                        let d = floor - low;
                        m[0] += d;
                        m[2] += d;
                        m[5] += d;
                    }
                }
            }
        }
    }

    /// The length of `e` in the metric of point `v`.
    pub fn length_at(&self, v: u32, e: DVec3) -> f64 {
        match self {
            SizeMap::Iso(h) => e.length() / h[v as usize],
            SizeMap::Aniso(m) => {
                let m = matrix(&m[v as usize]);
                e.dot(m * e).max(0.0).sqrt()
            }
        }
    }

    /// The metric length of the edge from `a` to `b` (at `pa`, `pb`): the
    /// mean of its lengths in the two ends' metrics.
    pub fn edge_length(&self, a: u32, b: u32, pa: DVec3, pb: DVec3) -> f64 {
        let e = pb - pa;
        0.5 * (self.length_at(a, e) + self.length_at(b, e))
    }

    /// The map `x → Lᵀx` with `LLᵀ` the mean metric of the points `vs`
    /// (Cholesky), under which Euclidean lengths are metric lengths; `None`
    /// for an isotropic map, whose quality is the Euclidean one (the
    /// minimum sine is invariant under scaling). The Cholesky factor of a
    /// positive-definite matrix has a positive diagonal, so the map keeps
    /// orientation.
    pub fn transform(&self, vs: &[u32]) -> Option<DMat3> {
        let SizeMap::Aniso(m) = self else {
            return None;
        };
        let k = vs.len().max(1) as f64;
        let mean: [f64; 6] =
            std::array::from_fn(|i| vs.iter().map(|&v| m[v as usize][i]).sum::<f64>() / k);
        let a = matrix(&mean);
        let l11 = a.col(0)[0].max(0.0).sqrt();
        let l21 = a.col(0)[1] / l11;
        let l31 = a.col(0)[2] / l11;
        let l22 = (a.col(1)[1] - l21 * l21).max(0.0).sqrt();
        let l32 = (a.col(1)[2] - l31 * l21) / l22;
        let l33 = (a.col(2)[2] - l31 * l31 - l32 * l32).max(0.0).sqrt();
        // Lᵀ, column by column (glam matrices are column-major).
        let lt = DMat3::from_cols(
            DVec3::new(l11, 0.0, 0.0),
            DVec3::new(l21, l22, 0.0),
            DVec3::new(l31, l32, l33),
        );
        lt.is_finite().then_some(lt)
    }

    /// Values per point: 1 (a length) or 6 (a metric).
    pub fn components(&self) -> usize {
        match self {
            SizeMap::Iso(_) => 1,
            SizeMap::Aniso(_) => 6,
        }
    }

    /// The values of point `i` ([`SizeMap::components`] of them).
    pub fn entry(&self, i: usize) -> &[f64] {
        match self {
            SizeMap::Iso(h) => std::slice::from_ref(&h[i]),
            SizeMap::Aniso(m) => &m[i],
        }
    }

    /// An empty map of the same kind.
    #[cfg(feature = "mpi")]
    pub(crate) fn empty_like(&self) -> SizeMap {
        match self {
            SizeMap::Iso(_) => SizeMap::Iso(Vec::new()),
            SizeMap::Aniso(_) => SizeMap::Aniso(Vec::new()),
        }
    }

    /// The entries of points `ids`, in that order.
    #[cfg(feature = "mpi")]
    pub(crate) fn gather(&self, ids: &[u32]) -> SizeMap {
        match self {
            SizeMap::Iso(h) => SizeMap::Iso(ids.iter().map(|&v| h[v as usize]).collect()),
            SizeMap::Aniso(m) => SizeMap::Aniso(ids.iter().map(|&v| m[v as usize]).collect()),
        }
    }

    /// Appends point `i` of `from`, a map of the same kind (of the other
    /// kind, nothing: callers check the kinds first).
    #[cfg(feature = "mpi")]
    pub(crate) fn push_entry(&mut self, from: &SizeMap, i: usize) {
        match (self, from) {
            (SizeMap::Iso(to), SizeMap::Iso(h)) => to.push(h[i]),
            (SizeMap::Aniso(to), SizeMap::Aniso(m)) => to.push(m[i]),
            _ => debug_assert!(false, "size maps of two kinds"),
        }
    }

    /// Appends the size of a new point halfway between `a` and `b`.
    fn push_mean(&mut self, a: u32, b: u32) {
        match self {
            SizeMap::Iso(h) => {
                let x = 0.5 * (h[a as usize] + h[b as usize]);
                h.push(x);
            }
            SizeMap::Aniso(m) => {
                let (p, q) = (m[a as usize], m[b as usize]);
                m.push(std::array::from_fn(|i| 0.5 * (p[i] + q[i])));
            }
        }
    }
}

/// The symmetric matrix of MMG's `m11 m12 m22 m13 m23 m33`: the order of
/// a type-3 solution in a Medit `.sol` (the lower triangle row by row).
/// MMG's reader (`MMG5_readDoubleSol3D`) swaps the file's slots 2 and 3 into
/// its internal order `m11 m12 m13 m22 m23 m33`, which confirms the file
/// order.
pub fn matrix(m: &[f64; 6]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(m[0], m[1], m[3]),
        DVec3::new(m[1], m[2], m[4]),
        DVec3::new(m[3], m[4], m[5]),
    )
}

/// Whether MMG's `m11 m12 m22 m13 m23 m33` is positive definite
/// (Sylvester's criterion: the three leading minors are positive).
pub fn is_positive_definite(m: &[f64; 6]) -> bool {
    let d1 = m[0];
    let d2 = m[0] * m[2] - m[1] * m[1];
    let d3 = matrix(m).determinant();
    m.iter().all(|x| x.is_finite()) && d1 > 0.0 && d2 > 0.0 && d3 > 0.0
}

/// A lower bound of the smallest eigenvalue of a symmetric matrix
/// (Gershgorin's discs: each eigenvalue lies within a row's radius of its
/// diagonal entry).
fn min_eigenvalue(m: &[f64; 6]) -> f64 {
    let a = matrix(m);
    (0..3)
        .map(|i| {
            let r: f64 = (0..3).filter(|&j| j != i).map(|j| a.col(j)[i].abs()).sum();
            a.col(i)[i] - r
        })
        .fold(f64::INFINITY, f64::min)
}

/// What one [`size_pass`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SizeReport {
    /// Edges longer than [`SPLIT_ABOVE`] when the pass began.
    pub long_edges: usize,
    /// Edges split.
    pub split: usize,
    /// Splits refused (a new tet inverted or below the quality floor).
    pub refused: usize,
    /// Edges still longer than [`SPLIT_ABOVE`] after the pass.
    pub long_after: usize,
    /// Long edges left whole because they lie on a partition face (a
    /// distributed part's cut, which the rank across must split too); they
    /// count in `long_edges`, not in `refused`.
    pub on_cut: usize,
}

/// Options of [`size_pass`].
#[derive(Clone, Debug, Default)]
pub struct SizeOptions {
    /// Minimum sine of the signed dihedral angles no new tet may fall
    /// below, measured in the metric for an anisotropic map (`None`: the
    /// worst tet of the mesh when the pass begins, measured in the metric).
    pub quality_floor: Option<f64>,
    /// The optimize phase after the splits (`passes: 0` skips it; vertex
    /// insertion is off there whatever this says, see [`size_pass`]).
    pub improve: ImproveOptions,
}

/// The optimize phase of the size passes: `effort`'s options with
/// `passes`, `threshold` and `hausd`, no vertex insertion (an inserted
/// point would have no size), and with the linear `boundary` rule the
/// domain kept exactly, as the √3 step keeps it.
pub fn size_improve_options(
    effort: crate::improve::Effort,
    passes: usize,
    threshold: f64,
    hausd: Option<f64>,
    boundary: crate::stencil::Sqrt3Rule,
) -> ImproveOptions {
    let mut io = without_insertion(&effort.improve_options(passes, threshold, hausd));
    super::step::keep_domain_for(&mut io, boundary);
    io
}

/// `o` without vertex insertion and without Laplacian moves for the mean:
/// the size passes' optimize phase, whatever options it is given (an
/// inserted point would need a size, and the map only gives one to the
/// midpoint of a split it made, `push_mean`; a move to the neighbours'
/// centroid knows nothing of the map and evens out the graded sizes the
/// passes made: on the tripod's 2-rank `--hsiz` run it left 98 edges
/// above 1.5 times their size, against 73 serially).
pub(crate) fn without_insertion(o: &ImproveOptions) -> ImproveOptions {
    ImproveOptions {
        insert_vertices: false,
        smooth_for_mean: false,
        ..o.clone()
    }
}

/// The long edges of `mesh`, longest first (ties by vertex ids).
pub fn long_edges(mesh: &TetMesh, size: &SizeMap) -> Vec<(f64, [u32; 2])> {
    let mut long: Vec<(f64, [u32; 2])> = mesh
        .edges()
        .into_iter()
        .map(|[a, b]| (size.edge_length(a, b, mesh.point(a), mesh.point(b)), [a, b]))
        .filter(|&(l, _)| l > SPLIT_ABOVE)
        .collect();
    long.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    long
}

/// The worst minimum sine over the live tets.
pub fn worst_quality(mesh: &TetMesh) -> f64 {
    mesh.tet_ids()
        .map(|t| tet_min_sine(&mesh.tet_points(t)))
        .fold(f64::INFINITY, f64::min)
}

/// The minimum sine of the tet with corners `p` seen through `t`.
fn quality_in(t: Option<DMat3>, p: [DVec3; 4]) -> f64 {
    match t {
        Some(t) => tet_min_sine(&p.map(|x| t * x)),
        None => tet_min_sine(&p),
    }
}

/// The worst minimum sine over the live tets in the metric of `size`
/// (each tet through the mean metric of its corners; the Euclidean
/// [`worst_quality`] for an isotropic map).
pub fn worst_metric_quality(mesh: &TetMesh, size: &SizeMap) -> f64 {
    mesh.tet_ids()
        .map(|t| quality_in(size.transform(&mesh.tet(t)), mesh.tet_points(t)))
        .fold(f64::INFINITY, f64::min)
}

/// The worst quality (in the metric of the edge) of the tets that
/// splitting edge `(a, b)` at its midpoint would make, or `None` when the
/// edge is not in the mesh. `shell` is scratch space.
pub(crate) fn split_quality(
    mesh: &TetMesh,
    size: &SizeMap,
    a: u32,
    b: u32,
    shell: &mut Vec<u32>,
) -> Option<f64> {
    mesh.edge_shell(a, b, shell);
    if shell.is_empty() {
        return None;
    }
    let mid = (mesh.point(a) + mesh.point(b)) * 0.5;
    let tr = size.transform(&[a, b]);
    let worst = shell
        .iter()
        .flat_map(|&t| {
            let v = mesh.tet(t);
            let p = mesh.tet_points(t);
            let mut p1 = p;
            let mut p2 = p;
            for i in 0..4 {
                if v[i] == b {
                    p1[i] = mid;
                }
                if v[i] == a {
                    p2[i] = mid;
                }
            }
            [quality_in(tr, p1), quality_in(tr, p2)]
        })
        .fold(f64::INFINITY, f64::min);
    Some(worst)
}

/// Splits edge `(a, b)` at its midpoint, the new point's size the mean of
/// the ends'; an error (nothing changed) when [`split_edge`] refuses.
/// The midpoint is `(pa + pb) * 0.5`, the same bits whichever end comes
/// first (floating-point addition is commutative), so two ranks splitting
/// the same edge of their cut create the same point.
pub(crate) fn split_at_midpoint(
    mesh: &mut TetMesh,
    size: &mut SizeMap,
    a: u32,
    b: u32,
) -> Result<(), crate::ops::OpError> {
    let mid = (mesh.point(a) + mesh.point(b)) * 0.5;
    split_edge(mesh, a, b, mid)?;
    size.push_mean(a, b);
    Ok(())
}

/// One size pass (see the module documentation). `size` covers the points
/// of `mesh` and grows with it.
pub fn size_pass(mesh: &mut TetMesh, size: &mut SizeMap, opts: &SizeOptions) -> SizeReport {
    assert_eq!(size.len(), mesh.n_points(), "one size per point");
    let floor = opts
        .quality_floor
        .unwrap_or_else(|| worst_metric_quality(mesh, size));
    let long = long_edges(mesh, size);
    let mut report = SizeReport {
        long_edges: long.len(),
        ..SizeReport::default()
    };
    let cut = crate::mesh::partition::partition_edges(mesh);
    let mut shell = Vec::new();
    for (_, [a, b]) in long {
        if cut.contains(&[a, b]) {
            report.on_cut += 1;
            continue;
        }
        // An earlier split may have cut this edge already.
        let Some(worst_new) = split_quality(mesh, size, a, b, &mut shell) else {
            continue;
        };
        if worst_new < floor {
            report.refused += 1;
        } else if split_at_midpoint(mesh, size, a, b).is_ok() {
            report.split += 1;
        } else {
            report.refused += 1;
        }
    }
    if opts.improve.passes > 0 {
        improve(mesh, &without_insertion(&opts.improve));
    }
    debug_assert_eq!(size.len(), mesh.n_points());
    report.long_after = long_edges(mesh, size).len();
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    #[test]
    fn mmg_order_and_positive_definiteness() {
        // diag(1, 4, 9) with m12 = 0.5: m11 m12 m22 m13 m23 m33.
        let m = [1.0, 0.5, 4.0, 0.0, 0.0, 9.0];
        let a = matrix(&m);
        assert_eq!(a.col(1)[0], 0.5);
        assert_eq!(a.col(0)[1], 0.5);
        assert_eq!(a.col(1)[1], 4.0);
        assert!(is_positive_definite(&m));
        assert!(!is_positive_definite(&[1.0, 2.0, 1.0, 0.0, 0.0, 1.0]));
        assert!(!is_positive_definite(&[1.0, 0.0, 1.0, 0.0, 0.0, -1.0]));
    }

    #[test]
    fn a_uniform_size_is_met_and_the_mesh_stays_valid() {
        let mut mesh = TetMesh::from_data(&cube_grid(2)).unwrap().0;
        let floor = worst_quality(&mesh);
        let mut size = SizeMap::Iso(vec![0.2; mesh.n_points()]);
        for _ in 0..20 {
            let r = size_pass(&mut mesh, &mut size, &SizeOptions::default());
            mesh.check().unwrap();
            if r.long_after == 0 {
                break;
            }
        }
        assert!(long_edges(&mesh, &size).is_empty());
        assert!(worst_quality(&mesh) >= floor - 1e-12);
    }
}
