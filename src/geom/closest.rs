//! Closest points on triangles and segments: the projections of the
//! boundary smoother and of field transfer, and the distances of Hausdorff
//! bounds.

use glam::DVec3;

/// The closest point to `p` of the triangle `(a, b, c)` and its barycentric
/// coordinates — Ericson, *Real-Time Collision Detection* (2005), §5.1.5,
/// by Voronoi regions of the vertices, edges and face.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, [f64; 3]) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// Closest point to `p` on segment `ab` (its end `a` when the segment is a point).
pub fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let l = d.length_squared();
    if l == 0.0 {
        return a;
    }
    let s = ((p - a).dot(d) / l).clamp(0.0, 1.0);
    if s == 0.0 {
        a
    } else if s == 1.0 {
        b
    } else {
        a + s * d
    }
}

/// Distance from `p` to triangle `abc`.
pub fn distance_to_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (closest_point_on_triangle(p, a, b, c).0 - p).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let (q, w) = closest_point_on_triangle(DVec3::new(0.25, 0.25, 3.0), a, b, c);
        assert_eq!(q, DVec3::new(0.25, 0.25, 0.0));
        assert!((w[0] - 0.5).abs() < 1e-15);
        assert_eq!(
            closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c).0,
            a
        );
        assert_eq!(
            closest_point_on_triangle(DVec3::new(2.0, -1.0, 0.0), a, b, c).0,
            b
        );
        let (q, w) = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((q - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
        assert!((w[1] - 0.5).abs() < 1e-15 && (w[2] - 0.5).abs() < 1e-15);
        assert_eq!(
            closest_on_segment(DVec3::new(0.5, 3.0, 0.0), a, b),
            DVec3::new(0.5, 0.0, 0.0)
        );
        // 3-4-5: the distance from (0, 0, 0) to the far edge.
        let d = distance_to_triangle(
            DVec3::ZERO,
            DVec3::new(3.0, -1.0, 4.0),
            DVec3::new(3.0, 1.0, 4.0),
            DVec3::new(3.0, 0.0, 9.0),
        );
        assert!((d - 5.0).abs() < 1e-15);
    }
}
