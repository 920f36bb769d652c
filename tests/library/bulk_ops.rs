//! The bulk (parallel) 1-4 split and 2-3 flip of a √3 step against the local
//! operations applied one by one: the bulk result must be the same mesh, slot
//! for slot (vertices, adjacency, generation, region, level, parent, points,
//! vertex → tet), and equal for one and two threads. Inputs: the tripod, a
//! seeded jittered cube with free slots, an adaptive selection, flips
//! refused on purpose, and the flip phase repairing an invalid flip first.

use tetrefine::ball_stays_positive;
use tetrefine::cube_grid;
use tetrefine::geom::orient3d;
use tetrefine::io::load_mesh;
use tetrefine::ops::{
    flip23, flip23_bulk, flip23_valid, flip32, make_flips_valid, split14, split14_bulk, FlipBatch,
};
use tetrefine::topo::TET_EDGES;
use tetrefine::TetMesh;

/// The old split phase: `split14` on the selected tets in ascending order.
fn split_one_by_one(mesh: &mut TetMesh, sel: Option<&[bool]>) -> usize {
    let ids: Vec<u32> = mesh
        .tet_ids()
        .filter(|&t| sel.is_none_or(|s| s[t as usize]))
        .collect();
    let mut n = 0;
    for t in ids {
        let p = mesh.tet_points(t);
        let level = mesh.level(t);
        if let Ok(children) = split14(mesh, t, (p[0] + p[1] + p[2] + p[3]) * 0.25) {
            for c in children {
                mesh.set_level(c, level + 1);
            }
            n += 1;
        }
    }
    n
}

/// The old flip phase: `flip23` on the faces in order, skipping those not
/// allowed.
fn flip_one_by_one(mesh: &mut TetMesh, faces: &[(u32, usize)], allowed: &[bool]) -> usize {
    faces
        .iter()
        .zip(allowed)
        .filter(|&(&(t, f), &ok)| ok && flip23(mesh, t, f).is_ok())
        .count()
}

/// Asserts that two meshes are the same slot for slot.
fn assert_same(a: &TetMesh, b: &TetMesh) {
    assert_eq!(a.n_tet_slots(), b.n_tet_slots());
    assert_eq!(a.n_tets(), b.n_tets());
    assert_eq!(a.tet_slots(), b.tet_slots());
    let bits = |m: &TetMesh| -> Vec<[u64; 3]> {
        m.points()
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect()
    };
    assert_eq!(bits(a), bits(b));
    for t in 0..a.n_tet_slots() as u32 {
        assert_eq!(a.generation(t), b.generation(t), "generation of {t}");
        if a.is_alive(t) {
            assert_eq!(a.adj(t), b.adj(t), "adjacency of {t}");
            assert_eq!(a.region(t), b.region(t), "region of {t}");
            assert_eq!(a.level(t), b.level(t), "level of {t}");
            assert_eq!(a.parent(t), b.parent(t), "parent of {t}");
        }
    }
    for v in 0..a.n_points() as u32 {
        assert_eq!(a.tet_of_vertex(v), b.tet_of_vertex(v), "v2t of {v}");
    }
    assert_eq!(a.face_markers(), b.face_markers());
}

/// Sum of six times the tet volumes.
fn volume6(m: &TetMesh) -> f64 {
    m.tet_ids()
        .map(|t| {
            let p = m.tet_points(t);
            orient3d(p[0], p[1], p[2], p[3])
        })
        .sum()
}

fn with_threads<R: Send>(n: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .unwrap()
        .install(f)
}

/// Runs bulk split + flip and the one-by-one reference on copies of `mesh`,
/// with flips at the faces where `refuse(i)` is true refused on purpose;
/// checks that all agree and returns (split, flipped, flip faces).
fn compare(
    mesh: &TetMesh,
    sel: Option<&[bool]>,
    refuse: impl Fn(usize) -> bool + Sync,
) -> (usize, usize, usize) {
    let first = mesh.n_points() as u32;
    let vol0 = volume6(mesh);

    let mut seq = mesh.clone();
    let s_seq = split_one_by_one(&mut seq, sel);
    let mut results = Vec::new();
    for threads in [1, 2] {
        let mut m = mesh.clone();
        let s = with_threads(threads, || split14_bulk(&mut m, sel));
        assert_eq!(s, s_seq);
        m.check().unwrap();
        assert_same(&m, &seq);
        results.push(m);
    }

    let batch = FlipBatch::barycentre_faces(&seq, first);
    let faces = batch.faces();
    for (i, &(t, f)) in faces.iter().enumerate() {
        assert_eq!(batch.is_valid(i), flip23_valid(&seq, t, f));
    }
    let allowed: Vec<bool> = (0..faces.len())
        .map(|i| batch.is_valid(i) && !refuse(i))
        .collect();
    let f_seq = flip_one_by_one(&mut seq, &faces, &allowed);
    seq.check().unwrap();
    for (threads, mut m) in [1, 2].into_iter().zip(results) {
        let f = with_threads(threads, || {
            let mut b = FlipBatch::barycentre_faces(&m, first);
            assert_eq!(b.faces(), faces);
            for i in (0..faces.len()).filter(|&i| refuse(i)) {
                b.refuse(i);
            }
            flip23_bulk(&mut m, b)
        });
        assert_eq!(f, f_seq);
        m.check().unwrap();
        assert_same(&m, &seq);
    }
    let vol = volume6(&seq);
    assert!((vol - vol0).abs() <= 1e-12 * vol0.abs(), "{vol} vs {vol0}");
    (s_seq, f_seq, faces.len())
}

