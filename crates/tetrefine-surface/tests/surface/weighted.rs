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
            attractors: Some(Attractors {
                tightness: 2.0,
                sets: vec![AttractorSet {
                    position: [0.2, 0.1, 3.0],
                    strength: 1.0,
                    weights: set(&[(WeightName::Edge, 0.0)]),
                }],
                mode: Mode::Add,
                active: None,
            }),
            spherical: Some(SphericalGradient {
                center: [0.0; 3],
                stops: vec![Stop {
                    at: 1.0,
                    weights: set(&[(WeightName::Vertex, 3.0)]),
                }],
                ..Default::default()
            }),
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
        attractors: Some(Attractors {
            tightness: 2.0,
            sets: vec![at(-1.0, 0.2), at(2.0, 0.6)],
            mode: Mode::Add,
            active: None,
        }),
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
        axis: Some(AxisGradient {
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
        }),
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
    assert_eq!(
        cfg.attractors.as_ref().unwrap().sets[0].weights[&WeightName::Vertex],
        0.2
    );
    assert_eq!(cfg.axis.as_ref().unwrap().axis, Axis::Y);
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
