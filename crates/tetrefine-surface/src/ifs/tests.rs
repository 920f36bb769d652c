//! Tests of the IFS construction, its contraction certificate and its
//! attractors, against closed forms.

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
        (IfsKind::ClampedCubicBSpline, curve[..4].to_vec()),
        (IfsKind::ClampedCubicBSpline, curve.clone()),
        (IfsKind::Bezier, curve[..2].to_vec()),
        (IfsKind::Bezier, curve.clone()),
        (IfsKind::Loop, bumpy_net(IfsKind::Loop).1),
        (IfsKind::Sqrt3, bumpy_net(IfsKind::Sqrt3).1),
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
        let q =
            2.0 * (t - 0.5) * (t - 1.0) * p0 - 4.0 * t * (t - 1.0) * p1 + 2.0 * t * (t - 0.5) * p2;
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
                    let q = bicubic_patch(&p, nu, nv, uu * (nu - 3) as f64, vv * (nv - 3) as f64);
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

// ---------------------------------------------------------------------------
// Clamped B-spline, Bézier, Loop, √3, subsets, start sets.

/// Cox–de Boor: the cubic B-spline with full knot vector `knots` at `t`
/// (right-continuous; `t` at the last knot evaluates the last span).
fn de_boor_curve(p: &[DVec3], knots: &[f64], t: f64) -> DVec3 {
    let last = *knots.last().expect("knots");
    let n = p.len();
    // Degree-0 basis.
    let mut basis: Vec<f64> = (0..knots.len() - 1)
        .map(|i| {
            let inside = knots[i] <= t && t < knots[i + 1];
            let at_end = t == last && knots[i] < knots[i + 1] && knots[i + 1] == last;
            if inside || at_end {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    for d in 1..=3 {
        basis = (0..knots.len() - 1 - d)
            .map(|i| {
                let a = knots[i + d] - knots[i];
                let b = knots[i + d + 1] - knots[i + 1];
                let left = if a > 0.0 {
                    (t - knots[i]) / a * basis[i]
                } else {
                    0.0
                };
                let right = if b > 0.0 {
                    (knots[i + d + 1] - t) / b * basis[i + 1]
                } else {
                    0.0
                };
                left + right
            })
            .collect();
    }
    (0..n).map(|i| basis[i] * p[i]).sum()
}

#[test]
fn clamped_bspline_passes_through_its_ends_and_is_the_de_boor_curve() {
    for n in [4usize, 5, 6, 9] {
        let p: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(i as f64, ((i * 7) % 5) as f64 - 2.0, (i as f64 * 0.9).cos()))
            .collect();
        let l = (n - 3) as f64;
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|i| i as f64));
        knots.extend([l; 4]);
        let k = 7;
        let shape =
            ifs_shape(IfsKind::ClampedCubicBSpline, &p, k, &IfsOptions::default()).expect("shape");
        let IfsShape::Polylines(lines) = shape else {
            panic!("a curve is polylines")
        };
        assert_eq!(lines.len(), 1);
        let line = &lines[0];
        assert_eq!(line.len(), (1 << k) + 1);
        assert!(line[0].distance(p[0]) < 1e-12, "n = {n}: starts at p_0");
        assert!(
            line[line.len() - 1].distance(p[n - 1]) < 1e-12,
            "ends at p_(n-1)"
        );
        for (j, x) in line.iter().enumerate() {
            let t = l * j as f64 / (1 << k) as f64;
            let want = de_boor_curve(&p, &knots, t);
            assert!(x.distance(want) < 1e-12, "n = {n}, t = {t}: {x} vs {want}");
        }
    }
    // The paper's two matrices for knots {0,0,0,1,2,2,2} (five points).
    let ifs = Ifs::new(IfsKind::ClampedCubicBSpline, &[DVec3::ZERO; 5]).expect("ifs");
    let s1 = [
        [1.0, 0.0, 0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0, 0.0, 0.0],
        [0.0, 0.75, 0.25, 0.0, 0.0],
        [0.0, 0.375, 0.5, 0.125, 0.0],
        [0.0, 0.25, 0.5, 0.25, 0.0],
    ];
    let s2 = [
        [0.0, 0.25, 0.5, 0.25, 0.0],
        [0.0, 0.125, 0.5, 0.375, 0.0],
        [0.0, 0.0, 0.25, 0.75, 0.0],
        [0.0, 0.0, 0.0, 0.5, 0.5],
        [0.0, 0.0, 0.0, 0.0, 1.0],
    ];
    for (i, s) in [s1, s2].iter().enumerate() {
        let want: Vec<f64> = s.iter().flatten().copied().collect();
        for (a, b) in ifs.map(i).iter().zip(&want) {
            assert!((a - b).abs() < 1e-15, "map {i}: {:?}", ifs.map(i));
        }
    }
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

fn bernstein_curve(p: &[DVec3], t: f64) -> DVec3 {
    let d = p.len() - 1;
    (0..=d)
        .map(|i| binomial(d, i) * t.powi(i as i32) * (1.0 - t).powi((d - i) as i32) * p[i])
        .sum()
}

#[test]
fn bezier_union_of_halves_is_the_bernstein_curve() {
    for n in [2usize, 3, 4, 7] {
        let p: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new((i as f64 * 1.3).sin(), i as f64 * 0.5, ((i * i) % 3) as f64))
            .collect();
        let k = 8;
        let IfsShape::Polylines(lines) =
            ifs_shape(IfsKind::Bezier, &p, k, &IfsOptions::default()).expect("shape")
        else {
            panic!("polylines")
        };
        let line = &lines[0];
        assert_eq!(line.len(), (1 << k) + 1);
        for (j, x) in line.iter().enumerate() {
            let t = j as f64 / (1 << k) as f64;
            assert!(
                x.distance(bernstein_curve(&p, t)) < 1e-12,
                "n = {n}, t = {t}"
            );
        }
        assert_eq!((line[0], line[1 << k]), (p[0], p[n - 1]), "exact ends");
    }
}

