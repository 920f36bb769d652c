//! Exact orientation predicate.
//!
//! We wrap Shewchuk's adaptive-precision `orient3d` (the `robust` crate) and flip
//! its sign so that it agrees with the *signed volume* convention used by Gmsh,
//! Medit/MMG and TetGen output: a tetrahedron `(a, b, c, d)` is positively
//! oriented when `(b - a) · ((c - a) × (d - a)) > 0`, i.e. when `d` lies on the
//! side of triangle `abc` that its counter-clockwise normal points to.
//!
//! Shewchuk's own routine returns a positive value when `d` lies *below* the
//! plane of `abc` seen counter-clockwise, which is the opposite sign; mixing the
//! two conventions is the classic source of "every tet inverted" bugs, so the
//! rest of the crate only ever calls the functions in this module.

use glam::DVec3;

/// The sign of an exact orientation test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Orientation {
    /// Strictly positive signed volume.
    Positive,
    /// Exactly coplanar points.
    Zero,
    /// Strictly negative signed volume.
    Negative,
}

#[inline]
fn coord(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Six times the signed volume of `(a, b, c, d)`, with an exactly correct sign.
///
/// The magnitude is the adaptive-precision approximation of the determinant;
/// only the sign is guaranteed exact.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    -robust::orient3d(coord(a), coord(b), coord(c), coord(d))
}

/// Exact sign of the signed volume of `(a, b, c, d)`.
#[inline]
pub fn orient3d_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Orientation {
    let v = orient3d(a, b, c, d);
    if v > 0.0 {
        Orientation::Positive
    } else if v < 0.0 {
        Orientation::Negative
    } else {
        Orientation::Zero
    }
}

/// Whether the tet with corners `p` is positively oriented: exactly (the
/// exact predicate), and also as a solver computing in doubles sees it (the
/// Jacobian determinant `(p1 − p0) · ((p2 − p0) × (p3 − p0))` evaluated in
/// `f64`, as FEM codes and [`crate::geom::tet_volume`] do). A sliver can be
/// positive exactly yet negative in doubles; every operation checks its new
/// tets with this, so it refuses such tets as it refuses inverted ones.
#[inline]
pub fn is_positive(p: &[DVec3; 4]) -> bool {
    orient3d(p[0], p[1], p[2], p[3]) > 0.0 && positive_in_doubles(p)
}

/// The Jacobian determinant of the tet in plain `f64` arithmetic is > 0.
#[inline]
pub fn positive_in_doubles(p: &[DVec3; 4]) -> bool {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) > 0.0
}

/// Whether every tet (as its four corners) is positively oriented: the one
/// "all tets positive" check of the crate.
#[inline]
pub fn all_positive(tets: impl IntoIterator<Item = [DVec3; 4]>) -> bool {
    tets.into_iter().all(|p| is_positive(&p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sliver_positive_exactly_but_not_in_doubles_is_not_positive() {
        // Nearly coplanar tets: d on the plane of abc up to rounding. The
        // exact and the double-precision signs then disagree often.
        let mut state = 0x1234_5678_9ABC_DEF0u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut disagreements = 0;
        for _ in 0..10_000 {
            let mut r = || DVec3::new(next(), next(), next());
            let (a, b, c) = (r(), r(), r());
            let (s, t) = (next(), next());
            let d = a + s * (b - a) + t * (c - a);
            let p = [a, b, c, d];
            let exact = orient3d(a, b, c, d) > 0.0;
            let doubles = (b - a).dot((c - a).cross(d - a)) > 0.0;
            assert_eq!(is_positive(&p), exact && doubles);
            if exact && !doubles {
                disagreements += 1;
            }
        }
        assert!(disagreements > 100, "{disagreements}");
    }

    #[test]
    fn corner_tet_is_positive_and_swapped_is_negative() {
        let o = DVec3::ZERO;
        let x = DVec3::X;
        let y = DVec3::Y;
        let z = DVec3::Z;
        assert_eq!(orient3d_sign(o, x, y, z), Orientation::Positive);
        assert_eq!(orient3d_sign(o, y, x, z), Orientation::Negative);
        assert!((orient3d(o, x, y, z) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn nearly_coplanar_points_get_the_exact_sign() {
        // d is above the plane z = 0 by one ulp-ish amount at a large offset: a
        // naive determinant loses it to cancellation, the adaptive one does not.
        let base = 1.0e8;
        let a = DVec3::new(base, base, 0.0);
        let b = DVec3::new(base + 1.0, base, 0.0);
        let c = DVec3::new(base, base + 1.0, 0.0);
        let d = DVec3::new(base + 0.5, base + 0.5, 1e-30);
        assert_eq!(orient3d_sign(a, b, c, d), Orientation::Positive);
        let d0 = DVec3::new(base + 0.25, base + 0.5, 0.0);
        assert_eq!(orient3d_sign(a, b, c, d0), Orientation::Zero);
    }
}
