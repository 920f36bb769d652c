//! Small meshes built from their definitions, shared by the surface tests.
#![allow(dead_code)]

use glam::DVec3;
use tetrefine_surface::PolyMesh;

/// Regular octahedron with vertices on the axes (outward faces).
pub fn octahedron() -> PolyMesh {
    let p = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let f = vec![
        vec![0, 2, 4],
        vec![2, 1, 4],
        vec![1, 3, 4],
        vec![3, 0, 4],
        vec![2, 0, 5],
        vec![1, 2, 5],
        vec![3, 1, 5],
        vec![0, 3, 5],
    ];
    PolyMesh::new(p, f)
}

/// Unit cube [0,1]³ with outward quads.
pub fn cube() -> PolyMesh {
    let mut p = Vec::new();
    for i in 0..8 {
        p.push(DVec3::new(
            (i & 1) as f64,
            ((i >> 1) & 1) as f64,
            ((i >> 2) & 1) as f64,
        ));
    }
    let f = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    PolyMesh::new(p, f)
}

/// Bipyramid over a regular n-gon of radius 1 in z = 0, apexes at ±h.
/// Vertex 0 is the top apex (valence n), 1 the bottom one.
pub fn bipyramid(n: usize, h: f64) -> PolyMesh {
    let mut p = vec![DVec3::new(0.0, 0.0, h), DVec3::new(0.0, 0.0, -h)];
    for k in 0..n {
        let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        p.push(DVec3::new(a.cos(), a.sin(), 0.0));
    }
    let mut f = Vec::new();
    for k in 0..n {
        let (a, b) = (2 + k as u32, 2 + ((k + 1) % n) as u32);
        f.push(vec![a, b, 0]);
        f.push(vec![b, a, 1]);
    }
    PolyMesh::new(p, f)
}

/// Triangulated (m × n) grid of the rectangle [0,m]×[0,n] mapped by `map`,
/// each square cut along the same diagonal; vertex (i, j) has id i*(n+1)+j.
pub fn tri_grid(m: usize, n: usize, map: impl Fn(f64, f64) -> DVec3) -> PolyMesh {
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut p = Vec::new();
    for i in 0..=m {
        for j in 0..=n {
            p.push(map(i as f64, j as f64));
        }
    }
    let mut f = Vec::new();
    for i in 0..m {
        for j in 0..n {
            f.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(p, f)
}

/// Regular planar triangular lattice: rows of equilateral triangles, edge 1.
pub fn tri_lattice(m: usize, n: usize) -> PolyMesh {
    tri_grid(m, n, |i, j| {
        DVec3::new(i - 0.5 * j, j * 3f64.sqrt() / 2.0, 0.0)
    })
}

/// Torus of m × n quads (major radius 3, minor 1); vertex (i, j) has id
/// i*n + j, quad (i, j) has id i*n + j and corners (i,j),(i+1,j),(i+1,j+1),(i,j+1).
pub fn quad_torus(m: usize, n: usize) -> PolyMesh {
    quad_torus_with(m, n, |u, v| {
        let (a, b) = (
            2.0 * std::f64::consts::PI * u / m as f64,
            2.0 * std::f64::consts::PI * v / n as f64,
        );
        DVec3::new(
            (3.0 + b.cos()) * a.cos(),
            (3.0 + b.cos()) * a.sin(),
            b.sin(),
        )
    })
}

/// As [`quad_torus`] with control points from `map(i, j)`.
pub fn quad_torus_with(m: usize, n: usize, map: impl Fn(f64, f64) -> DVec3) -> PolyMesh {
    let id = |i: usize, j: usize| ((i % m) * n + (j % n)) as u32;
    let mut p = Vec::new();
    for i in 0..m {
        for j in 0..n {
            p.push(map(i as f64, j as f64));
        }
    }
    let mut f = Vec::new();
    for i in 0..m {
        for j in 0..n {
            f.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(p, f)
}

/// The quad torus with every quad cut along the same diagonal: every vertex
/// has valence 6.
pub fn tri_torus(m: usize, n: usize) -> PolyMesh {
    let q = quad_torus(m, n);
    let mut f = Vec::new();
    for quad in &q.faces {
        f.push(vec![quad[0], quad[1], quad[2]]);
        f.push(vec![quad[0], quad[2], quad[3]]);
    }
    PolyMesh::new(q.points, f)
}

/// Icosahedron (all vertices valence 5).
pub fn icosahedron() -> PolyMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let p = vec![
        DVec3::new(-1.0, t, 0.0),
        DVec3::new(1.0, t, 0.0),
        DVec3::new(-1.0, -t, 0.0),
        DVec3::new(1.0, -t, 0.0),
        DVec3::new(0.0, -1.0, t),
        DVec3::new(0.0, 1.0, t),
        DVec3::new(0.0, -1.0, -t),
        DVec3::new(0.0, 1.0, -t),
        DVec3::new(t, 0.0, -1.0),
        DVec3::new(t, 0.0, 1.0),
        DVec3::new(-t, 0.0, -1.0),
        DVec3::new(-t, 0.0, 1.0),
    ];
    let f: Vec<Vec<u32>> = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ]
    .iter()
    .map(|t| t.to_vec())
    .collect();
    PolyMesh::new(p, f)
}

/// The regular tetrahedron inscribed in the cube [-1, 1]³, outward faces.
pub fn tetrahedron() -> PolyMesh {
    PolyMesh::new(
        vec![
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ],
        vec![vec![0, 1, 2], vec![0, 3, 1], vec![0, 2, 3], vec![1, 3, 2]],
    )
}
