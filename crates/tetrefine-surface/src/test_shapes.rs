//! Test support: small closed polyhedra, and topology and geometry checks
//! written independently of the schemes' own adjacency code.

use super::PolyMesh;
use glam::DVec3;
use std::collections::{HashMap, HashSet};

/// Orient every face of a convex polyhedron outwards (away from the centroid).
pub(crate) fn orient_convex(points: Vec<DVec3>, mut faces: Vec<Vec<u32>>) -> PolyMesh {
    let c = points.iter().sum::<DVec3>() / points.len() as f64;
    for f in &mut faces {
        let pts: Vec<DVec3> = f.iter().map(|&i| points[i as usize]).collect();
        let fc = pts.iter().sum::<DVec3>() / pts.len() as f64;
        if newell_normal(&pts).dot(fc - c) < 0.0 {
            f.reverse();
        }
    }
    PolyMesh { points, faces }
}

/// Newell's polygon normal (twice the vector area).
pub(crate) fn newell_normal(pts: &[DVec3]) -> DVec3 {
    (0..pts.len())
        .map(|i| pts[i].cross(pts[(i + 1) % pts.len()]))
        .sum()
}

pub(crate) fn tetrahedron() -> PolyMesh {
    let p = vec![
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    orient_convex(
        p,
        vec![vec![0, 1, 2], vec![0, 1, 3], vec![0, 2, 3], vec![1, 2, 3]],
    )
}

/// The cube [0, side]^3.
pub(crate) fn cube(side: f64) -> PolyMesh {
    let p = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64) * side)
        .collect();
    let faces = vec![
        vec![0, 1, 3, 2],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 3, 7, 6],
        vec![0, 2, 6, 4],
        vec![1, 3, 7, 5],
    ];
    orient_convex(p, faces)
}

pub(crate) fn octahedron() -> PolyMesh {
    let p = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut faces = Vec::new();
    for x in [0u32, 1] {
        for y in [2u32, 3] {
            for z in [4u32, 5] {
                faces.push(vec![x, y, z]);
            }
        }
    }
    orient_convex(p, faces)
}

pub(crate) fn icosahedron() -> PolyMesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p = Vec::new();
    for a in [-1.0, 1.0] {
        for b in [-phi, phi] {
            p.push(DVec3::new(0.0, a, b));
            p.push(DVec3::new(a, b, 0.0));
            p.push(DVec3::new(b, 0.0, a));
        }
    }
    let adjacent = |i: usize, j: usize| (p[i].distance(p[j]) - 2.0).abs() < 1e-9;
    let mut faces = Vec::new();
    for i in 0..12 {
        for j in i + 1..12 {
            for k in j + 1..12 {
                if adjacent(i, j) && adjacent(j, k) && adjacent(i, k) {
                    faces.push(vec![i as u32, j as u32, k as u32]);
                }
            }
        }
    }
    assert_eq!(faces.len(), 20);
    orient_convex(p, faces)
}

/// The icosahedron with `levels` rounds of 1-to-4 triangle splits, projected
/// to the unit sphere (valences 5 and 6).
pub(crate) fn icosphere(levels: usize) -> PolyMesh {
    let mut m = icosahedron();
    for p in &mut m.points {
        *p = p.normalize();
    }
    for _ in 0..levels {
        let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
        let mut faces = Vec::new();
        let mut points = m.points.clone();
        let mut mid = |a: u32, b: u32, points: &mut Vec<DVec3>| -> u32 {
            *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push((points[a as usize] + points[b as usize]).normalize());
                points.len() as u32 - 1
            })
        };
        for f in &m.faces {
            let (a, b, c) = (f[0], f[1], f[2]);
            let ab = mid(a, b, &mut points);
            let bc = mid(b, c, &mut points);
            let ca = mid(c, a, &mut points);
            faces.extend([
                vec![a, ab, ca],
                vec![ab, b, bc],
                vec![ca, bc, c],
                vec![ab, bc, ca],
            ]);
        }
        m = PolyMesh { points, faces };
    }
    m
}

