//! Hansmeyer's weighted Catmull–Clark (seed 001): zero weights are plain
//! Catmull–Clark, each equation checked on the cube by hand, spatial and
//! group weights, locks, and the JSON configuration.

use crate::shapes::*;
use glam::DVec3;
use std::io::Write;
use tetrefine_surface::catmull_clark::catmull_clark;
use tetrefine_surface::catmull_clark_weighted::*;
use tetrefine_surface::{Features, PolyMesh};

fn cfg_with(w: Weights) -> WeightedConfig {
    WeightedConfig {
        iterations: vec![w],
        ..Default::default()
    }
}

fn set(pairs: &[(WeightName, f64)]) -> WeightSet {
    pairs.iter().copied().collect()
}

fn face_point(out: &PolyMesh, input: &PolyMesh, f: usize) -> DVec3 {
    // Face points follow the V vertex points and E edge points.
    let e = input.edge_list().len();
    out.points[input.points.len() + e + f]
}

#[test]
fn zero_weights_give_plain_catmull_clark_bit_for_bit() {
    let zero = Weights::default();
    let configs = [
        WeightedConfig::default(),
        cfg_with(zero),
        // Every mechanism present, every weight zero.
        WeightedConfig {
            iterations: vec![zero, zero],
            mu_by_valence: [(3, 1.0), (4, -0.5)].into_iter().collect(),
            mu_by_pattern: [("3F3E".to_string(), 2.0)].into_iter().collect(),
            attractors: vec![Attractors {
                tightness: 2.0,
                sets: vec![AttractorSet {
                    position: [0.2, 0.1, 3.0],
                    strength: 1.0,
                    weights: set(&[(WeightName::Edge, 0.0)]),
                }],
                background: 0.0,
                mode: Mode::Add,
                active: None,
            }],
            spherical: vec![SphericalGradient {
                center: [0.0; 3],
                stops: vec![Stop {
                    at: 1.0,
                    weights: set(&[(WeightName::Vertex, 3.0)]),
                }],
                ..Default::default()
            }],
            merge_distance: 1e-9,
            vertex_groups: vec![VertexGroup {
                vertices: vec![1, 2],
                weights: Some(zero),
                lock_iterations: 0,
                lock_start: 0,
            }],
            face_groups: vec![FaceGroup {
                faces: vec![0],
                weights: zero,
            }],
            locked_edges: vec![],
            ..Default::default()
        },
    ];
    let creased = Features {
        creases: vec![[0, 1], [1, 3]],
        ..Default::default()
    };
    for cfg in &configs {
        for (mesh, feat) in [
            (cube(), Features::default()),
            (cube(), creased.clone()),
            (quad_torus(5, 4), Features::default()),
            (octahedron(), Features::default()),
        ] {
            let a = catmull_clark(&mesh, 3, &feat).unwrap();
            let b = catmull_clark_weighted(&mesh, 3, cfg, &feat).unwrap();
            assert_eq!(a, b);
        }
    }
}

#[test]
fn face_extrusion_moves_face_points_along_the_normal() {
    // Eq. 1 on the unit cube: face point = centroid + n · √area · w; √area = 1.
    let mesh = cube();
    let w = 0.4;
    let out = catmull_clark_weighted(
        &mesh,
        1,
        &cfg_with(Weights {
            face_extrude: w,
            ..Default::default()
        }),
        &Features::default(),
    )
    .unwrap();
    let centre = DVec3::splat(0.5);
    for f in 0..6 {
        let c = mesh.face_centroid(f);
        let outward = (c - centre) * 2.0; // unit normal of a cube face
        assert!(face_point(&out, &mesh, f).distance(c + outward * w) < 1e-15);
    }
}

#[test]
fn vertex_weight_follows_equation_three() {
    // Eq. 3 with w_v = 1 at a cube corner (valence 3):
    // V = (2 F̄ + 2 R̄ (1 − 1/2) + 0 P)/3. At (0,0,0) the face centroids average
    // to (1/3)(1,1,1) and the edge midpoints to (1/6)(1,1,1), so
    // V = (2/3 + 1/6)/3 (1,1,1) = (5/18)(1,1,1).
    let out = catmull_clark_weighted(
        &cube(),
        1,
        &cfg_with(Weights {
            vertex: 1.0,
            ..Default::default()
        }),
        &Features::default(),
    )
    .unwrap();
    assert!(
        out.points[0].distance(DVec3::splat(5.0 / 18.0)) < 1e-15,
        "{}",
        out.points[0]
    );
}

#[test]
fn edge_weight_and_extrusion_follow_equation_two() {
    // Edge 0-1 of the cube, from (0,0,0) to (1,0,0), between the faces
    // z = 0 (normal −z) and y = 0 (normal −y): with w_e = 1/2 and extrusion
    // 0.3, E = ((F1+F2)·3/2 + (P1+P2)/2)/4 + 0.3 (0,−1,−1)/√2.
    let mesh = cube();
    let cfg = cfg_with(Weights {
        edge: 0.5,
        edge_extrude: 0.3,
        ..Default::default()
    });
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    let (f1, f2) = (DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.5, 0.0, 0.5));
    let (p1, p2) = (DVec3::ZERO, DVec3::X);
    let expect =
        ((f1 + f2) * 1.5 + (p1 + p2) * 0.5) / 4.0 + DVec3::new(0.0, -1.0, -1.0) / 2f64.sqrt() * 0.3;
    let e01 = mesh.edge_list().iter().position(|e| *e == [0, 1]).unwrap();
    assert!(out.points[8 + e01].distance(expect) < 1e-15);
}

#[test]
fn attraction_follows_equations_ten_and_eleven() {
    // μ = 1 for valence 3 (every cube vertex). Eq. 10 with w₆ = 1 pulls an
    // extruded face point back to the centroid; eq. 11 with w₇ = 1/2 pulls
    // an edge point to the midpoint of its edge.
    let mesh = cube();
    let cfg = WeightedConfig {
        iterations: vec![Weights {
            face_extrude: 0.5,
            face_attract: 1.0,
            edge: 0.3,
            edge_attract: 0.5,
            ..Default::default()
        }],
        mu_by_valence: [(3, 1.0)].into_iter().collect(),
        ..Default::default()
    };
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    for f in 0..6 {
        assert!(face_point(&out, &mesh, f).distance(mesh.face_centroid(f)) < 1e-15);
    }
    for (e, [a, b]) in mesh.edge_list().iter().enumerate() {
        let mid = (mesh.points[*a as usize] + mesh.points[*b as usize]) * 0.5;
        assert!(out.points[8 + e].distance(mid) < 1e-15);
    }
}

