//! Laplacian smoothing: the vertex goes to its ball's ODT target (the
//! optimal Delaunay triangulation update of Chen and Xu, 2004, as Alliez et
//! al. use it in "Variational tetrahedral meshing", 2005) or to the
//! centroid of its neighbours (Field 1988), kept only if its ball gets
//! better: a higher worst tet, or, where the caller allows it, a higher
//! mean with the worst kept above a bar (the "smart" Laplacian of Freitag,
//! 1997, judges a move by its ball's quality in the same way).

use super::BallPoints;
use crate::mesh::TetMesh;
use glam::DVec3;

/// The ball of a vertex as it stands, for [`laplacian_position_in`].
#[derive(Clone, Copy, Debug)]
pub struct BallNow {
    /// Its worst tet quality.
    pub worst: f64,
    /// Its mean tet quality.
    pub mean: f64,
    /// Position in the ball of a tet to check first (the worst one; any
    /// position works, one past the end for none).
    pub first: usize,
    /// The worst may fall to just above this (never below `worst` if that is
    /// lower) for a higher mean; `f64::INFINITY`: the worst must rise.
    pub keep: f64,
}

/// Where the Laplacian move would take `v`, without moving it (the ball's
/// corners loaded in `bp`): the ball's ODT target, else the centroid of its
/// neighbours, else the point halfway to that centroid — the first of these
/// where every tet is above `min(now.worst, now.keep)`, nothing inverts,
/// and the mean rises (or stays while the worst rises) — and the ball's new
/// worst quality there. On success `qualities` holds the ball's tet
/// qualities at the position, in `ball` order.
///
/// Measured on the seven shipped meshes (one default step): the ODT target
/// tried first raised the average minimum dihedral angle by 0.26°–0.75°
/// (tripod 46.58° → 47.25°, the holed bar 47.13° → 47.88°) for up to a
/// fifth more time (a quarter on cube grids); in place of the centroid it
/// lowered it by 0.3°–2.2° (near the boundary the circumcentres of flat
/// tets pull too far). The halfway point raised it by another 0.15°–0.9°
/// (mmg_cube 43.0° → 43.9°).
pub fn laplacian_position_in(
    mesh: &TetMesh,
    v: u32,
    ball: &[u32],
    bp: &BallPoints,
    now: BallNow,
    qualities: &mut Vec<f64>,
) -> Option<(DVec3, f64)> {
    let mut judge = |x: DVec3| judge_position(x, bp, now, qualities, ball.len());
    if let Some(r) = bp.odt_target().and_then(&mut judge) {
        return Some(r);
    }
    let x0 = mesh.point(v);
    let target = bp.neighbour_centroid(mesh.n_points(), v).unwrap_or(x0);
    judge(target).or_else(|| judge(x0 + 0.5 * (target - x0)))
}

