//! The optimize phase's parallel parts: the colour classes it smooths at the
//! same time are independent sets (no two vertices of a class share a tet),
//! and `improve` gives the same mesh whatever the number of threads, never
//! inverts a tet and never lowers the worst quality.

use std::collections::HashSet;
use std::path::Path;
use tetrefine::geom::{orient3d, tet_min_sine};
use tetrefine::io::load_mesh;
use tetrefine::mesh::generate::cube_grid;
use tetrefine::smooth::colour::{colour_balls_except, colour_classes, Balls};
use tetrefine::smooth::{ball_stays_positive, fixed_vertices, improve, ImproveOptions};
use tetrefine::TetMesh;

fn worst_quality(mesh: &TetMesh) -> f64 {
    mesh.tet_ids()
        .map(|t| tet_min_sine(&mesh.tet_points(t)))
        .fold(f64::INFINITY, f64::min)
}

fn all_positive(mesh: &TetMesh) -> bool {
    mesh.tet_ids().all(|t| {
        let p = mesh.tet_points(t);
        orient3d(p[0], p[1], p[2], p[3]) > 0.0
    })
}

/// The 8³ cube grid with every interior vertex moved by up to 0.35 of the
/// grid step along each axis (a fixed pseudo-random sequence), each move
/// kept only if no tet of its ball inverts: a mesh with many poor tets.
fn perturbed_cube() -> TetMesh {
    let n = 8;
    let (mut mesh, _) = TetMesh::from_data(&cube_grid(n)).unwrap();
    let fixed = fixed_vertices(&mesh);
    let h = 1.0 / n as f64;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        // xorshift64*: a deterministic sequence in [-1, 1).
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let r = state.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let mut ball = Vec::new();
    for v in 0..mesh.n_points() as u32 {
        let d = glam::DVec3::new(next(), next(), next()) * (0.35 * h);
        if fixed[v as usize] {
            continue;
        }
        let x = mesh.point(v) + d;
        mesh.ball(v, &mut ball);
        if ball_stays_positive(&mesh, v, &ball, x) {
            mesh.set_point(v, x);
        }
    }
    assert!(all_positive(&mesh));
    mesh
}

fn improve_with_threads(
    mesh: &TetMesh,
    threads: usize,
) -> (TetMesh, tetrefine::smooth::ImproveReport) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut m = mesh.clone();
    let report = pool.install(|| improve(&mut m, &ImproveOptions::default()));
    (m, report)
}

#[test]
fn colour_classes_of_the_tripod_are_independent_sets() {
    let (mesh, _) = load_mesh(Path::new("meshes/tripod.mesh")).unwrap();
    let fixed = fixed_vertices(&mesh);
    let verts: Vec<u32> = (0..mesh.n_points() as u32)
        .filter(|&v| !fixed[v as usize] && mesh.tet_of_vertex(v).is_some())
        .collect();
    assert!(verts.len() > 100, "the tripod has interior vertices");
    let classes = colour_classes(&mesh, &verts);
    assert!(classes.len() > 1);
    // Every vertex is in exactly one class.
    let mut seen = HashSet::new();
    for c in &classes {
        for &v in c {
            assert!(seen.insert(v), "vertex {v} in two classes");
        }
    }
    assert_eq!(seen.len(), verts.len());
    // No tet holds two vertices of one class.
    for c in &classes {
        let class: HashSet<u32> = c.iter().copied().collect();
        for t in mesh.tet_ids() {
            let k = mesh.tet(t).iter().filter(|v| class.contains(v)).count();
            assert!(k <= 1, "tet {t} holds {k} vertices of one class");
        }
    }
}

#[test]
fn vertices_set_apart_get_classes_of_their_own_before_and_after() {
    let (mesh, _) = load_mesh(Path::new("meshes/tripod.mesh")).unwrap();
    let fixed = fixed_vertices(&mesh);
    let verts: Vec<u32> = (0..mesh.n_points() as u32)
        .filter(|&v| !fixed[v as usize] && mesh.tet_of_vertex(v).is_some())
        .collect();
    let balls = Balls::gather(&mesh, &verts);
    let apart: Vec<u32> = (0..verts.len() as u32).filter(|i| i % 7 == 0).collect();
    let mut masks = Vec::new();
    let classes = colour_balls_except(&balls, &mut masks, |i| i % 7 == 0);
    let k = apart.len();
    let expected: Vec<Vec<u32>> = apart.iter().map(|&i| vec![i]).collect();
    assert_eq!(&classes[..k], &expected[..]);
    assert_eq!(&classes[classes.len() - k..], &expected[..]);
    assert!(masks.iter().all(|&m| m == 0), "scratch left clean");
    // The classes in between hold every other vertex once, independently.
    let mut seen = HashSet::new();
    for c in &classes[k..classes.len() - k] {
        let mut tets = HashSet::new();
        for &i in c {
            assert!(i % 7 != 0 && seen.insert(i));
            for &t in balls.ball(i as usize) {
                assert!(tets.insert(t), "tet {t} shared within a class");
            }
        }
    }
    assert_eq!(seen.len() + k, verts.len());
}

#[test]
fn improve_is_thread_independent_and_never_inverts() {
    let mesh = perturbed_cube();
    let before = worst_quality(&mesh);
    let (one, r1) = improve_with_threads(&mesh, 1);
    let (three, r3) = improve_with_threads(&mesh, 3);
    assert_eq!(r1, r3);
    assert!(r1.laplacian_moves + r1.optimized_moves > 0, "{r1:?}");
    assert_eq!(one.points(), three.points());
    assert_eq!(one.tet_slots(), three.tet_slots());
    for m in [&one, &three] {
        m.check().unwrap();
        assert!(all_positive(m));
        assert!(worst_quality(m) >= before);
    }
    // The volume of the unit cube is unchanged (boundary vertices stay put).
    let volume: f64 = one
        .tet_ids()
        .map(|t| {
            let p = one.tet_points(t);
            (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
        })
        .sum();
    assert!((volume - 1.0).abs() < 1e-12, "{volume}");
}