#[test]
fn attractor_sets_blend_by_equations_eight_and_nine() {
    // Two sets at (−1, ½, ½) and (2, ½, ½); distances are divided by the
    // diagonal of the box around the cube and the sets, √11. For the face
    // x = 0 (centroid (0, ½, ½)): d₁ = 1/√11, d₂ = 2/√11, with t = 2, h = 1.
    let mesh = cube();
    // In "add" mode on a zero base the weight is Σ cₐ wₐ itself.
    let at = |x: f64, w: f64| AttractorSet {
        position: [x, 0.5, 0.5],
        strength: 1.0,
        weights: set(&[(WeightName::FaceExtrude, w)]),
    };
    let cfg = WeightedConfig {
        attractors: vec![Attractors {
            tightness: 2.0,
            sets: vec![at(-1.0, 0.2), at(2.0, 0.6)],
            background: 0.0,
            mode: Mode::Add,
            active: None,
        }],
        ..Default::default()
    };
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    let s = 11f64.sqrt();
    let (c1, c2) = ((1.0 - 1.0 / s).powi(2), (1.0 - 2.0 / s).powi(2));
    let w = (0.2 * c1 + 0.6 * c2) / (c1 + c2);
    let f = mesh
        .faces
        .iter()
        .position(|f| f.iter().all(|&v| mesh.points[v as usize].x == 0.0))
        .unwrap();
    let expect = DVec3::new(0.0, 0.5, 0.5) + DVec3::NEG_X * w;
    assert!(face_point(&out, &mesh, f).distance(expect) < 1e-15);
}

#[test]
fn axis_gradient_interpolates_between_stops() {
    // face_extrude 0 at z = 0 and 1 at z = 1: the bottom face gets 0, the
    // sides (centroid z = ½) 0.5, the top 1.
    let mesh = cube();
    let cfg = WeightedConfig {
        axis: vec![AxisGradient {
            axis: Axis::Z,
            from: AxisStop {
                at: 0.0,
                weights: WeightSet::new(),
            },
            to: AxisStop {
                at: 1.0,
                weights: set(&[(WeightName::FaceExtrude, 1.0)]),
            },
            mode: Mode::Add,
            active: None,
        }],
        ..Default::default()
    };
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    for f in 0..6 {
        let c = mesh.face_centroid(f);
        let n = (c - DVec3::splat(0.5)) * 2.0;
        assert!(face_point(&out, &mesh, f).distance(c + n * c.z) < 1e-15);
    }
}

#[test]
fn face_groups_have_their_own_weights() {
    let mesh = cube();
    let cfg = WeightedConfig {
        face_groups: vec![FaceGroup {
            faces: vec![1],
            weights: Weights {
                face_extrude: 0.5,
                ..Default::default()
            },
        }],
        ..Default::default()
    };
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    for f in 0..6 {
        let c = mesh.face_centroid(f);
        let n = (c - DVec3::splat(0.5)) * 2.0;
        let w = if f == 1 { 0.5 } else { 0.0 };
        assert!(face_point(&out, &mesh, f).distance(c + n * w) < 1e-15);
    }
}

#[test]
fn locked_edges_stay_fixed_for_l_iterations() {
    // Edge 0-1 of the cube, (0,0,0)-(1,0,0), locked for L = 2 iterations:
    // after iteration k ≤ 2 the edge is the chain of 2^k + 1 points at x = j/2^k
    // on the original segment; after iteration 3 its ends move.
    let mesh = cube();
    let cfg = WeightedConfig {
        locked_edges: vec![LockedEdges {
            edges: vec![[1, 0]],
            iterations: 2,
            start: 0,
        }],
        ..Default::default()
    };
    for k in 1..=2usize {
        let out = catmull_clark_weighted(&mesh, k, &cfg, &Features::default()).unwrap();
        assert_eq!(out.points[0], DVec3::ZERO);
        assert_eq!(out.points[1], DVec3::X);
        let on_segment: Vec<f64> = out
            .points
            .iter()
            .filter(|p| p.y == 0.0 && p.z == 0.0)
            .map(|p| p.x)
            .collect();
        let n = 1usize << k;
        assert_eq!(on_segment.len(), n + 1, "iteration {k}");
        for j in 0..=n {
            let x = j as f64 / n as f64;
            assert!(
                on_segment.contains(&x),
                "iteration {k}: no point at x = {x}"
            );
        }
        // Everything else moved as in Catmull–Clark (away from the cube corners).
        let plain = catmull_clark(&mesh, k, &Features::default()).unwrap();
        assert_ne!(plain.points[0], out.points[0]);
        assert_eq!(
            plain.points[7], out.points[7],
            "far corner is not affected in iteration {k}"
        );
    }
    let three = catmull_clark_weighted(&mesh, 3, &cfg, &Features::default()).unwrap();
    assert_ne!(three.points[0], DVec3::ZERO);
    assert_ne!(three.points[1], DVec3::X);
}

#[test]
fn vertex_groups_lock_their_vertices() {
    let mesh = cube();
    let cfg = WeightedConfig {
        vertex_groups: vec![VertexGroup {
            vertices: vec![7],
            weights: None,
            lock_iterations: 2,
            lock_start: 0,
        }],
        ..Default::default()
    };
    for k in 1..=2 {
        let out = catmull_clark_weighted(&mesh, k, &cfg, &Features::default()).unwrap();
        assert_eq!(out.points[7], DVec3::ONE);
    }
    let out = catmull_clark_weighted(&mesh, 3, &cfg, &Features::default()).unwrap();
    assert!(out.points[7].distance(DVec3::ONE) > 1e-3);
}

#[test]
fn weights_per_iteration_change_between_iterations() {
    // Iteration 1 plain, iteration 2 with extrusion: the first step equals
    // plain Catmull–Clark, the second does not.
    let mesh = cube();
    let cfg = WeightedConfig {
        iterations: vec![
            Weights::default(),
            Weights {
                face_extrude: 0.3,
                ..Default::default()
            },
        ],
        ..Default::default()
    };
    let f = Features::default();
    assert_eq!(
        catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap(),
        catmull_clark(&mesh, 1, &f).unwrap()
    );
    assert_ne!(
        catmull_clark_weighted(&mesh, 2, &cfg, &f).unwrap(),
        catmull_clark(&mesh, 2, &f).unwrap()
    );
}

