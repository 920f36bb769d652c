//! Helpers shared by the marking and indicator tests: a structured tet grid
//! built by hand (no generator of the crate is used) and a deterministic
//! pseudo-random sequence.

use tetrefine::{MeshData, TetMesh};

/// The unit cubes `[i,i+1]×[j,j+1]×[k,k+1]` of an `nx×ny×nz` block, each cut
/// into the 6 tets of Freudenthal–Kuhn (one per ordering of the axes, all
/// around the diagonal from the cube's smallest to its largest corner), so
/// neighbouring cubes meet conformingly. Tets are listed cube by cube
/// (x fastest, then y, then z); the region of a tet is `i + 1`, its cube's x
/// index plus one.
pub fn kuhn_grid(nx: usize, ny: usize, nz: usize) -> MeshData {
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut d = MeshData::default();
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                d.points.push([i as f64, j as f64, k as f64]);
            }
        }
    }
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for p in perms {
                    let mut c = [i, j, k];
                    let mut t = [id(c[0], c[1], c[2]); 4];
                    for (s, &axis) in p.iter().enumerate() {
                        c[axis] += 1;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    d.tets.push(t);
                    d.tet_regions.push(i as i32 + 1);
                }
            }
        }
    }
    d
}

/// The store built from [`kuhn_grid`].
pub fn kuhn_mesh(nx: usize, ny: usize, nz: usize) -> (MeshData, TetMesh) {
    let d = kuhn_grid(nx, ny, nz);
    let (m, _) = TetMesh::from_data(&d).expect("the Kuhn grid is a valid mesh");
    (d, m)
}

/// Centroid of tet `t` of `d`, from the plain data.
pub fn centroid(d: &MeshData, t: usize) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in &d.tets[t] {
        for (ca, pa) in c.iter_mut().zip(d.points[v as usize]) {
            *ca += pa;
        }
    }
    c.map(|x| x / 4.0)
}

/// The tests' seeded generator: the crate's own (one RNG in the workspace).
pub use tetrefine::SplitMix64 as Rng;
