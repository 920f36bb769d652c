//! Uniform 1:8 red refinement (`refine::bisect`): counts from the scheme's
//! definition (8 tets per tet, one new point per edge, 4 child faces per face,
//! 2 halves per edge), exact volume per parent, children built from parent
//! corners and edge midpoints, tags carried over, `check()` (exact positive
//! orientation, mutual adjacency), and byte-identical CLI output with 1 and 2
//! threads.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use tetrefine::detect_features;
use tetrefine::geom::tet_volume;
use tetrefine::io::load_mesh;
use tetrefine::ops::{flip23, flip23_valid, flip32};
use tetrefine::topo::edge_key;
use tetrefine::topo::TET_EDGES;
use tetrefine::TetMesh;
use tetrefine::{bisect, bisect_steps};

fn load(name: &str) -> TetMesh {
    load_mesh(&crate::support::path("meshes").join(name))
        .unwrap()
        .0
}

/// Distinct edges, counted independently of the code under test.
fn edge_count(m: &TetMesh) -> usize {
    let mut edges = HashSet::new();
    for t in m.tet_ids() {
        let v = m.tet(t);
        for e in TET_EDGES {
            edges.insert(edge_key(v[e[0]], v[e[1]]));
        }
    }
    edges.len()
}

fn boundary_faces(m: &TetMesh) -> usize {
    m.tet_ids()
        .map(|t| (0..4).filter(|&f| m.is_boundary_face(t, f)).count())
        .sum()
}

fn volume(m: &TetMesh) -> f64 {
    m.tet_ids().map(|t| tet_volume(&m.tet_points(t))).sum()
}

type Bits = [u64; 3];

fn bits(p: glam::DVec3) -> Bits {
    p.to_array().map(f64::to_bits)
}

/// Output point id by exact coordinates.
fn point_index(m: &TetMesh) -> HashMap<Bits, u32> {
    (0..m.n_points() as u32)
        .map(|v| (bits(m.point(v)), v))
        .collect()
}

fn check_one_step(name: &str, input: &TetMesh) {
    let out = bisect(input).unwrap();
    out.check()
        .unwrap_or_else(|e| panic!("{name}: check failed: {e}"));
    let (n, e) = (input.n_tets(), edge_count(input));
    assert_eq!(out.n_tets(), 8 * n, "{name}: tets");
    assert_eq!(out.n_points(), input.n_points() + e, "{name}: V + E points");
    // Edges after the step: 2 per old edge, 3 per old face, 1 per tet (the
    // octahedron diagonal). Faces: interior + boundary = (4n_t + n_b)/2.
    let faces = (4 * n + boundary_faces(input)) / 2;
    assert_eq!(edge_count(&out), 2 * e + 3 * faces + n, "{name}: edges");
    assert_eq!(boundary_faces(&out), 4 * boundary_faces(input), "{name}");

    // Volume, overall and per parent, to 1e-12 relative.
    let (v0, v1) = (volume(input), volume(&out));
    assert!((v1 - v0).abs() <= 1e-12 * v0, "{name}: volume {v0} -> {v1}");

    // Children of live tet i are 8i..8i+8: built from its corners and edge
    // midpoints, same region, level + 1, same input ancestor, volumes adding up.
    let ids: Vec<u32> = input.tet_ids().collect();
    for (i, &t) in ids.iter().enumerate() {
        let p = input.tet_points(t);
        let mut allowed: HashSet<Bits> = p.iter().map(|&q| bits(q)).collect();
        for [a, b] in TET_EDGES {
            allowed.insert(bits((p[a] + p[b]) * 0.5));
        }
        let parent_vol = tet_volume(&p);
        let mut sum = 0.0;
        for c in 0..8 {
            let ch = (8 * i + c) as u32;
            let q = out.tet_points(ch);
            assert!(q.iter().all(|&x| allowed.contains(&bits(x))), "{name}");
            assert_eq!(out.region(ch), input.region(t), "{name}: region");
            assert_eq!(out.level(ch), input.level(t) + 1, "{name}: level");
            assert_eq!(out.parent(ch), input.parent(t), "{name}: parent");
            sum += tet_volume(&q);
        }
        assert!(
            (sum - parent_vol).abs() <= 1e-12 * parent_vol,
            "{name}: tet {i}: {parent_vol} vs {sum}"
        );
    }

    // Marked faces → four children with the marker; feature edges → two
    // halves; corners and required vertices unchanged.
    assert_eq!(
        out.face_markers().len(),
        4 * input.face_markers().len(),
        "{name}"
    );
    assert_eq!(
        out.feature_edges().len(),
        2 * input.feature_edges().len(),
        "{name}"
    );
    let at = point_index(&out);
    let id = |p: glam::DVec3| at[&bits(p)];
    for (&[a, b, c], &m) in input.face_markers() {
        let pa = input.point(a);
        let pb = input.point(b);
        let pc = input.point(c);
        let (ab, bc, ca) = (
            id((pa + pb) * 0.5),
            id((pb + pc) * 0.5),
            id((pc + pa) * 0.5),
        );
        for f in [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]] {
            assert_eq!(out.face_marker(f), Some(m), "{name}: face {f:?}");
        }
    }
    for (&[a, b], &m) in input.feature_edges() {
        let mid = id((input.point(a) + input.point(b)) * 0.5);
        assert_eq!(out.feature_edge(a, mid), Some(m), "{name}");
        assert_eq!(out.feature_edge(mid, b), Some(m), "{name}");
    }
    assert_eq!(out.corners(), input.corners(), "{name}");
    assert_eq!(out.required_vertices(), input.required_vertices(), "{name}");
    // Per-region tet counts ×8.
    let count = |m: &TetMesh, k: usize| {
        let mut h: HashMap<i32, usize> = HashMap::new();
        for t in m.tet_ids() {
            *h.entry(m.region(t)).or_default() += k;
        }
        h
    };
    assert_eq!(count(&out, 1), count(input, 8), "{name}: regions");
}