#[test]
fn json_configuration_reads_and_reports_errors_by_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("w.json");
    std::fs::File::create(&good)
        .unwrap()
        .write_all(
            br#"{
  "iterations": [ { "face_extrude": 0.25, "edge": 0.1 } ],
  "mu_by_valence": { "3": 0.5 },
  "attractors": { "tightness": 3, "sets": [ { "position": [0, 0, 2], "strength": 1, "weights": { "vertex": 0.2 } } ] },
  "axis": { "axis": "y", "from": { "at": 0 }, "to": { "at": 1, "weights": { "edge_extrude": 0.1 } } },
  "vertex_groups": [ { "vertices": [0, 1], "lock_iterations": 2 } ],
  "face_groups": [ { "faces": [2], "weights": { "face_face": 0.3 } } ],
  "locked_edges": [ { "edges": [[2, 3]], "iterations": 1 } ]
}"#,
        )
        .unwrap();
    let cfg = WeightedConfig::from_json_file(&good).unwrap();
    assert_eq!(cfg.iterations[0].face_extrude, 0.25);
    assert_eq!(cfg.mu_by_valence[&3], 0.5);
    assert_eq!(cfg.attractors[0].sets[0].weights[&WeightName::Vertex], 0.2);
    assert_eq!(cfg.axis[0].axis, Axis::Y);
    assert_eq!(cfg.locked_edges[0].edges, vec![[2, 3]]);
    let out = catmull_clark_weighted(&cube(), 2, &cfg, &Features::default()).unwrap();
    out.validate().unwrap();

    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\n  \"iterations\": [],\n  \"face_extrud\": 1\n}\n").unwrap();
    let e = WeightedConfig::from_json_file(&bad)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with(&format!("{}:3:", bad.display())), "{e}");
    assert!(e.contains("face_extrud"), "{e}");

    let cfg = WeightedConfig {
        locked_edges: vec![LockedEdges {
            edges: vec![[0, 7]],
            iterations: 1,
            start: 0,
        }],
        ..Default::default()
    };
    let e = catmull_clark_weighted(&cube(), 1, &cfg, &Features::default()).unwrap_err();
    assert!(e.to_string().contains("0-7"), "{e}");
}

#[test]
fn vertex_extrusion_moves_vertex_points_along_the_vertex_normal() {
    // Eq. 3 with w_v = 0 and extrusion w at the cube corner (0,0,0): the
    // plain point (F̄ + 2R̄)/3 = (1/3 + 1/3)/3 (1,1,1) = (2/9)(1,1,1), moved
    // along the normalised sum of the three unit face normals,
    // −(1,1,1)/√3, times the mean √area of those faces, 1.
    let w = 0.3;
    let out = catmull_clark_weighted(
        &cube(),
        1,
        &cfg_with(Weights {
            vertex_extrude: w,
            ..Default::default()
        }),
        &Features::default(),
    )
    .unwrap();
    let expect = DVec3::splat(2.0 / 9.0) - DVec3::ONE / 3f64.sqrt() * w;
    assert!(out.points[0].distance(expect) < 1e-15, "{}", out.points[0]);
}

#[test]
fn face_point_weights_follow_equation_four_from_the_second_iteration() {
    // Iteration 1 plain, iteration 2 with face_vertex = a, face_face = b:
    // every quad of the plain first step is (vertex, edge, face, edge)
    // derived, so its face point is
    // (P₀(1 + a) + P₂(1 + b) + (P₁ + P₃)(1 − (a + b)/2))/4,
    // computed here from plain Catmull–Clark, an independent code path.
    let (a, b) = (0.4, -0.2);
    let mesh = cube();
    let cfg = WeightedConfig {
        iterations: vec![
            Weights::default(),
            Weights {
                face_vertex: a,
                face_face: b,
                ..Default::default()
            },
        ],
        ..Default::default()
    };
    let one = catmull_clark(&mesh, 1, &Features::default()).unwrap();
    let two = catmull_clark_weighted(&mesh, 2, &cfg, &Features::default()).unwrap();
    let base = one.points.len() + one.edge_list().len();
    for (f, q) in one.faces.iter().enumerate() {
        let p = |k: usize| one.points[q[k] as usize];
        let expect =
            (p(0) * (1.0 + a) + p(2) * (1.0 + b) + (p(1) + p(3)) * (1.0 - (a + b) / 2.0)) / 4.0;
        assert!(two.points[base + f].distance(expect) < 1e-14, "face {f}");
    }
    // In the first iteration eq. 4 does not apply: the same weights there
    // give plain Catmull–Clark.
    let first = WeightedConfig {
        iterations: vec![cfg.iterations[1]],
        ..Default::default()
    };
    assert_eq!(
        catmull_clark_weighted(&mesh, 1, &first, &Features::default()).unwrap(),
        one
    );
}

#[test]
fn locks_can_start_after_iteration_n() {
    // Vertex 7 locked in iterations 1..3 (lock_start 1, 2 iterations): it
    // moves as in plain Catmull–Clark in the first iteration and then stays
    // there for two iterations; the fourth moves it again.
    let mesh = cube();
    let f = Features::default();
    let cfg = WeightedConfig {
        vertex_groups: vec![VertexGroup {
            vertices: vec![7],
            weights: None,
            lock_iterations: 2,
            lock_start: 1,
        }],
        ..Default::default()
    };
    let after_one = catmull_clark(&mesh, 1, &f).unwrap().points[7];
    assert_eq!(
        catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap().points[7],
        after_one
    );
    for k in 2..=3 {
        let out = catmull_clark_weighted(&mesh, k, &cfg, &f).unwrap();
        assert_eq!(out.points[7], after_one, "iteration {k}");
    }
    let four = catmull_clark_weighted(&mesh, 4, &cfg, &f).unwrap();
    assert_ne!(four.points[7], after_one);

    // Edge 0-1 locked from iteration 1 for 2 iterations: after the first
    // (plain) iteration it is the chain v0, m, v1; those three points stay,
    // and after iterations 2 and 3 the chain has 5 and 9 points on the
    // straight segments v0-m and m-v1, at their dyadic fractions.
    let cfg = WeightedConfig {
        locked_edges: vec![LockedEdges {
            edges: vec![[0, 1]],
            iterations: 2,
            start: 1,
        }],
        ..Default::default()
    };
    let one = catmull_clark(&mesh, 1, &f).unwrap();
    let e01 = mesh.edge_list().iter().position(|e| *e == [0, 1]).unwrap();
    let (a, m, b) = (one.points[0], one.points[8 + e01], one.points[1]);
    assert_eq!(catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap(), one);
    for k in 2..=3usize {
        let out = catmull_clark_weighted(&mesh, k, &cfg, &f).unwrap();
        assert_eq!(out.points[0], a);
        assert_eq!(out.points[1], b);
        assert_eq!(out.points[8 + e01], m);
        let n = 1usize << (k - 1);
        for (p, q) in [(a, m), (m, b)] {
            for j in 0..=n {
                let t = j as f64 / n as f64;
                let x = p + (q - p) * t;
                assert!(
                    out.points.iter().any(|y| y.distance(x) < 1e-15),
                    "iteration {k}: no chain point at {x}"
                );
            }
        }
    }
    let four = catmull_clark_weighted(&mesh, 4, &cfg, &f).unwrap();
    assert_ne!(four.points[0], a);
}

