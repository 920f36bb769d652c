//! Fields carried over (issue 17, point 1): a linear field through two √3
//! steps is reproduced at every output point, cell fields follow `parent`,
//! points outside the input domain take the value of the nearest input
//! boundary point. Every expectation is computed here from the closed form
//! and from brute-force geometry, not from the library's search structures.

use glam::DVec3;
use tetrefine::io::load_mesh;
use tetrefine::{
    copy_cell_field, interpolate_point_field, locate_parents, locate_points, refine, RefineOptions,
    Sqrt3Rule, TetMesh,
};

fn f(p: DVec3) -> f64 {
    // a + b·x + c·y + d·z with coefficients of different sizes and signs.
    1.25 - 0.75 * p.x + 2.5 * p.y + 0.125 * p.z
}

fn tripod() -> TetMesh {
    load_mesh(&crate::support::root().join("meshes/tripod.mesh"))
        .expect("the tripod loads")
        .0
}

/// Refines `input` twice with `rule`, compacts and locates parents.
fn refined_twice(input: &TetMesh, rule: Sqrt3Rule) -> TetMesh {
    let mut mesh = input.clone();
    let opts = RefineOptions {
        boundary: rule,
        ..RefineOptions::default()
    };
    refine(&mut mesh, 2, &opts);
    locate_parents(input, &mut mesh);
    mesh.compact();
    mesh
}

/// Six times the signed volume of `(a, b, c, d)` with an exact sign, from
/// Shewchuk's predicate directly (which is positive for the opposite
/// orientation).
fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let k = |p: DVec3| robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    -robust::orient3d(k(a), k(b), k(c), k(d))
}

/// Whether some input tet holds `x`, by scanning every tet with the exact
/// predicate (no walk, no grid).
fn inside_by_scan(input: &TetMesh, x: DVec3) -> bool {
    input.tet_ids().any(|t| {
        let [a, b, c, d] = input.tet_points(t);
        orient3d(x, b, c, d) >= 0.0
            && orient3d(a, x, c, d) >= 0.0
            && orient3d(a, b, x, d) >= 0.0
            && orient3d(a, b, c, x) >= 0.0
    })
}

/// The nearest point of segment `[a, b]` to `p`.
fn on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    a + t * (b - a)
}

/// The nearest point of the input boundary to `p`, over every boundary
/// face: the projection onto the face's plane when it falls inside the
/// triangle (by signed areas), else the nearest point of its three edges.
fn nearest_boundary_point(input: &TetMesh, p: DVec3) -> DVec3 {
    let mut best = (f64::INFINITY, p);
    for t in input.tet_ids() {
        for face in 0..4 {
            if !input.is_boundary_face(t, face) {
                continue;
            }
            let [a, b, c] = input.face_vertices(t, face).map(|v| input.point(v));
            let n = (b - a).cross(c - a).normalize();
            let q = p - n * (p - a).dot(n);
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(u, v)| (v - u).cross(q - u).dot(n) >= 0.0);
            let cand = if inside {
                q
            } else {
                [(a, b), (b, c), (c, a)]
                    .iter()
                    .map(|&(u, v)| on_segment(p, u, v))
                    .min_by(|x, y| x.distance(p).total_cmp(&y.distance(p)))
                    .unwrap()
            };
            let d = cand.distance(p);
            if d < best.0 {
                best = (d, cand);
            }
        }
    }
    best.1
}

#[test]
fn a_linear_field_survives_two_steps_with_the_linear_boundary_rule() {
    let input = tripod();
    let mesh = refined_twice(&input, Sqrt3Rule::Linear);
    let values: Vec<f64> = input.points().iter().map(|&p| f(p)).collect();
    let locs = locate_points(&input, &mesh);
    assert_eq!(locs.len(), mesh.n_points());
    let out = interpolate_point_field(input.tet_slots(), &locs, &values, 1);
    let mut worst = 0.0f64;
    for (v, &x) in mesh.points().iter().enumerate() {
        worst = worst.max((out[v] - f(x)).abs());
    }
    // Barycentric weights sum to 1 up to a few roundings; values are O(10).
    assert!(
        worst <= 1e-9,
        "worst deviation from the closed form {worst:e}"
    );
}

#[test]
fn outside_points_take_the_nearest_boundary_value_and_inside_points_are_exact() {
    let input = tripod();
    let mesh = refined_twice(&input, Sqrt3Rule::Interpolating);
    // Three components: the field itself and two other linear functions.
    let g = |p: DVec3| [f(p), p.x - p.z, 3.0 * p.y + 7.0];
    let values: Vec<f64> = input.points().iter().flat_map(|&p| g(p)).collect();
    let locs = locate_points(&input, &mesh);
    let out = interpolate_point_field(input.tet_slots(), &locs, &values, 3);
    let (mut inside, mut outside) = (0, 0);
    for (v, &x) in mesh.points().iter().enumerate() {
        let here = &out[3 * v..3 * v + 3];
        if locs[v].outside {
            outside += 1;
            assert!(!inside_by_scan(&input, x), "point {v} {x} is inside");
            let q = nearest_boundary_point(&input, x);
            for (k, want) in g(q).iter().enumerate() {
                assert!(
                    (here[k] - want).abs() <= 1e-9,
                    "point {v}: component {k} {} vs {want} at the nearest boundary point {q}",
                    here[k]
                );
            }
        } else {
            inside += 1;
            for (k, want) in g(x).iter().enumerate() {
                assert!((here[k] - want).abs() <= 1e-9, "point {v}, component {k}");
            }
        }
    }
    assert!(outside > 0, "the interpolating rule moves some points out");
    assert!(inside > outside, "{inside} inside, {outside} outside");
}

#[test]
fn cell_fields_are_the_parents_values() {
    let input = tripod();
    let mesh = refined_twice(&input, Sqrt3Rule::Linear);
    let values: Vec<f64> = (0..input.n_tets())
        .flat_map(|t| [t as f64 * 0.5, -(t as f64)])
        .collect();
    let parents: Vec<u32> = mesh.tet_ids().map(|t| mesh.parent(t)).collect();
    let out = copy_cell_field(&parents, &values, 2);
    assert_eq!(out.len(), 2 * mesh.n_tets());
    for (i, t) in mesh.tet_ids().enumerate() {
        let p = mesh.parent(t) as f64;
        assert_eq!(out[2 * i], p * 0.5);
        assert_eq!(out[2 * i + 1], -p);
    }
}

#[test]
fn point_locations_do_not_depend_on_the_thread_count() {
    let input = tripod();
    let mesh = refined_twice(&input, Sqrt3Rule::Interpolating);
    let run = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| locate_points(&input, &mesh))
    };
    assert_eq!(run(1), run(3));
}
