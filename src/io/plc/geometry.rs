//! Plane geometry of facets (projection, loops, interior points), ray
//! directions and the union-find the analysis glues sides with.

use glam::DVec3;

/// A closed polygon of a facet, in the facet's 2-D projection.
pub(super) struct Loop {
    /// Canonical point ids.
    pub(super) verts: Vec<u32>,
    /// 2-D coordinates (the facet's projection) of `verts`.
    pub(super) uv: Vec<[f64; 2]>,
    /// Area in 3-D.
    pub(super) area: f64,
    /// Counter-clockwise seen from the facet normal.
    pub(super) ccw: bool,
}

/// A facet in its plane.
pub(super) struct FacetGeom {
    /// Unit normal.
    pub(super) n: DVec3,
    /// A point of the plane (centered coordinates).
    pub(super) o: DVec3,
    /// The coordinate axis dropped by the 2-D projection (the normal's largest).
    pub(super) drop: usize,
    /// Largest distance of a vertex from the plane.
    pub(super) deviation: f64,
    pub(super) loops: Vec<Loop>,
}

/// The part of a facet between one loop and the loops directly inside it.
pub(super) struct Piece {
    pub(super) facet: usize,
    /// Index of the outer loop in the facet's loops.
    pub(super) outer: usize,
    /// Indices of the inner loops.
    pub(super) inner: Vec<usize>,
    pub(super) area: f64,
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
}

/// One piece leaving an edge: `d` is the in-plane direction into the piece.
#[derive(Clone, Copy)]
pub(super) struct Incidence {
    pub(super) piece: u32,
    pub(super) d: DVec3,
    pub(super) from_segment: bool,
}

/// Each edge (sorted canonical point ids) with the pieces that leave it.
pub(super) type EdgeIncidences = Vec<([u32; 2], Vec<Incidence>)>;

pub(super) struct UnionFind(Vec<u32>);

impl UnionFind {
    pub(super) fn new(n: usize) -> UnionFind {
        UnionFind((0..n as u32).collect())
    }
    pub(super) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let p = self.0[x as usize];
            self.0[x as usize] = self.0[p as usize];
            x = p;
        }
        x
    }
    pub(super) fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
    }
}

/// Index of side `s` (+1 or -1) of piece `k`.
#[inline]
pub(super) fn side(k: usize, s: f64) -> u32 {
    (2 * k + usize::from(s < 0.0)) as u32
}

/// 2-D coordinates of `p` with axis `drop` removed (cyclic order kept).
#[inline]
pub(super) fn project(p: DVec3, drop: usize) -> [f64; 2] {
    match drop {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

/// Twice the area vector of a polygon (Newell's method).
pub(super) fn newell(pts: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    let first = pts.clone().next();
    let mut n = DVec3::ZERO;
    let mut prev: Option<DVec3> = None;
    for p in pts {
        if let Some(q) = prev {
            n += q.cross(p);
        }
        prev = Some(p);
    }
    if let (Some(q), Some(f)) = (prev, first) {
        n += q.cross(f);
    }
    n
}

/// Even-odd point-in-polygon test.
pub(super) fn inside_loop(uv: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = uv.len();
    for i in 0..n {
        let (a, b) = (uv[i], uv[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if x > p[0] {
                inside = !inside;
            }
        }
    }
    inside
}

/// Distance from `p` to the closest edge of a loop.
pub(super) fn loop_distance(uv: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let n = uv.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (uv[i], uv[(i + 1) % n]);
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let (px, py) = (p[0] - a[0], p[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        let t = if len2 > 0.0 {
            ((px * ex + py * ey) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (dx, dy) = (px - t * ex, py - t * ey);
        best = best.min((dx * dx + dy * dy).sqrt());
    }
    best
}

/// A point strictly inside the region that the even-odd rule over `loops`
/// defines: a horizontal scanline between vertex heights, in the middle of
/// the widest interval it has inside.
pub(super) fn interior_point(loops: &[&[[f64; 2]]]) -> Option<[f64; 2]> {
    let mut ys: Vec<f64> = loops.iter().flat_map(|l| l.iter().map(|p| p[1])).collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let mut gaps: Vec<(f64, f64)> = ys
        .windows(2)
        .map(|w| (w[1] - w[0], 0.5 * (w[0] + w[1])))
        .collect();
    gaps.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(_, y) in gaps.iter().take(16) {
        let mut xs: Vec<f64> = Vec::new();
        for l in loops {
            let n = l.len();
            for i in 0..n {
                let (a, b) = (l[i], l[(i + 1) % n]);
                if (a[1] > y) != (b[1] > y) {
                    xs.push(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        let best = xs
            .chunks_exact(2)
            .map(|w| (w[1] - w[0], 0.5 * (w[0] + w[1])))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((w, x)) = best {
            if w > 0.0 {
                return Some([x, y]);
            }
        }
    }
    None
}

/// Generic directions for ray casting (a fixed pseudo-random sequence, so
/// that results are reproducible).
pub(super) fn ray_directions() -> impl Iterator<Item = DVec3> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    std::iter::from_fn(move || loop {
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let v = DVec3::new(next(), next(), next());
        let l = v.length();
        if l > 0.2 && l <= 1.0 {
            return Some(v / l);
        }
    })
    .take(64)
}

pub(super) enum Ray {
    /// Pieces hit, by increasing distance.
    Hits(Vec<(f64, usize)>),
    /// The ray grazes an edge or a plane: try another direction.
    Degenerate,
    /// The origin lies on this piece.
    OnPiece,
}

/// The smallest loop of facet `g` that contains the 2-D point `p`.
pub(super) fn innermost_loop(g: &FacetGeom, p: [f64; 2]) -> Option<usize> {
    (0..g.loops.len())
        .filter(|&l| inside_loop(&g.loops[l].uv, p))
        .min_by(|&i, &j| g.loops[i].area.total_cmp(&g.loops[j].area))
}

/// Whether the ray `x0 + t dir`, `t >= 0`, meets the box `[lo, hi]` grown by `tol`.
pub(super) fn ray_meets_box(x0: DVec3, dir: DVec3, lo: DVec3, hi: DVec3, tol: f64) -> bool {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        let (l, h) = (lo[a] - tol, hi[a] + tol);
        if dir[a] == 0.0 {
            if x0[a] < l || x0[a] > h {
                return false;
            }
        } else {
            let (ta, tb) = ((l - x0[a]) / dir[a], (h - x0[a]) / dir[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

pub(super) fn sorted(v: &[u32]) -> Vec<u32> {
    let mut s = v.to_vec();
    s.sort_unstable();
    s
}

#[inline]
pub(super) fn edge(a: u32, b: u32) -> [u32; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}