/// The planar position of lattice point `(i, j)`.
fn lattice_xy(q: [i64; 2]) -> DVec3 {
    DVec3::new(
        q[0] as f64 + 0.5 * q[1] as f64,
        3f64.sqrt() / 2.0 * q[1] as f64,
        0.0,
    )
}

/// A bumpy net: the regular planar net lifted by a smooth height plus a
/// pseudo-random one.
fn bumpy_net(kind: IfsKind) -> (Vec<[i64; 2]>, Vec<DVec3>) {
    let net = triangle_net(kind).expect("net");
    let mut rng = SplitMix64(11);
    let pts = net
        .iter()
        .map(|&q| {
            let x = lattice_xy(q);
            x + DVec3::new(
                0.05 * rng.next_f64(),
                0.0,
                (x.x * 0.8).sin() + 0.3 * rng.next_f64(),
            )
        })
        .collect();
    (net, pts)
}

/// The six lattice neighbours, written out independently of the module.
const RING: [[i64; 2]; 6] = [[1, 0], [1, -1], [0, -1], [-1, 0], [-1, 1], [0, 1]];

/// One regular Loop step on a lattice patch (keys in the current level's
/// lattice): every fine point whose stencil is available.
fn loop_step_reference(pts: &HashMap<[i64; 2], DVec3>) -> HashMap<[i64; 2], DVec3> {
    let mut out = HashMap::new();
    for (&v, &x) in pts {
        let ring: Option<Vec<DVec3>> = RING
            .iter()
            .map(|d| pts.get(&[v[0] + d[0], v[1] + d[1]]).copied())
            .collect();
        if let Some(ring) = ring {
            out.insert(
                [2 * v[0], 2 * v[1]],
                0.625 * x + ring.iter().sum::<DVec3>() / 16.0,
            );
        }
        for d in RING {
            let w = [v[0] + d[0], v[1] + d[1]];
            let Some(&y) = pts.get(&w) else { continue };
            // The two points next to both ends.
            let common: Vec<DVec3> = RING
                .iter()
                .map(|e| [v[0] + e[0], v[1] + e[1]])
                .filter(|c| RING.iter().any(|f| [w[0] + f[0], w[1] + f[1]] == *c))
                .filter_map(|c| pts.get(&c).copied())
                .collect();
            if common.len() == 2 {
                out.insert(
                    [v[0] + w[0], v[1] + w[1]],
                    0.375 * (x + y) + 0.125 * (common[0] + common[1]),
                );
            }
        }
    }
    out
}

