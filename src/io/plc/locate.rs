//! Exact point location: which cell of the surface holds a seed.
//!
//! The cells come from the analysis (shells glued around edges, grouped by
//! ray walks); which cell a *seed* lies in is then decided exactly, with no
//! tolerance, so that a seed outside every region is always refused before
//! TetGen sees it (TetGen crashes on one) and a seed inside a region is
//! never refused.
//!
//! **Why it is exact.** The boundary of a cell `c` is the set of pieces with
//! exactly one side in `c`; as a mod-2 chain it is closed (around every edge
//! the wedges of `c` start and end at such pieces, an even number in all).
//! For a closed mod-2 surface `S` and a segment `pq` that meets `S` only in
//! interior points of its triangles, the number of crossings is odd exactly
//! when one of `p`, `q` is enclosed by `S` and the other is not. We take `q`
//! strictly outside the bounding box of the surface (a comparison of doubles,
//! exact), so `q` lies in no bounded cell and the parity of the crossings of
//! `∂c` says whether `p` lies in `c`. Each piece is the mod-2 sum of the
//! fan triangles of its loops (outer and inner: the fan of a simple loop
//! covers the region it bounds an odd number of times and the rest of its
//! plane an even number of times). A crossing of triangle `abc` by `pq` is
//! decided by five orientation signs, `orient3d(a,b,c,p)`,
//! `orient3d(a,b,c,q)` (opposite: the segment crosses the plane) and
//! `orient3d(p,q,a,b)`, `orient3d(p,q,b,c)`, `orient3d(p,q,c,a)` (all of one
//! sign: the line passes through the open triangle), each computed by
//! [`crate::geom::orient3d_exact`] on the input doubles themselves (not the
//! centred copies the analysis uses, which are rounded), so every sign is
//! the true one. When a sign is zero where it matters — `pq` through an edge
//! or a vertex, or `q` in a triangle's plane — the result would depend on
//! more than the signs, so another `q` is drawn; those `q` lie on finitely
//! many planes and lines, so a pseudo-random `q` avoids them. A seed in the
//! plane of one of a piece's triangles is judged by an exact 2-D even-odd
//! test in the facet's projection (on the piece: the seed is on a facet,
//! an error; off it: the segment leaves the plane at once and does not cross
//! the piece). For facets that are planar only within the analysis'
//! tolerance, the surface tested is the fan triangulation of their loops,
//! which is where the mesher puts them as well, up to that tolerance.

use super::validate::Analysis;
use super::PlcError;
use crate::geom::{orient2d_exact, orient3d_exact};
use glam::DVec3;

/// How a segment meets one triangle.
enum Meet {
    /// Crosses its interior.
    Cross,
    /// Misses it.
    Miss,
    /// The seed lies in the triangle's plane.
    Coplanar,
    /// Through an edge or a vertex, or `q` in the plane: draw another `q`.
    Degenerate,
}

fn meet(a: DVec3, b: DVec3, c: DVec3, p: DVec3, q: DVec3) -> Meet {
    let sp = orient3d_exact(a, b, c, p);
    if sp == 0 {
        return Meet::Coplanar;
    }
    let sq = orient3d_exact(a, b, c, q);
    if sq == 0 {
        return Meet::Degenerate;
    }
    if sp == sq {
        return Meet::Miss;
    }
    let o = [
        orient3d_exact(p, q, a, b),
        orient3d_exact(p, q, b, c),
        orient3d_exact(p, q, c, a),
    ];
    let (pos, neg) = (o.contains(&1), o.contains(&-1));
    if pos && neg {
        Meet::Miss
    } else if o.contains(&0) {
        Meet::Degenerate
    } else {
        Meet::Cross
    }
}

/// Whether `a, b, c` are collinear (a fan triangle of zero area, which no
/// segment crosses in its interior), exactly.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    (0..3).all(|d| {
        let pr = |p: DVec3| super::geometry::project(p, d);
        orient2d_exact(pr(a), pr(b), pr(c)) == 0
    })
}

/// Where a 2-D point lies against the even-odd region of some loops.
#[derive(PartialEq)]
enum InPlane {
    Inside,
    OnBoundary,
    Outside,
}

/// Exact even-odd test (a ray towards +u; comparisons and exact orient2d only).
fn in_loops(loops: &[Vec<[f64; 2]>], p: [f64; 2]) -> InPlane {
    let mut inside = false;
    for l in loops {
        let n = l.len();
        for i in 0..n {
            let (a, b) = (l[i], l[(i + 1) % n]);
            let o = orient2d_exact(a, b, p);
            if o == 0
                && p[0] >= a[0].min(b[0])
                && p[0] <= a[0].max(b[0])
                && p[1] >= a[1].min(b[1])
                && p[1] <= a[1].max(b[1])
            {
                return InPlane::OnBoundary;
            }
            // Half-open in v, so a vertex at the ray's height counts once.
            if (a[1] > p[1]) != (b[1] > p[1]) {
                // Upwards edge: p is left of it (o > 0) exactly when the
                // crossing lies to the right of p; downwards, the reverse.
                let right = if b[1] > a[1] { o > 0 } else { o < 0 };
                if right {
                    inside = !inside;
                }
            }
        }
    }
    if inside {
        InPlane::Inside
    } else {
        InPlane::Outside
    }
}

