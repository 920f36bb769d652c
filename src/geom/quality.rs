//! Dihedral angles, the signed minimum-sine quality measure and volumes.
//!
//! Local numbering: that of [`crate::topo`] (sketch below); face `f` is
//! opposite vertex `f`.
//!
//! ```text
//!            3
//!           /|\          edges: 0:(0,1) 1:(0,2) 2:(0,3)
//!          / | \                3:(1,2) 4:(1,3) 5:(2,3)
//!         /  |  \        face f = the triangle without vertex f,
//!        0---|---2       outward-oriented as TET_FACES[f]
//!         \  |  /
//!          \ | /
//!            1
//! ```
//!
//! For a positively oriented tet with `D = (v1-v0)·((v2-v0)×(v3-v0))` (six times
//! the volume) and outward face normals `n_f` of length twice the face area, the
//! dihedral angle `θ` at edge `ij` between the faces opposite `k` and `l` has
//!
//! * `cos θ = -n_k·n_l / (|n_k| |n_l|)`
//! * `sin θ = D |v_j - v_i| / (|n_k| |n_l|)`  (the `3V·ℓ / (2 A_k A_l)` identity)
//!
//! The second form keeps the sign of `D`, so it is the *signed* sine that the
//! √3 paper (Burkhart, Hamann and Umlauf, "Adaptive and feature-preserving
//! subdivision for high-quality tetrahedral meshes", §2.3) uses as its quality:
//! the minimum over the six edges, 0.9428 (= sin 70.53°) for the regular tet,
//! negative for an inverted one.

use crate::topo::{TET_EDGES, TET_EDGE_OPPOSITE};
use glam::DVec3;

/// Shape figures of one tetrahedron.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetQuality {
    /// Minimum over the six edges of the sine of the signed dihedral angle.
    pub min_sine: f64,
    /// Smallest dihedral angle in degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle in degrees.
    pub max_dihedral_deg: f64,
    /// Signed volume.
    pub volume: f64,
}