/// One regular Kobbelt √3 step on a lattice patch whose six neighbour
/// offsets (counter-clockwise) are `dirs`: old points with a full ring are
/// relaxed (`α = 1/3`), every triangle gets its centroid.
fn sqrt3_step_reference(
    pts: &HashMap<[i64; 2], DVec3>,
    dirs: &[[i64; 2]; 6],
) -> HashMap<[i64; 2], DVec3> {
    let mut out = HashMap::new();
    for (&v, &x) in pts {
        let ring: Option<Vec<DVec3>> = dirs
            .iter()
            .map(|d| pts.get(&[v[0] + d[0], v[1] + d[1]]).copied())
            .collect();
        if let Some(ring) = ring {
            out.insert(v, 2.0 / 3.0 * x + ring.iter().sum::<DVec3>() / 18.0);
        }
        for j in 0..6 {
            let (a, b) = (dirs[j], dirs[(j + 1) % 6]);
            let (pa, pb) = ([v[0] + a[0], v[1] + a[1]], [v[0] + b[0], v[1] + b[1]]);
            if let (Some(&ya), Some(&yb)) = (pts.get(&pa), pts.get(&pb)) {
                let s = [a[0] + b[0], a[1] + b[1]];
                assert!(s[0] % 3 == 0 && s[1] % 3 == 0, "centroid on the lattice");
                out.insert([v[0] + s[0] / 3, v[1] + s[1] / 3], (x + ya + yb) / 3.0);
            }
        }
    }
    out
}

/// Limit points `v/2 + Σ ring/12` of the level points `(a, b)`, `a, b ≥ 0`,
/// `a + b ≤ side` (the closed triangle).
fn limit_points(pts: &HashMap<[i64; 2], DVec3>, side: i64) -> Vec<DVec3> {
    let mut out = Vec::new();
    for a in 0..=side {
        for b in 0..=side - a {
            let v = pts[&[a, b]];
            let ring: DVec3 = RING.iter().map(|d| pts[&[a + d[0], b + d[1]]]).sum();
            out.push(0.5 * v + ring / 12.0);
        }
    }
    out
}

/// Every point of `want` is a vertex of `mesh` (to 1e-12) and the counts
/// agree.
fn same_vertices(mesh: &PolyMesh, want: &[DVec3]) {
    assert_eq!(mesh.points.len(), want.len());
    for w in want {
        let d = mesh
            .points
            .iter()
            .map(|x| x.distance(*w))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-12, "limit point {w} is {d} from the mesh");
    }
}

fn surface(kind: IfsKind, p: &[DVec3], k: usize, maps: Option<Vec<usize>>) -> PolyMesh {
    let opts = IfsOptions {
        maps,
        start: IfsStart::Attractor,
    };
    match ifs_shape(kind, p, k, &opts).expect("shape") {
        IfsShape::Surface(m) => m,
        other => panic!("surface expected, got {other:?}"),
    }
}

#[test]
fn loop_ifs_vertices_are_the_loop_limit_points() {
    // Loop at valence 6 (β = 1/16): the limit position is
    // (1 − 6χ) v + χ Σ neighbours with χ = 1/(3/(8β) + 6) = 1/12, i.e.
    // v/2 + Σ/12 (the left eigenvector of the 1-ring subdivision matrix).
    let (net, p) = bumpy_net(IfsKind::Loop);
    assert_eq!(net.len(), 12);
    for k in 1..=4usize {
        let mesh = surface(IfsKind::Loop, &p, k, None);
        let side = 1i64 << k;
        assert_eq!(mesh.faces.len(), 4usize.pow(k as u32));
        assert_eq!(
            mesh.points.len() as i64,
            (side + 1) * (side + 2) / 2,
            "k = {k}"
        );
        let mut pts: HashMap<[i64; 2], DVec3> =
            net.iter().copied().zip(p.iter().copied()).collect();
        for _ in 0..k {
            pts = loop_step_reference(&pts);
        }
        same_vertices(&mesh, &limit_points(&pts, side));
        // Manifold, consistently oriented triangles (a disc).
        assert!(mesh.validate().is_ok());
        assert_eq!(mesh.euler_characteristic(), 1);
    }
}