/// The dual of the icosahedron through its face centroids: a regular
/// dodecahedron (planar pentagons, 3-valent vertices).
pub(crate) fn dodecahedron() -> PolyMesh {
    let ico = icosahedron();
    let centroids: Vec<DVec3> = ico
        .faces
        .iter()
        .map(|f| f.iter().map(|&i| ico.points[i as usize]).sum::<DVec3>() / 3.0)
        .collect();
    let mut faces = Vec::new();
    for (v, &axis) in ico.points.iter().enumerate() {
        let mut around: Vec<u32> = (0..ico.faces.len() as u32)
            .filter(|&f| ico.faces[f as usize].contains(&(v as u32)))
            .collect();
        let a = axis.normalize();
        let e1 = a.any_orthonormal_vector();
        let e2 = a.cross(e1);
        around.sort_by(|&f, &g| {
            let ang = |f: u32| {
                let d = centroids[f as usize] - axis;
                d.dot(e2).atan2(d.dot(e1))
            };
            ang(f).total_cmp(&ang(g))
        });
        faces.push(around);
    }
    orient_convex(centroids, faces)
}

/// The solid between a counter-clockwise polygon `base` (seen from +z) and a
/// polygon `top` above it with corresponding corners joined by quadrilaterals.
pub(crate) fn prism(base: &[DVec3], top: &[DVec3]) -> PolyMesh {
    let n = base.len() as u32;
    let mut points = base.to_vec();
    points.extend_from_slice(top);
    let mut faces = vec![(0..n).rev().collect::<Vec<u32>>(), (n..2 * n).collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, n + j, n + i]);
    }
    PolyMesh { points, faces }
}

/// The L-shaped prism: non-convex planar faces, all vertices 3-valent.
pub(crate) fn l_prism() -> PolyMesh {
    let base: Vec<DVec3> = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
    let top: Vec<DVec3> = base.iter().map(|&b| b + DVec3::Z).collect();
    prism(&base, &top)
}

/// A frustum over a random convex polygon (`sides` corners): the top is the
/// base scaled towards a random apex, so every face is planar and every vertex
/// 3-valent.
pub(crate) fn random_frustum(seed: u64, sides: usize) -> PolyMesh {
    let mut rng = tetrefine::SplitMix64(seed);
    let mut angles: Vec<f64> = (0..sides)
        .map(|_| rng.next_f64() * std::f64::consts::TAU)
        .collect();
    angles.sort_by(f64::total_cmp);
    let base: Vec<DVec3> = angles
        .iter()
        .map(|&a| DVec3::new(a.cos(), a.sin(), 0.0) * (0.7 + 0.6 * rng.next_f64()))
        .collect();
    // Convex hull order is the angle order only for a star-shaped polygon;
    // keep it star-shaped (planar faces are all that matter here).
    let apex = DVec3::new(
        rng.next_f64() - 0.5,
        rng.next_f64() - 0.5,
        1.5 + rng.next_f64(),
    );
    let s = 0.3 + 0.4 * rng.next_f64();
    let top: Vec<DVec3> = base.iter().map(|&b| apex + s * (b - apex)).collect();
    prism(&base, &top)
}

