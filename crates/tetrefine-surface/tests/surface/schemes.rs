//! Loop, Catmull–Clark and Doo–Sabin: counts per step from V, E, F, and
//! limit positions against the closed forms of the splines they generalise.

use crate::shapes::*;
use glam::DVec3;
use std::collections::{HashMap, HashSet};
use tetrefine_surface::catmull_clark::catmull_clark;
use tetrefine_surface::doo_sabin::doo_sabin;
use tetrefine_surface::loop_scheme::{loop_beta, loop_subdivide};
use tetrefine_surface::{Features, PolyMesh};

fn counts(m: &PolyMesh) -> (usize, usize, usize) {
    (m.used_vertices(), m.edge_list().len(), m.faces.len())
}

fn neighbours(m: &PolyMesh) -> HashMap<u32, HashSet<u32>> {
    let mut nb: HashMap<u32, HashSet<u32>> = HashMap::new();
    for [a, b] in m.edge_list() {
        nb.entry(a).or_default().insert(b);
        nb.entry(b).or_default().insert(a);
    }
    nb
}

/// A deterministic wobble so that control nets are not symmetric.
fn wobble(i: f64, j: f64) -> DVec3 {
    DVec3::new(
        (1.3 * i + 0.7 * j).sin() * 0.2,
        (0.9 * i - 1.1 * j).cos() * 0.15,
        (2.1 * i + 0.3 * j).sin() * 0.25,
    )
}