#[test]
fn sqrt3_ifs_vertices_are_the_sqrt3_limit_points() {
    // Kobbelt's √3 at valence 6 (α = 1/3): on (v, r = mean of the ring) one
    // step is v' = (1 − α) v + α r and r' = (v + 2r)/3 (the new ring is the
    // six centroids, whose mean is (v + 2r)/3). The left eigenvector of
    // [[1 − α, α], [1/3, 2/3]] for eigenvalue 1 is (1, 3α)/(1 + 3α) =
    // (1/2, 1/2), so the limit is v/2 + r/2 = v/2 + Σ/12.
    let (net, p) = bumpy_net(IfsKind::Sqrt3);
    assert_eq!(net.len(), 27);
    let level1 = [[1, 1], [-1, 2], [-2, 1], [-1, -1], [1, -2], [2, -1]];
    for k in 1..=3u32 {
        let mesh = surface(IfsKind::Sqrt3, &p, k as usize, None);
        let side = 3i64.pow(k);
        assert_eq!(mesh.faces.len(), 9usize.pow(k));
        assert_eq!(mesh.points.len() as i64, (side + 1) * (side + 2) / 2);
        // Keys in units of 3^-k of the coarse lattice.
        let mut pts: HashMap<[i64; 2], DVec3> = net
            .iter()
            .map(|&q| [q[0] * side, q[1] * side])
            .zip(p.iter().copied())
            .collect();
        for t in 0..k {
            let scale = 3i64.pow(k - t);
            let dirs = RING.map(|d| [d[0] * scale, d[1] * scale]);
            pts = sqrt3_step_reference(&pts, &dirs);
            let scale = 3i64.pow(k - t - 1);
            let dirs = level1.map(|d: [i64; 2]| [d[0] * scale, d[1] * scale]);
            pts = sqrt3_step_reference(&pts, &dirs);
        }
        same_vertices(&mesh, &limit_points(&pts, side));
        assert!(mesh.validate().is_ok());
        assert_eq!(mesh.euler_characteristic(), 1);
    }
}

#[test]
fn planar_nets_give_planar_patches() {
    for kind in [IfsKind::Loop, IfsKind::Sqrt3] {
        // The regular net: both schemes reproduce linear functions, so the
        // patch is the triangle itself, its vertices the fine lattice.
        let p = regular_net(kind).expect("net");
        let k = 3;
        let mesh = surface(kind, &p, k, None);
        let side = if kind == IfsKind::Loop { 8 } else { 27 };
        let want: Vec<DVec3> = (0..=side)
            .flat_map(|a| (0..=side - a).map(move |b| (a, b)))
            .map(|(a, b)| lattice_xy([a, b]) / side as f64)
            .collect();
        same_vertices(&mesh, &want);
        // A tilted affine image of the net: every point stays in its plane.
        let normal = DVec3::new(-0.3, 0.2, 1.0).normalize();
        let tilted: Vec<DVec3> = p
            .iter()
            .map(|x| {
                let (a, b) = (x.x + 0.4 * x.y, 1.5 * x.y);
                DVec3::new(a, b, 0.3 * a - 0.2 * b + 1.0)
            })
            .collect();
        let offset = normal.dot(tilted[0]);
        assert!(offset.abs() > 0.5);
        let mesh = surface(kind, &tilted, k, None);
        for x in &mesh.points {
            assert!(
                (normal.dot(*x) - offset).abs() < 1e-12,
                "{kind:?}: {x} off the plane"
            );
        }
    }
}

