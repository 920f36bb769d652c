//! √3 subdivision (Kobbelt; Labsik–Greiner): counts, trisection, planarity,
//! the α(n) rule, interpolation, creases, adaptive refinement.

use crate::shapes::*;
use glam::DVec3;
use std::collections::{HashMap, HashSet};
use tetrefine_surface::sqrt3::*;
use tetrefine_surface::PolyMesh;

fn tris(m: &PolyMesh) -> Vec<[u32; 3]> {
    m.triangles().unwrap()
}

fn adjacency(m: &PolyMesh) -> HashSet<[u32; 2]> {
    m.edge_list().into_iter().collect()
}

#[test]
fn face_count_triples_every_step_closed_and_open() {
    let closed = icosahedron();
    let open = tri_grid(4, 3, |x, y| DVec3::new(x, y, 0.1 * x * y));
    for rule in [
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Linear,
    ] {
        for mesh in [&closed, &open] {
            let mut s = Sqrt3Surface {
                points: mesh.points.clone(),
                tris: tris(mesh),
                creases: HashSet::new(),
                corners: HashSet::new(),
                generation: 0,
            };
            let mut f = mesh.faces.len();
            for _ in 0..4 {
                s.step(rule, &FaceSelection::All);
                f *= 3;
                assert_eq!(s.tris.len(), f);
                let pm = s.to_polymesh();
                pm.validate().unwrap();
                // The surface keeps its topology: χ and the boundary loops.
                assert_eq!(pm.euler_characteristic(), mesh.euler_characteristic());
            }
        }
    }
}

#[test]
fn vertex_counts_follow_v_plus_f_and_boundary_trisection() {
    // Closed: V' = V + F. Open, odd step: V' = V + F; even step: V' = V + F - Fb + 2 Eb
    // (Fb boundary triangles get two boundary points instead of a face point).
    let mesh = tri_grid(3, 3, |x, y| DVec3::new(x, y, 0.0));
    let (v0, f0, eb0) = (16usize, 18usize, 12usize);
    let s1 = sqrt3(&mesh, Sqrt3Rule::Linear, 1, &Sqrt3Options::default()).unwrap();
    assert_eq!(s1.points.len(), v0 + f0);
    assert_eq!(s1.boundary_edges().len(), eb0); // boundary kept in odd steps
    let s2 = sqrt3(&mesh, Sqrt3Rule::Linear, 2, &Sqrt3Options::default()).unwrap();
    let (v1, f1, eb1) = (v0 + f0, 3 * f0, eb0);
    assert_eq!(s2.points.len(), v1 + (f1 - eb1) + 2 * eb1);
    assert_eq!(s2.boundary_edges().len(), 3 * eb0); // trisected in even steps
}

#[test]
fn two_steps_trisect_every_original_edge() {
    // Kobbelt, Fig. 2: after two steps every old edge a-b is replaced by a
    // path a-p-q-b through two new vertices.
    for mesh in [icosahedron(), octahedron(), bipyramid(7, 1.3)] {
        let out = sqrt3(&mesh, Sqrt3Rule::Approximating, 2, &Sqrt3Options::default()).unwrap();
        let adj = adjacency(&out);
        let mut nbrs: HashMap<u32, Vec<u32>> = HashMap::new();
        for &[a, b] in &adj {
            nbrs.entry(a).or_default().push(b);
            nbrs.entry(b).or_default().push(a);
        }
        let nv0 = mesh.points.len() as u32;
        let nv1 = nv0 + mesh.faces.len() as u32;
        for [a, b] in mesh.edge_list() {
            assert!(!adj.contains(&[a, b]), "old edge survived two flips");
            // Second-generation neighbours of a and of b that are adjacent.
            let gen2 =
                |v: u32| -> Vec<u32> { nbrs[&v].iter().copied().filter(|&w| w >= nv1).collect() };
            let mut paths = 0;
            for p in gen2(a) {
                for q in gen2(b) {
                    if p != q && adj.contains(&[p.min(q), p.max(q)]) {
                        paths += 1;
                    }
                }
            }
            assert_eq!(
                paths, 1,
                "edge {a}-{b} is not trisected by exactly one path"
            );
        }
    }
}