#[test]
fn mmg_cube_one_step() {
    let m = load("mmg_cube.mesh");
    assert!(!m.face_markers().is_empty() && !m.feature_edges().is_empty());
    assert!(!m.corners().is_empty());
    check_one_step("mmg_cube", &m);
}

#[test]
fn tripod_one_step_with_detected_features() {
    let mut m = load("tripod.mesh");
    detect_features(&mut m, 45.0);
    assert!(!m.feature_edges().is_empty());
    check_one_step("tripod", &m);
}

#[test]
fn gmsh_t16_regions_and_interfaces() {
    // Six physical volumes sharing marked interface faces.
    let m = load("gmsh_t16.mesh");
    let regions: HashSet<i32> = m.tet_ids().map(|t| m.region(t)).collect();
    assert!(regions.len() > 1);
    check_one_step("gmsh_t16", &m);
}

#[test]
fn two_steps_give_64_times_the_tets() {
    let m = load("mmg_cube.mesh");
    let e1 = edge_count(&m);
    let once = bisect(&m).unwrap();
    let e2 = edge_count(&once);
    let twice = bisect_steps(&m, 2).unwrap();
    twice.check().unwrap();
    assert_eq!(twice.n_tets(), 64 * m.n_tets());
    assert_eq!(twice.n_points(), m.n_points() + e1 + e2);
    assert_eq!(twice.face_markers().len(), 16 * m.face_markers().len());
    assert!(twice.tet_ids().all(|t| twice.level(t) == 2));
    let (v0, v2) = (volume(&m), volume(&twice));
    assert!((v2 - v0).abs() <= 1e-12 * v0);
}

#[test]
fn mesh_with_dead_slots() {
    // A 2-3 flip followed by the 3-2 flip back leaves one dead slot.
    let mut m = load("mmg_cube.mesh");
    let (t, f) = m
        .tet_ids()
        .flat_map(|t| (0..4).map(move |f| (t, f)))
        .find(|&(t, f)| !m.is_boundary_face(t, f) && flip23_valid(&m, t, f))
        .unwrap();
    let three = flip23(&mut m, t, f).unwrap();
    let shared: Vec<u32> = m
        .tet(three[0])
        .into_iter()
        .filter(|v| m.tet(three[1]).contains(v) && m.tet(three[2]).contains(v))
        .collect();
    assert_eq!(shared.len(), 2);
    let v = m.tet(three[0]);
    let e = TET_EDGES
        .iter()
        .position(|&[a, b]| edge_key(v[a], v[b]) == edge_key(shared[0], shared[1]))
        .unwrap();
    flip32(&mut m, three[0], e).unwrap();
    m.check().unwrap();
    assert!(m.n_tet_slots() > m.n_tets());
    check_one_step("mmg_cube with a dead slot", &m);
}

fn run_cli(threads: &str, input: &Path, output: &Path) {
    let status = crate::tetrefine_command()
        .env("RAYON_NUM_THREADS", threads)
        .arg("bisect")
        .arg(input)
        .arg("-o")
        .arg(output)
        .arg("--steps")
        .arg("2")
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
}

#[test]
fn cli_output_is_identical_with_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["mmg_cube.mesh", "tripod.mesh"] {
        let input = PathBuf::from("meshes").join(name);
        let one = dir.path().join(format!("one_{name}"));
        let two = dir.path().join(format!("two_{name}"));
        run_cli("1", &input, &one);
        run_cli("2", &input, &two);
        let (a, b) = (std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap());
        assert!(!a.is_empty());
        assert!(a == b, "{name}: outputs differ between 1 and 2 threads");
        // And the file is the 64× mesh.
        let (back, _) = load_mesh(&one).unwrap();
        assert_eq!(back.n_tets(), 64 * load(name).n_tets());
    }
}

#[test]
fn cli_bad_input_fails_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.mesh");
    std::fs::write(
        &bad,
        "MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\n",
    )
    .unwrap();
    let out = dir.path().join("out.mesh");
    let r = crate::tetrefine_command()
        .args(["bisect"])
        .arg(&bad)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("bad.mesh"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists());
}
