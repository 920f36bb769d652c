//! The dihedral-angle arithmetic of the statistics: the extreme cosines of
//! four tets at a time, a fast arc cosine for the averages, and the histogram
//! bin of a tet found from its cosine.
//!
//! Which figures come from which arithmetic, and why:
//!
//! * The six cosines of a tet are computed operation for operation as in
//!   [`crate::geom::tet_quality`] ([`cosine_extremes`]), so the extreme
//!   cosines are the same bits.
//! * Worst and best angles are the libm `acos` of the extreme cosine over a
//!   whole chunk of tets ([`exact_deg`]): `acos` is monotone, so one call per
//!   chunk gives the same bits as one per tet.
//! * The histogram bin is a monotone function of the cosine, so it is found by
//!   comparing the cosine with precomputed thresholds ([`BinThresholds`]):
//!   the same bin as the libm angle would give, without the angle.
//! * Only the averages need an angle per tet; they use [`acos_deg`], a
//!   branch-free arc cosine within 1e-15 rad of libm's, built from `+ - * /`
//!   and `sqrt` alone, so it is the same bits on every machine and in the
//!   vector and scalar code.

use crate::report::stats::Histogram;
use crate::topo::TET_EDGE_OPPOSITE;
use std::cmp::Ordering;

/// Tets whose angles are computed side by side.
pub(super) const LANES: usize = 4;

/// One `f64` per tet of a batch.
pub(super) type Lanes = [f64; LANES];

/// A point or vector per tet of a batch, coordinate-major so that the
/// compiler can use vector instructions across the batch.
#[derive(Clone, Copy)]
pub(super) struct LaneVec {
    pub x: Lanes,
    pub y: Lanes,
    pub z: Lanes,
}

#[inline(always)]
pub(super) fn lanes(f: impl Fn(usize) -> f64) -> Lanes {
    [f(0), f(1), f(2), f(3)]
}

impl LaneVec {
    #[inline(always)]
    fn sub(self, o: LaneVec) -> LaneVec {
        LaneVec {
            x: lanes(|i| self.x[i] - o.x[i]),
            y: lanes(|i| self.y[i] - o.y[i]),
            z: lanes(|i| self.z[i] - o.z[i]),
        }
    }

    /// glam's `DVec3::cross`, operation for operation.
    #[inline(always)]
    fn cross(self, o: LaneVec) -> LaneVec {
        LaneVec {
            x: lanes(|i| self.y[i] * o.z[i] - o.y[i] * self.z[i]),
            y: lanes(|i| self.z[i] * o.x[i] - o.z[i] * self.x[i]),
            z: lanes(|i| self.x[i] * o.y[i] - o.x[i] * self.y[i]),
        }
    }

    /// glam's `DVec3::dot`, operation for operation.
    #[inline(always)]
    fn dot(self, o: LaneVec) -> Lanes {
        lanes(|i| (self.x[i] * o.x[i]) + (self.y[i] * o.y[i]) + (self.z[i] * o.z[i]))
    }
}

/// What the statistics need of the dihedral angles of a batch of tets.
pub(super) struct CosineExtremes {
    /// Largest of the six cosines (the smallest angle).
    pub max_cos: Lanes,
    /// Smallest of the six cosines (the largest angle).
    pub min_cos: Lanes,
    /// Whether every face has a finite reciprocal length (no zero-area face).
    pub proper: [bool; LANES],
    /// Six times the signed volume.
    pub d: Lanes,
    /// `|a|²|b|²|c|²` for the edge vectors `a, b, c` from corner 0 (see
    /// [`super::is_inverted`]).
    pub edge_product: Lanes,
}

