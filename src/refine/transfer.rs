//! Carrying a solver's fields from an input mesh to its refinement.
//!
//! * **Point location** ([`locate_points`]): for every output point, the
//!   input tet that holds it and its barycentric coordinates there — the
//!   *vertex parent map*. The containing tet is found with exact predicates
//!   (the visibility walk of [`super::parents::walk_to`] from the parent of
//!   a tet at the point, then, if the walk ends elsewhere, the tets of a
//!   uniform grid cell: every tet whose bounding box holds the point is
//!   tested, so a point inside the domain is always found).
//! * **Outside points**: a boundary rule that moves the surface (the
//!   interpolating and approximating √3 rules) puts some output points
//!   outside the input domain. Such a point gets the **nearest point of the
//!   input boundary** (closest point over every input boundary face, found
//!   by a ring search over a grid of the faces' boxes), and the barycentric
//!   coordinates of that point in the tet of its face (the coordinate of the
//!   tet's fourth vertex is 0). A field is then extended constantly along
//!   the boundary's normals, the usual choice of solution transfer codes.
//! * **Interpolation** ([`interpolate_point_field`]) works on plain arrays:
//!   `Σ λ_i f(v_i)` over the four vertices of the located tet, component by
//!   component, so a field linear in x, y, z is reproduced to round-off at
//!   every output point inside the input domain. **Cell fields**
//!   ([`copy_cell_field`]) are copied from each output tet's `parent`
//!   (the input tet that holds its centroid, [`super::locate_parents`]).

use super::parents::{contains, walk_to};
use crate::geom::{closest_point_on_triangle, orient3d};
use crate::mesh::TetMesh;
use crate::topo::TET_FACES;
use glam::DVec3;
use rayon::prelude::*;

/// Where one output point lies in the input mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointParent {
    /// The input tet holding the point (or, for an outside point, the tet of
    /// the boundary face nearest to it).
    pub tet: u32,
    /// Barycentric coordinates in `tet`, in the order of its vertices
    /// (`TetMesh::tet`): non-negative, summing to 1.
    pub bary: [f64; 4],
    /// Whether the point lies outside the input domain (then `bary` are the
    /// coordinates of the nearest input boundary point).
    pub outside: bool,
}

/// Locates every point of `output` in `input` (see the module documentation).
/// Points no live tet of `output` uses get the location of their nearest
/// boundary point too. Deterministic: the answer of each point depends only
/// on the two meshes, not on the thread count.
pub fn locate_points(input: &TetMesh, output: &TetMesh) -> Vec<PointParent> {
    let Some(first) = input.tet_ids().next() else {
        return Vec::new();
    };
    let tets = TetGrid::new(input);
    let faces = BoundaryFaces::new(input);
    (0..output.n_points() as u32)
        .into_par_iter()
        .with_min_len(256)
        .map(|v| {
            let x = output.point(v);
            let hint = output
                .tet_of_vertex(v)
                .map(|t| output.parent(t))
                .filter(|&p| (p as usize) < input.n_tet_slots() && input.is_alive(p))
                .unwrap_or(first);
            let t = walk_to(input, hint, x);
            let found = if contains(input, t, x) {
                Some(t)
            } else {
                tets.find(input, x)
            };
            match found {
                Some(t) => PointParent {
                    tet: t,
                    bary: barycentric(input, t, x),
                    outside: false,
                },
                None => faces.nearest(input, x),
            }
        })
        .collect()
}

/// Barycentric coordinates of `x` in tet `t`: sub-volumes by the exact
/// predicate's estimate, divided by their sum. For `x` in the closed tet each
/// sub-volume's sign is exact (so none is negative); dividing by the sum
/// rather than by the tet's own volume makes the four sum to 1 up to one
/// rounding, which is what linear reproduction needs.
pub fn barycentric(mesh: &TetMesh, t: u32, x: DVec3) -> [f64; 4] {
    let [a, b, c, d] = mesh.tet_points(t);
    let l = [
        orient3d(x, b, c, d).max(0.0),
        orient3d(a, x, c, d).max(0.0),
        orient3d(a, b, x, d).max(0.0),
        orient3d(a, b, c, x).max(0.0),
    ];
    let s: f64 = l.iter().sum();
    if s > 0.0 {
        l.map(|v| v / s)
    } else {
        // Only for a flat tet, which the store never holds.
        [0.25; 4]
    }
}