#[test]
fn loop_counts_per_step() {
    let nf = Features::default();
    for mesh in [
        icosahedron(),
        octahedron(),
        tri_grid(3, 2, |x, y| DVec3::new(x, y, 0.0)),
    ] {
        let (mut v, mut e, mut f) = counts(&mesh);
        let chi = mesh.euler_characteristic();
        for k in 1..=3 {
            let out = loop_subdivide(&mesh, k, &nf).unwrap();
            out.validate().unwrap();
            (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
            assert_eq!(counts(&out), (v, e, f), "step {k}");
            assert_eq!(out.euler_characteristic(), chi);
        }
    }
}

#[test]
fn loop_edge_and_vertex_masks() {
    // One step on a valence-6 torus: edge point 3/8 (a+b) + 1/8 (c+d) with
    // c, d the two common neighbours; vertex 5/8 p + 1/16 Σ (β(6) = 1/16).
    assert!((loop_beta(6) - 1.0 / 16.0).abs() < 1e-15);
    assert!((loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
    let mesh = tri_torus(6, 5);
    let out = loop_subdivide(&mesh, 1, &Features::default()).unwrap();
    let nb0 = neighbours(&mesh);
    let nb1 = neighbours(&out);
    let p = &mesh.points;
    for [a, b] in mesh.edge_list() {
        let common0: Vec<u32> = nb0[&a].intersection(&nb0[&b]).copied().collect();
        assert_eq!(common0.len(), 2);
        let common1: Vec<u32> = nb1[&a].intersection(&nb1[&b]).copied().collect();
        assert_eq!(common1.len(), 1);
        let ep = out.points[common1[0] as usize];
        let expect = (p[a as usize] + p[b as usize]) * 0.375
            + (p[common0[0] as usize] + p[common0[1] as usize]) * 0.125;
        assert!(ep.distance(expect) < 1e-13);
    }
    for v in 0..p.len() {
        let s: DVec3 = nb0[&(v as u32)].iter().map(|&w| p[w as usize]).sum();
        let expect = p[v] * (10.0 / 16.0) + s / 16.0;
        assert!(out.points[v].distance(expect) < 1e-13);
    }
}

#[test]
fn loop_limit_positions_match_the_box_spline_mask() {
    // On a regular mesh Loop's surface is the quartic box spline; its value
    // at a vertex is p/2 + Σ pᵢ/12. The mask is a left eigenvector of the
    // step, so it gives the same point on every refined mesh, and the vertex
    // itself converges to it.
    let mut mesh = tri_torus(7, 6);
    for (k, p) in mesh.points.iter_mut().enumerate() {
        *p += wobble(k as f64, 0.5 * k as f64);
    }
    let limit = |m: &PolyMesh, v: u32, nb: &HashMap<u32, HashSet<u32>>| -> DVec3 {
        assert_eq!(nb[&v].len(), 6);
        let s: DVec3 = nb[&v].iter().map(|&w| m.points[w as usize]).sum();
        m.points[v as usize] * 0.5 + s / 12.0
    };
    let nb0 = neighbours(&mesh);
    let l0: Vec<DVec3> = (0..mesh.points.len() as u32)
        .map(|v| limit(&mesh, v, &nb0))
        .collect();
    let mut last_err = f64::INFINITY;
    for k in 1..=3 {
        let out = loop_subdivide(&mesh, k, &Features::default()).unwrap();
        let nb = neighbours(&out);
        let mut err = 0.0f64;
        for v in 0..mesh.points.len() as u32 {
            assert!(
                limit(&out, v, &nb).distance(l0[v as usize]) < 1e-12,
                "step {k} vertex {v}"
            );
            err = err.max(out.points[v as usize].distance(l0[v as usize]));
        }
        assert!(err < 0.55 * last_err, "step {k}: {err} vs {last_err}");
        last_err = err;
    }
}

#[test]
fn catmull_clark_counts_per_step() {
    let nf = Features::default();
    let open = PolyMesh::new(
        tri_grid(3, 2, |x, y| DVec3::new(x, y, 0.0)).points,
        (0..3u32)
            .flat_map(|i| {
                (0..2u32).map(move |j| {
                    vec![
                        i * 3 + j,
                        (i + 1) * 3 + j,
                        (i + 1) * 3 + j + 1,
                        i * 3 + j + 1,
                    ]
                })
            })
            .collect(),
    );
    for mesh in [cube(), quad_torus(5, 4), octahedron(), open] {
        let chi = mesh.euler_characteristic();
        let (mut v, mut e, mut f) = counts(&mesh);
        let mut sides: usize = mesh.faces.iter().map(|f| f.len()).sum();
        for k in 1..=3 {
            let out = catmull_clark(&mesh, k, &nf).unwrap();
            out.validate().unwrap();
            (v, e, f) = (v + e + f, 2 * e + sides, sides);
            sides = 4 * f;
            assert_eq!(counts(&out), (v, e, f), "step {k}");
            assert_eq!(out.euler_characteristic(), chi);
        }
    }
    // The cube: 26 vertices, 48 edges, 24 quads after one step.
    assert_eq!(
        counts(&catmull_clark(&cube(), 1, &nf).unwrap()),
        (26, 48, 24)
    );
}

/// The uniform cubic B-spline N(t), centred at 0 with support [−2, 2].
fn cubic_bspline(t: f64) -> f64 {
    let a = t.abs();
    if a >= 2.0 {
        0.0
    } else if a >= 1.0 {
        (2.0 - a).powi(3) / 6.0
    } else {
        (4.0 - 6.0 * a * a + 3.0 * a * a * a) / 6.0
    }
}

/// The uniform quadratic B-spline, centred at 0 with support [−3/2, 3/2].
fn quadratic_bspline(t: f64) -> f64 {
    let a = t.abs();
    if a >= 1.5 {
        0.0
    } else if a >= 0.5 {
        (1.5 - a).powi(2) / 2.0
    } else {
        0.75 - a * a
    }
}

/// Tensor-product spline of a periodic (m × n) control net at (u, v).
fn spline(net: &[DVec3], m: usize, n: usize, u: f64, v: f64, basis: fn(f64) -> f64) -> DVec3 {
    let mut s = DVec3::ZERO;
    let (i0, j0) = (u.floor() as i64, v.floor() as i64);
    for a in i0 - 2..=i0 + 3 {
        for b in j0 - 2..=j0 + 3 {
            let w = basis(u - a as f64) * basis(v - b as f64);
            if w != 0.0 {
                let id = (a.rem_euclid(m as i64) as usize) * n + b.rem_euclid(n as i64) as usize;
                s += net[id] * w;
            }
        }
    }
    s
}

/// Limit of a valence-4 vertex of a quad mesh by the bicubic mask
/// (16 p + 4 Σ edge neighbours + Σ diagonals)/36, read off the faces.
fn bicubic_limit(m: &PolyMesh, w: u32) -> DVec3 {
    let mut s = m.points[w as usize] * 16.0;
    let mut nfaces = 0;
    for f in &m.faces {
        if let Some(k) = f.iter().position(|&x| x == w) {
            assert_eq!(f.len(), 4);
            nfaces += 1;
            // Each edge neighbour is seen from its two faces: 2 + 2 = 4.
            s += (m.points[f[(k + 1) % 4] as usize] + m.points[f[(k + 3) % 4] as usize]) * 2.0;
            s += m.points[f[(k + 2) % 4] as usize];
        }
    }
    assert_eq!(nfaces, 4);
    s / 36.0
}

#[test]
fn catmull_clark_limit_is_the_bicubic_bspline() {
    let (m, n) = (8usize, 6usize);
    let mesh = quad_torus_with(m, n, |i, j| {
        let base = quad_torus(m, n).points[(i as usize) * n + j as usize];
        base + wobble(i, j)
    });
    let net = mesh.points.clone();
    let nf = Features::default();
    // Parameters of the points made by the first step: old vertices,
    // edge points (found as the common neighbour of the edge's ends) and
    // face points (the common vertex of the children of two opposite corners).
    let one = catmull_clark(&mesh, 1, &nf).unwrap();
    let nb1 = neighbours(&one);
    let id = |i: usize, j: usize| ((i % m) * n + (j % n)) as u32;
    let mut probes: Vec<(u32, f64, f64)> = Vec::new();
    for i in 0..m {
        for j in 0..n {
            probes.push((id(i, j), i as f64, j as f64));
            for (a, b, u, v) in [
                (id(i, j), id(i + 1, j), i as f64 + 0.5, j as f64),
                (id(i, j), id(i, j + 1), i as f64, j as f64 + 0.5),
            ] {
                let c: Vec<u32> = nb1[&a].intersection(&nb1[&b]).copied().collect();
                assert_eq!(c.len(), 1);
                probes.push((c[0], u, v));
            }
            let verts_of = |v: u32| -> HashSet<u32> {
                one.faces
                    .iter()
                    .filter(|f| f.contains(&v))
                    .flatten()
                    .copied()
                    .collect()
            };
            let c: Vec<u32> = verts_of(id(i, j))
                .intersection(&verts_of(id(i + 1, j + 1)))
                .copied()
                .collect();
            assert_eq!(c.len(), 1);
            probes.push((c[0], i as f64 + 0.5, j as f64 + 0.5));
        }
    }
    let mut last_err = f64::INFINITY;
    for k in 1..=3 {
        let out = catmull_clark(&mesh, k, &nf).unwrap();
        let mut err = 0.0f64;
        for &(w, u, v) in &probes {
            let s = spline(&net, m, n, u, v, cubic_bspline);
            assert!(
                bicubic_limit(&out, w).distance(s) < 1e-12,
                "step {k}, point {w} at ({u}, {v})"
            );
            err = err.max(out.points[w as usize].distance(s));
        }
        // Control points approach the surface like h², i.e. by 1/4 per step.
        assert!(err < 0.3 * last_err, "step {k}: {err} vs {last_err}");
        last_err = err;
    }
}

#[test]
fn doo_sabin_counts_per_step() {
    for mesh in [cube(), quad_torus(4, 5), icosahedron()] {
        let chi = mesh.euler_characteristic();
        let (mut v, mut e, mut f) = counts(&mesh);
        for k in 1..=3 {
            let out = doo_sabin(&mesh, k).unwrap();
            out.validate().unwrap();
            (v, e, f) = (2 * e, 4 * e, f + e + v);
            assert_eq!(counts(&out), (v, e, f), "step {k}");
            assert_eq!(out.euler_characteristic(), chi);
        }
    }
    assert_eq!(counts(&doo_sabin(&cube(), 1).unwrap()), (24, 48, 26));
}

#[test]
fn doo_sabin_limit_is_the_biquadratic_bspline() {
    let (m, n) = (6usize, 7usize);
    let mesh = quad_torus_with(m, n, |i, j| {
        quad_torus(m, n).points[(i as usize) * n + j as usize] + wobble(i, j)
    });
    let net = mesh.points.clone();
    let (v0, e0, f0) = counts(&mesh);
    let centroid = |m: &PolyMesh, f: usize| m.face_centroid(f);
    let radius = |m: &PolyMesh, f: usize| {
        let c = m.face_centroid(f);
        m.faces[f]
            .iter()
            .map(|&v| m.points[v as usize].distance(c))
            .fold(0.0, f64::max)
    };
    let mut last = vec![f64::INFINITY; f0 + v0];
    for k in 1..=3 {
        let out = doo_sabin(&mesh, k).unwrap();
        for i in 0..m {
            for j in 0..n {
                // The face (i, j) shrinks to the spline at the face centre,
                // S(i + 1/2, j + 1/2), which is the face's centroid.
                let f = i * n + j;
                let s = spline(
                    &net,
                    m,
                    n,
                    i as f64 + 0.5,
                    j as f64 + 0.5,
                    quadratic_bspline,
                );
                assert!(s.distance(mesh.face_centroid(f)) < 1e-12);
                assert!(centroid(&out, f).distance(s) < 1e-12, "step {k}, face {f}");
                // The vertex (i, j) becomes the face F + E + v, shrinking to S(i, j).
                let vf = f0 + e0 + i * n + j;
                let s = spline(&net, m, n, i as f64, j as f64, quadratic_bspline);
                assert!(
                    centroid(&out, vf).distance(s) < 1e-12,
                    "step {k}, vertex face {vf}"
                );
                for (slot, face) in [(f, f), (f0 + i * n + j, vf)] {
                    let r = radius(&out, face);
                    assert!(
                        r < 0.55 * last[slot],
                        "step {k}: face {face} does not shrink"
                    );
                    last[slot] = r;
                }
            }
        }
    }
}
