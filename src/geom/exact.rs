//! Orientation signs that are exact for *every* pair of finite doubles.
//!
//! Shewchuk's adaptive predicates ([`crate::geom::orient3d`]) are exact only
//! while no intermediate product overflows or underflows: with coordinates
//! near 1e±300, or a model of size 1 holding a coordinate of 1e-310, the
//! products of three coordinate differences leave the doubles' range and the
//! sign may be wrong. The functions here have no such precondition:
//!
//! * **fast path**: the points are scaled by the power of two `2^-E` that
//!   brings their largest coordinate into [1, 2). If every scaled coordinate
//!   is exactly what it was times `2^-E` (checked by scaling back) and a whole
//!   multiple of `2^-300`, then every difference and every product the
//!   expansion arithmetic forms is a multiple of `2^-900` (nonzero ones are at
//!   least `2^-900`, far above the smallest normal double `2^-1022`) and below
//!   `2^20` in magnitude, so neither underflow nor overflow can occur and
//!   Shewchuk's arithmetic is exact. Scaling by a power of two does not change
//!   a sign.
//! * **otherwise** (a model spanning more than 2^300 in magnitude, subnormal
//!   coordinates, or a largest coordinate beyond 2^±1000): every coordinate is
//!   written as an integer times `2^emin` (the smallest exponent among them),
//!   and the determinant is evaluated in exact big-integer arithmetic.

use glam::DVec3;

/// Sign of `(b − a) · ((c − a) × (d − a))`: 1, 0 or −1, exactly (the sign
/// convention of [`crate::geom::orient3d`]).
pub fn orient3d_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let pts = [a, b, c, d];
    let coords: Vec<f64> = pts.iter().flat_map(|p| p.to_array()).collect();
    if let Some(s) = fast_scale(&coords) {
        let v = crate::geom::orient3d(a * s, b * s, c * s, d * s);
        return sign(v);
    }
    big3(&coords)
}

/// [`orient3d_exact`] in big-integer arithmetic, on `a, b, c, d` flattened.
fn big3(coords: &[f64]) -> i8 {
    let [ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz] = integers(coords);
    let (u_x, u_y, u_z) = (bx.sub(&ax), by.sub(&ay), bz.sub(&az));
    let (cax, cay, caz) = (cx.sub(&ax), cy.sub(&ay), cz.sub(&az));
    let (dax, day, daz) = (dx.sub(&ax), dy.sub(&ay), dz.sub(&az));
    let m1 = cay.mul(&daz).sub(&caz.mul(&day));
    let m2 = cax.mul(&daz).sub(&caz.mul(&dax));
    let m3 = cax.mul(&day).sub(&cay.mul(&dax));
    u_x.mul(&m1).sub(&u_y.mul(&m2)).add(&u_z.mul(&m3)).sign()
}