/// A torus as an `nu × nv` grid of quadrilaterals.
pub(crate) fn torus(nu: u32, nv: u32) -> PolyMesh {
    let mut points = Vec::new();
    for i in 0..nu {
        let phi = i as f64 / nu as f64 * std::f64::consts::TAU;
        for j in 0..nv {
            let th = j as f64 / nv as f64 * std::f64::consts::TAU;
            let r = 2.0 + th.cos();
            points.push(DVec3::new(r * phi.cos(), r * phi.sin(), th.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut faces = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh { points, faces }
}

/// Counts of a closed oriented manifold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Topology {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub components: usize,
    pub euler: i64,
}

/// Check that `mesh` is a closed, consistently oriented 2-manifold by
/// following shared edges: every edge in exactly two faces, used once in
/// each direction; the corners around every vertex form one cycle.
pub(crate) fn closed_manifold_topology(mesh: &PolyMesh) -> Result<Topology, String> {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        if face.len() < 3 {
            return Err(format!("face {f} has {} vertices", face.len()));
        }
        let distinct: HashSet<u32> = face.iter().copied().collect();
        if distinct.len() != face.len() {
            return Err(format!("face {f} repeats a vertex"));
        }
        for i in 0..face.len() {
            let e = (face[i], face[(i + 1) % face.len()]);
            if directed.insert(e, f).is_some() {
                return Err(format!("directed edge {e:?} used twice"));
            }
        }
    }
    for &(a, b) in directed.keys() {
        if !directed.contains_key(&(b, a)) {
            return Err(format!("edge {a}-{b} has one face"));
        }
    }
    // Vertex links: corner (prev, next) at v; following prev -> next must
    // give a single cycle through all corners at v.
    let mut corners: HashMap<u32, HashMap<u32, u32>> = HashMap::new();
    for face in &mesh.faces {
        let n = face.len();
        for i in 0..n {
            let (u, v, w) = (face[(i + n - 1) % n], face[i], face[(i + 1) % n]);
            corners.entry(v).or_default().insert(u, w);
        }
    }
    for (&v, link) in &corners {
        let start = *link.keys().next().expect("non-empty");
        let mut x = start;
        let mut steps = 0;
        loop {
            x = *link
                .get(&x)
                .ok_or_else(|| format!("link of vertex {v} is broken at {x}"))?;
            steps += 1;
            if x == start || steps > link.len() {
                break;
            }
        }
        if x != start || steps != link.len() {
            return Err(format!("vertex {v}: link is not one cycle"));
        }
    }
    // Components by union-find over the faces' vertices.
    let mut parent: Vec<usize> = (0..mesh.points.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for face in &mesh.faces {
        for w in face.windows(2) {
            let (a, b) = (
                find(&mut parent, w[0] as usize),
                find(&mut parent, w[1] as usize),
            );
            parent[a] = b;
        }
    }
    let used: HashSet<u32> = mesh.faces.iter().flatten().copied().collect();
    let roots: HashSet<usize> = used
        .iter()
        .map(|&v| find(&mut parent, v as usize))
        .collect();
    let edges = directed.len() / 2;
    Ok(Topology {
        vertices: used.len(),
        edges,
        faces: mesh.faces.len(),
        components: roots.len(),
        euler: used.len() as i64 - edges as i64 + mesh.faces.len() as i64,
    })
}

/// Number of distinct neighbours of every used vertex.
pub(crate) fn valences(mesh: &PolyMesh) -> HashMap<u32, usize> {
    let mut nb: HashMap<u32, HashSet<u32>> = HashMap::new();
    for f in &mesh.faces {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            nb.entry(a).or_default().insert(b);
            nb.entry(b).or_default().insert(a);
        }
    }
    nb.into_iter().map(|(v, s)| (v, s.len())).collect()
}

/// A minimal Wavefront OBJ writer (`v` and 1-based `f` lines).
pub(crate) fn write_obj(mesh: &PolyMesh) -> String {
    let mut s = String::new();
    for p in &mesh.points {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for f in &mesh.faces {
        let ids: Vec<String> = f.iter().map(|i| (i + 1).to_string()).collect();
        s += &format!("f {}\n", ids.join(" "));
    }
    s
}

/// A minimal Wavefront OBJ reader for [`write_obj`]'s output.
pub(crate) fn read_obj(text: &str) -> PolyMesh {
    let mut m = PolyMesh::default();
    for line in text.lines() {
        let mut t = line.split_whitespace();
        match t.next() {
            Some("v") => {
                let c: Vec<f64> = t.map(|x| x.parse().expect("coordinate")).collect();
                m.points.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => m
                .faces
                .push(t.map(|x| x.parse::<u32>().expect("index") - 1).collect()),
            _ => {}
        }
    }
    m
}

/// Largest distance of `pts` from their least-squares plane (through the
/// centroid, normal = eigenvector of the smallest covariance eigenvalue).
pub(crate) fn plane_deviation(pts: &[DVec3]) -> f64 {
    let c = pts.iter().sum::<DVec3>() / pts.len() as f64;
    let mut a = [[0.0f64; 3]; 3];
    for p in pts {
        let d = *p - c;
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += d[i] * d[j];
            }
        }
    }
    let n = smallest_eigenvector(a);
    pts.iter()
        .map(|p| (*p - c).dot(n).abs())
        .fold(0.0, f64::max)
}

/// Cyclic Jacobi rotations on a symmetric 3 × 3 matrix.
#[allow(clippy::needless_range_loop)] // index notation mirrors the formulas
fn smallest_eigenvector(mut a: [[f64; 3]; 3]) -> DVec3 {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..100 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        if off < 1e-300 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let k = (0..3)
        .min_by(|&i, &j| a[i][i].total_cmp(&a[j][j]))
        .expect("three");
    DVec3::new(v[0][k], v[1][k], v[2][k]).normalize()
}

/// Signed volume enclosed by a closed oriented polygon mesh (faces fanned
/// from their first vertex); positive for outward faces.
pub(crate) fn signed_volume(mesh: &PolyMesh) -> f64 {
    let p = |i: u32| mesh.points[i as usize];
    mesh.faces
        .iter()
        .map(|f| {
            (1..f.len() - 1)
                .map(|i| p(f[0]).dot(p(f[i]).cross(p(f[i + 1]))))
                .sum::<f64>()
        })
        .sum::<f64>()
        / 6.0
}
