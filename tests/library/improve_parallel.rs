//! The optimize phase's parallel parts: the colour classes it smooths at the
//! same time are independent sets (no two vertices of a class share a tet),
//! and `improve` gives the same mesh whatever the number of threads, never
//! inverts a tet and never lowers the worst quality.

use tetrefine::ball_stays_positive;
use tetrefine::cube_grid;
use tetrefine::geom::{orient3d, tet_min_sine};
use tetrefine::TetMesh;
use tetrefine::{improve, ImproveOptions};

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
    let fixed = mesh.fixed_vertices();
    let h = 1.0 / n as f64;
    let mut rng = tetrefine::SplitMix64(0x2545_f491_4f6c_dd1d);
    // A deterministic sequence in [-1, 1).
    let mut next = || 2.0 * rng.next_f64() - 1.0;
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

fn in_pool<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn improve_with(
    mesh: &TetMesh,
    threads: usize,
    opts: &ImproveOptions,
) -> (TetMesh, tetrefine::ImproveReport) {
    let mut m = mesh.clone();
    let report = in_pool(threads, || improve(&mut m, opts));
    (m, report)
}

fn improve_with_threads(mesh: &TetMesh, threads: usize) -> (TetMesh, tetrefine::ImproveReport) {
    improve_with(mesh, threads, &ImproveOptions::default())
}

#[test]
fn improve_in_small_blocks_is_thread_independent_and_never_inverts() {
    let mesh = perturbed_cube();
    let before = worst_quality(&mesh);
    let opts = ImproveOptions {
        smooth_block: 37,
        ..Default::default()
    };
    let (one, r1) = improve_with(&mesh, 1, &opts);
    let (three, r3) = improve_with(&mesh, 3, &opts);
    assert_eq!(r1, r3);
    assert!(r1.laplacian_moves + r1.optimized_moves > 0, "{r1:?}");
    assert_eq!(one.points(), three.points());
    assert_eq!(one.tet_slots(), three.tet_slots());
    one.check().unwrap();
    assert!(all_positive(&one));
    assert!(worst_quality(&one) >= before);
}

#[test]
fn improve_is_thread_independent_and_never_inverts() {
    let mesh = perturbed_cube();
    let before = worst_quality(&mesh);
    let (one, r1) = improve_with_threads(&mesh, 1);
    let (three, r3) = improve_with_threads(&mesh, 3);
    assert_eq!(r1, r3);
    assert!(r1.laplacian_moves + r1.optimized_moves > 0, "{r1:?}");
    // The face sweep's parallel search is exercised too.
    assert!(r1.faces_removed > 0, "{r1:?}");
    assert_eq!(one.points(), three.points());
    assert_eq!(one.tet_slots(), three.tet_slots());
    for threads in [2, 4] {
        let (m, r) = improve_with_threads(&mesh, threads);
        assert_eq!(r1, r, "{threads} threads");
        assert_eq!(one.points(), m.points(), "{threads} threads");
        assert_eq!(one.tet_slots(), m.tet_slots(), "{threads} threads");
    }
    for m in [&one, &three] {
        m.check().unwrap();
        assert!(all_positive(m));
        assert!(worst_quality(m) >= before);
    }
    // The volume of the unit cube is unchanged: boundary vertices move only
    // inside a flat face (their projection keeps the axis coordinate exact),
    // and the untagged cube edges are creases the smoother does not cut.
    let volume: f64 = one
        .tet_ids()
        .map(|t| {
            let p = one.tet_points(t);
            (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
        })
        .sum();
    assert!((volume - 1.0).abs() < 1e-12, "{volume}");
}
