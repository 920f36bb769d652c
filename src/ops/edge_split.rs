//! Edge split: a new vertex on an edge splits every tet of the edge's shell
//! in two — conforming by construction, since every face holding the edge
//! is split the same way on both sides.
//!
//! ```text
//!              a                   each shell tet (…a…b…), the other two
//!             /|\                  vertices p and q, becomes
//!            / | \                   the tet with b replaced by m
//!           /  m  \                  the tet with a replaced by m
//!          /  /|\  \               (substitution keeps the orientation);
//!         p--/-|-\--q              faces (a,b,p) become (a,m,p), (m,b,p)
//!          \/  |  \/               with its marker; a feature edge (a,b)
//!           \  |  /                becomes the feature edges (a,m), (m,b)
//!            \ | /                 with its marker, so m is a feature
//!              b                   vertex; a boundary edge gives a
//!                                  boundary vertex.
//! ```
//!
//! The longest-edge bisection of Rivara ("Mesh refinement processes based
//! on the generalized bisection of simplices", SIAM J. Numer. Anal. 21,
//! 1984) cuts a tet the same way; MMG3D's size-driven remeshing splits its
//! long edges with this shell split too.

use super::{replace_cavity_raw, OpError};
use crate::geom::is_positive;
use crate::mesh::TetMesh;
use glam::DVec3;

/// The two halves of a shell tet `v` of edge `(a, b)` split at vertex `m`:
/// `v` with `b` replaced by `m`, then with `a` replaced by `m` (the
/// substitution keeps the orientation; see the sketch above).
pub(crate) fn split_halves(v: [u32; 4], a: u32, b: u32, m: u32) -> [[u32; 4]; 2] {
    let ia = v.iter().position(|&x| x == a).expect("a shell tet holds a");
    let ib = v.iter().position(|&x| x == b).expect("a shell tet holds b");
    let mut t1 = v;
    t1[ib] = m;
    let mut t2 = v;
    t2[ia] = m;
    [t1, t2]
}

/// Splits the edge `(a, b)` at `p` (a point near its midpoint): every tet
/// holding the edge (found through the ball of `a`, so several fans of a
/// non-manifold edge are all split) becomes two, each keeping its tet's
/// region, `level` and `parent`; face markers and the feature tag of the
/// edge go to the pieces. Every new tet is checked with the exact
/// orientation predicate and for a positive Jacobian in doubles
/// ([`is_positive`]); if one fails, nothing changes and
/// [`OpError::WouldInvert`] comes back. Returns the new vertex and the new
/// tets.
pub fn split_edge(
    mesh: &mut TetMesh,
    a: u32,
    b: u32,
    p: DVec3,
) -> Result<(u32, Vec<u32>), OpError> {
    let mut around = Vec::new();
    mesh.edge_shell(a, b, &mut around);
    split_shell(mesh, a, b, p, &around)
}

