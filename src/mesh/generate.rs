//! Generated meshes for tests and benchmarks, and the tests' total volume.
//!
//! [`cube_grid`] triangulates the unit cube with the Freudenthal–Kuhn scheme
//! (H. Freudenthal, "Simplizialzerlegungen von beschränkter Flachheit", Annals
//! of Mathematics 43, 1942; H. W. Kuhn, "Some combinatorial lemmas in
//! topology", IBM J. Res. Dev. 4, 1960): every small cube is cut into the six
//! tets around its main diagonal, one per ordering of the three axes.

use super::MeshData;

/// The unit cube `[0,1]³` cut into `n³` equal cubes, each into six tets
/// (Freudenthal/Kuhn): `(n+1)³` points, `6n³` positively oriented tets.
///
/// The tet of the axis ordering `(a, b, c)` in the cube with lower corner `p`
/// is `p, p+e_a, p+e_a+e_b, p+(1,1,1)`. Every square face of every small cube
/// is then split along the diagonal through its lowest and highest corners,
/// the same from both sides, so the triangulation is conforming across cubes.
/// All tets are congruent, with dihedral angles 45°, 45°, 60°, 90°, 90°, 90°.
///
/// Point `(i, j, k)` (coordinates `(i/n, j/n, k/n)`) has id
/// `i + (n+1)·(j + (n+1)·k)`. Regions are all 0 and there are no tags.
/// `n = 0` gives an empty mesh (one point, no tets).
pub fn cube_grid(n: usize) -> MeshData {
    let m = n + 1;
    let h = if n == 0 { 0.0 } else { 1.0 / n as f64 };
    let mut points = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                points.push([i as f64 * h, j as f64 * h, k as f64 * h]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + m * (j + m * k)) as u32;
    // Axis orderings with their parity; odd orderings give negatively oriented
    // vertex lists, fixed by swapping the first two vertices.
    const ORDERINGS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], true),
        ([1, 2, 0], true),
        ([2, 0, 1], true),
        ([0, 2, 1], false),
        ([1, 0, 2], false),
        ([2, 1, 0], false),
    ];
    let mut tets = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for &(order, even) in &ORDERINGS {
                    let mut c = [i, j, k];
                    let v0 = id(c[0], c[1], c[2]);
                    c[order[0]] += 1;
                    let v1 = id(c[0], c[1], c[2]);
                    c[order[1]] += 1;
                    let v2 = id(c[0], c[1], c[2]);
                    let v3 = id(i + 1, j + 1, k + 1);
                    tets.push(if even {
                        [v0, v1, v2, v3]
                    } else {
                        [v1, v0, v2, v3]
                    });
                }
            }
        }
    }
    MeshData {
        points,
        tets,
        ..MeshData::default()
    }
}

/// The sum of the signed volumes of `mesh`'s live tets, for tests that
/// compare it with a closed form.
#[cfg(test)]
pub(crate) fn total_volume(mesh: &super::TetMesh) -> f64 {
    mesh.tet_ids()
        .map(|t| crate::geom::tet_volume(&mesh.tet_points(t)))
        .sum()
}

/// The number of boundary faces of `mesh`'s live tets (faces with no
/// neighbour), for tests that count them by hand.
#[cfg(test)]
pub(crate) fn boundary_face_count(mesh: &super::TetMesh) -> usize {
    mesh.tet_ids()
        .flat_map(|t| mesh.adj(t))
        .filter(|&h| h == super::NO_ADJ)
        .count()
}