#[test]
fn mu_by_face_edge_pattern_overrides_mu_by_valence() {
    // One open unit quad: its corners are in 1 face with 2 edges ("1F2E").
    // Face point extruded by 0.5 along +z (√area = 1); eq. 10 with w₆ = 1
    // and μ = 1 at every corner pulls it back to the centroid exactly as
    // F + Σ(Pₖ − F)/4 = centroid; μ by pattern 0 overrides μ by valence 1.
    let quad = PolyMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        vec![vec![0, 1, 2, 3]],
    );
    let w = Weights {
        face_extrude: 0.5,
        face_attract: 1.0,
        ..Default::default()
    };
    let f = Features::default();
    let run = |valence: &[(u32, f64)], pattern: &[(&str, f64)]| {
        let cfg = WeightedConfig {
            iterations: vec![w],
            mu_by_valence: valence.iter().copied().collect(),
            mu_by_pattern: pattern.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            ..Default::default()
        };
        catmull_clark_weighted(&quad, 1, &cfg, &f).map(|m| m.points[8])
    };
    let centroid = DVec3::new(0.5, 0.5, 0.0);
    let extruded = centroid + DVec3::Z * 0.5;
    assert!(run(&[], &[("1F2E", 1.0)]).unwrap().distance(centroid) < 1e-15);
    assert!(run(&[(2, 1.0)], &[]).unwrap().distance(centroid) < 1e-15);
    assert_eq!(run(&[(2, 1.0)], &[("1F2E", 0.0)]).unwrap(), extruded);
    assert_eq!(run(&[], &[("2F2E", 1.0)]).unwrap(), extruded);
    let e = run(&[], &[("4F", 1.0)]).unwrap_err().to_string();
    assert!(e.contains("'4F'"), "{e}");
}

// ---- Composition rule and the spatial fields (issue 19, point 1) ----