/// [`split_edge`] with the shell of `(a, b)` given: `around`, every tet
/// holding the edge, ascending (a caller that has just gathered it saves
/// the walk).
pub(crate) fn split_shell(
    mesh: &mut TetMesh,
    a: u32,
    b: u32,
    p: DVec3,
    around: &[u32],
) -> Result<(u32, Vec<u32>), OpError> {
    debug_assert!(around.windows(2).all(|w| w[0] < w[1]));
    debug_assert!(around
        .iter()
        .all(|&t| mesh.tet(t).contains(&a) && mesh.tet(t).contains(&b)));
    if around.is_empty() {
        return Err(OpError::NotApplicable("no tet holds the edge"));
    }
    let mut new = Vec::with_capacity(2 * around.len());
    let mut origin = Vec::with_capacity(2 * around.len());
    let mut others: Vec<u32> = Vec::new();
    for (i, &t) in around.iter().enumerate() {
        let v = mesh.tet(t);
        // m, once it has an id
        new.extend(split_halves(v, a, b, u32::MAX));
        origin.extend([i, i]);
        others.extend(v.iter().copied().filter(|&x| x != a && x != b));
    }
    // Check before adding the point: the substituted corners in doubles.
    let corners = |t: &[u32; 4]| t.map(|x| if x == u32::MAX { p } else { mesh.point(x) });
    if !new.iter().all(|t| is_positive(&corners(t))) {
        return Err(OpError::WouldInvert);
    }
    others.sort_unstable();
    others.dedup();
    let face_markers: Vec<(u32, Option<i32>)> = others
        .iter()
        .map(|&q| (q, mesh.face_marker([a, b, q])))
        .collect();
    let edge_marker = mesh.feature_edge(a, b);
    let m = mesh.add_point(p);
    for t in new.iter_mut() {
        for x in t.iter_mut() {
            if *x == u32::MAX {
                *x = m;
            }
        }
    }
    match replace_cavity_raw(mesh, around, &new, &origin) {
        Ok(ids) => {
            for (q, mk) in face_markers {
                if mk.is_some() {
                    mesh.set_face_marker([a, b, q], None);
                    mesh.set_face_marker([a, m, q], mk);
                    mesh.set_face_marker([m, b, q], mk);
                }
            }
            if edge_marker.is_some() {
                mesh.set_feature_edge(a, b, None);
                mesh.set_feature_edge(a, m, edge_marker);
                mesh.set_feature_edge(m, b, edge_marker);
            }
            Ok((m, ids))
        }
        Err(e) => {
            mesh.pop_unused_point(m);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;
    use crate::mesh::generate::total_volume as volume;
    use crate::topo::TET_EDGES;

    fn cube(n: usize) -> TetMesh {
        TetMesh::from_data(&cube_grid(n)).expect("a cube").0
    }

    #[test]
    fn every_edge_of_a_cube_splits_conformingly() {
        let base = cube(2);
        let mut edges: Vec<[u32; 2]> = base
            .tet_ids()
            .flat_map(|t| {
                let v = base.tet(t);
                TET_EDGES.map(|[i, j]| crate::topo::edge_key(v[i], v[j]))
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        for [a, b] in edges {
            let mut m = base.clone();
            let shell = m.tet_ids().filter(|&t| {
                let v = m.tet(t);
                v.contains(&a) && v.contains(&b)
            });
            let k = shell.count();
            let n = m.n_tets();
            let mid = (m.point(a) + m.point(b)) * 0.5;
            let (v, ids) = split_edge(&mut m, a, b, mid).expect("a midpoint split is valid");
            assert_eq!(ids.len(), 2 * k);
            assert_eq!(m.n_tets(), n + k);
            assert_eq!(m.point(v), mid);
            m.check().expect("the split mesh is valid");
            assert!((volume(&m) - 1.0).abs() < 1e-12);
            assert!(m.tet_ids().all(|t| !{
                let w = m.tet(t);
                w.contains(&a) && w.contains(&b)
            }));
        }
    }

    #[test]
    fn markers_features_region_and_parent_follow_the_pieces() {
        let mut m = cube(1);
        // A boundary edge of the unit cube: along x at y = z = 0.
        let pa = DVec3::ZERO;
        let pb = DVec3::X;
        let a = (0..m.n_points() as u32)
            .find(|&v| m.point(v) == pa)
            .unwrap();
        let b = (0..m.n_points() as u32)
            .find(|&v| m.point(v) == pb)
            .unwrap();
        m.set_feature_edge(a, b, Some(7));
        let shell: Vec<u32> = m
            .tet_ids()
            .filter(|&t| m.tet(t).contains(&a) && m.tet(t).contains(&b))
            .collect();
        for &t in &shell {
            m.set_region(t, 3);
            m.set_level(t, 2);
            m.set_parent(t, 40 + t);
            for f in 0..4 {
                let fv = m.face_vertices(t, f);
                if m.is_boundary_face(t, f) && fv.contains(&a) && fv.contains(&b) {
                    m.set_face_marker(fv, Some(5));
                }
            }
        }
        let parents: Vec<u32> = shell.iter().map(|&t| 40 + t).collect();
        let (v, ids) = split_edge(&mut m, a, b, DVec3::new(0.5, 0.0, 0.0)).unwrap();
        m.check().unwrap();
        assert_eq!(m.feature_edge(a, v), Some(7));
        assert_eq!(m.feature_edge(v, b), Some(7));
        assert_eq!(m.feature_edge(a, b), None);
        assert!(m.fixed_vertices()[v as usize], "a feature vertex");
        for &t in &ids {
            assert_eq!(m.region(t), 3);
            assert_eq!(m.level(t), 2);
            assert!(parents.contains(&m.parent(t)));
        }
        let marked = m
            .face_markers()
            .iter()
            .filter(|(k, &mk)| mk == 5 && k.contains(&v))
            .count();
        assert_eq!(marked, 4, "two marked boundary faces, each split in two");
    }

    #[test]
    fn a_split_that_would_invert_is_refused_and_changes_nothing() {
        let mut m = cube(1);
        let before = (m.n_points(), m.n_tets(), m.tet_slots().to_vec());
        let (a, b) = (0, 1);
        let t = m
            .tet_ids()
            .find(|&t| m.tet(t).contains(&a) && m.tet(t).contains(&b));
        assert!(t.is_some());
        // Far off the edge: some piece turns over.
        let far = DVec3::new(5.0, -3.0, 9.0);
        assert_eq!(split_edge(&mut m, a, b, far), Err(OpError::WouldInvert));
        assert_eq!(before, (m.n_points(), m.n_tets(), m.tet_slots().to_vec()));
        m.check().unwrap();
    }
}