#[test]
fn two_linear_steps_put_the_trisection_points_at_the_thirds() {
    // On a regular lattice the two apexes x, y of an edge a-b satisfy
    // x + y = a + b, so the two-step face point (5a + 2b + x + y)/9 is
    // exactly (2a + b)/3; boundary edges are trisected at the thirds.
    let mesh = tri_lattice(4, 4);
    let out = sqrt3(&mesh, Sqrt3Rule::Linear, 2, &Sqrt3Options::default()).unwrap();
    let pts: Vec<DVec3> = out.points.clone();
    let adj = adjacency(&out);
    let boundary: HashSet<[u32; 2]> = mesh.boundary_edges().into_iter().collect();
    for [a, b] in mesh.edge_list() {
        let (pa, pb) = (pts[a as usize], pts[b as usize]);
        let t1 = (pa * 2.0 + pb) / 3.0;
        let t2 = (pa + pb * 2.0) / 3.0;
        let find = |target: DVec3| pts.iter().position(|p| p.distance(target) < 1e-12);
        let (Some(p), Some(q)) = (find(t1), find(t2)) else {
            panic!(
                "edge {a}-{b} (boundary: {}) has no points at its thirds",
                boundary.contains(&[a, b])
            );
        };
        let (p, q) = (p as u32, q as u32);
        assert!(adj.contains(&[a.min(p), a.max(p)]));
        assert!(adj.contains(&[p.min(q), p.max(q)]));
        assert!(adj.contains(&[q.min(b), q.max(b)]));
    }
}

#[test]
fn planar_meshes_stay_planar() {
    let plane =
        |x: f64, y: f64| DVec3::new(x + 0.13 * (y * 1.7).sin(), y + 0.11 * (x * 2.3).cos(), 0.0);
    let flat = tri_grid(5, 4, plane);
    // Tilt it: z = 0.3 x - 0.2 y + 1.
    let mut mesh = flat.clone();
    for p in &mut mesh.points {
        p.z = 0.3 * p.x - 0.2 * p.y + 1.0;
    }
    for rule in [
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Linear,
    ] {
        let out = sqrt3(&mesh, rule, 4, &Sqrt3Options::default()).unwrap();
        for p in &out.points {
            assert!(
                (p.z - (0.3 * p.x - 0.2 * p.y + 1.0)).abs() < 1e-12,
                "{rule:?}: {p}"
            );
        }
    }
}

#[test]
fn kobbelt_alpha_matches_hand_values() {
    // α(n) = (4 - 2cos(2π/n))/9: cos(2π/3) = -1/2, cos(π/2) = 0,
    // cos(2π/5) = (√5-1)/4, cos(π/3) = 1/2, cos(π/4) = √2/2.
    let hand = [
        (3, 5.0 / 9.0),
        (4, 4.0 / 9.0),
        (5, (4.0 - (5f64.sqrt() - 1.0) / 2.0) / 9.0),
        (6, 1.0 / 3.0),
        (8, (4.0 - 2f64.sqrt()) / 9.0),
    ];
    for (n, a) in hand {
        assert!((kobbelt_alpha(n) - a).abs() < 1e-15, "n = {n}");
    }
}

#[test]
fn approximating_rule_moves_an_apex_by_alpha() {
    // Apex at (0,0,h) over a regular n-gon of radius 1 in z = 0: the
    // neighbours average to the origin, so the apex moves to (0,0,(1-α)h).
    let hand = [
        (3, 5.0 / 9.0),
        (4, 4.0 / 9.0),
        (5, (4.0 - (5f64.sqrt() - 1.0) / 2.0) / 9.0),
        (6, 1.0 / 3.0),
        (8, (4.0 - 2f64.sqrt()) / 9.0),
    ];
    let h = 1.7;
    for (n, alpha) in hand {
        let m = bipyramid(n, h);
        let pos = sqrt3_positions(
            &m.points,
            &tris(&m),
            Sqrt3Rule::Approximating,
            &HashSet::new(),
            &HashSet::new(),
        );
        let apex = pos.vertices[0];
        assert!(apex.x.abs() < 1e-14 && apex.y.abs() < 1e-14);
        assert!(
            (apex.z - (1.0 - alpha) * h).abs() < 1e-14,
            "n = {n}: {}",
            apex.z
        );
        // And the face points are the centroids.
        for (t, tri) in tris(&m).iter().enumerate() {
            let c =
                (m.points[tri[0] as usize] + m.points[tri[1] as usize] + m.points[tri[2] as usize])
                    / 3.0;
            assert!(pos.faces[t].distance(c) < 1e-15);
        }
    }
}

