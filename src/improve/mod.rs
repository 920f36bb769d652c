//! Mesh improvement: vertex smoothing (Laplacian, then optimization-based) and
//! interior edge removal, as in §3.2 of the √3 paper (Burkhart, Hamann and Umlauf).
//!
//! The objective everywhere is the paper's quality: the minimum signed sine of
//! the dihedral angles of a tet, and for a vertex the minimum over its ball.

pub mod boundary_smooth;
pub mod colour;
pub mod effort;
mod insertion;
pub mod laplacian;
mod long_edges;
pub mod optimize;
pub mod passes;
pub mod ring;

pub use boundary_smooth::BoundarySmoothOptions;
pub use effort::Effort;
pub(crate) use long_edges::{split_long_edges, LengthCap, LongEdgeSplits};
pub use passes::{improve, ImproveOptions, ImproveReport, DEFAULT_THRESHOLD};

use crate::geom::{all_positive, tet_min_sine};
use crate::mesh::TetMesh;
use glam::DVec3;
use std::cell::RefCell;

/// Smallest quality over the tets of `ball` as they stand (tests).
#[cfg(test)]
pub fn ball_quality(mesh: &TetMesh, ball: &[u32]) -> f64 {
    ball.iter()
        .map(|&t| tet_min_sine(&mesh.tet_points(t)))
        .fold(f64::INFINITY, f64::min)
}

/// Runs `f` on this thread's "seen in this call" stamps, one per point of a
/// mesh of `n_points` points, with a fresh epoch: a point is seen when its
/// stamp equals the epoch, and only `v` is seen at the start. A ball has
/// about fifteen neighbours among seventy corner entries; a stamp lookup
/// costs fewer instructions than scanning the list found so far.
fn with_stamps<R>(n_points: usize, v: u32, f: impl FnOnce(&mut [u32], u32) -> R) -> R {
    thread_local! {
        static SEEN: RefCell<(Vec<u32>, u32)> = const { RefCell::new((Vec::new(), 0)) };
    }
    SEEN.with(|seen| {
        let (stamp, epoch) = &mut *seen.borrow_mut();
        if stamp.len() < n_points {
            stamp.resize(n_points, 0);
        }
        *epoch = epoch.wrapping_add(1);
        if *epoch == 0 {
            stamp.iter_mut().for_each(|s| *s = 0);
            *epoch = 1;
        }
        stamp[v as usize] = *epoch;
        f(stamp, *epoch)
    })
}

/// The corners of every tet of a vertex's ball, loaded once, so that the
/// ball's qualities with the vertex at trial positions need no lookups in the
/// mesh. Each evaluation computes exactly what `mesh::moves::tet_points_with` followed by
/// [`tet_min_sine`] (or [`orient3d`](crate::geom::orient3d)) computes.
#[derive(Clone, Debug, Default)]
pub struct BallPoints {
    /// Corners of each ball tet, as stored in the mesh.
    pts: Vec<[DVec3; 4]>,
    /// Position of the vertex among each tet's corners (4: not a corner).
    at: Vec<u8>,
    /// Vertex ids of each ball tet, as stored in the mesh.
    ids: Vec<[u32; 4]>,
}

impl BallPoints {
    /// Loads the corners of the tets of `ball`, the ball of `v`.
    pub fn load(&mut self, mesh: &TetMesh, v: u32, ball: &[u32]) {
        self.pts.clear();
        self.at.clear();
        self.ids.clear();
        for &t in ball {
            let tv = mesh.tet(t);
            self.ids.push(tv);
            self.pts.push(mesh.tet_points(t));
            self.at
                .push(tv.iter().position(|&u| u == v).map_or(4, |i| i as u8));
        }
    }

    /// Loads the ball a new vertex splitting the edge `(a, b)` would have:
    /// both halves of each tet of the edge's `shell` (see
    /// [`crate::ops::split_edge`]), the new vertex a placeholder id
    /// (`u32::MAX`: [`BallPoints::neighbour_centroid`], which indexes by
    /// id, does not apply to such a ball).
    pub(crate) fn load_edge_split(&mut self, mesh: &TetMesh, a: u32, b: u32, shell: &[u32]) {
        self.pts.clear();
        self.at.clear();
        self.ids.clear();
        for &t in shell {
            for half in crate::ops::split_halves(mesh.tet(t), a, b, u32::MAX) {
                let at = half
                    .iter()
                    .position(|&u| u == u32::MAX)
                    .expect("the new vertex");
                self.ids.push(half);
                self.pts.push(half.map(|u| {
                    if u == u32::MAX {
                        DVec3::ZERO
                    } else {
                        mesh.point(u)
                    }
                }));
                self.at.push(at as u8);
            }
        }
    }