/// Interpolates a point field of the input (`values`: `components` values
/// per input point) at the output points located by [`locate_points`]:
/// `Σ λ_i f(v_i)` over the vertices `input_tets[tet]` of each location.
pub fn interpolate_point_field(
    input_tets: &[[u32; 4]],
    locations: &[PointParent],
    values: &[f64],
    components: usize,
) -> Vec<f64> {
    let c = components;
    let mut out = vec![0.0; locations.len() * c];
    out.par_chunks_mut(c.max(1))
        .zip(locations.par_iter())
        .for_each(|(o, loc)| {
            let v = input_tets[loc.tet as usize];
            for (k, ok) in o.iter_mut().enumerate() {
                *ok = (0..4)
                    .map(|i| loc.bary[i] * values[v[i] as usize * c + k])
                    .sum();
            }
        });
    out
}

/// Copies a cell field of the input (`values`: `components` values per
/// input tet) to the output tets whose parents are `parents` (one input tet
/// id per output tet).
pub fn copy_cell_field(parents: &[u32], values: &[f64], components: usize) -> Vec<f64> {
    let c = components;
    parents
        .iter()
        .flat_map(|&p| values[p as usize * c..(p as usize + 1) * c].iter().copied())
        .collect()
}

/// A uniform grid of cubic cells over a bounding box; item `i` is listed in
/// every cell its box overlaps.
struct Grid {
    lo: DVec3,
    h: f64,
    dims: [usize; 3],
    /// Per cell, `start[c]..start[c+1]` into `items`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    /// A grid with about one cell per box over the boxes `(lo, hi)`.
    fn new(boxes: &[(DVec3, DVec3)]) -> Grid {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &(a, b) in boxes {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        if boxes.is_empty() {
            lo = DVec3::ZERO;
            hi = DVec3::ONE;
        }
        let ext = (hi - lo).max(DVec3::splat(1e-300));
        let n = boxes.len().max(1) as f64;
        // Cube cells of about one box's share of the bounding volume; the
        // longest extent gets at most 256 cells, so the table stays small.
        let mut h = (ext.x * ext.y * ext.z / n)
            .cbrt()
            .max(ext.max_element() / 256.0);
        if !(h.is_finite() && h > 0.0) {
            h = ext.max_element().max(1.0);
        }
        let dims = [
            ((ext.x / h).ceil() as usize).clamp(1, 256),
            ((ext.y / h).ceil() as usize).clamp(1, 256),
            ((ext.z / h).ceil() as usize).clamp(1, 256),
        ];
        let mut g = Grid {
            lo,
            h,
            dims,
            start: Vec::new(),
            items: Vec::new(),
        };
        let ncell = dims[0] * dims[1] * dims[2];
        let mut count = vec![0u32; ncell + 1];
        for &(a, b) in boxes {
            g.for_cells(a, b, |c| count[c] += 1);
        }
        let mut acc = 0u32;
        for c in count.iter_mut() {
            let k = *c;
            *c = acc;
            acc += k;
        }
        let mut fill = count.clone();
        g.items = vec![0; acc as usize];
        for (i, &(a, b)) in boxes.iter().enumerate() {
            let items = &mut g.items;
            g_cells(lo, h, dims, a, b, |c| {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
            });
        }
        g.start = count;
        g
    }

    fn index(&self, p: DVec3) -> [usize; 3] {
        cell_index(self.lo, self.h, self.dims, p)
    }

    fn for_cells(&self, a: DVec3, b: DVec3, f: impl FnMut(usize)) {
        g_cells(self.lo, self.h, self.dims, a, b, f)
    }

    fn cell(&self, i: [usize; 3]) -> &[u32] {
        let c = (i[2] * self.dims[1] + i[1]) * self.dims[0] + i[0];
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

fn cell_index(lo: DVec3, h: f64, dims: [usize; 3], p: DVec3) -> [usize; 3] {
    let r = (p - lo) / h;
    let f = |x: f64, n: usize| {
        if x.is_nan() || x <= 0.0 {
            0
        } else {
            (x as usize).min(n - 1)
        }
    };
    [f(r.x, dims[0]), f(r.y, dims[1]), f(r.z, dims[2])]
}

fn g_cells(lo: DVec3, h: f64, dims: [usize; 3], a: DVec3, b: DVec3, mut f: impl FnMut(usize)) {
    let i0 = cell_index(lo, h, dims, a);
    let i1 = cell_index(lo, h, dims, b);
    for z in i0[2]..=i1[2] {
        for y in i0[1]..=i1[1] {
            for x in i0[0]..=i1[0] {
                f((z * dims[1] + y) * dims[0] + x);
            }
        }
    }
}

fn bounds(p: &[DVec3]) -> (DVec3, DVec3) {
    let lo = p.iter().fold(DVec3::splat(f64::INFINITY), |m, &q| m.min(q));
    let hi = p
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |m, &q| m.max(q));
    (lo, hi)
}

/// The input tets in a grid of their boxes: exact point location.
struct TetGrid {
    ids: Vec<u32>,
    grid: Grid,
}

impl TetGrid {
    fn new(mesh: &TetMesh) -> TetGrid {
        let ids: Vec<u32> = mesh.tet_ids().collect();
        let boxes: Vec<_> = ids.iter().map(|&t| bounds(&mesh.tet_points(t))).collect();
        TetGrid {
            grid: Grid::new(&boxes),
            ids,
        }
    }

    /// The lowest-id tet holding `x` (exact predicates), if any does.
    fn find(&self, mesh: &TetMesh, x: DVec3) -> Option<u32> {
        // A tet holding x has x in its box, so it is listed in x's cell
        // (boxes are registered with the same rounding of the cell index).
        self.grid
            .cell(self.grid.index(x))
            .iter()
            .map(|&i| self.ids[i as usize])
            .filter(|&t| contains(mesh, t, x))
            .min()
    }
}

/// The input's boundary faces in a grid of their boxes: nearest points.
struct BoundaryFaces {
    /// `(tet, face)` per boundary face.
    faces: Vec<(u32, usize)>,
    grid: Grid,
}

impl BoundaryFaces {
    fn new(mesh: &TetMesh) -> BoundaryFaces {
        let mut faces = Vec::new();
        for t in mesh.tet_ids() {
            for f in 0..4 {
                if mesh.is_boundary_face(t, f) {
                    faces.push((t, f));
                }
            }
        }
        let boxes: Vec<_> = faces
            .iter()
            .map(|&(t, f)| bounds(&mesh.face_vertices(t, f).map(|v| mesh.point(v))))
            .collect();
        BoundaryFaces {
            grid: Grid::new(&boxes),
            faces,
        }
    }

    /// The location of the input boundary point nearest to `x`: ring search
    /// over the grid, shell after shell around `x`'s cell. A face not yet
    /// seen lies only in cells of later shells, at least `k·h` away after
    /// shell `k` (x is inside — or, clamped, beyond — its own cell), so the
    /// search stops once the best distance is within that bound. Ties go to
    /// the lowest face index, so the answer does not depend on threads.
    fn nearest(&self, mesh: &TetMesh, x: DVec3) -> PointParent {
        let g = &self.grid;
        let c = g.index(x);
        let max_k = g.dims.iter().copied().max().unwrap_or(1);
        let mut best: Option<(f64, usize, [f64; 3])> = None;
        for k in 0..=max_k {
            let lo = c.map(|i| i.saturating_sub(k));
            let hi = [0, 1, 2].map(|a| (c[a] + k).min(g.dims[a] - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for xx in lo[0]..=hi[0] {
                        let ring = [xx, y, z]
                            .iter()
                            .zip(&c)
                            .map(|(&i, &ci)| i.abs_diff(ci))
                            .max()
                            .unwrap_or(0);
                        if ring != k {
                            continue;
                        }
                        for &i in g.cell([xx, y, z]) {
                            let (t, f) = self.faces[i as usize];
                            let [a, b, cc] = mesh.face_vertices(t, f).map(|v| mesh.point(v));
                            let (q, w) = closest_point_on_triangle(x, a, b, cc);
                            let d = q.distance_squared(x);
                            let better = match best {
                                None => true,
                                Some((bd, bi, _)) => d < bd || (d == bd && (i as usize) < bi),
                            };
                            if better {
                                best = Some((d, i as usize, w));
                            }
                        }
                    }
                }
            }
            if let Some((d, _, _)) = best {
                let reach = k as f64 * g.h;
                if d.sqrt() <= reach {
                    break;
                }
            }
        }
        let (_, i, w) = best.expect("an input with tets has boundary faces");
        let (t, f) = self.faces[i];
        let mut bary = [0.0; 4];
        for (j, &l) in TET_FACES[f].iter().enumerate() {
            bary[l] = w[j];
        }
        PointParent {
            tet: t,
            bary,
            outside: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    #[test]
    fn points_are_found_inside_and_projected_outside() {
        let input = TetMesh::from_data(&cube_grid(3)).expect("a cube").0;
        let mut out = TetMesh::default();
        let inside = out.add_point(DVec3::new(0.3, 0.7, 0.2));
        let outside = out.add_point(DVec3::new(1.5, 0.5, 0.5));
        let loc = locate_points(&input, &out);
        assert!(!loc[inside as usize].outside);
        let back = |l: &PointParent| {
            let p = input.tet_points(l.tet);
            (0..4).map(|i| p[i] * l.bary[i]).sum::<DVec3>()
        };
        assert!((back(&loc[inside as usize]) - DVec3::new(0.3, 0.7, 0.2)).length() < 1e-14);
        assert!(loc[outside as usize].outside);
        assert!((back(&loc[outside as usize]) - DVec3::new(1.0, 0.5, 0.5)).length() < 1e-14);
    }
}