#[test]
fn interpolating_rule_keeps_old_vertices() {
    for mesh in [icosahedron(), bipyramid(5, 0.8), tri_torus(6, 5)] {
        let out = sqrt3(&mesh, Sqrt3Rule::Interpolating, 3, &Sqrt3Options::default()).unwrap();
        for (v, p) in mesh.points.iter().enumerate() {
            assert_eq!(out.points[v], *p);
        }
        // Points of the first step stay too.
        let one = sqrt3(&mesh, Sqrt3Rule::Interpolating, 1, &Sqrt3Options::default()).unwrap();
        for (v, p) in one.points.iter().enumerate() {
            assert_eq!(out.points[v], *p);
        }
    }
}

#[test]
fn interpolating_regular_face_point_uses_the_twelve_point_stencil() {
    // On a valence-6 torus, in lattice coordinates a triangle (A, B, C) has
    // tips P + Q − R across its edges and outer points 2P − R (P ≠ R); the
    // Labsik–Greiner face point is 32/81 Σ A − 1/81 Σ tips − 2/81 Σ outer.
    let (m, n) = (7usize, 6usize);
    let mesh = tri_torus(m, n);
    let id =
        |c: [i64; 2]| (c[0].rem_euclid(m as i64) as usize) * n + c[1].rem_euclid(n as i64) as usize;
    let pos = sqrt3_positions(
        &mesh.points,
        &tris(&mesh),
        Sqrt3Rule::Interpolating,
        &HashSet::new(),
        &HashSet::new(),
    );
    let p = |c: [i64; 2]| mesh.points[id(c)];
    for i in 0..m as i64 {
        for j in 0..n as i64 {
            let lattice = [
                [[i, j], [i + 1, j], [i + 1, j + 1]],
                [[i, j], [i + 1, j + 1], [i, j + 1]],
            ];
            for (k, tri) in lattice.iter().enumerate() {
                let mut expect = DVec3::ZERO;
                for a in 0..3 {
                    let (pp, q, r) = (tri[a], tri[(a + 1) % 3], tri[(a + 2) % 3]);
                    expect += p(pp) * (32.0 / 81.0);
                    expect -= p([pp[0] + q[0] - r[0], pp[1] + q[1] - r[1]]) * (1.0 / 81.0);
                    // The ordered pairs (P, R) and (R, P) over the three
                    // corners give each of the six outer points once.
                    for (x, y) in [(pp, r), (r, pp)] {
                        expect -= p([2 * x[0] - y[0], 2 * x[1] - y[1]]) * (2.0 / 81.0);
                    }
                }
                let face = 2 * id([i, j]) + k;
                assert!(pos.faces[face].distance(expect) < 1e-13, "face {face}");
            }
        }
    }
}

#[test]
fn labsik_greiner_vertex_stencils_reproduce_the_centroid_of_a_regular_fan() {
    // Centre at the origin, neighbours r_j on the unit circle at angles
    // θ_j = (2j − 1)π/k from the bisector of the triangle (0, r0, r1): the
    // affine stencil must give that triangle's centroid, (2/3)cos(π/k) along
    // the bisector.
    for k in 3..=12 {
        let (wc, w) = labsik_greiner_weights(k);
        assert!((wc + w.iter().sum::<f64>() - 1.0).abs() < 1e-14, "k = {k}");
        let mut p = DVec3::ZERO;
        for (j, wj) in w.iter().enumerate() {
            let t = (2.0 * j as f64 - 1.0) * std::f64::consts::PI / k as f64;
            p += DVec3::new(t.cos(), t.sin(), 0.0) * *wj;
        }
        let expect = DVec3::new(
            2.0 / 3.0 * (std::f64::consts::PI / k as f64).cos(),
            0.0,
            0.0,
        );
        assert!(p.distance(expect) < 1e-14, "k = {k}: {p}");
    }
}