/// Sign of `(b − a) × (c − a)` (counter-clockwise positive), exactly.
pub fn orient2d_exact(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i8 {
    let coords = [a[0], a[1], b[0], b[1], c[0], c[1]];
    if let Some(s) = fast_scale(&coords) {
        let k = |p: [f64; 2]| robust::Coord {
            x: p[0] * s,
            y: p[1] * s,
        };
        return sign(robust::orient2d(k(a), k(b), k(c)));
    }
    let [ax, ay, bx, by, cx, cy] = integers(&coords);
    let (u_x, u_y) = (bx.sub(&ax), by.sub(&ay));
    let (cax, cay) = (cx.sub(&ax), cy.sub(&ay));
    u_x.mul(&cay).sub(&u_y.mul(&cax)).sign()
}

fn sign(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// The power of two of the fast path (see the module documentation), or
/// `None` when the big-integer path is needed.
fn fast_scale(coords: &[f64]) -> Option<f64> {
    let m = coords.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if m == 0.0 {
        return Some(1.0);
    }
    // Unbiased exponent of the largest coordinate (normal numbers only).
    let e = ((m.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    if !(-1000..=1000).contains(&e) || !m.is_finite() {
        return None;
    }
    let s = f64::from_bits(((1023 - e) as u64) << 52); // 2^-e, a normal double
    let back = f64::from_bits(((1023 + e) as u64) << 52); // 2^e
    let grid = f64::from_bits(((1023 + 300) as u64) << 52); // 2^300
    coords
        .iter()
        .all(|&c| {
            let x = c * s;
            x * back == c && (x * grid).fract() == 0.0
        })
        .then_some(s)
}

/// Each coordinate as an exact integer times `2^emin` (the same `emin` for all).
fn integers<const N: usize>(coords: &[f64]) -> [Big; N] {
    let parts: Vec<(i64, i32)> = coords.iter().map(|&c| decompose(c)).collect();
    let emin = parts
        .iter()
        .filter(|(m, _)| *m != 0)
        .map(|&(_, e)| e)
        .min()
        .unwrap_or(0);
    std::array::from_fn(|i| {
        let (m, e) = parts[i];
        Big::from_shifted(m, (e - emin) as u32)
    })
}

/// A finite double as `m · 2^e` with `|m| < 2^53`.
fn decompose(c: f64) -> (i64, i32) {
    let bits = c.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1i64 << 52), exp - 1075)
    };
    (if c.is_sign_negative() { -m } else { m }, e)
}

/// A signed big integer: magnitude in little-endian 64-bit limbs (no
/// trailing zero limbs; zero is the empty vector and never negative).
#[derive(Clone, Debug)]
struct Big {
    neg: bool,
    mag: Vec<u64>,
}

impl Big {
    fn from_shifted(m: i64, shift: u32) -> Big {
        let v = m.unsigned_abs();
        let (limb, bit) = ((shift / 64) as usize, shift % 64);
        let mut mag = vec![0u64; limb + 2];
        mag[limb] = v << bit;
        if bit > 0 {
            mag[limb + 1] = v >> (64 - bit);
        }
        Big::norm(m < 0, mag)
    }

    fn norm(neg: bool, mut mag: Vec<u64>) -> Big {
        while mag.last() == Some(&0) {
            mag.pop();
        }
        Big {
            neg: neg && !mag.is_empty(),
            mag,
        }
    }

    fn sign(&self) -> i8 {
        if self.mag.is_empty() {
            0
        } else if self.neg {
            -1
        } else {
            1
        }
    }

    fn cmp_mag(a: &[u64], b: &[u64]) -> std::cmp::Ordering {
        a.len()
            .cmp(&b.len())
            .then_with(|| a.iter().rev().cmp(b.iter().rev()))
    }

    fn add_mag(a: &[u64], b: &[u64]) -> Vec<u64> {
        let mut out = Vec::with_capacity(a.len().max(b.len()) + 1);
        let mut carry = 0u64;
        for i in 0..a.len().max(b.len()) {
            let (x, c1) = a.get(i).copied().unwrap_or(0).overflowing_add(carry);
            let (y, c2) = x.overflowing_add(b.get(i).copied().unwrap_or(0));
            out.push(y);
            carry = u64::from(c1) + u64::from(c2);
        }
        out.push(carry);
        out
    }

    /// `a − b` for `|a| ≥ |b|`.
    fn sub_mag(a: &[u64], b: &[u64]) -> Vec<u64> {
        let mut out = Vec::with_capacity(a.len());
        let mut borrow = 0u64;
        for (i, &x) in a.iter().enumerate() {
            let (y, b1) = x.overflowing_sub(b.get(i).copied().unwrap_or(0));
            let (z, b2) = y.overflowing_sub(borrow);
            out.push(z);
            borrow = u64::from(b1) + u64::from(b2);
        }
        out
    }

    fn add(&self, o: &Big) -> Big {
        if self.neg == o.neg {
            return Big::norm(self.neg, Big::add_mag(&self.mag, &o.mag));
        }
        match Big::cmp_mag(&self.mag, &o.mag) {
            std::cmp::Ordering::Less => Big::norm(o.neg, Big::sub_mag(&o.mag, &self.mag)),
            _ => Big::norm(self.neg, Big::sub_mag(&self.mag, &o.mag)),
        }
    }

    fn sub(&self, o: &Big) -> Big {
        self.add(&Big {
            neg: !o.neg && !o.mag.is_empty(),
            mag: o.mag.clone(),
        })
    }

    fn mul(&self, o: &Big) -> Big {
        let mut out = vec![0u64; self.mag.len() + o.mag.len() + 1];
        for (i, &x) in self.mag.iter().enumerate() {
            let mut carry = 0u128;
            for (j, &y) in o.mag.iter().enumerate() {
                let t = out[i + j] as u128 + x as u128 * y as u128 + carry;
                out[i + j] = t as u64;
                carry = t >> 64;
            }
            let mut k = i + o.mag.len();
            while carry > 0 {
                let t = out[k] as u128 + carry;
                out[k] = t as u64;
                carry = t >> 64;
                k += 1;
            }
        }
        Big::norm(self.neg != o.neg, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive3(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
        sign(crate::geom::orient3d(a, b, c, d))
    }

    #[test]
    fn agrees_with_the_adaptive_predicate_where_that_one_is_exact() {
        let mut state = 0x0123_4567_89AB_CDEFu64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..2000 {
            let mut r = || DVec3::new(next(), next(), next());
            let (a, b, c) = (r(), r(), r());
            // Every other case nearly coplanar.
            let d = if i % 2 == 0 {
                let (s, t) = (next(), next());
                a + s * (b - a) + t * (c - a)
            } else {
                r()
            };
            assert_eq!(orient3d_exact(a, b, c, d), naive3(a, b, c, d));
            // The big-integer path on the same points.
            let flat: Vec<f64> = [a, b, c, d].iter().flat_map(|p| p.to_array()).collect();
            assert_eq!(big3(&flat), naive3(a, b, c, d), "{i}");
        }
    }

    #[test]
    fn huge_and_tiny_coordinates_get_the_right_sign() {
        for s in [1e300, 1e-300, 1e308, 5e-324 * 2f64.powi(60)] {
            let o = DVec3::ZERO;
            let (x, y, z) = (DVec3::X * s, DVec3::Y * s, DVec3::Z * s);
            assert_eq!(orient3d_exact(o, x, y, z), 1, "{s}");
            assert_eq!(orient3d_exact(o, y, x, z), -1, "{s}");
            assert_eq!(orient3d_exact(o, x, y, x + y), 0, "{s}");
            assert_eq!(orient2d_exact([0.0, 0.0], [s, 0.0], [0.0, s]), 1);
            assert_eq!(orient2d_exact([0.0, 0.0], [s, 0.0], [2.0 * s, 0.0]), 0);
        }
        // A unit model with a coordinate of 1e-310: the adaptive predicate's
        // products underflow, the exact one keeps the sign.
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.0, 1e-160, 0.0);
        let d = DVec3::new(0.0, 0.0, 1e-160);
        assert_eq!(orient3d_exact(a, b, c, d), 1);
        assert_eq!(orient3d_exact(a, b, d, c), -1);
    }
}