/// A small seeded generator (64-bit LCG, Knuth's constants).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `cube_grid(n)` with interior points moved at random (seeded) by up to
/// 0.3 grid steps, halving the amplitude until the mesh stays valid,
/// then a few 2-3 + 3-2 flip pairs so that the free list is not empty.
fn jittered_cube(n: usize, seed: u64) -> TetMesh {
    let base = cube_grid(n);
    let mut amp = 0.3;
    let mut mesh = loop {
        let mut d = base.clone();
        let mut rng = Lcg(seed);
        let h = 1.0 / n as f64;
        for p in d.points.iter_mut() {
            let interior = p.iter().all(|&x| x > 0.5 * h && x < 1.0 - 0.5 * h);
            for x in p.iter_mut() {
                let r = rng.next() * 2.0 - 1.0;
                if interior {
                    *x += r * amp * h;
                }
            }
        }
        let Ok((m, _)) = TetMesh::from_data(&d) else {
            amp *= 0.5;
            continue;
        };
        let positive = m.tet_ids().all(|t| {
            let p = m.tet_points(t);
            orient3d(p[0], p[1], p[2], p[3]) > 0.0
        });
        if positive && m.n_tets() == base.tets.len() {
            break m;
        }
        amp *= 0.5;
    };
    // 2-3 then 3-2 around the new edge: one slot freed each time.
    let mut freed = 0;
    let mut t = 0;
    while freed < 5 && (t as usize) < mesh.n_tet_slots() {
        if mesh.is_alive(t) && !mesh.is_boundary_face(t, 0) && flip23_valid(&mesh, t, 0) {
            if let Ok(new) = flip23(&mut mesh, t, 0) {
                // Edge p-q is (2, 3) of every new tet.
                let e = TET_EDGES.iter().position(|&e| e == [2, 3]).unwrap();
                if flip32(&mut mesh, new[0], e).is_ok() {
                    freed += 1;
                }
            }
        }
        t += 37;
    }
    mesh.check().unwrap();
    mesh
}

#[test]
fn bulk_equals_one_by_one_on_the_cube_with_the_closed_form_counts() {
    let n = 5;
    let (mesh, _) = TetMesh::from_data(&cube_grid(n)).unwrap();
    let (split, flipped, faces) = compare(&mesh, None, |_| false);
    // Every tet splits; every interior face (6n³ tets × 4 faces, less the
    // 12n² boundary triangles, counted twice) flips.
    assert_eq!(split, 6 * n * n * n);
    assert_eq!(faces, 12 * n * n * n - 6 * n * n);
    assert_eq!(flipped, faces);
}

