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

/// Whether every point of the triangles `from` lies within `limit` of the
/// union of the triangles `to` (one direction of a Hausdorff bound: call it
/// both ways for the Hausdorff distance; used by the boundary cap removal
/// and the boundary edge flip, `crate::ops`). On a triangle `S`, the distance to one
/// triangle `T` of `to` is convex, so its largest value on `S` is at a corner
/// of `S`; the distance to the union is at most the distance to any one `T`.
/// So `min over T of max over the corners of S` bounds the distance on `S`
/// from above (exactly, up to the rounding of the distances). Where that
/// bound is above `limit`, `S` is cut in four at its edge midpoints and
/// each piece is judged again, down to [`MAX_DEPTH`] cuts: pieces near the
/// seam between two `T` shrink until their bound is tight, so the answer
/// errs only on the safe side (a refusal) and only within a piece of
/// 2^-MAX_DEPTH of the face's size of the limit.
pub(crate) fn surfaces_within(from: &[[DVec3; 3]], to: &[[DVec3; 3]], limit: f64) -> bool {
    fn piece(s: [DVec3; 3], to: &[[DVec3; 3]], limit: f64, depth: u32) -> bool {
        let bound = to
            .iter()
            .map(|t| {
                s.iter()
                    .map(|&x| distance_to_triangle(x, t[0], t[1], t[2]))
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        if bound <= limit {
            return true;
        }
        // The corners themselves are farther than the limit: no cut helps.
        let corner_far = s.iter().any(|&x| {
            to.iter()
                .map(|t| distance_to_triangle(x, t[0], t[1], t[2]))
                .fold(f64::INFINITY, f64::min)
                > limit
        });
        if corner_far || depth == MAX_DEPTH {
            return false;
        }
        let [a, b, c] = s;
        let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
        [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            .into_iter()
            .all(|q| piece(q, to, limit, depth + 1))
    }
    from.iter().all(|&f| piece(f, to, limit, 0))
}

/// Deepest cut of [`surfaces_within`]: 4^8 pieces at most per face, about 2^8 along
/// a seam in practice.
const MAX_DEPTH: u32 = 8;

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

    #[test]
    fn the_distance_test_is_tight_between_parallel_squares_and_a_fold() {
        let sq = |z: f64| {
            let p = [
                DVec3::new(0.0, 0.0, z),
                DVec3::new(1.0, 0.0, z),
                DVec3::new(1.0, 1.0, z),
                DVec3::new(0.0, 1.0, z),
            ];
            [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
        };
        assert!(surfaces_within(&sq(0.25), &sq(0.0), 0.25 + 1e-15));
        assert!(!surfaces_within(&sq(0.25), &sq(0.0), 0.25 - 1e-12));
        // A flat square at z = h against the square folded along its
        // diagonal (1,0)-(0,1): corners (0,0) and (1,1) at z = 0, the other
        // two at z = 2h, i.e. the planes z = 2h(x + y) and z = 2h(2 - x - y).
        // Every point of the flat square is h / sqrt(1 + 8h²) = 0.0962 (for
        // h = 0.1) from the nearer plane, with its foot inside the fold's
        // triangle, so 0.9 h fails and 1.1 h passes, both ways.
        let h = 0.1;
        let p = [
            DVec3::new(0.0, 0.0, h),
            DVec3::new(1.0, 0.0, h),
            DVec3::new(1.0, 1.0, h),
            DVec3::new(0.0, 1.0, h),
        ];
        let flat = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
        let q = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 2.0 * h),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 2.0 * h),
        ];
        let fold = [[q[0], q[1], q[3]], [q[1], q[2], q[3]]];
        assert!(!surfaces_within(&flat, &fold, 0.9 * h));
        assert!(surfaces_within(&flat, &fold, 1.1 * h) && surfaces_within(&fold, &flat, 1.1 * h));
    }
}
