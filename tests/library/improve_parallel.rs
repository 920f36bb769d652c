//! The optimize phase's parallel parts: the colour classes it smooths at the
//! same time are independent sets (no two vertices of a class share a tet),
//! and `improve` gives the same mesh whatever the number of threads, never
//! inverts a tet and never lowers the worst quality.

use std::collections::HashSet;

use tetrefine::geom::{orient3d, tet_min_sine};
use tetrefine::improve::colour::{colour_balls_except, colour_classes, sequential_levels, Balls};
use tetrefine::improve::{improve, ImproveOptions};
use tetrefine::io::load_mesh;
use tetrefine::mesh::ball_stays_positive;
use tetrefine::mesh::generate::cube_grid;
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
    let fixed = mesh.fixed_vertices();
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
) -> (TetMesh, tetrefine::improve::ImproveReport) {
    let mut m = mesh.clone();
    let report = in_pool(threads, || improve(&mut m, opts));
    (m, report)
}

fn improve_with_threads(
    mesh: &TetMesh,
    threads: usize,
) -> (TetMesh, tetrefine::improve::ImproveReport) {
    improve_with(mesh, threads, &ImproveOptions::default())
}

#[test]
fn gathered_balls_are_the_walked_balls_in_ascending_order() {
    let (mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    // Every other vertex, so that the index has holes.
    let verts: Vec<u32> = (0..mesh.n_points() as u32).step_by(2).collect();
    let mut walked = Vec::new();
    for threads in [1, 3] {
        let balls = in_pool(threads, || Balls::gather(&mesh, &verts));
        assert_eq!(balls.len(), verts.len());
        for (i, &v) in verts.iter().enumerate() {
            mesh.ball(v, &mut walked);
            walked.sort_unstable();
            assert_eq!(balls.ball(i), &walked[..], "ball of {v}, {threads} threads");
        }
    }
    assert!(Balls::gather(&mesh, &[]).is_empty());
}

#[test]
fn dependency_levels_keep_every_earlier_conflict_earlier() {
    let (mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    let verts: Vec<u32> = (0..mesh.n_points() as u32)
        .filter(|&v| mesh.tet_of_vertex(v).is_some())
        .collect();
    let balls = Balls::gather(&mesh, &verts);
    // A stretch of neighbours in memory, each visited twice, as the vertices
    // set apart are (before and after the colour classes).
    let mut seq: Vec<u32> = (0..200).collect();
    seq.extend(0..200u32);
    let mut level = Vec::new();
    let groups = sequential_levels(&mesh, &balls, &verts, &seq, &mut level);
    assert!(level.iter().all(|&l| l == 0), "scratch left clean");
    // Entry k of seq is the k-th occurrence, in group order, of its index.
    let mut group_of = vec![Vec::new(); seq.len()];
    for (g, group) in groups.iter().enumerate() {
        for &i in group {
            group_of[i as usize].push(g);
        }
    }
    let mut seen = vec![0usize; seq.len()];
    let entry_group: Vec<usize> = seq
        .iter()
        .map(|&i| {
            let g = group_of[i as usize][seen[i as usize]];
            seen[i as usize] += 1;
            g
        })
        .collect();
    let shares = |a: u32, b: u32| {
        let (ba, bb) = (balls.ball(a as usize), balls.ball(b as usize));
        a == b || ba.iter().any(|t| bb.contains(t))
    };
    let mut conflicts = 0;
    for k in 0..seq.len() {
        for j in 0..k {
            if shares(seq[j], seq[k]) {
                conflicts += 1;
                assert!(entry_group[j] < entry_group[k], "entries {j} and {k}");
            }
        }
    }
    assert!(
        conflicts > seq.len(),
        "the stretch is connected: {conflicts}"
    );
    for group in &groups {
        for (a, &x) in group.iter().enumerate() {
            for &y in &group[..a] {
                assert!(!shares(x, y), "{x} and {y} share a tet in one group");
            }
        }
    }
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
fn colour_classes_of_the_tripod_are_independent_sets() {
    let (mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    let fixed = mesh.fixed_vertices();
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
    let (mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    let fixed = mesh.fixed_vertices();
    let verts: Vec<u32> = (0..mesh.n_points() as u32)
        .filter(|&v| !fixed[v as usize] && mesh.tet_of_vertex(v).is_some())
        .collect();
    let balls = Balls::gather(&mesh, &verts);
    let apart: Vec<u32> = (0..verts.len() as u32).filter(|i| i % 7 == 0).collect();
    let classes = colour_balls_except(&mesh, &balls, &verts, |i| i % 7 == 0);
    let k = apart.len();
    let expected: Vec<Vec<u32>> = apart.iter().map(|&i| vec![i]).collect();
    assert_eq!(&classes[..k], &expected[..]);
    assert_eq!(&classes[classes.len() - k..], &expected[..]);
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