/// Two square pyramids that touch only at point 0, `v` (a pinch: the walk
/// around `v` from one of its tets sees one pyramid): one below the plane
/// z = 0 (apex point 1 at depth `depth`), its base points 3–6 at (±1, ±1),
/// and one above it (apex point 2 at height `depth`), its base points 7–10
/// at ±`half` on the axes; each base is fanned from `v`, which must lie
/// inside both, into four tets, listed upper and lower in turn (in this
/// order `v`'s stored tet is in the lower pyramid). Tests of operations at
/// pinch vertices use it.
#[cfg(test)]
pub(crate) fn pinched_pyramids(v: [f64; 3], half: f64, depth: f64) -> MeshData {
    let mut points = vec![v, [0.0, 0.0, -depth], [0.0, 0.0, depth]];
    points.extend([
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
    ]);
    points.extend([
        [half, 0.0, 0.0],
        [0.0, half, 0.0],
        [-half, 0.0, 0.0],
        [0.0, -half, 0.0],
    ]);
    let mut tets = Vec::new();
    for i in 0..4u32 {
        tets.push([0, 7 + i, 7 + (i + 1) % 4, 2]);
        tets.push([0, 3 + (i + 1) % 4, 3 + i, 1]);
    }
    MeshData {
        points,
        tets,
        ..MeshData::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{dihedral_angles, tet_quality};
    use crate::mesh::TetMesh;
    use crate::report::MeshStats;
    use glam::DVec3;

    /// Distinct edges of the Kuhn triangulation of an n×n×n grid, by direction:
    /// * the 3 axis directions: for the x axis, n segments on each of the
    ///   (n+1)² grid lines, so 3·n(n+1)²;
    /// * the 3 face-diagonal directions e_a+e_b (one diagonal per unit square,
    ///   the one through its lowest and highest corner): n² squares in each of
    ///   the n+1 planes normal to the third axis, so 3·n²(n+1);
    /// * the main diagonal (1,1,1): one per cube, n³.
    fn kuhn_edges(n: usize) -> usize {
        3 * n * (n + 1) * (n + 1) + 3 * n * n * (n + 1) + n * n * n
    }

    #[test]
    fn counts_match_closed_forms() {
        for n in 1..=5 {
            let data = cube_grid(n);
            assert_eq!(data.points.len(), (n + 1).pow(3));
            assert_eq!(data.tets.len(), 6 * n.pow(3));
            let (mesh, report) = TetMesh::from_data(&data).unwrap();
            assert_eq!(report.reoriented, 0, "all tets are generated positive");
            assert_eq!(report.unreferenced_points, 0);
            mesh.check().unwrap();
            let s = MeshStats::compute(&mesh);
            assert_eq!(s.nodes, (n + 1).pow(3));
            assert_eq!(s.tets, 6 * n.pow(3));
            // Each of the 6 sides holds n² squares, each cut into 2 triangles.
            assert_eq!(s.boundary_faces, 12 * n * n);
            assert_eq!(s.interior_faces, (4 * 6 * n.pow(3) - 12 * n * n) / 2);
            assert_eq!(s.edges, kuhn_edges(n));
            // Euler characteristic of a ball: V - E + F - T = 1.
            let (v, e, f, t) = (
                s.nodes as i64,
                s.edges as i64,
                (s.boundary_faces + s.interior_faces) as i64,
                s.tets as i64,
            );
            assert_eq!(v - e + f - t, 1);
            assert_eq!(s.inverted, 0);
            assert!((s.volume - 1.0).abs() < 1e-12, "{}", s.volume);
        }
    }

    #[test]
    fn volume_is_exactly_one() {
        // With n a power of two every coordinate and every 6·volume = 1/n³ is
        // exact in binary floating point, so the sum is exactly 6.
        for n in [1usize, 2, 4, 8] {
            let data = cube_grid(n);
            let p = |v: u32| DVec3::from(data.points[v as usize]);
            let six_vol: f64 = data
                .tets
                .iter()
                .map(|t| {
                    let (a, b, c, d) = (p(t[0]), p(t[1]), p(t[2]), p(t[3]));
                    (b - a).dot((c - a).cross(d - a))
                })
                .sum();
            assert_eq!(six_vol, 6.0);
        }
    }

    #[test]
    fn every_tet_is_the_kuhn_simplex() {
        // The Kuhn (path) simplex, e.g. 0, x, x+y, x+y+z: its faces have normals
        // ±z, ±x, (1,-1,0)/√2 and (0,1,-1)/√2, so the dihedral angles are three
        // right angles, one of 60° and two of 45°; volume 1/(6n³).
        let n = 3;
        let data = cube_grid(n);
        for t in &data.tets {
            let p = t.map(|v| DVec3::from(data.points[v as usize]));
            let mut a: Vec<f64> = dihedral_angles(&p).iter().map(|x| x.to_degrees()).collect();
            a.sort_by(f64::total_cmp);
            for (got, want) in a.iter().zip([45.0, 45.0, 60.0, 90.0, 90.0, 90.0]) {
                assert!((got - want).abs() < 1e-9, "{a:?}");
            }
            let q = tet_quality(&p);
            assert!((q.min_dihedral_deg - 45.0).abs() < 1e-9, "{q:?}");
            assert!((q.max_dihedral_deg - 90.0).abs() < 1e-9, "{q:?}");
            assert!((q.volume - 1.0 / (6.0 * 27.0)).abs() < 1e-15);
        }
    }

    #[test]
    fn zero_cells_is_empty() {
        let data = cube_grid(0);
        assert_eq!(data.points.len(), 1);
        assert!(data.tets.is_empty());
    }
}