/// The extreme cosines, `D` and the edge product of each tet of a batch
/// (corner `j` of tet `i` in lane `i` of `p[j]`).
///
/// The arithmetic is that of [`crate::geom::tet_quality`], operation for
/// operation and in the same order, so the cosines are the same bits; the
/// sines, which the statistics do not need, are left out.
#[inline(always)]
pub(super) fn cosine_extremes(p: &[LaneVec; 4]) -> CosineExtremes {
    let e1 = p[1].sub(p[0]);
    let e2 = p[2].sub(p[0]);
    let e3 = p[3].sub(p[0]);
    let n = [
        p[2].sub(p[1]).cross(p[3].sub(p[1])),
        e3.cross(e2),
        e1.cross(e3),
        e2.cross(e1),
    ];
    // DVec3::length_recip = 1 / sqrt(dot(v, v)).
    let recip_len = |v: LaneVec| {
        let l2 = v.dot(v);
        lanes(|i| 1.0 / l2[i].sqrt())
    };
    let inv = [
        recip_len(n[0]),
        recip_len(n[1]),
        recip_len(n[2]),
        recip_len(n[3]),
    ];
    let d = e1.dot(e2.cross(e3));
    let (l1, l2, l3) = (e1.dot(e1), e2.dot(e2), e3.dot(e3));
    let edge_product = lanes(|i| l1[i] * l2[i] * l3[i]);
    let mut max_cos = [f64::NEG_INFINITY; LANES];
    let mut min_cos = [f64::INFINITY; LANES];
    for &[k, l] in &TET_EDGE_OPPOSITE {
        let dot = n[k].dot(n[l]);
        for i in 0..LANES {
            let s = inv[k][i] * inv[l][i];
            let cos = -dot[i] * s;
            // f64::max/min of tet_quality, written as selects (one vector
            // instruction each): the same results, as the running extremes
            // start at ∓∞ and never become NaN, and a NaN cosine is skipped
            // by both forms.
            max_cos[i] = if cos > max_cos[i] { cos } else { max_cos[i] };
            min_cos[i] = if cos < min_cos[i] { cos } else { min_cos[i] };
        }
    }
    let proper = std::array::from_fn(|i| (0..4).all(|f| inv[f][i].is_finite()));
    CosineExtremes {
        max_cos,
        min_cos,
        proper,
        d,
        edge_product,
    }
}