#[test]
fn crease_vertices_stay_on_their_crease() {
    // A tent z = 0.5|x - 2| over [0,4]×[0,4], folded along x = 2, with the
    // fold tagged as a crease.
    let mesh = tri_grid(4, 4, |x, y| DVec3::new(x, y, 0.5 * (x - 2.0).abs()));
    let on_fold = |p: DVec3| (p.x - 2.0).abs() < 1e-12 && p.z.abs() < 1e-12;
    let creases: Vec<[u32; 2]> = mesh
        .edge_list()
        .into_iter()
        .filter(|e| on_fold(mesh.points[e[0] as usize]) && on_fold(mesh.points[e[1] as usize]))
        .collect();
    assert_eq!(creases.len(), 4);
    for rule in [
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Linear,
    ] {
        let mut s = Sqrt3Surface {
            points: mesh.points.clone(),
            tris: tris(&mesh),
            creases: creases.iter().copied().collect(),
            corners: HashSet::new(),
            generation: 0,
        };
        for step in 1..=4 {
            s.step(rule, &FaceSelection::All);
            // Odd steps keep the 4 crease edges, even ones trisect them.
            let expect = 4 * 3usize.pow((step / 2) as u32);
            assert_eq!(s.creases.len(), expect, "{rule:?} step {step}");
            for e in &s.creases {
                for &v in e {
                    let p = s.points[v as usize];
                    assert!(on_fold(p), "{rule:?} step {step}: crease vertex {v} at {p}");
                    assert!((-1e-12..=4.0 + 1e-12).contains(&p.y));
                }
            }
            s.to_polymesh().validate().unwrap();
        }
        // The crease stays a crease: the two sides keep their planes.
        for p in &s.points {
            if rule == Sqrt3Rule::Linear {
                assert!((p.z - 0.5 * (p.x - 2.0).abs()).abs() < 1e-12);
            }
        }
        if rule != Sqrt3Rule::Approximating {
            for (v, p) in mesh.points.iter().enumerate() {
                if on_fold(*p) {
                    assert_eq!(s.points[v], *p, "{rule:?}: crease vertex moved");
                }
            }
        }
    }
}

#[test]
fn approximating_crease_rule_is_the_ternary_cubic_bspline() {
    // The crease vertex rule in a trisecting step is (4, 19, 4)/27 and the
    // trisection points (1, 16, 10)/27: on a crease polyline through
    // (0,0,0), (1,0,0), (2,0,1) check one interior crease vertex.
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(0.5, 1.0, 0.0),
        DVec3::new(1.5, 1.0, 0.0),
    ];
    let tris = vec![[0, 1, 3], [1, 4, 3], [1, 2, 4]];
    // The open boundary 0-1-2-4-3-0 is the curve; vertex 2 is tagged as a
    // corner, so the curve 0-1-2 ends there.
    let trisected: HashSet<[u32; 2]> = [[0, 1], [1, 2]].into_iter().collect();
    let corners: HashSet<u32> = [2].into_iter().collect();
    let r = sqrt3_positions_trisecting(
        &points,
        &tris,
        Sqrt3Rule::Approximating,
        &HashSet::new(),
        &corners,
        &trisected,
    );
    assert_eq!(r.positions.vertices[2], points[2]);
    // Vertex 0 does not move: its other boundary edge 0-3 is not trisected.
    assert_eq!(r.positions.vertices[0], points[0]);
    let expect = (points[0] * 4.0 + points[1] * 19.0 + points[2] * 4.0) / 27.0;
    assert!(r.positions.vertices[1].distance(expect) < 1e-15);
    // Edge 1-2: the point near 1 is (P0 + 16 P1 + 10 P2)/27.
    let [near1, near2] = r.edge_points[&[1, 2]];
    assert!(near1.distance((points[0] + points[1] * 16.0 + points[2] * 10.0) / 27.0) < 1e-15);
    // Vertex 2 ends the curve: its missing neighbour is 2·P2 − P1.
    let ghost = points[2] * 2.0 - points[1];
    assert!(near2.distance((points[1] * 10.0 + points[2] * 16.0 + ghost) / 27.0) < 1e-15);
}