/// Signed volume of the tet `p` (positive for the crate's orientation).
#[inline]
pub fn tet_volume(p: &[DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

/// Outward normals (length = twice the face area) of the four faces.
#[inline]
fn face_normals(p: &[DVec3; 4]) -> [DVec3; 4] {
    [
        (p[2] - p[1]).cross(p[3] - p[1]),
        (p[3] - p[0]).cross(p[2] - p[0]),
        (p[1] - p[0]).cross(p[3] - p[0]),
        (p[2] - p[0]).cross(p[1] - p[0]),
    ]
}

/// The six dihedral angles in radians, in the order of [`TET_EDGES`].
///
/// Each angle lies in `[0, π]` for a positively oriented tet; for an inverted
/// tet the angles are measured with the signed sine and so fall in `[-π, 0]`.
pub fn dihedral_angles(p: &[DVec3; 4]) -> [f64; 6] {
    let n = face_normals(p);
    let d = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
    let mut out = [0.0; 6];
    for (e, (&[i, j], &[k, l])) in TET_EDGES.iter().zip(TET_EDGE_OPPOSITE.iter()).enumerate() {
        let denom = n[k].length() * n[l].length();
        if denom == 0.0 {
            out[e] = 0.0;
            continue;
        }
        let cos = -n[k].dot(n[l]) / denom;
        let sin = d * (p[j] - p[i]).length() / denom;
        out[e] = sin.atan2(cos);
    }
    out
}

/// Quality figures of one tet: min signed sine, min/max dihedral, volume.
///
/// Degenerate tets (a face of zero area) get quality 0 and angles 0/180.
#[inline]
pub fn tet_quality(p: &[DVec3; 4]) -> TetQuality {
    let n = face_normals(p);
    let inv = [
        n[0].length_recip(),
        n[1].length_recip(),
        n[2].length_recip(),
        n[3].length_recip(),
    ];
    let d = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
    let volume = d / 6.0;
    if !inv.iter().all(|x| x.is_finite()) {
        return TetQuality {
            min_sine: 0.0,
            min_dihedral_deg: 0.0,
            max_dihedral_deg: 180.0,
            volume,
        };
    }
    let mut min_sine = f64::INFINITY;
    let mut max_cos = f64::NEG_INFINITY;
    let mut min_cos = f64::INFINITY;
    for (&[i, j], &[k, l]) in TET_EDGES.iter().zip(TET_EDGE_OPPOSITE.iter()) {
        let s = inv[k] * inv[l];
        let cos = -n[k].dot(n[l]) * s;
        let sin = d * (p[j] - p[i]).length() * s;
        min_sine = min_sine.min(sin);
        max_cos = max_cos.max(cos);
        min_cos = min_cos.min(cos);
    }
    // The angle is monotone in its cosine on [0, π], so the extreme angles come
    // from the extreme cosines: two acos instead of six atan2.
    let (mut lo, mut hi) = (
        max_cos.clamp(-1.0, 1.0).acos().to_degrees(),
        min_cos.clamp(-1.0, 1.0).acos().to_degrees(),
    );
    if d < 0.0 {
        // Inverted: report the angles of the signed-sine convention.
        (lo, hi) = (-hi, -lo);
    }
    TetQuality {
        min_sine,
        min_dihedral_deg: lo,
        max_dihedral_deg: hi,
        volume,
    }
}

/// Minimum signed sine of the dihedral angles only (the optimiser's objective).
///
/// With `D` six times the signed volume, `sin θ_ij = D |e_ij| / (|n_k| |n_l|)`,
/// so the minimum over the edges is `D · sqrt(min_ij |e_ij|² / (|n_k|² |n_l|²))`
/// for `D > 0` (the max for `D < 0`): one square root instead of ten. Edge
/// `ij` lies on the faces opposite `k` and `l`, so with `N` the product of
/// the four `|n|²`, `1 / (|n_k|² |n_l|²) = |n_i|² |n_j|² / N`: one division
/// instead of four. `N` grows as the sixteenth power of the tet's size, so
/// it stays a normal `f64` for edge lengths from 1e-19 to 1e19 — every
/// unit a mesh is written in; a tet below that range reads as degenerate
/// (quality 0), never as good.
#[inline]
pub fn tet_min_sine(p: &[DVec3; 4]) -> f64 {
    let n = face_normals(p);
    // n[3] = (p2 - p0) × (p1 - p0), so D = (p1 - p0) · ((p2 - p0) × (p3 - p0))
    // = -(p3 - p0) · n[3].
    let d = -(p[3] - p[0]).dot(n[3]);
    let n2 = [
        n[0].length_squared(),
        n[1].length_squared(),
        n[2].length_squared(),
        n[3].length_squared(),
    ];
    let all = n2[0] * n2[1] * n2[2] * n2[3];
    if !all.is_normal() {
        return if all.is_nan() { f64::NAN } else { 0.0 };
    }
    let mut lo = f64::INFINITY;
    let mut hi = 0.0f64;
    for &[i, j] in TET_EDGES.iter() {
        let r = (p[j] - p[i]).length_squared() * n2[i] * n2[j];
        lo = lo.min(r);
        hi = hi.max(r);
    }
    d * (if d >= 0.0 { lo } else { hi } / all).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn regular() -> [DVec3; 4] {
        [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ]
    }

    fn positive(mut p: [DVec3; 4]) -> [DVec3; 4] {
        if tet_volume(&p) < 0.0 {
            p.swap(0, 1);
        }
        p
    }

    #[test]
    fn regular_tet_has_arccos_one_third_everywhere() {
        let p = positive(regular());
        let expect = (1.0f64 / 3.0).acos().to_degrees(); // 70.528779...
        assert!((expect - 70.5288).abs() < 1e-4);
        for a in dihedral_angles(&p) {
            assert!((a.to_degrees() - expect).abs() < 1e-12);
        }
        let q = tet_quality(&p);
        assert!((q.min_dihedral_deg - expect).abs() < 1e-9);
        assert!((q.max_dihedral_deg - expect).abs() < 1e-9);
        // sin(arccos(1/3)) = 2√2/3 = 0.942809...
        assert!((q.min_sine - 2.0 * 2f64.sqrt() / 3.0).abs() < 1e-12);
        assert!((tet_min_sine(&p) - q.min_sine).abs() < 1e-15);
    }

    #[test]
    fn corner_tet_has_three_right_angles_and_three_of_54_7356() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let mut a: Vec<f64> = dihedral_angles(&p).iter().map(|x| x.to_degrees()).collect();
        a.sort_by(f64::total_cmp);
        // arccos(1/√3) = 54.7356103...
        let small = (1.0 / 3f64.sqrt()).acos().to_degrees();
        assert!((small - 54.7356).abs() < 1e-4);
        for x in &a[..3] {
            assert!((x - small).abs() < 1e-12, "{a:?}");
        }
        for x in &a[3..] {
            assert!((x - 90.0).abs() < 1e-12, "{a:?}");
        }
        let q = tet_quality(&p);
        assert!((q.volume - 1.0 / 6.0).abs() < 1e-15);
        assert!((q.min_dihedral_deg - small).abs() < 1e-9);
        assert!((q.max_dihedral_deg - 90.0).abs() < 1e-9);
    }

    #[test]
    fn sliver_has_angles_near_zero_and_180() {
        // Four points almost on a square in the plane z=0: the classic sliver.
        let h = 1e-4;
        let p = positive([
            DVec3::new(0.0, 0.0, h),
            DVec3::new(1.0, 1.0, h),
            DVec3::new(1.0, 0.0, -h),
            DVec3::new(0.0, 1.0, -h),
        ]);
        let q = tet_quality(&p);
        assert!(q.volume > 0.0);
        assert!(q.min_dihedral_deg < 0.1, "{q:?}");
        assert!(q.max_dihedral_deg > 179.9, "{q:?}");
        assert!(q.min_sine > 0.0 && q.min_sine < 1e-3);
    }

    #[test]
    fn inverted_tet_has_negative_quality() {
        let p = [DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Z];
        let q = tet_quality(&p);
        assert!(q.volume < 0.0);
        assert!(q.min_sine < 0.0);
        assert!(tet_min_sine(&p) < 0.0);
        assert!(q.min_dihedral_deg < 0.0);
    }

    #[test]
    fn fast_and_angle_forms_agree_on_random_tets() {
        let mut s = 12345u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..1000 {
            let p = positive([
                DVec3::new(rnd(), rnd(), rnd()),
                DVec3::new(rnd(), rnd(), rnd()),
                DVec3::new(rnd(), rnd(), rnd()),
                DVec3::new(rnd(), rnd(), rnd()),
            ]);
            let a = dihedral_angles(&p);
            let lo = a.iter().cloned().fold(f64::INFINITY, f64::min).to_degrees();
            let hi = a
                .iter()
                .cloned()
                .fold(f64::NEG_INFINITY, f64::max)
                .to_degrees();
            let q = tet_quality(&p);
            assert!((q.min_dihedral_deg - lo).abs() < 1e-6);
            assert!((q.max_dihedral_deg - hi).abs() < 1e-6);
            let smin = a.iter().map(|x| x.sin()).fold(f64::INFINITY, f64::min);
            assert!((q.min_sine - smin).abs() < 1e-9);
            assert!((tet_min_sine(&p) - smin).abs() < 1e-9);
            // Inverted copy: the signed sine flips sign.
            let inv = [p[1], p[0], p[2], p[3]];
            assert!(
                (tet_min_sine(&inv) + a.iter().map(|x| x.sin()).fold(f64::NEG_INFINITY, f64::max))
                    .abs()
                    < 1e-9
            );
        }
    }

    /// The one-division form holds over the documented range of sizes:
    /// the regular tet's 2√2/3 at edge lengths 1e-15 and 1e15, and a flat
    /// tet reads 0.
    #[test]
    fn min_sine_is_scale_free_over_the_range() {
        let p = positive(regular());
        for s in [1e-15, 1e-6, 1.0, 1e6, 1e15] {
            let q = p.map(|x| x * s);
            assert!(
                (tet_min_sine(&q) - 2.0 * 2f64.sqrt() / 3.0).abs() < 1e-12,
                "{s}"
            );
        }
        let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::X + DVec3::Y];
        assert_eq!(tet_min_sine(&flat), 0.0);
    }
}