#[test]
fn dropping_maps_keeps_q_to_the_k_pieces_on_the_surface() {
    let (_, p) = bumpy_net(IfsKind::Loop);
    let k = 4;
    let full = surface(IfsKind::Loop, &p, k, None);
    // The three corner maps: a Sierpinski gasket on the Loop surface, 3^k
    // triangles on (3^(k+1) + 3)/2 vertices, every one a vertex of the full
    // mesh (the subset's attractor lies in the full one).
    let gasket = surface(IfsKind::Loop, &p, k, Some(vec![2, 0, 1]));
    assert_eq!(gasket.faces.len(), 3usize.pow(k as u32));
    assert_eq!(gasket.points.len(), (3usize.pow(k as u32 + 1) + 3) / 2);
    for x in &gasket.points {
        let d = full
            .points
            .iter()
            .map(|y| y.distance(*x))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-12);
    }
    let (_, q) = bumpy_net(IfsKind::Sqrt3);
    for keep in [vec![0, 1, 2, 6, 7, 8], vec![4], vec![0, 8]] {
        let m = surface(IfsKind::Sqrt3, &q, 2, Some(keep.clone()));
        assert_eq!(m.faces.len(), keep.len().pow(2), "{keep:?}");
    }
    // Koch with its two outer maps: 2^k separate pieces.
    let IfsShape::Polylines(lines) = ifs_shape(
        IfsKind::Koch,
        &koch_control(),
        k,
        &IfsOptions {
            maps: Some(vec![0, 3]),
            start: IfsStart::Attractor,
        },
    )
    .expect("koch") else {
        panic!("polylines")
    };
    assert_eq!(lines.len(), 1 << k);
    assert!(lines.iter().all(|l| l.len() == 2));
    // Bézier with its left map only: one piece, [0, 2^-k].
    let p3 = [
        DVec3::ZERO,
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(3.0, 0.0, 1.0),
    ];
    let IfsShape::Polylines(lines) = ifs_shape(
        IfsKind::Bezier,
        &p3,
        k,
        &IfsOptions {
            maps: Some(vec![0]),
            start: IfsStart::Attractor,
        },
    )
    .expect("bezier") else {
        panic!("polylines")
    };
    assert_eq!(lines.len(), 1);
    assert!(lines[0][1].distance(bernstein_curve(&p3, 1.0 / 16.0)) < 1e-12);
    // Bad subsets.
    let ifs = Ifs::new(IfsKind::Loop, &p).expect("ifs");
    for (keep, msg) in [
        (vec![0, 4], "map 4 does not exist: Loop has maps 0 to 3"),
        (vec![1, 1], "map 1 is given twice"),
        (vec![], "keep at least one map"),
    ] {
        assert_eq!(ifs.subset(&keep).unwrap_err().to_string(), msg);
    }
}