#[test]
fn bulk_equals_one_by_one_on_the_tripod() {
    let (mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    let (split, _, _) = compare(&mesh, None, |_| false);
    assert_eq!(split, 2799);
}

#[test]
fn bulk_equals_one_by_one_on_a_jittered_cube_with_free_slots() {
    let mesh = jittered_cube(6, 7);
    assert!(mesh.n_tet_slots() > mesh.n_tets(), "no free slots made");
    let (split, _, _) = compare(&mesh, None, |_| false);
    assert_eq!(split, mesh.n_tets());
}

#[test]
fn bulk_equals_one_by_one_with_an_adaptive_selection() {
    let mesh = jittered_cube(6, 11);
    let mut rng = Lcg(3);
    let sel: Vec<bool> = (0..mesh.n_tet_slots()).map(|_| rng.next() < 0.4).collect();
    let expected = mesh.tet_ids().filter(|&t| sel[t as usize]).count();
    let (split, flipped, faces) = compare(&mesh, Some(&sel), |_| false);
    assert_eq!(split, expected);
    assert!(flipped > 0 && faces < 2 * expected);
}

#[test]
fn bulk_equals_one_by_one_with_refused_flips() {
    let mesh = jittered_cube(6, 5);
    // Refuse every third flip: the neighbours of a refused pair must be
    // re-linked to the refused tets, not to flipped ones.
    let (_, flipped, faces) = compare(&mesh, None, |i| i % 3 == 0);
    assert!(flipped < faces && flipped > 0);
}

/// Two tets on the face (0,0,0) (1,0,0) (0,1,0), one with its apex far out
/// at (5,5,1): the segment between the barycentres (1.5,1.5,0.25) and
/// (0.275,0.275,-0.25) crosses the face's plane at (0.8875,0.8875,0), outside
/// the face, so the flip is invalid as split. The flip phase pulls both
/// barycentres towards the face's centroid (a factor 0.15 brings the crossing
/// inside, x + y < 1) and then flips in bulk: 8 children + 1 = 9 tets.
#[test]
fn the_flip_phase_repairs_an_invalid_flip_and_then_flips_in_bulk() {
    use tetrefine::MeshData;
    use tetrefine::{refine_step, Phase, RefineOptions};
    let data = MeshData {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 1.0],
            [0.1, 0.1, -1.0],
        ],
        tets: vec![[0, 1, 2, 3], [0, 2, 1, 4]],
        ..Default::default()
    };
    let (mut mesh, _) = TetMesh::from_data(&data).unwrap();
    let first = mesh.n_points() as u32;
    let mut split = mesh.clone();
    split14_bulk(&mut split, None);
    let batch = FlipBatch::barycentre_faces(&split, first);
    assert_eq!(batch.len(), 1);
    assert!(!batch.is_valid(0));
    let vol0 = volume6(&mesh);
    let r = refine_step(
        &mut mesh,
        1,
        &RefineOptions {
            stop_after: Some(Phase::Flip),
            check_each_phase: true,
            ..Default::default()
        },
    );
    assert!(r.check_failures.is_empty(), "{:?}", r.check_failures);
    assert_eq!(r.split, 2);
    assert_eq!(r.moved_barycentres, 2);
    assert_eq!((r.flipped, r.refused_flips), (1, 0));
    assert_eq!(mesh.n_tets(), 9);
    assert!((volume6(&mesh) - vol0).abs() <= 1e-12 * vol0);
}

/// The one-by-one repair the parallel [`make_flips_valid`] must equal: for
/// each initially invalid flip in batch order, pull both barycentres towards
/// the face's centroid by the first factor of 0.7, 0.5, 0.3, 0.15, 0.05 that
/// keeps their balls positive, makes the flip valid and keeps every other
/// flip of theirs that was valid valid. Returns the number of points moved.
fn repair_one_by_one(mesh: &mut TetMesh, faces: &[(u32, usize)]) -> usize {
    let apexes = |m: &TetMesh, t: u32, f: usize| {
        let (u, g) = TetMesh::half_face(m.adj(t)[f]);
        (m.tet(t)[f], m.tet(u)[g])
    };
    let invalid: Vec<(u32, usize)> = faces
        .iter()
        .copied()
        .filter(|&(t, f)| !flip23_valid(mesh, t, f))
        .collect();
    let mut moved = 0;
    let mut ball = Vec::new();
    for (t, f) in invalid {
        let (p, q) = apexes(mesh, t, f);
        let fv = mesh.face_vertices(t, f);
        let c = (mesh.point(fv[0]) + mesh.point(fv[1]) + mesh.point(fv[2])) / 3.0;
        let (p0, q0) = (mesh.point(p), mesh.point(q));
        // Every other flip with p or q as an apex, by a plain scan.
        let others: Vec<(u32, usize)> = faces
            .iter()
            .copied()
            .filter(|&x| x != (t, f))
            .filter(|&(a, b)| {
                let (x, y) = apexes(mesh, a, b);
                [p, q].contains(&x) || [p, q].contains(&y)
            })
            .collect();
        let was_valid: Vec<bool> = others
            .iter()
            .map(|&(a, b)| flip23_valid(mesh, a, b))
            .collect();
        for s in [0.7, 0.5, 0.3, 0.15, 0.05] {
            let (p1, q1) = (c + (p0 - c) * s, c + (q0 - c) * s);
            mesh.ball(p, &mut ball);
            let p_ok = ball_stays_positive(mesh, p, &ball, p1);
            mesh.ball(q, &mut ball);
            let q_ok = ball_stays_positive(mesh, q, &ball, q1);
            if !(p_ok && q_ok) {
                continue;
            }
            mesh.set_point(p, p1);
            mesh.set_point(q, q1);
            let ok = flip23_valid(mesh, t, f)
                && others
                    .iter()
                    .zip(&was_valid)
                    .all(|(&(a, b), &w)| !w || flip23_valid(mesh, a, b));
            if ok {
                moved += 2;
                break;
            }
            mesh.set_point(p, p0);
            mesh.set_point(q, q0);
        }
    }
    moved
}