/// An open m × m grid of unit quads in z = 0, counter-clockwise seen from +z.
fn flat_grid(m: u32) -> PolyMesh {
    let mut p = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            p.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let id = |i: u32, j: u32| j * (m + 1) + i;
    let mut f = Vec::new();
    for j in 0..m {
        for i in 0..m {
            f.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(p, f)
}

/// The four corners of [`flat_grid`] tagged as corners (fixed), so that its
/// boundary stays straight: boundary points stay or go to midpoints.
fn grid_corners(m: u32) -> Features {
    Features {
        corners: vec![0, m, (m + 1) * m, (m + 1) * (m + 1) - 1],
        ..Default::default()
    }
}

fn base(w: Weights) -> WeightedConfig {
    cfg_with(w)
}

fn extrude(w: f64) -> Weights {
    Weights {
        face_extrude: w,
        ..Default::default()
    }
}

/// Unit outward normal of cube face `f` (√area = 1).
fn cube_normal(mesh: &PolyMesh, f: usize) -> DVec3 {
    (mesh.face_centroid(f) - DVec3::splat(0.5)) * 2.0
}

fn stop(at: f64, pairs: &[(WeightName, f64)]) -> Stop {
    Stop {
        at,
        weights: set(pairs),
    }
}

#[test]
fn equation_one_on_the_cube_in_closed_form() {
    // Eq. 1: F = (P₁+P₂+P₃+P₄)/4 + n·w. The face y = 0 of the unit cube has
    // corners (0,0,0), (1,0,0), (1,0,1), (0,0,1): F = (½, 0, ½) + (0, −1, 0)·w.
    let w = -0.35;
    let mesh = cube();
    let out = catmull_clark_weighted(&mesh, 1, &base(extrude(w)), &Features::default()).unwrap();
    // Face 2 is [0, 1, 5, 4], the face y = 0.
    assert_eq!(face_point(&out, &mesh, 2), DVec3::new(0.5, -w, 0.5));
}

#[test]
fn equation_four_on_a_flat_quad_in_closed_form() {
    // One open unit quad, its corners tagged. The plain first step makes the four quads
    // (corner, edge midpoint, centre, edge midpoint): boundary points are the
    // corners (fixed) and the midpoints, the face point the centre (½, ½).
    // Eq. 4 in the second step, for the quad at the corner (0, 0):
    // F = ((0,0)(1+a) + (½,½)(1+b) + ((½,0) + (0,½))(1 − (a+b)/2))/4
    //   = (½,½)(2 + (b − a)/2)/4.
    let quad = flat_grid(1);
    let (a, b) = (0.4, -0.2);
    let cfg = WeightedConfig {
        iterations: vec![
            Weights::default(),
            Weights {
                face_vertex: a,
                face_face: b,
                ..Default::default()
            },
        ],
        ..Default::default()
    };
    let out = catmull_clark_weighted(&quad, 2, &cfg, &grid_corners(1)).unwrap();
    let s = 0.5 * (2.0 + (b - a) / 2.0) / 4.0; // 0.2125
    assert!((s - 0.2125).abs() < 1e-15);
    for (x, y) in [(s, s), (1.0 - s, s), (1.0 - s, 1.0 - s), (s, 1.0 - s)] {
        let expect = DVec3::new(x, y, 0.0);
        assert!(
            out.points.iter().any(|p| p.distance(expect) < 1e-15),
            "no face point at {expect}"
        );
    }
    // Plain Catmull–Clark puts it at the sub-quad's centre (¼, ¼).
    let plain =
        catmull_clark_weighted(&quad, 2, &WeightedConfig::default(), &grid_corners(1)).unwrap();
    assert!(plain
        .points
        .iter()
        .any(|p| p.distance(DVec3::new(0.25, 0.25, 0.0)) < 1e-15));
    assert!(!out
        .points
        .iter()
        .any(|p| p.distance(DVec3::new(0.25, 0.25, 0.0)) < 1e-9));
}

#[test]
fn spatial_fields_modulate_the_iteration_weights_instead_of_replacing_them() {
    // Base: face_extrude 0.2, vertex 1 (eq. 3 at the cube corner (0,0,0)
    // gives (5/18)(1,1,1) without face extrusion there, see above).
    // Axis z in scale mode, factor 1 at z = 0 to 3 at z = 1, naming only
    // face_extrude; spherical in add mode, +0.1 everywhere.
    // Face weight = 0.2 · (1 + 2 z_c) + 0.1: bottom 0.3, sides 0.5, top 0.7.
    let mesh = cube();
    let mut cfg = base(Weights {
        face_extrude: 0.2,
        ..Default::default()
    });
    cfg.axis = vec![AxisGradient {
        axis: Axis::Z,
        from: stop(0.0, &[(WeightName::FaceExtrude, 1.0)]),
        to: stop(1.0, &[(WeightName::FaceExtrude, 3.0)]),
        mode: Mode::Scale,
        active: None,
    }];
    cfg.spherical = vec![SphericalGradient {
        center: [0.5; 3],
        stops: vec![stop(0.0, &[(WeightName::FaceExtrude, 0.1)])],
        mode: Mode::Add,
        active: None,
    }];
    let f = Features::default();
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    for face in 0..6 {
        let c = mesh.face_centroid(face);
        let w = 0.2 * (1.0 + 2.0 * c.z) + 0.1;
        let got = face_point(&out, &mesh, face);
        assert!(
            got.distance(c + cube_normal(&mesh, face) * w) < 1e-15,
            "face {face}"
        );
    }
    // A field naming only edge_extrude leaves the iteration's vertex weight:
    // eq. 3 with w_v = 1 at (0,0,0) as without the field.
    let mut cfg = base(Weights {
        vertex: 1.0,
        ..Default::default()
    });
    cfg.axis = vec![AxisGradient {
        axis: Axis::X,
        from: stop(0.0, &[(WeightName::EdgeExtrude, 5.0)]),
        to: stop(1.0, &[(WeightName::EdgeExtrude, 5.0)]),
        mode: Mode::Scale,
        active: None,
    }];
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    assert!(out.points[0].distance(DVec3::splat(5.0 / 18.0)) < 1e-15);
    // Per-iteration weights and fields together: iteration weights 0.2 then
    // 0; the field (factor 3 everywhere) acts in iteration 0 only
    // ("active": [0, 0]); a second field with "active": [1, 1] adds 0.3 in
    // iteration 1 only. The first step is eq. 1 with w = 0.6; the second
    // differs from the run without the second field.
    let mut cfg = WeightedConfig {
        iterations: vec![extrude(0.2), extrude(0.0)],
        ..Default::default()
    };
    cfg.radial = vec![RadialGradient {
        center: [0.0; 3],
        direction: [0.0, 0.0, 1.0],
        stops: vec![stop(0.0, &[(WeightName::FaceExtrude, 3.0)])],
        mode: Mode::Scale,
        active: Some([0, 0]),
    }];
    let one = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    for face in 0..6 {
        let c = mesh.face_centroid(face);
        let got = face_point(&one, &mesh, face);
        assert!(got.distance(c + cube_normal(&mesh, face) * 0.6) < 1e-15);
    }
    let two_without = catmull_clark_weighted(&mesh, 2, &cfg, &f).unwrap();
    cfg.spherical = vec![SphericalGradient {
        center: [0.5; 3],
        stops: vec![stop(0.0, &[(WeightName::FaceExtrude, 0.3)])],
        mode: Mode::Add,
        active: Some([1, 1]),
    }];
    assert_eq!(catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap(), one);
    let two_with = catmull_clark_weighted(&mesh, 2, &cfg, &f).unwrap();
    assert_ne!(two_with, two_without);
    // Iteration 1 has base 0, so only the added 0.3 moves its face points:
    // every second-step face point of the run with it is 0.3·√area off the
    // centroid of its face, along the face normal.
    let ne = one.edge_list().len();
    for (k, q) in one.faces.iter().enumerate() {
        let c = q.iter().map(|&v| one.points[v as usize]).sum::<DVec3>() / 4.0;
        let d = two_with.points[one.points.len() + ne + k] - c;
        let n = one.face_newell(k);
        let expect = n.normalize() * (n.length() * 0.5).sqrt() * 0.3;
        assert!(d.distance(expect) < 1e-12, "face {k}");
        assert_eq!(two_without.points[one.points.len() + ne + k], c);
    }
}

/// Face points of `out` (one step from `mesh`) equal those of `plain`
/// except on the faces in `changed`.
fn only_faces_changed(mesh: &PolyMesh, out: &PolyMesh, plain: &PolyMesh, changed: &[usize]) {
    for f in 0..mesh.faces.len() {
        let (a, b) = (face_point(out, mesh, f), face_point(plain, mesh, f));
        if changed.contains(&f) {
            assert_ne!(a, b, "face {f} should change");
        } else {
            assert_eq!(a, b, "face {f} should not change");
        }
    }
}

#[test]
fn spherical_gradient_changes_only_the_faces_near_its_centre() {
    // Centre (½, ½, −½): the bottom face's centroid is at distance ½, the
    // sides at √(1/4 + 1) ≈ 1.118, the top at 3/2. Stops: factor 3 at ½,
    // 1 from 1 on. Only the bottom face (factor 3) moves.
    let mesh = cube();
    let f = Features::default();
    let mut cfg = base(extrude(0.2));
    let plain = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    cfg.spherical = vec![SphericalGradient {
        center: [0.5, 0.5, -0.5],
        stops: vec![
            stop(0.5, &[(WeightName::FaceExtrude, 3.0)]),
            stop(1.0, &[(WeightName::FaceExtrude, 1.0)]),
        ],
        mode: Mode::Scale,
        active: None,
    }];
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    let bottom = 0; // [0, 2, 3, 1], z = 0
    only_faces_changed(&mesh, &out, &plain, &[bottom]);
    assert!(face_point(&out, &mesh, bottom).distance(DVec3::new(0.5, 0.5, -0.6)) < 1e-15);
    // Midway between the stops the factor is 2.
    cfg.spherical[0].center = [0.5, 0.5, -0.75];
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    assert!(face_point(&out, &mesh, bottom).distance(DVec3::new(0.5, 0.5, -0.4)) < 1e-15);
}

#[test]
fn radial_gradient_depends_on_the_distance_from_its_line_only() {
    // Line: the z axis. Centroid distances: faces x = 0 and y = 0: ½; the
    // bottom and top: √2/2; x = 1 and y = 1: √(1 + 1/4). Stops: factor 3 at
    // ½, 1 from 0.6 on, so only faces x = 0 (4) and y = 0 (2) move, by
    // 0.2 · 3 — the top and bottom, at the same distance from the line but
    // different z, both stay.
    let mesh = cube();
    let f = Features::default();
    let mut cfg = base(extrude(0.2));
    let plain = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    cfg.radial = vec![RadialGradient {
        center: [0.0, 0.0, 7.0],
        direction: [0.0, 0.0, -2.0],
        stops: vec![
            stop(0.5, &[(WeightName::FaceExtrude, 3.0)]),
            stop(0.6, &[(WeightName::FaceExtrude, 1.0)]),
        ],
        mode: Mode::Scale,
        active: None,
    }];
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    only_faces_changed(&mesh, &out, &plain, &[2, 4]);
    assert!(face_point(&out, &mesh, 4).distance(DVec3::new(-0.6, 0.5, 0.5)) < 1e-15);
    assert!(face_point(&out, &mesh, 2).distance(DVec3::new(0.5, -0.6, 0.5)) < 1e-15);
}

/// Two steps on the flat 3 × 3 grid with its corners tagged, the second with vertex extrusion `w`:
/// the first (plain) step gives the grid of spacing ½; in the second every
/// interior old point moves along z by ½ (the mean √area) · w · factor and
/// nothing else moves off z = 0. Returns (x, y, |z|) of the points off it.
fn lifted_points(cfg: &WeightedConfig) -> Vec<(f64, f64, f64)> {
    let out = catmull_clark_weighted(&flat_grid(3), 2, cfg, &grid_corners(3)).unwrap();
    out.points
        .iter()
        .filter(|p| p.z != 0.0)
        .map(|p| (p.x, p.y, p.z.abs()))
        .collect()
}

fn vertex_extrude_in_second_step(w: f64) -> WeightedConfig {
    WeightedConfig {
        iterations: vec![
            Weights::default(),
            Weights {
                vertex_extrude: w,
                ..Default::default()
            },
        ],
        ..Default::default()
    }
}

/// Expected |z| of the interior points of the half grid: ½ · w · factor(x, y).
fn check_lifted(got: &[(f64, f64, f64)], w: f64, factor: impl Fn(f64, f64) -> f64) {
    let mut n = 0;
    for i in 1..6 {
        for j in 1..6 {
            let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
            let z = 0.5 * w * factor(x, y);
            let hit = got
                .iter()
                .find(|p| (p.0 - x).abs() < 1e-12 && (p.1 - y).abs() < 1e-12);
            match hit {
                Some(p) => {
                    assert!((p.2 - z).abs() < 1e-12, "({x}, {y}): {} vs {z}", p.2);
                    n += 1;
                }
                None => assert!(z.abs() < 1e-12, "({x}, {y}) should be lifted by {z}"),
            }
        }
    }
    assert_eq!(got.len(), n, "points lifted that should not be");
}

#[test]
fn distance_to_the_input_vertices_weights_the_points_by_it() {
    // After the plain first step the interior old points are the input
    // vertices (distance 0 to them), the edge midpoints (½) and the face
    // centres (√2/2). Factor: 0 at distance 0, 1 at ½, 3 at 1, so the input
    // vertices stay, the midpoints rise by ½ w, the centres by
    // ½ w (1 + 2 (√2/2 − ½)/½).
    let w = 0.4;
    let plain = lifted_points(&vertex_extrude_in_second_step(w));
    check_lifted(&plain, w, |_, _| 1.0);
    let mut cfg = vertex_extrude_in_second_step(w);
    cfg.vertex_distance = vec![Ramp {
        stops: vec![
            stop(0.0, &[(WeightName::VertexExtrude, 0.0)]),
            stop(0.5, &[(WeightName::VertexExtrude, 1.0)]),
            stop(1.0, &[(WeightName::VertexExtrude, 3.0)]),
        ],
        ..Default::default()
    }];
    let centre = 1.0 + 2.0 * (2f64.sqrt() / 2.0 - 0.5) / 0.5;
    check_lifted(&lifted_points(&cfg), w, |x, y| {
        match (x.fract() == 0.0, y.fract() == 0.0) {
            (true, true) => 0.0,
            (false, false) => centre,
            _ => 1.0,
        }
    });
}

#[test]
fn distance_to_the_input_edges_weights_the_points_by_it() {
    // Input vertices and edge midpoints lie on input edges (distance 0), the
    // face centres are ½ from the nearest edge. Factor 1 at 0, 3 at ½: only
    // the centres change, to three times the plain lift.
    let w = 0.4;
    let mut cfg = vertex_extrude_in_second_step(w);
    cfg.edge_distance = vec![Ramp {
        stops: vec![
            stop(0.0, &[(WeightName::VertexExtrude, 1.0)]),
            stop(0.5, &[(WeightName::VertexExtrude, 3.0)]),
        ],
        ..Default::default()
    }];
    check_lifted(&lifted_points(&cfg), w, |x, y| {
        if x.fract() != 0.0 && y.fract() != 0.0 {
            3.0
        } else {
            1.0
        }
    });
}

#[test]
fn planarity_weights_follow_the_papers_measure() {
    // The quad (0,0,0), (1,0,0), (1,1,h), (0,1,0). Distance of each corner
    // from the plane of the other three over their perimeter:
    // corner 2: h / (2 + √2);
    // corner 0: h/√(1 + 2h²) / (2√(1 + h²) + √2);
    // corners 1, 3: h/√(1 + h²) / (1 + √(1 + h²) + √(2 + h²)).
    // Planarity p = their mean; factor 1 at 0 rising to 3 at 0.1.
    // Eq. 1: F = centroid + n̂ √area · 0.2 · factor with the vector area
    // ½ (P₂ − P₀) × (P₃ − P₁) = ½ (−h, −h, 2).
    let h: f64 = 0.3;
    let quad = PolyMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, h), DVec3::Y],
        vec![vec![0, 1, 2, 3]],
    );
    let (s1, s2) = ((1.0 + h * h).sqrt(), 2f64.sqrt());
    let p = (h / (2.0 + s2)
        + h / (1.0 + 2.0 * h * h).sqrt() / (2.0 * s1 + s2)
        + 2.0 * (h / s1) / (1.0 + s1 + (2.0 + h * h).sqrt()))
        / 4.0;
    assert!(p > 0.0 && p < 0.1);
    let factor = 1.0 + 2.0 * p / 0.1;
    let mut cfg = base(extrude(0.2));
    cfg.planarity = vec![Ramp {
        stops: vec![
            stop(0.0, &[(WeightName::FaceExtrude, 1.0)]),
            stop(0.1, &[(WeightName::FaceExtrude, 3.0)]),
        ],
        ..Default::default()
    }];
    let out = catmull_clark_weighted(&quad, 1, &cfg, &Features::default()).unwrap();
    let area = DVec3::new(-h, -h, 2.0) * 0.5;
    let expect =
        DVec3::new(0.5, 0.5, h / 4.0) + area.normalize() * area.length().sqrt() * 0.2 * factor;
    assert!(
        out.points[8].distance(expect) < 1e-14,
        "{} vs {expect}",
        out.points[8]
    );
    // A flat quad has planarity 0: factor 1, the same as without the field.
    let flat = flat_grid(1);
    let without = catmull_clark_weighted(&flat, 1, &base(extrude(0.2)), &Features::default());
    assert_eq!(
        catmull_clark_weighted(&flat, 1, &cfg, &Features::default()).unwrap(),
        without.unwrap()
    );
}