/// The angle in degrees of cosine `c` as [`crate::geom::tet_quality`] computes
/// it (libm `acos` of the clamped cosine).
#[inline]
pub(super) fn exact_deg(c: f64) -> f64 {
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

// The rational approximation asin(s) ≈ s + s·z·P(z)/Q(z), z = s², of fdlibm's
// e_asin.c / e_acos.c (Sun Microsystems, 1993), with its published
// coefficients (written as published, more digits than an f64 holds, so
// that they can be checked against the source); on 0 ≤ s ≤ 1/2 its error is
// below 2^-58.75.
#[allow(clippy::excessive_precision)]
const P_S0: f64 = 1.666_666_666_666_666_574_15e-1;
#[allow(clippy::excessive_precision)]
const P_S1: f64 = -3.255_658_186_224_009_154_05e-1;
#[allow(clippy::excessive_precision)]
const P_S2: f64 = 2.012_125_321_348_629_258_81e-1;
#[allow(clippy::excessive_precision)]
const P_S3: f64 = -4.005_553_450_067_941_140_27e-2;
#[allow(clippy::excessive_precision)]
const P_S4: f64 = 7.915_349_942_898_145_321_76e-4;
#[allow(clippy::excessive_precision)]
const P_S5: f64 = 3.479_331_075_960_211_675_70e-5;
#[allow(clippy::excessive_precision)]
const Q_S1: f64 = -2.403_394_911_734_414_218_78;
#[allow(clippy::excessive_precision)]
const Q_S2: f64 = 2.020_945_760_233_505_694_71;
#[allow(clippy::excessive_precision)]
const Q_S3: f64 = -6.882_839_716_054_532_930_30e-1;
#[allow(clippy::excessive_precision)]
const Q_S4: f64 = 7.703_815_055_590_193_527_91e-2;

/// `acos(x).to_degrees()` for each lane, `x` clamped to `[-1, 1]`, within
/// 1e-15 rad (6e-14°) of libm; see `fast_acos_is_within_1e_15_of_libm`.
///
/// fdlibm's reduction without branches: for `|x| ≤ 1/2`,
/// `acos x = π/2 − asin x`; for `|x| > 1/2`, with `s = sqrt((1 − |x|)/2)`,
/// `acos |x| = 2 asin s` and `acos(−|x|) = π − 2 asin s`. Both arguments are
/// computed for every lane and the right one selected, so the loop
/// vectorises; only `+ - * /` and `sqrt` are used, each correctly rounded,
/// so the result does not depend on the machine or the vector width.
#[inline(always)]
pub(super) fn acos_deg(x: Lanes) -> Lanes {
    use std::f64::consts::{FRAC_PI_2, PI};
    // One operation at a time across the lanes, selects instead of branches,
    // so that each line becomes one vector instruction.
    // Clamped as by f64::clamp (a NaN stays NaN), in selects.
    let x = lanes(|i| {
        let x = if x[i] < -1.0 { -1.0 } else { x[i] };
        if x > 1.0 {
            1.0
        } else {
            x
        }
    });
    let a = lanes(|i| x[i].abs());
    let big = std::array::from_fn::<bool, LANES, _>(|i| a[i] > 0.5);
    let z_big = lanes(|i| (1.0 - a[i]) * 0.5);
    let z = lanes(|i| if big[i] { z_big[i] } else { x[i] * x[i] });
    let root = lanes(|i| z_big[i].sqrt());
    let s = lanes(|i| if big[i] { root[i] } else { a[i] });
    let p = lanes(|i| {
        let z = z[i];
        z * (P_S0 + z * (P_S1 + z * (P_S2 + z * (P_S3 + z * (P_S4 + z * P_S5)))))
    });
    let q = lanes(|i| {
        let z = z[i];
        1.0 + z * (Q_S1 + z * (Q_S2 + z * (Q_S3 + z * Q_S4)))
    });
    let asin_s = lanes(|i| s[i] + s[i] * (p[i] / q[i]));
    let twice = lanes(|i| 2.0 * asin_s[i]);
    let positive = std::array::from_fn::<bool, LANES, _>(|i| x[i] > 0.0);
    let rad = lanes(|i| match (big[i], positive[i]) {
        (true, true) => twice[i],
        (true, false) => PI - twice[i],
        (false, true) => FRAC_PI_2 - asin_s[i],
        (false, false) => FRAC_PI_2 + asin_s[i],
    });
    lanes(|i| rad[i].to_degrees())
}

/// The histogram bin of a tet as a function of its largest cosine `c`:
/// `bin(c) = histogram.bin(exact_deg(c))`, found by comparisons.
///
/// That function is non-increasing in `c` (`acos` decreases, the bin grows
/// with the angle), so for each bin `k ≥ 1` the cosines with `bin ≥ k` are
/// those `≤ τ_k`, where `τ_k` is the largest such float, found once per
/// histogram by bisection over the floats of `[-1, 1]` with libm itself.
/// Comparing with the thresholds then gives exactly the bin of the libm
/// angle, even for angles on a bin edge (such as the 45° of the cube grid).
pub(super) struct BinThresholds {
    /// `tau[k]` for `k = 0..=n`; `tau[0] = +∞` and `tau[n] = -∞` (no cosine
    /// reaches bin `n`).
    tau: Vec<f64>,
    /// The histogram's lower end and bins per degree, for first guesses.
    lo_deg: f64,
    per_deg: f64,
}

/// Position of `x` in the order of the floats (monotone, for bisection).
fn float_key(x: f64) -> i64 {
    let b = x.to_bits() as i64;
    if b < 0 {
        -(b & i64::MAX)
    } else {
        b
    }
}

fn key_float(k: i64) -> f64 {
    if k < 0 {
        f64::from_bits((-k) as u64 | (1 << 63))
    } else {
        f64::from_bits(k as u64)
    }
}

impl BinThresholds {
    /// Thresholds of `histogram`'s bins (about 200 libm calls for 71 bins).
    pub fn new(histogram: &Histogram) -> BinThresholds {
        let n = histogram.counts.len();
        let bin = |c: f64| histogram.bin(exact_deg(c));
        let (lo, hi) = (float_key(-1.0), float_key(1.0));
        let mut tau = vec![f64::INFINITY; n + 1];
        tau[n] = f64::NEG_INFINITY;
        for (k, t) in tau.iter_mut().enumerate().take(n).skip(1) {
            if bin(1.0) >= k {
                continue; // every cosine: +∞
            }
            if bin(-1.0) < k {
                *t = f64::NEG_INFINITY; // no cosine
                continue;
            }
            // bin(key_float(a)) ≥ k > bin(key_float(b)); start from a guess
            // near cos(edge) and widen geometrically until it brackets.
            let edge = histogram.edges_deg[k].clamp(0.0, 180.0).to_radians().cos();
            let guess = float_key(edge).clamp(lo, hi);
            let (mut a, mut b);
            if bin(key_float(guess)) >= k {
                a = guess;
                let mut step = 1;
                loop {
                    b = (a + step).min(hi);
                    if bin(key_float(b)) < k {
                        break;
                    }
                    a = b;
                    step *= 2;
                }
            } else {
                b = guess;
                let mut step = 1;
                loop {
                    a = (b - step).max(lo);
                    if bin(key_float(a)) >= k {
                        break;
                    }
                    b = a;
                    step *= 2;
                }
            }
            while b - a > 1 {
                let m = a + (b - a) / 2;
                if bin(key_float(m)) >= k {
                    a = m;
                } else {
                    b = m;
                }
            }
            *t = key_float(a);
        }
        let (lo_deg, hi_deg) = (histogram.edges_deg[0], histogram.edges_deg[n]);
        let per_deg = n as f64 / (hi_deg - lo_deg);
        BinThresholds {
            tau,
            lo_deg,
            per_deg: if per_deg.is_finite() { per_deg } else { 0.0 },
        }
    }

    /// First guesses of the bins of angles `deg` (close to the exact angles),
    /// for [`BinThresholds::bin`]; any value is correct, a close one is fast.
    #[inline(always)]
    pub fn estimates(&self, deg: Lanes) -> [usize; LANES] {
        let y = lanes(|i| ((deg[i] - self.lo_deg) * self.per_deg).max(0.0));
        std::array::from_fn(|i| y[i] as u32 as usize)
    }

    /// Bin of largest cosine `c`, starting the search from bin `estimate`
    /// (from an angle close to the exact one, so usually no step is taken).
    #[inline(always)]
    pub fn bin(&self, c: f64, estimate: usize) -> usize {
        let n = self.tau.len() - 1;
        let mut b = estimate.min(n - 1);
        while b + 1 < n && c <= self.tau[b + 1] {
            b += 1;
        }
        // Not `c > tau`: a NaN cosine must end in bin 0, as its NaN angle does.
        let at_most =
            |tau: f64| matches!(c.partial_cmp(&tau), Some(Ordering::Less | Ordering::Equal));
        while b > 0 && !at_most(self.tau[b]) {
            b -= 1;
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xorshift(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn fast_acos_is_within_1e_15_of_libm() {
        let mut rnd = xorshift(3);
        let mut xs: Vec<f64> = (0..=200_000).map(|i| -1.0 + i as f64 / 100_000.0).collect();
        xs.extend((0..200_000).map(|_| 2.0 * rnd() - 1.0));
        // Near the ends and the switch points of the reduction, ulp by ulp.
        for c in [-1.0f64, -0.5, 0.0, 0.5, 1.0] {
            let k = float_key(c);
            xs.extend((-2000..=2000).map(|d| key_float(k + d).clamp(-1.0, 1.0)));
        }
        xs.extend([-0.0, f64::MIN_POSITIVE, 1e-300, -1e-17]);
        let mut worst = 0.0f64;
        for chunk in xs.chunks_exact(LANES) {
            let fast = acos_deg([chunk[0], chunk[1], chunk[2], chunk[3]]);
            for (&x, &f) in chunk.iter().zip(&fast) {
                worst = worst.max((f.to_radians() - x.acos()).abs());
            }
        }
        assert!(worst < 1e-15, "max error {worst:e} rad");
        // Clamping, as exact_deg does.
        assert_eq!(acos_deg([1.5, -7.0, 1.0, -1.0]), [0.0, 180.0, 0.0, 180.0]);
    }

    #[test]
    fn thresholds_give_the_bin_of_the_libm_angle() {
        let mut rnd = xorshift(11);
        for h in [
            Histogram::new(0.0, 71.0, 71),
            Histogram::new(0.0, 71.0, 10),
            Histogram::new(0.0, 180.0, 7),
            Histogram::new(-10.0, 200.0, 13),
            Histogram::new(30.0, 31.0, 1),
        ] {
            let thresholds = BinThresholds::new(&h);
            let mut cs: Vec<f64> = (0..20_000).map(|_| 2.0 * rnd() - 1.0).collect();
            // The cosines next to every bin edge, ulp by ulp: where a fast
            // angle could land on the wrong side.
            for e in &h.edges_deg {
                let k = float_key(e.to_radians().cos());
                cs.extend((-40..=40).map(|d| key_float(k + d)));
            }
            cs.extend([1.0, -1.0, 0.0, 2.0, -2.0, f64::NAN, f64::INFINITY]);
            // The cube grid's 45°, and the regular tet's 70.53°.
            cs.extend([std::f64::consts::FRAC_1_SQRT_2, 1.0 / 3.0]);
            for c in cs {
                let want = h.bin(exact_deg(c));
                for estimate in [0, want.saturating_sub(1), want, want + 1, 1000] {
                    assert_eq!(thresholds.bin(c, estimate), want, "{c:e} {h:?}");
                }
            }
        }
    }
}
