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

/// Whether the tet with corners `p` is positively oriented (exact predicate):
/// neither inverted nor flat. Every operation checks its new tets with this.
#[inline]
pub fn is_positive(p: &[DVec3; 4]) -> bool {
    orient3d(p[0], p[1], p[2], p[3]) > 0.0
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