#[test]
fn attractor_sets_scale_the_iteration_weights() {
    // One set, strength 1, at (½, ½, −1), tightness 1: its influence is the
    // only one, so every face's factor is its value 2 (scale mode) where its
    // influence is positive: face_extrude 0.2 → 0.4 on every face.
    let mesh = cube();
    let mut cfg = base(extrude(0.2));
    cfg.attractors = vec![Attractors {
        tightness: 1.0,
        sets: vec![AttractorSet {
            position: [0.5, 0.5, -1.0],
            strength: 1.0,
            weights: set(&[(WeightName::FaceExtrude, 2.0)]),
        }],
        background: 0.0,
        mode: Mode::Scale,
        active: None,
    }];
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    for face in 0..6 {
        let c = mesh.face_centroid(face);
        let got = face_point(&out, &mesh, face);
        assert!(got.distance(c + cube_normal(&mesh, face) * 0.4) < 1e-15);
    }
    // With a background of strength 1 (neutral factor 1 at distance 0):
    // distances are divided by the diagonal of the box (0,0,−1)-(1,1,1),
    // √6. With tightness 1 the set's influence at a face is
    // c = 1 − |centroid − set|/√6 and eq. 9 with the background gives the
    // factor (2c + 1·1)/(c + 1).
    cfg.attractors[0].background = 1.0;
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    let set_at = DVec3::new(0.5, 0.5, -1.0);
    let mut factors = Vec::new();
    for face in 0..6 {
        let c = mesh.face_centroid(face);
        let infl = 1.0 - c.distance(set_at) / 6f64.sqrt();
        let factor = (2.0 * infl + 1.0) / (infl + 1.0);
        factors.push(factor);
        let got = face_point(&out, &mesh, face);
        assert!(got.distance(c + cube_normal(&mesh, face) * 0.2 * factor) < 1e-15);
    }
    // The bottom (nearest) is pulled most, the top least.
    assert!(factors[0] > factors[2] && factors[2] > factors[1]);
}

