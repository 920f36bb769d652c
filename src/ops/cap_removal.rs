//! Boundary cap removal: a tet with two boundary faces is taken out of the
//! mesh, and its two interior faces become the boundary there.
//!
//! ```text
//!              k                  tet t = (…) with boundary faces opposite
//!             /|\                 its local vertices i and j: (j,k,l) and
//!            / | \                (i,k,l), folded along the edge k-l. Its
//!           /  |  \               interior faces (i,j,l) and (i,j,k) meet
//!          i---+---j              along i-j. After the removal the boundary
//!           \  |  /               runs over (i,j,k) and (i,j,l): the fold
//!            \ | /                k-l is gone and i-j is a boundary edge.
//!              l
//! ```
//!
//! The refinement's boundary phases can leave such caps as slivers that no
//! vertex move repairs: all four corners lie on the boundary, two of them
//! often fixed (corners, feature lines). MMG3D removes boundary slivers the
//! same way, under its Hausdorff bound (Dapogny, Dobrzynski and Frey, JCP
//! 2014); so does Stellar's multi-face removal at the boundary (Klingner and
//! Shewchuk, IMR 2007). No point moves and no tet is created, so nothing can
//! be inverted; the domain loses the cap's volume.

use super::OpError;
use crate::geom::closest::surfaces_within;
use crate::geom::tet_min_sine;
use crate::mesh::{TetMesh, NO_ADJ};
use crate::topo::{local_edge, TET_FACES};
use glam::DVec3;

/// Limits of a cap removal.
#[derive(Clone, Copy, Debug)]
pub struct CapLimits {
    /// Largest distance between the old and the new boundary (the Hausdorff
    /// distance of the two surfaces, bounded from above).
    pub hausd: f64,
    /// The new boundary faces (i,j,k) and (i,j,l) must not meet at a crease:
    /// their normals differ by at most this many degrees.
    pub crease_angle: f64,
}

/// Removes tet `t` when it is a boundary cap that may go: exactly two
/// boundary faces, with the same marker, folded along an edge that is no
/// feature edge; its other two faces unconstrained (same region on both
/// sides, no marker); the edge joining its two other vertices not on the
/// boundary yet (so the boundary stays a manifold) and no feature edge; the
/// new boundary faces within `limits` of the old ones. On `Err` the mesh is
/// unchanged.
pub fn remove_boundary_cap(mesh: &mut TetMesh, t: u32, limits: CapLimits) -> Result<(), OpError> {
    let adj = mesh.adj(t);
    let open: Vec<usize> = (0..4).filter(|&f| adj[f] == NO_ADJ).collect();
    let [i, j] = open[..] else {
        return Err(OpError::NotApplicable("not exactly two boundary faces"));
    };
    let [k, l] = [0, 1, 2, 3]
        .into_iter()
        .filter(|&x| x != i && x != j)
        .collect::<Vec<_>>()[..]
    else {
        unreachable!("four local vertices minus two leave two")
    };
    let v = mesh.tet(t);
    if mesh.is_feature_edge(v[k], v[l]) || mesh.is_feature_edge(v[i], v[j]) {
        return Err(OpError::NotApplicable("a feature edge would change"));
    }
    if mesh.face_marker(mesh.face_vertices(t, i)) != mesh.face_marker(mesh.face_vertices(t, j)) {
        return Err(OpError::NotApplicable("boundary faces of two markers"));
    }
    if mesh
        .face_marker(mesh.face_vertices(t, i))
        .is_some_and(crate::mesh::partition::is_partition_marker)
    {
        return Err(OpError::NotApplicable("a partition face must stay"));
    }
    for f in [k, l] {
        if mesh.face_is_constrained(t, Some(adj[f] >> 2), mesh.face_vertices(t, f)) {
            return Err(OpError::NotApplicable("an interior face is constrained"));
        }
    }
    // Edge i-j on the boundary already: the walk around it from t meets a
    // boundary face (an open ring). Its faces in t are both interior, so an
    // open ring means another boundary fan at i-j: removing t would give the
    // edge four boundary faces.
    if !mesh.for_each_tet_around_edge(t, local_edge(i, j), |_| true) {
        return Err(OpError::NotApplicable(
            "the new boundary edge is on the boundary already",
        ));
    }
    let p = mesh.tet_points(t);
    let old = [TET_FACES[i], TET_FACES[j]].map(|f| [p[f[0]], p[f[1]], p[f[2]]]);
    let new = [TET_FACES[k], TET_FACES[l]].map(|f| [p[f[0]], p[f[1]], p[f[2]]]);
    let normal = |f: &[DVec3; 3]| (f[1] - f[0]).cross(f[2] - f[0]).normalize();
    // Outward normals of the new boundary: TET_FACES lists faces outward.
    let cos = normal(&new[0]).dot(normal(&new[1]));
    // NaN (a degenerate face) refuses as a crease does.
    if cos.is_nan() || cos < limits.crease_angle.to_radians().cos() {
        return Err(OpError::NotApplicable(
            "the new boundary would have a crease",
        ));
    }
    if !(surfaces_within(&old, &new, limits.hausd) && surfaces_within(&new, &old, limits.hausd)) {
        return Err(OpError::NotApplicable("beyond the Hausdorff bound"));
    }
    let marker = mesh.face_marker(mesh.face_vertices(t, i));
    let (new_k, new_l) = (mesh.face_vertices(t, k), mesh.face_vertices(t, l));
    if marker.is_some() {
        mesh.set_face_marker(mesh.face_vertices(t, i), None);
        mesh.set_face_marker(mesh.face_vertices(t, j), None);
        mesh.set_face_marker(new_k, marker);
        mesh.set_face_marker(new_l, marker);
    }
    // Every vertex of t stays in a neighbour: i, j and l lie in the
    // neighbour across face k, i, j and k in the one across face l.
    mesh.remove_tet_opening(t);
    Ok(())
}

