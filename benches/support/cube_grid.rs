//! A structured cube mesh for benchmarks: the unit cube cut into `n³` cells,
//! each split into six tets around its main diagonal (the Freudenthal–Kuhn
//! triangulation, which is conforming because every cell uses the same
//! diagonal direction). `6 n³` tets, `(n + 1)³` points, region 1, and the
//! boundary triangles marked by side: 1/2 for x = 0/1, 3/4 for y, 5/6 for z.
//!
//! Shared by `benches/bisect.rs` and `examples/cube_mesh.rs` via `#[path]`.

use tetrefine::{MeshData, TetMesh};

/// The mesh data of the `n³`-cell cube (tets positively oriented).
pub fn cube_grid_data(n: usize) -> MeshData {
    let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let h = 1.0 / n as f64;
    let mut points = Vec::with_capacity((n + 1).pow(3));
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                points.push([i as f64 * h, j as f64 * h, k as f64 * h]);
            }
        }
    }
    // Paths from corner (0,0,0) to (1,1,1) of a cell, one axis at a time; the
    // even permutations give positive tets, the odd ones are turned around.
    const PERMS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], true),
        ([1, 2, 0], true),
        ([2, 0, 1], true),
        ([0, 2, 1], false),
        ([2, 1, 0], false),
        ([1, 0, 2], false),
    ];
    let mut tets = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for (perm, even) in PERMS {
                    let mut c = [i, j, k];
                    let mut v = [id(c[0], c[1], c[2]); 4];
                    for (s, &axis) in perm.iter().enumerate() {
                        c[axis] += 1;
                        v[s + 1] = id(c[0], c[1], c[2]);
                    }
                    if !even {
                        v.swap(0, 1);
                    }
                    tets.push(v);
                }
            }
        }
    }
    let tet_regions = vec![1; tets.len()];
    let mut data = MeshData {
        points,
        tets,
        tet_regions,
        ..Default::default()
    };
    // Boundary triangles: faces of one tet only. Build once to find them.
    let (mesh, _) = TetMesh::from_data(&data).expect("the cube grid is a valid mesh");
    for t in mesh.tet_ids() {
        for f in 0..4 {
            if mesh.is_boundary_face(t, f) {
                let fv = mesh.face_vertices(t, f);
                let p = fv.map(|v| mesh.point(v));
                let marker = (0..3)
                    .find_map(|axis| {
                        if p.iter().all(|q| q[axis] == 0.0) {
                            Some(2 * axis as i32 + 1)
                        } else if p.iter().all(|q| q[axis] == 1.0) {
                            Some(2 * axis as i32 + 2)
                        } else {
                            None
                        }
                    })
                    .expect("a boundary face lies on a side of the cube");
                data.triangles.push((fv, marker));
            }
        }
    }
    data
}

/// The built mesh of [`cube_grid_data`].
pub fn cube_grid(n: usize) -> TetMesh {
    TetMesh::from_data(&cube_grid_data(n))
        .expect("the cube grid is a valid mesh")
        .0
}