impl Analysis {
    /// The loops of piece `k` (outer first) as input points.
    fn piece_points(&self, k: usize, raw: &[[f64; 3]]) -> Vec<Vec<DVec3>> {
        let p = &self.pieces[k];
        let g = &self.facets[p.facet];
        std::iter::once(p.outer)
            .chain(p.inner.iter().copied())
            .map(|l| {
                g.loops[l]
                    .verts
                    .iter()
                    .map(|&v| DVec3::from_array(raw[v as usize]))
                    .collect()
            })
            .collect()
    }

    /// The bounded cell holding `x` (input coordinates), or `None` when `x`
    /// is outside every one, decided exactly (see the module documentation).
    /// `cell_of_side[s]` is the cell of piece side `s`, `bounded[c]` whether
    /// cell `c` is bounded.
    #[allow(clippy::too_many_arguments)] // a private helper of `cells`
    pub(super) fn locate_exact(
        &self,
        x: [f64; 3],
        raw: &[[f64; 3]],
        cell_of_side: &[usize],
        bounded: &[bool],
        what: &'static str,
        index: usize,
    ) -> Result<Option<usize>, PlcError> {
        let p = DVec3::from_array(x);
        let loops: Vec<Vec<Vec<DVec3>>> = (0..self.pieces.len())
            .map(|k| self.piece_points(k, raw))
            .collect();
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for q in loops.iter().flatten().flatten() {
            lo = lo.min(*q);
            hi = hi.max(*q);
        }
        // Outside the bounding box: outside (exact comparisons).
        if (0..3).any(|a| p[a] < lo[a] || p[a] > hi[a]) {
            return Ok(None);
        }
        let mut state: u64 = 0x2545_F491_4F6C_DD1D ^ (index as u64).wrapping_mul(0x9E37_79B9);
        let mut rnd = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        'draw: for attempt in 0..96 {
            // q: beyond the box along one axis (alternating), anywhere near
            // it along the others. Halves avoid overflow at 1e308.
            let out_axis = attempt % 3;
            let mut q = DVec3::ZERO;
            for a in 0..3 {
                let (h, l) = (0.5 * hi[a], 0.5 * lo[a]);
                let v = if a == out_axis {
                    if attempt % 6 < 3 {
                        hi[a] + (h - l) * (0.5 + rnd())
                    } else {
                        lo[a] - (h - l) * (0.5 + rnd())
                    }
                } else {
                    h + l + (h - l) * (3.0 * rnd() - 1.5)
                };
                q[a] = v.clamp(-f64::MAX, f64::MAX);
            }
            if !(q[out_axis] > hi[out_axis] || q[out_axis] < lo[out_axis]) {
                continue; // the box reaches the end of the doubles there
            }
            let (slo, shi) = (p.min(q), p.max(q));
            let mut parity = vec![false; bounded.len()];
            for (k, piece) in loops.iter().enumerate() {
                let mut crossings = 0usize;
                let mut coplanar = false;
                'piece: for l in piece {
                    // Skip the loop when its box misses the segment's box.
                    let (mut llo, mut lhi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                    for v in l {
                        llo = llo.min(*v);
                        lhi = lhi.max(*v);
                    }
                    if (0..3).any(|a| lhi[a] < slo[a] || llo[a] > shi[a]) {
                        continue;
                    }
                    for i in 1..l.len() - 1 {
                        let (a, b, c) = (l[0], l[i], l[i + 1]);
                        if collinear(a, b, c) {
                            continue;
                        }
                        match meet(a, b, c, p, q) {
                            Meet::Cross => crossings += 1,
                            Meet::Miss => {}
                            Meet::Degenerate => continue 'draw,
                            Meet::Coplanar => {
                                coplanar = true;
                                break 'piece;
                            }
                        }
                    }
                }
                if coplanar {
                    let drop = self.facets[self.pieces[k].facet].drop;
                    let uv: Vec<Vec<[f64; 2]>> = piece
                        .iter()
                        .map(|l| {
                            l.iter()
                                .map(|&v| super::geometry::project(v, drop))
                                .collect()
                        })
                        .collect();
                    if in_loops(&uv, super::geometry::project(p, drop)) != InPlane::Outside {
                        return Err(PlcError::SeedOnFacet {
                            what,
                            index: index + 1,
                            facet: self.pieces[k].facet + 1,
                            line: None,
                        });
                    }
                    continue; // the segment leaves the plane at once
                }
                if crossings % 2 == 1 {
                    let (c1, c2) = (cell_of_side[2 * k], cell_of_side[2 * k + 1]);
                    if c1 != c2 {
                        parity[c1] = !parity[c1];
                        parity[c2] = !parity[c2];
                    }
                }
            }
            let mut found = (0..bounded.len()).filter(|&c| bounded[c] && parity[c]);
            return match (found.next(), found.next()) {
                (None, _) => Ok(None),
                (Some(c), None) => Ok(Some(c)),
                (Some(_), Some(_)) => Err(PlcError::Inconsistent(format!(
                    "{what} {} lies in two cells at once",
                    index + 1
                ))),
            };
        }
        Err(PlcError::Inconsistent(format!(
            "{what} {} cannot be located: every segment from it meets an edge",
            index + 1
        )))
    }
}