/// The ball's new worst quality if `v` stood at `x` and the move is kept
/// by the rule of [`laplacian_position_in`] (`n` tets in the ball).
fn judge_position(
    x: DVec3,
    bp: &BallPoints,
    now: BallNow,
    qualities: &mut Vec<f64>,
    n: usize,
) -> Option<(DVec3, f64)> {
    let (current_mean, first) = (now.mean, now.first);
    let current = now.worst.min(now.keep);
    // Every tet must end above `current`; any tet at or below it settles the
    // answer, and the likeliest one to be is the one `first` (the caller's
    // worst tet), so it is tried before the others. With `keep` at infinity
    // every tet above the worst means the worst rises, so the test below is
    // the mean's alone.
    let quality = |i: usize| bp.quality(i, x);
    let head = (first < bp.len()).then(|| quality(first));
    if head.is_some_and(|s| s.is_nan() || s <= current) {
        return None;
    }
    qualities.clear();
    let mut q = f64::INFINITY;
    let mut sum = 0.0;
    for i in 0..bp.len() {
        let s = match head {
            Some(h) if i == first => h,
            _ => quality(i),
        };
        if s.is_nan() || s <= current {
            return None;
        }
        q = q.min(s);
        sum += s;
        qualities.push(s);
    }
    let mean = sum / n.max(1) as f64;
    let better = mean > current_mean || (mean >= current_mean && q > now.worst);
    (better && bp.stays_positive(x)).then_some((x, q))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;

    fn mesh(points: Vec<[f64; 3]>, tets: Vec<[u32; 4]>) -> TetMesh {
        let data = MeshData {
            points,
            tets,
            ..Default::default()
        };
        TetMesh::from_data(&data).expect("a valid mesh").0
    }

    /// The ODT target of a one-tet ball is that tet's circumcentre: a point
    /// as far from each of the four corners.
    #[test]
    fn odt_target_of_one_tet_is_its_circumcentre() {
        let m = mesh(
            vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.1, 0.0],
                [0.3, 1.5, 0.2],
                [0.1, 0.4, 1.7],
            ],
            vec![[0, 1, 2, 3]],
        );
        let mut bp = BallPoints::default();
        bp.load(&m, 0, &[0]);
        let c = bp.odt_target().expect("a positive ball");
        let r: Vec<f64> = (0..4).map(|v| c.distance(m.point(v))).collect();
        for x in &r[1..] {
            assert!((x - r[0]).abs() < 1e-12 * r[0], "{r:?}");
        }
    }

    /// The octahedron's eight tets around its centre: each circumcentre is
    /// at (±½, ±½, ±½) with equal volumes, so the target is the centre.
    #[test]
    fn odt_target_of_a_symmetric_ball_is_its_centre() {
        let mut points = vec![[0.0; 3]];
        for a in 0..3 {
            for s in [1.0, -1.0] {
                let mut p = [0.0; 3];
                p[a] = s;
                points.push(p);
            }
        }
        // Points 1..=6: +x, -x, +y, -y, +z, -z; each octant's tet, oriented.
        let mut tets = Vec::new();
        for x in [1u32, 2] {
            for y in [3u32, 4] {
                for z in [5u32, 6] {
                    let flips = (x == 2) as u8 + (y == 4) as u8 + (z == 6) as u8;
                    tets.push(if flips % 2 == 0 {
                        [0, x, y, z]
                    } else {
                        [0, y, x, z]
                    });
                }
            }
        }
        let m = mesh(points, tets);
        let ball: Vec<u32> = (0..8).collect();
        let mut bp = BallPoints::default();
        bp.load(&m, 0, &ball);
        let c = bp.odt_target().expect("a positive ball");
        assert!(c.length() < 1e-15, "{c}");
    }

    /// Two tets of different volumes around the origin: the target is
    /// their circumcentres weighted by their volumes, each circumcentre
    /// solved here from its three bisector planes by Cramer's rule.
    #[test]
    fn odt_target_weighs_circumcentres_by_volume() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.2, 0.3, 1.0],
            [0.3, 0.2, -3.0],
        ];
        let m = mesh(pts.to_vec(), vec![[0, 1, 2, 3], [0, 2, 1, 4]]);
        let mut bp = BallPoints::default();
        bp.load(&m, 0, &[0, 1]);
        let got = bp.odt_target().expect("a positive ball");
        let det3 = |r: [[f64; 3]; 3]| {
            r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
                - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
                + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0])
        };
        let mut sum = [0.0; 3];
        let mut vol = 0.0;
        for t in [[0, 1, 2, 3], [0, 2, 1, 4]] {
            let a = pts[t[0]];
            // |x - a|² = |x - p|²  <=>  2 (p - a) · x = |p|² - |a|².
            let rows: Vec<[f64; 3]> = t[1..]
                .iter()
                .map(|&k| std::array::from_fn(|i| 2.0 * (pts[k][i] - a[i])))
                .collect();
            let rhs: Vec<f64> = t[1..]
                .iter()
                .map(|&k| (0..3).map(|i| pts[k][i] * pts[k][i] - a[i] * a[i]).sum())
                .collect();
            let m3 = [rows[0], rows[1], rows[2]];
            let d = det3(m3);
            let c: [f64; 3] = std::array::from_fn(|col| {
                let mut r = m3;
                for (row, &b) in r.iter_mut().zip(&rhs) {
                    row[col] = b;
                }
                det3(r) / d
            });
            let v = (d / 8.0).abs() / 6.0;
            for i in 0..3 {
                sum[i] += v * c[i];
            }
            vol += v;
        }
        let want = DVec3::from_array(sum) / vol;
        assert!(got.distance(want) < 1e-12, "{got} against {want}");
    }
}