#[test]
fn merge_distance_joins_coincident_points() {
    // A "pillow": one unit square twice, back to back, its four vertices
    // locked for the step. Both face points are the centre (½, ½, 0), the
    // edge points ((F₁ + F₂) + (P₁ + P₂))/4 are (½, ¼, 0) and the like; so
    // without merging there are 4 + 4 + 2 = 10 distinct points, with merging
    // 9, and the 8 quads all keep 4 corners, the four of each side sharing
    // the joined centre.
    let pillow = PolyMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        vec![vec![0, 1, 2, 3], vec![0, 3, 2, 1]],
    );
    let f = Features::default();
    let locked = WeightedConfig {
        vertex_groups: vec![VertexGroup {
            vertices: vec![0, 1, 2, 3],
            weights: None,
            lock_iterations: 1,
            lock_start: 0,
        }],
        ..Default::default()
    };
    let apart = catmull_clark_weighted(&pillow, 1, &locked, &f).unwrap();
    assert_eq!(apart.points.len(), 10);
    let e01 = DVec3::new(0.5, 0.25, 0.0);
    assert!(apart.points.contains(&e01));
    let cfg = WeightedConfig {
        merge_distance: 1e-6,
        ..locked.clone()
    };
    let joined = catmull_clark_weighted(&pillow, 1, &cfg, &f).unwrap();
    assert_eq!(joined.points.len(), 9);
    assert_eq!(joined.faces.len(), 8);
    let centre = joined
        .points
        .iter()
        .position(|p| *p == DVec3::new(0.5, 0.5, 0.0))
        .unwrap() as u32;
    assert!(joined
        .faces
        .iter()
        .all(|q| q.len() == 4 && q.contains(&centre)));
    // The other points are those of the run without merging, in order.
    assert_eq!(joined.points[..8], apart.points[..8]);
    assert_eq!(joined.points[..4], pillow.points[..]);
    // Without the lock all four vertex points also fall on the centre
    // ((F̄ + 2R̄ − P)/2 = (½, ½, 0) at every corner): every quad
    // (V, E, F, E) becomes (C, E, C, E), two slivers C-E, and is removed.
    let all = WeightedConfig {
        merge_distance: 1e-6,
        ..Default::default()
    };
    let gone = catmull_clark_weighted(&pillow, 1, &all, &f).unwrap();
    assert!(gone.faces.is_empty(), "{:?} {:?}", gone.faces, gone.points);
    assert_eq!(gone.points.len(), 5);
    // A distance below every gap joins nothing.
    let cfg = WeightedConfig {
        merge_distance: 0.1,
        ..Default::default()
    };
    let mesh = cube();
    assert_eq!(
        catmull_clark_weighted(&mesh, 2, &cfg, &f).unwrap(),
        catmull_clark(&mesh, 2, &f).unwrap()
    );
}