#[test]
fn adaptive_refinement_splits_only_selected_faces() {
    let mesh = tri_grid(6, 6, |x, y| DVec3::new(x, y, 0.05 * x * y));
    let sel = FaceSelection::Box {
        min: DVec3::new(-1.0, -1.0, -10.0),
        max: DVec3::new(2.5, 2.5, 10.0),
    };
    let chosen = (0..mesh.faces.len())
        .filter(|&f| sel.contains(mesh.face_centroid(f)))
        .count();
    let opts = Sqrt3Options {
        selection: sel.clone(),
        ..Default::default()
    };
    let one = sqrt3(&mesh, Sqrt3Rule::Approximating, 1, &opts).unwrap();
    assert_eq!(one.faces.len(), mesh.faces.len() + 2 * chosen);
    one.validate().unwrap();
    // Faces far from the box are untouched, with their vertices in place.
    let far: Vec<&Vec<u32>> = mesh
        .faces
        .iter()
        .enumerate()
        .filter(|(f, _)| mesh.face_centroid(*f).x > 4.0)
        .map(|(_, t)| t)
        .collect();
    let out: HashSet<Vec<u32>> = one.faces.iter().cloned().collect();
    for t in far {
        assert!(out.contains(t));
        for &v in t {
            assert_eq!(one.points[v as usize], mesh.points[v as usize]);
        }
    }
    let three = sqrt3(&mesh, Sqrt3Rule::Interpolating, 3, &opts).unwrap();
    three.validate().unwrap();
    assert!(three.faces.len() < mesh.faces.len() * 27);
    assert_eq!(three.euler_characteristic(), 1);
}

#[test]
fn bad_input_is_refused_with_a_reason() {
    let quad = cube();
    let e = sqrt3(&quad, Sqrt3Rule::Approximating, 1, &Sqrt3Options::default()).unwrap_err();
    assert!(e.to_string().contains("triangle"), "{e}");
    let mut flipped = octahedron();
    flipped.faces[0].reverse();
    let e = sqrt3(
        &flipped,
        Sqrt3Rule::Approximating,
        1,
        &Sqrt3Options::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("orientations disagree"), "{e}");
    let opts = Sqrt3Options {
        features: tetrefine_surface::features::Features {
            creases: vec![[0, 1]],
            ..Default::default()
        },
        ..Default::default()
    };
    let e = sqrt3(&octahedron(), Sqrt3Rule::Approximating, 1, &opts).unwrap_err();
    assert!(e.to_string().contains("not an edge"), "{e}");
}

#[test]
fn points_in_no_triangle_are_left_alone() {
    let mut m = icosahedron();
    let lonely = DVec3::new(7.0, 8.0, 9.0);
    m.points.push(lonely);
    for rule in [
        Sqrt3Rule::Approximating,
        Sqrt3Rule::Interpolating,
        Sqrt3Rule::Linear,
    ] {
        let pos = sqrt3_positions(&m.points, &tris(&m), rule, &HashSet::new(), &HashSet::new());
        assert_eq!(pos.vertices.len(), m.points.len());
        assert_eq!(pos.faces.len(), m.faces.len());
        assert_eq!(pos.vertices[12], lonely);
    }
}

#[test]
fn cube_edges_found_by_angle_stay_straight_and_corners_stay() {
    // The cube cut into triangles; --crease-angle 45 tags exactly its 12
    // edges; each cube corner has three crease edges, so it is a corner.
    let q = cube();
    let mut faces = Vec::new();
    for f in &q.faces {
        faces.push(vec![f[0], f[1], f[2]]);
        faces.push(vec![f[0], f[2], f[3]]);
    }
    let mesh = PolyMesh::new(q.points.clone(), faces);
    let opts = Sqrt3Options {
        features: tetrefine_surface::features::Features {
            crease_angle: Some(45.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let out = sqrt3(&mesh, Sqrt3Rule::Approximating, 4, &opts).unwrap();
    out.validate().unwrap();
    for v in 0..8 {
        assert_eq!(out.points[v], mesh.points[v]);
    }
    // Every point stays in the cube; points on its edges stay on them: a
    // point with two coordinates in {0, 1} is on a cube edge. Along each
    // original edge, 3² = 9 segments after four steps.
    let on_edge = out
        .points
        .iter()
        .filter(|p| {
            p.to_array()
                .iter()
                .filter(|c| **c == 0.0 || **c == 1.0)
                .count()
                >= 2
        })
        .count();
    assert_eq!(on_edge, 8 + 12 * 8);
    for p in &out.points {
        assert!(p.cmpge(DVec3::splat(-1e-12)).all() && p.cmple(DVec3::splat(1.0 + 1e-12)).all());
    }
}