    /// The centroid of the distinct neighbours of `v` (the ball's vertex,
    /// in a mesh of `n_points` points), summed in the order they first
    /// appear in the ball: the Laplacian target. `None` for an empty ball.
    /// Reads only what [`BallPoints::load`] loaded, so the ball is not walked
    /// a second time in the mesh.
    pub fn neighbour_centroid(&self, n_points: usize, v: u32) -> Option<DVec3> {
        with_stamps(n_points, v, |stamp, epoch| {
            let mut sum = DVec3::ZERO;
            let mut n = 0usize;
            for (ids, pts) in self.ids.iter().zip(&self.pts) {
                for (&x, &p) in ids.iter().zip(pts) {
                    let s = &mut stamp[x as usize];
                    if *s != epoch {
                        *s = epoch;
                        sum += p;
                        n += 1;
                    }
                }
            }
            (n > 0).then(|| sum / n as f64)
        })
    }

    /// The ODT target: the mean of the ball's tet circumcentres weighted
    /// by the tets' volumes (`None` if the ball's volume is not positive).
    ///
    /// For a tet `a, b, c, d` with `u = b - a`, `v = c - a`, `w = d - a` and
    /// `D = u · (v × w)`, the circumcentre is `a + m / (2D)` with
    /// `m = |u|² v × w + |v|² w × u + |w|² u × v`, so `D` times it is
    /// `D a + m / 2`: no division per tet, and a flat tet, whose
    /// circumcentre runs off to infinity, adds its bounded `m / 2` (weight
    /// zero times infinity done right).
    pub fn odt_target(&self) -> Option<DVec3> {
        let mut sum = DVec3::ZERO;
        let mut vol = 0.0;
        for p in &self.pts {
            let a = p[0];
            let (u, v, w) = (p[1] - a, p[2] - a, p[3] - a);
            let vw = v.cross(w);
            let det = u.dot(vw);
            let num = u.length_squared() * vw
                + v.length_squared() * w.cross(u)
                + w.length_squared() * u.cross(v);
            sum += det * a + num * 0.5;
            vol += det;
        }
        (vol > 0.0).then(|| sum / vol)
    }

    /// Number of tets.
    pub fn len(&self) -> usize {
        self.pts.len()
    }

    /// Corners of tet `i` of the ball with the vertex at `x`.
    #[inline]
    pub fn tet_with(&self, i: usize, x: DVec3) -> [DVec3; 4] {
        let mut p = self.pts[i];
        if let Some(c) = p.get_mut(self.at[i] as usize) {
            *c = x;
        }
        p
    }

    /// The other corners of tet `i` (those that are not the vertex), in order.
    pub fn others(&self, i: usize) -> impl Iterator<Item = DVec3> + '_ {
        let a = self.at[i] as usize;
        self.pts[i]
            .iter()
            .enumerate()
            .filter(move |&(k, _)| k != a)
            .map(|(_, &p)| p)
    }

    /// Quality of tet `i` with the vertex at `x`.
    #[inline]
    pub fn quality(&self, i: usize, x: DVec3) -> f64 {
        tet_min_sine(&self.tet_with(i, x))
    }

    /// The ball's worst quality with the vertex at `x` (NaN ignored, as
    /// `f64::min` ignores it).
    pub(crate) fn worst(&self, x: DVec3) -> f64 {
        (0..self.len())
            .map(|i| self.quality(i, x))
            .fold(f64::INFINITY, f64::min)
    }

    /// The ball's qualities with the vertex at `x`, into `out` (cleared
    /// first), if every one is above `bar` (a NaN quality counts as above,
    /// as `f64::min` ignores it); `None` at the first that is not.
    /// On success returns the smallest (NaN ignored).
    pub fn qualities_above(&self, x: DVec3, bar: f64, out: &mut Vec<f64>) -> Option<f64> {
        out.clear();
        let mut q = f64::INFINITY;
        for i in 0..self.pts.len() {
            let s = self.quality(i, x);
            if s <= bar {
                return None;
            }
            q = q.min(s);
            out.push(s);
        }
        Some(q)
    }

    /// Whether every tet stays positively oriented (exact predicate) with the
    /// vertex at `x`.
    pub fn stays_positive(&self, x: DVec3) -> bool {
        all_positive((0..self.pts.len()).map(|i| self.tet_with(i, x)))
    }
}