#[test]
fn any_start_set_converges_to_the_attractor() {
    // Bézier from a triangle (its middle corner is off the curve): the
    // images after k rounds lie within C 2^-k of the curve.
    let p = [
        DVec3::ZERO,
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(2.0, -1.0, 0.5),
        DVec3::new(3.0, 0.0, 0.0),
    ];
    let dist_to_curve = |x: DVec3| {
        (0..=4096)
            .map(|j| bernstein_curve(&p, j as f64 / 4096.0).distance(x))
            .fold(f64::INFINITY, f64::min)
    };
    let worst = |k: usize| {
        let opts = IfsOptions {
            maps: None,
            start: IfsStart::Triangle,
        };
        let IfsShape::Surface(m) = ifs_shape(IfsKind::Bezier, &p, k, &opts).expect("shape") else {
            panic!("triangles")
        };
        assert_eq!(m.faces.len(), 1 << k);
        assert_eq!(m.points.len(), 3 << k);
        m.points
            .iter()
            .map(|&x| dist_to_curve(x))
            .fold(0.0, f64::max)
    };
    let (w2, w8) = (worst(2), worst(8));
    assert!(w2 > 0.05, "{w2}");
    assert!(w8 < w2 / 30.0 && w8 < 2e-2, "{w2} {w8}");
    // A point and a segment: q^k points and segments.
    let opts = IfsOptions {
        maps: Some(vec![0, 1, 2]),
        start: IfsStart::Point,
    };
    let (_, net) = bumpy_net(IfsKind::Loop);
    let IfsShape::Points(pts) = ifs_shape(IfsKind::Loop, &net, 3, &opts).expect("points") else {
        panic!("points")
    };
    assert_eq!(pts.len(), 27);
    let opts = IfsOptions {
        maps: None,
        start: IfsStart::Segment,
    };
    let IfsShape::Polylines(segs) =
        ifs_shape(IfsKind::Koch, &koch_control(), 3, &opts).expect("segments")
    else {
        panic!("segments")
    };
    assert_eq!(segs.len(), 64);
    // Koch's segment start (0,0)–(1,0) gives the Koch polygon: segments of
    // length 3^-3.
    for s in &segs {
        assert!((s[0].distance(s[1]) - 1.0 / 27.0).abs() < 1e-12);
    }
    // A mesh start on the planar Loop net: copies of it, in the plane.
    let start = PolyMesh::new(
        vec![
            DVec3::new(5.0, 1.0, 0.0),
            DVec3::new(-2.0, 0.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
        ],
        vec![vec![0, 1, 2], vec![0, 2, 3]],
    );
    let flat = regular_net(IfsKind::Loop).expect("net");
    let opts = IfsOptions {
        maps: None,
        start: IfsStart::Mesh(start),
    };
    let IfsShape::Surface(m) = ifs_shape(IfsKind::Loop, &flat, 3, &opts).expect("mesh") else {
        panic!("surface")
    };
    assert_eq!((m.points.len(), m.faces.len()), (4 * 64, 2 * 64));
    // In the plane of the net, and the copies shrink towards the patch
    // triangle: the farthest point from its centroid after 3 and 6 rounds.
    let centre = DVec3::new(0.5, 3f64.sqrt() / 6.0, 0.0);
    let spread = |m: &PolyMesh| {
        m.points
            .iter()
            .map(|x| x.distance(centre))
            .fold(0.0, f64::max)
    };
    for x in &m.points {
        assert!(x.z.abs() < 1e-12);
    }
    let opts6 = IfsOptions {
        maps: None,
        start: opts.start.clone(),
    };
    let IfsShape::Surface(m6) = ifs_shape(IfsKind::Loop, &flat, 6, &opts6).expect("mesh") else {
        panic!("surface")
    };
    // The patch triangle's corners are 1/√3 from its centroid.
    let (s3, s6) = (spread(&m), spread(&m6));
    assert!(s6 < s3 && s6 < 1.0 / 3f64.sqrt() + 0.1, "{s3} {s6}");
}

#[test]
fn new_kinds_refuse_wrong_control_counts() {
    for (kind, n, msg) in [
        (
            IfsKind::Loop,
            11,
            "Loop needs exactly 12 control points, got 11",
        ),
        (
            IfsKind::Sqrt3,
            12,
            "Sqrt3 needs exactly 27 control points, got 12",
        ),
        (
            IfsKind::Bezier,
            1,
            "Bezier needs at least 2 control points, got 1",
        ),
        (
            IfsKind::ClampedCubicBSpline,
            3,
            "ClampedCubicBSpline needs at least 4 control points, got 3",
        ),
    ] {
        let err = Ifs::new(kind, &vec![DVec3::ZERO; n]).unwrap_err();
        assert_eq!(err.to_string(), msg);
    }
    let (_, p) = bumpy_net(IfsKind::Sqrt3);
    assert!(matches!(
        ifs_shape(IfsKind::Sqrt3, &p, 9, &IfsOptions::default()),
        Err(SurfaceError::TooLarge { .. })
    ));
    let bad_start = IfsOptions {
        maps: None,
        start: IfsStart::Mesh(PolyMesh::new(vec![DVec3::ZERO; 3], vec![vec![0, 1, 3]])),
    };
    assert_eq!(
        ifs_shape(IfsKind::Sqrt3, &p, 1, &bad_start).unwrap_err(),
        SurfaceError::VertexOutOfRange {
            face: 0,
            vertex: 3,
            count: 3
        }
    );
}

#[test]
fn bicubic_surface_is_a_triangle_mesh_of_patch_points() {
    let (nu, nv) = (5, 4);
    let p: Vec<DVec3> = (0..nu * nv)
        .map(|i| {
            let (u, v) = ((i / nv) as f64, (i % nv) as f64);
            DVec3::new(u, v, 0.4 * (u * 0.7).cos() * (v + 1.0).sqrt())
        })
        .collect();
    let k = 3;
    let mesh = surface(IfsKind::Bicubic { nu, nv }, &p, k, None);
    let side = (1usize << k) + 1;
    assert_eq!(mesh.points.len(), side * side);
    assert_eq!(mesh.faces.len(), 2 * 4usize.pow(k as u32));
    assert!(mesh.faces.iter().all(|f| f.len() == 3));
    let want: Vec<DVec3> = (0..side)
        .flat_map(|i| (0..side).map(move |j| (i, j)))
        .map(|(i, j)| {
            let u = (nu - 3) as f64 * i as f64 / (side - 1) as f64;
            let v = (nv - 3) as f64 * j as f64 / (side - 1) as f64;
            bicubic_patch(&p, nu, nv, u, v)
        })
        .collect();
    same_vertices(&mesh, &want);
    assert!(mesh.validate().is_ok());
    assert_eq!(mesh.euler_characteristic(), 1);
}

/// Distance in the plane `z = 0` from `x` to the triangle `abc`.
fn distance_to_triangle(x: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let cross = |u: DVec3, v: DVec3| u.x * v.y - u.y * v.x;
    let area = cross(b - a, c - a);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(p, q)| cross(q - p, x - p) * area >= 0.0);
    if inside {
        return 0.0;
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(p, q)| {
            let t = ((x - p).dot(q - p) / (q - p).length_squared()).clamp(0.0, 1.0);
            x.distance(p + t * (q - p))
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn surface_ifs_from_a_far_mesh_converges_to_the_patch() {
    // On the regular planar net the patch is the triangle (0,0), (1,0),
    // (1/2, √3/2) itself; a mesh far outside it is pulled onto it, the
    // farthest point's distance shrinking by the subdominant factor (1/2 for
    // Loop per step, 1/3 for √3 per double step) up to constants.
    let tri = [
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0),
    ];
    let far = PolyMesh::new(
        vec![
            DVec3::new(6.0, 5.0, 0.0),
            DVec3::new(9.0, 5.0, 0.0),
            DVec3::new(7.0, 8.0, 0.0),
        ],
        vec![vec![0, 1, 2]],
    );
    for (kind, k1, k2, factor) in [(IfsKind::Loop, 3, 7, 16.0), (IfsKind::Sqrt3, 2, 4, 9.0)] {
        let p = regular_net(kind).expect("net");
        let worst = |k: usize| {
            let opts = IfsOptions {
                maps: None,
                start: IfsStart::Mesh(far.clone()),
            };
            let IfsShape::Surface(m) = ifs_shape(kind, &p, k, &opts).expect("shape") else {
                panic!("surface")
            };
            m.points
                .iter()
                .map(|&x| distance_to_triangle(x, tri))
                .fold(0.0, f64::max)
        };
        let (d1, d2) = (worst(k1), worst(k2));
        assert!(d1 > 1e-3, "{kind:?}: {d1}");
        assert!(d2 < d1 / factor, "{kind:?}: {d1} then {d2}");
    }
}

#[test]
fn the_nets_are_the_smallest_closed_ones() {
    // Loop closes on the 12-point net; √3 does not (its rules after two
    // steps need points at distance 2), and closes on the 27-point net.
    assert!(
        lattice::lattice_maps(&lattice::net(1), &lattice::LOOP_SUBS, lattice::loop_fine).is_ok()
    );
    assert!(
        lattice::lattice_maps(&lattice::net(0), &lattice::LOOP_SUBS, lattice::loop_fine).is_err()
    );
    assert!(
        lattice::lattice_maps(&lattice::net(1), &lattice::SQRT3_SUBS, lattice::sqrt3_fine).is_err()
    );
    assert!(
        lattice::lattice_maps(&lattice::net(2), &lattice::SQRT3_SUBS, lattice::sqrt3_fine).is_ok()
    );
    // Every map's rows are affine combinations.
    for kind in [IfsKind::Loop, IfsKind::Sqrt3] {
        let ifs = Ifs::new(kind, &regular_net(kind).expect("net")).expect("ifs");
        let m = ifs.dimension();
        for i in 0..ifs.map_count() {
            for r in 0..m {
                let sum: f64 = ifs.map(i)[r * m..(r + 1) * m].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "{kind:?} map {i} row {r}");
            }
        }
    }
}