#[test]
fn bad_weight_files_name_the_file_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            r#"{ "spherical": { "center": [0,0,0], "stops": [ { "at": 0, "weights": { "edgy": 1 } } ] } }"#,
            "edgy",
        ),
        (r#"{ "radial": { "centre": [0,0,0] } }"#, "centre"),
        ("{\n  \"iterations\": [ { \"edge\": NaN } ]\n}", "edge"),
        (
            r#"{ "attractors": { "sets": [ { "strength": -1 } ] } }"#,
            "attractors.sets[0].strength",
        ),
        (r#"{ "merge_distance": -0.5 }"#, "merge_distance"),
        (
            r#"{ "planarity": { "stops": [ { "at": 1 }, { "at": 0.5 } ] } }"#,
            "planarity.stops[1].at",
        ),
        (
            r#"{ "axis": { "axis": "z", "from": { "at": 0 }, "to": { "at": 1 }, "active": [2, 1] } }"#,
            "axis.active",
        ),
        (
            r#"{ "radial": { "direction": [0,0,0], "stops": [ { "at": 0 } ] } }"#,
            "radial.direction",
        ),
    ];
    for (k, (text, field)) in cases.iter().enumerate() {
        let path = dir.path().join(format!("bad{k}.json"));
        std::fs::write(&path, text).unwrap();
        let e = WeightedConfig::from_json_file(&path)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(e.contains(field), "case {k}: {e}");
    }
}

#[test]
fn group_weights_are_a_base_that_the_fields_still_modulate() {
    // Face group {1} (the top, z = 1) with face_extrude 0.5 as its base; an
    // axis field in scale mode, factor 1 at z = 0 to 2 at z = 1. The top's
    // face point moves by 0.5 · 2 = 1 along +z; every other face has base
    // 0 (no iteration weights), so its face point stays at the centroid.
    let mesh = cube();
    let cfg = WeightedConfig {
        face_groups: vec![FaceGroup {
            faces: vec![1],
            weights: extrude(0.5),
        }],
        axis: vec![AxisGradient {
            axis: Axis::Z,
            from: stop(0.0, &[(WeightName::FaceExtrude, 1.0)]),
            to: stop(1.0, &[(WeightName::FaceExtrude, 2.0)]),
            mode: Mode::Scale,
            active: None,
        }],
        ..Default::default()
    };
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
    for f in 0..6 {
        let c = mesh.face_centroid(f);
        let expect = if f == 1 { DVec3::new(0.5, 0.5, 2.0) } else { c };
        assert_eq!(face_point(&out, &mesh, f), expect, "face {f}");
    }
}

#[test]
fn a_field_may_be_given_once_or_as_a_list() {
    // Two spherical fields (constant factors 2 and 3 in scale mode) multiply:
    // face_extrude 0.1 → 0.6 in iteration 0; the second acts only from
    // iteration 1 on, so with "active": [1, 1] the first step has 0.2.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.json");
    let text = |active: &str| {
        format!(
            r#"{{ "iterations": [ {{ "face_extrude": 0.1 }} ],
  "spherical": [
    {{ "stops": [ {{ "at": 0, "weights": {{ "face_extrude": 2 }} }} ] }},
    {{ "stops": [ {{ "at": 0, "weights": {{ "face_extrude": 3 }} }} ]{active} }} ],
  "axis": null }}"#
        )
    };
    let mesh = cube();
    for (active, w) in [("", 0.6), (r#", "active": [1, 1]"#, 0.2)] {
        std::fs::write(&path, text(active)).unwrap();
        let cfg = WeightedConfig::from_json_file(&path).unwrap();
        assert_eq!(cfg.spherical.len(), 2);
        assert!(cfg.axis.is_empty());
        let out = catmull_clark_weighted(&mesh, 1, &cfg, &Features::default()).unwrap();
        for f in 0..6 {
            let c = mesh.face_centroid(f);
            let got = face_point(&out, &mesh, f);
            assert!(
                got.distance(c + cube_normal(&mesh, f) * w) < 1e-15,
                "{active}"
            );
        }
    }
    // One object is a list of one; an error in a list names the entry.
    std::fs::write(&path, r#"{ "planarity": { "stops": [ { "at": 0 } ] } }"#).unwrap();
    assert_eq!(
        WeightedConfig::from_json_file(&path)
            .unwrap()
            .planarity
            .len(),
        1
    );
    std::fs::write(
        &path,
        r#"{ "planarity": [ { "stops": [ { "at": 0 } ] }, { "stops": [ { "at": 0 } ], "active": [3, 2] } ] }"#,
    )
    .unwrap();
    let e = WeightedConfig::from_json_file(&path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`planarity[1].active`"), "{e}");
}

#[test]
fn a_merge_that_pinches_the_surface_stops_the_next_step_with_an_error() {
    // The locked pillow of `merge_distance_joins_coincident_points`: the
    // joined centre has the four quads of each side around it, two fans
    // meeting in one point, which is no manifold; the second step refuses
    // it with the topology error instead of panicking.
    let pillow = PolyMesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        vec![vec![0, 1, 2, 3], vec![0, 3, 2, 1]],
    );
    let cfg = WeightedConfig {
        merge_distance: 1e-6,
        vertex_groups: vec![VertexGroup {
            vertices: vec![0, 1, 2, 3],
            weights: None,
            lock_iterations: 1,
            lock_start: 0,
        }],
        ..Default::default()
    };
    let f = Features::default();
    assert!(catmull_clark_weighted(&pillow, 1, &cfg, &f).is_ok());
    let e = catmull_clark_weighted(&pillow, 2, &cfg, &f).unwrap_err();
    assert!(
        matches!(e, tetrefine_surface::SubdivisionError::Topology(_)),
        "{e}"
    );
}

#[test]
fn vertex_group_weights_are_a_base_that_the_fields_still_modulate() {
    // Vertex 0 of the cube, (0,0,0), with its own vertex weight 0.5 and a
    // spherical field doubling `vertex` within ½ of the origin (factor 2
    // at 0.5, 1 from 0.6 on; the other corners are ≥ 1 away): eq. 3 with
    // w_v = 1 there, (5/18)(1,1,1); every other vertex point is plain.
    let mesh = cube();
    let cfg = WeightedConfig {
        vertex_groups: vec![VertexGroup {
            vertices: vec![0],
            weights: Some(Weights {
                vertex: 0.5,
                ..Default::default()
            }),
            lock_iterations: 0,
            lock_start: 0,
        }],
        spherical: vec![SphericalGradient {
            center: [0.0; 3],
            stops: vec![
                stop(0.5, &[(WeightName::Vertex, 2.0)]),
                stop(0.6, &[(WeightName::Vertex, 1.0)]),
            ],
            mode: Mode::Scale,
            active: None,
        }],
        ..Default::default()
    };
    let f = Features::default();
    let out = catmull_clark_weighted(&mesh, 1, &cfg, &f).unwrap();
    let plain = catmull_clark(&mesh, 1, &f).unwrap();
    assert!(out.points[0].distance(DVec3::splat(5.0 / 18.0)) < 1e-15);
    assert_eq!(out.points[1..], plain.points[1..]);
}