/// Splits `mesh`, repairs the flips one by one and with
/// [`make_flips_valid`] on one and two threads: the same points move to the
/// same places (bit for bit), the batch's verdicts equal `flip23_valid` on
/// the repaired mesh, and no tet is inverted. Returns (moved, invalid before,
/// invalid after, dependent pairs of repairs).
fn compare_repairs(mesh: &TetMesh) -> (usize, usize, usize, usize) {
    let first = mesh.n_points() as u32;
    let mut split = mesh.clone();
    split14_bulk(&mut split, None);
    let faces = FlipBatch::barycentre_faces(&split, first).faces();
    let invalid_before = faces
        .iter()
        .filter(|&&(t, f)| !flip23_valid(&split, t, f))
        .count();
    let dependent = dependent_repairs(&split, &faces);
    let mut seq = split.clone();
    let moved_seq = repair_one_by_one(&mut seq, &faces);
    for threads in [1, 2] {
        let mut m = split.clone();
        let (moved, batch) = with_threads(threads, || {
            let mut b = FlipBatch::barycentre_faces(&m, first);
            (make_flips_valid(&mut m, &mut b), b)
        });
        assert_eq!(moved, moved_seq, "{threads} threads");
        for (v, (a, b)) in m.points().iter().zip(seq.points()).enumerate() {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits),
                "point {v}"
            );
        }
        for (i, &(t, f)) in faces.iter().enumerate() {
            assert_eq!(batch.is_valid(i), flip23_valid(&seq, t, f), "flip {i}");
        }
        m.check().unwrap();
        assert!(m.tet_ids().all(|t| {
            let p = m.tet_points(t);
            orient3d(p[0], p[1], p[2], p[3]) > 0.0
        }));
    }
    let invalid_after = faces
        .iter()
        .filter(|&&(t, f)| !flip23_valid(&seq, t, f))
        .count();
    (moved_seq, invalid_before, invalid_after, dependent)
}

/// Pairs of initially invalid flips whose repairs reach a common barycentre
/// (they share an apex, or a flip joins an apex of one to an apex of the
/// other): the repair done first changes what the other sees.
fn dependent_repairs(mesh: &TetMesh, faces: &[(u32, usize)]) -> usize {
    let apexes = |t: u32, f: usize| {
        let (u, g) = TetMesh::half_face(mesh.adj(t)[f]);
        [mesh.tet(t)[f], mesh.tet(u)[g]]
    };
    let mut owners: std::collections::HashMap<u32, Vec<usize>> = Default::default();
    for (i, &(t, f)) in faces.iter().enumerate() {
        if !flip23_valid(mesh, t, f) {
            for x in apexes(t, f) {
                owners.entry(x).or_default().push(i);
            }
        }
    }
    let mut pairs = std::collections::BTreeSet::new();
    for &(t, f) in faces {
        let [x, y] = apexes(t, f);
        let none = Vec::new();
        let (a, b) = (
            owners.get(&x).unwrap_or(&none),
            owners.get(&y).unwrap_or(&none),
        );
        for &i in a.iter().chain(b) {
            for &j in a.iter().chain(b) {
                if i < j {
                    pairs.insert((i, j));
                }
            }
        }
    }
    pairs.len()
}

/// After a full √3 step (optimize included) of a jittered cube, the next
/// split has invalid flips, some of them dependent (repairs that reach the
/// same barycentres and must be done in batch order): the parallel repair
/// makes the very moves of the one-by-one repair.
#[test]
fn parallel_flip_repair_equals_the_one_by_one_repair_after_a_step() {
    use tetrefine::{refine_step, RefineOptions};
    let mut mesh = jittered_cube(4, 3);
    // The √3 step without the long-edge splits and second passes of the
    // default effort, which leave this small cube no dependent repair.
    let opts = RefineOptions {
        effort: tetrefine::Effort::Fast,
        ..Default::default()
    };
    refine_step(&mut mesh, 1, &opts);
    let (moved, before, after, dependent) = compare_repairs(&mesh);
    assert!(before > 0 && moved > 0, "{moved} moved of {before}");
    assert!(after < before);
    assert!(dependent > 0, "no dependent repairs");
}

/// The same on the tripod (a real mesh with three regions) after one step.
#[test]
fn parallel_flip_repair_equals_the_one_by_one_repair_on_the_refined_tripod() {
    use tetrefine::{refine_step, RefineOptions};
    let (mut mesh, _) = load_mesh(&crate::support::path("meshes/tripod.mesh")).unwrap();
    // At `fast`, as above: the default effort's two long-edge rounds leave
    // the tripod's next split no dependent repair.
    let opts = RefineOptions {
        effort: tetrefine::Effort::Fast,
        ..Default::default()
    };
    refine_step(&mut mesh, 1, &opts);
    let (moved, before, after, dependent) = compare_repairs(&mesh);
    assert!(before > 0 && moved > 0, "{moved} moved of {before}");
    assert!(after < before);
    assert!(dependent > 0, "no dependent repairs");
}