/// Whether `t` is a sliver cap worth trying: two boundary faces and quality
/// (min sine) below `bar`.
pub fn is_cap_below(mesh: &TetMesh, t: u32, bar: f64) -> bool {
    mesh.adj(t).iter().filter(|&&h| h == NO_ADJ).count() == 2
        && tet_min_sine(&mesh.tet_points(t)) < bar
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;

    /// A square pyramid with its apex below, `(0.5, 0.5, -1)`, over the
    /// square a (0,0,0), b (1,0,δ), c (1,1,0), e (0,1,δ): two tets split along
    /// the diagonal a-c, whose top faces fold into a valley along a-c. The cap
    /// (a, b, c, e) fills the valley: faces abc and ace are shared with the
    /// pyramid, abe and bce are the boundary, folded along b-e.
    ///
    /// ```text
    ///   e-------c      top view; the cap's boundary edge b-e runs
    ///   | \     |      across the pyramid's diagonal a-c
    ///   |   \   |
    ///   a-------b
    /// ```
    fn capped(delta: f64) -> (TetMesh, u32) {
        let data = MeshData {
            points: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, delta],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, delta],
                [0.5, 0.5, -1.0],
            ],
            tets: vec![[0, 1, 2, 4], [0, 2, 3, 4], [0, 1, 2, 3]],
            triangles: vec![([0, 1, 3], 7), ([1, 2, 3], 7)],
            ..Default::default()
        };
        let (m, _) = TetMesh::from_data(&data).unwrap();
        let cap = cap_of(&m);
        (m, cap)
    }

    const LOOSE: CapLimits = CapLimits {
        hausd: 1.0,
        crease_angle: 45.0,
    };

    /// Volume of the pyramid, by the formula (base area × height / 3 for
    /// each of its two tets over the triangles abc and ace, whose heights
    /// below the base are not equal: computed from the determinants).
    fn pyramid_volume(delta: f64) -> f64 {
        let det = |p: [[f64; 3]; 4]| {
            let u = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
            let v = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
            let w = [0, 1, 2].map(|k| p[3][k] - p[0][k]);
            (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]))
                .abs()
                / 6.0
        };
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, delta];
        let c = [1.0, 1.0, 0.0];
        let e = [0.0, 1.0, delta];
        let apex = [0.5, 0.5, -1.0];
        det([a, b, c, apex]) + det([a, c, e, apex])
    }

    #[test]
    fn a_valley_cap_goes_and_its_marker_moves_to_the_new_boundary() {
        let (mut m, cap) = capped(0.05);
        assert!(is_cap_below(&m, cap, 0.3));
        remove_boundary_cap(&mut m, cap, LOOSE).unwrap();
        m.check().unwrap();
        assert_eq!(m.n_tets(), 2);
        let vol: f64 = m
            .tet_ids()
            .map(|t| crate::geom::tet_volume(&m.tet_points(t)))
            .sum();
        assert!((vol - pyramid_volume(0.05)).abs() < 1e-15, "{vol}");
        // The new boundary faces abc and ace carry the old marker 7; the old
        // faces are gone.
        assert_eq!(m.face_marker([0, 1, 2]), Some(7));
        assert_eq!(m.face_marker([0, 2, 3]), Some(7));
        assert_eq!(m.face_marker([0, 1, 3]), None);
        let boundary = m
            .tet_ids()
            .flat_map(|t| m.adj(t))
            .filter(|&h| h == NO_ADJ)
            .count();
        assert_eq!(boundary, 6, "4 sides and 2 top faces of the pyramid");
    }

    #[test]
    fn caps_stay_when_a_rule_forbids_them() {
        // Beyond the bound: the middle of the fold b-e stands δ = 0.05 above
        // the middle of the diagonal a-c (some 0.035 from the new faces), so
        // a bound of 0.01 refuses.
        let (mut m, cap) = capped(0.05);
        let tight = CapLimits {
            hausd: 0.01,
            ..LOOSE
        };
        assert!(remove_boundary_cap(&mut m, cap, tight).is_err());
        assert_eq!(m.n_tets(), 3);
        // A feature edge along the fold.
        m.set_feature_edge(1, 3, Some(1));
        assert!(remove_boundary_cap(&mut m, cap, LOOSE).is_err());
        m.set_feature_edge(1, 3, None);
        // A deep valley: the normals of abc and ace, (-0.8, 0.8, 1) and
        // (0.8, -0.8, 1), are 97° apart.
        let (mut deep, cap) = capped(0.8);
        assert!(remove_boundary_cap(&mut deep, cap, LOOSE).is_err());
        assert_eq!(deep.n_tets(), 3);
        // Two markers on the two boundary faces.
        m.set_face_marker([1, 2, 3], Some(8));
        let cap = cap_of(&m);
        assert!(remove_boundary_cap(&mut m, cap, LOOSE).is_err());
        m.check().unwrap();
    }

    /// The cap: the tet without the apex (the pyramid's two tets have two
    /// boundary faces too, their sides).
    fn cap_of(m: &TetMesh) -> u32 {
        m.tet_ids().find(|&t| !m.tet(t).contains(&4)).unwrap()
    }
}
