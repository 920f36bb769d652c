//! Edge contraction: an interior vertex `v` is merged into a neighbour `u`
//! along the edge `(u, v)`; the tets holding the edge vanish and every other
//! tet of the ball of `v` takes `u` in its place.
//!
//! ```text
//!        a-------b              a-------b
//!       / \     / \            /  ___/ / \
//!      /   \   /   \          / _/    /   \
//!     c-----v-u-----d   ==>  c=======u-----d
//!      \   /   \   /          \ ‾\    \   /
//!       \ /     \ /            \  ‾‾‾\ \ /
//!        e-------f              e-------f
//! ```
//!
//! (A section through the edge: the tets `(u, v, ·, ·)` around the edge go,
//! the tets of `v` on the far side are stretched to `u`.)
//!
//! Where a sliver has one very short edge — after a refinement step, an
//! interior point crowded against a boundary point that may not move —
//! neither smoothing nor flips can lift it: the short edge stays in every
//! triangulation of its neighbourhood. Removing the edge is the remedy MMG3D
//! (its collapse operator, `colver`) and Stellar (Klingner and Shewchuk,
//! "Aggressive tetrahedral mesh improvement", IMR 2007) use.
//!
//! Why positive orientation of the new tets is the whole validity check:
//! the ball of an interior vertex is a closed polyhedron `P` bounded by the
//! link of `v`. The new tets are the cones from `u` (a vertex of `P`) over the
//! link triangles that do not hold `u`. If all of them are positively
//! oriented, `u` sees every such triangle from inside, so `P` is star-shaped
//! from `u` and the cones tile `P` exactly: the outer faces of the ball are
//! matched one to one and nothing outside changes. [`super::replace_cavity_raw`]
//! checks the orientation with the exact predicate and the matching before it
//! touches the mesh.

use super::{replace_cavity_raw, BoundaryFlipLimits, OpError};
use crate::geom::closest::surfaces_within;
use crate::geom::tet_min_sine;
use crate::mesh::{TetMesh, NO_ADJ};
use glam::DVec3;

/// Merges the interior vertex `v` into its neighbour `u` if every tet of the
/// new configuration is positively oriented and its worst quality (min sine)
/// is above `beat`. `v` must be free: no boundary, interface or marked face,
/// feature edge, corner or required mark at it; the tets of its ball keep
/// their region, `level` and `parent`. `ball` is scratch (it holds the ball
/// of `v` on return). On success returns the new tets; `v` is then a point no
/// tet uses (compaction drops it). On `Err` the mesh is unchanged.
pub fn contract_edge(
    mesh: &mut TetMesh,
    v: u32,
    u: u32,
    beat: f64,
    ball: &mut Vec<u32>,
) -> Result<Vec<u32>, OpError> {
    contract(mesh, v, u, beat, ball, None)
}

/// [`contract_edge`] for a vertex `v` on the boundary: `(u, v)` is a
/// boundary edge, the boundary faces at `v` have one marker (no partition
/// face), and `v` is on no interface, marked interior face or feature edge
/// and is no corner. The polygon the boundary faces at `v` form is
/// re-triangulated as a fan from `u`; the new boundary faces take the
/// marker. Under `limits.exact` every boundary face at `v` must lie in one
/// plane (exact `orient3d`), so the fan lies in it and the domain is
/// unchanged; otherwise no two old faces and no two new ones may meet at
/// more than `limits.crease_angle`, and the fan must stay within
/// `limits.hausd` of the old faces and they of it (measured from above as
/// the boundary cap removal measures it). An interior `v` is contracted as
/// by [`contract_edge`].
///
/// The cones of the argument above over the old boundary faces are left
/// out (flat, or outside the ball where the surface bends); the others tile
/// the ball re-bounded by the fan, and a fan triangle that would fold over
/// makes its tet inverted, which the exact check refuses.
pub fn contract_boundary_edge(
    mesh: &mut TetMesh,
    v: u32,
    u: u32,
    beat: f64,
    limits: BoundaryFlipLimits,
    ball: &mut Vec<u32>,
) -> Result<Vec<u32>, OpError> {
    contract(mesh, v, u, beat, ball, Some(limits))
}

fn contract(
    mesh: &mut TetMesh,
    v: u32,
    u: u32,
    beat: f64,
    ball: &mut Vec<u32>,
    boundary: Option<BoundaryFlipLimits>,
) -> Result<Vec<u32>, OpError> {
    if u == v {
        return Err(OpError::NotApplicable("an edge needs two vertices"));
    }
    if mesh.is_corner(v) || mesh.is_required(v) {
        return Err(OpError::NotApplicable("a corner or required vertex stays"));
    }
    mesh.ball(v, ball);
    if ball.is_empty() {
        return Err(OpError::NotApplicable("vertex in no tet"));
    }
    let region = mesh.region(ball[0]);
    let mut has_edge = false;
    // Boundary faces at v (flat mode): their corners and their marker.
    let mut open: Vec<[u32; 3]> = Vec::new();
    let mut marker = None;
    for &t in ball.iter() {
        let tv = mesh.tet(t);
        has_edge |= tv.contains(&u);
        if mesh.region(t) != region {
            return Err(OpError::NotApplicable("vertex on a region interface"));
        }
        for (f, &h) in mesh.adj(t).iter().enumerate() {
            // Faces holding v: the one opposite v is the ball's outside.
            if tv[f] == v {
                continue;
            }
            if h == NO_ADJ && boundary.is_some() {
                let face = mesh.face_vertices(t, f);
                let m = mesh.face_marker(face);
                if m.is_some_and(crate::mesh::partition::is_partition_marker) {
                    return Err(OpError::NotApplicable("vertex on a partition face"));
                }
                if !open.is_empty() && m != marker {
                    return Err(OpError::NotApplicable("boundary faces of two markers"));
                }
                marker = m;
                open.push(face);
            } else if h == NO_ADJ || mesh.is_interface_face(t, f) {
                return Err(OpError::NotApplicable("vertex on a constrained face"));
            }
        }
        if tv.iter().any(|&x| x != v && mesh.is_feature_edge(v, x)) {
            return Err(OpError::NotApplicable("vertex on a feature edge"));
        }
    }
    if !has_edge {
        return Err(OpError::NotApplicable("no edge between the two vertices"));
    }
    if let (Some(limits), false) = (boundary, open.is_empty()) {
        if !open.iter().any(|f| f.contains(&u)) {
            return Err(OpError::NotApplicable("not a boundary edge"));
        }
        boundary_stays(mesh, &open, v, u, limits)?;
    }
    let mut old = Vec::with_capacity(ball.len());
    let mut new = Vec::with_capacity(ball.len());
    let mut origin = Vec::with_capacity(ball.len());
    let mut worst = f64::INFINITY;
    for &t in ball.iter() {
        let tv = mesh.tet(t);
        old.push(t);
        if tv.contains(&u) {
            continue;
        }
        let nv = tv.map(|x| if x == v { u } else { x });
        worst = worst.min(tet_min_sine(&nv.map(|x| mesh.point(x))));
        if worst <= beat {
            return Err(OpError::NoImprovement);
        }
        origin.push(old.len() - 1);
        new.push(nv);
    }
    let ids = replace_cavity_raw(mesh, &old, &new, &origin)?;
    mesh.retire_point(v);
    Ok(ids)
}

/// Whether re-triangulating the boundary faces `open` at `v` as a fan from
/// `u` keeps the boundary within `limits` (see [`contract_boundary_edge`]).
fn boundary_stays(
    mesh: &TetMesh,
    open: &[[u32; 3]],
    v: u32,
    u: u32,
    limits: BoundaryFlipLimits,
) -> Result<(), OpError> {
    let corners = |f: &[u32; 3]| f.map(|x| mesh.point(x));
    if limits.exact {
        // Exactly one plane: every corner against the first face.
        let [a, b, c] = corners(&open[0]);
        let coplanar = open.iter().flatten().all(|&x| {
            crate::geom::orient3d_sign(a, b, c, mesh.point(x)) == crate::geom::Orientation::Zero
        });
        return if coplanar {
            Ok(())
        } else {
            Err(OpError::NotApplicable("boundary star not flat"))
        };
    }
    let old: Vec<[DVec3; 3]> = open.iter().map(corners).collect();
    let new: Vec<[DVec3; 3]> = open
        .iter()
        .filter(|f| !f.contains(&u))
        .map(|f| corners(&f.map(|x| if x == v { u } else { x })))
        .collect();
    let cos = limits.crease_angle.to_radians().cos();
    for faces in [&old, &new] {
        let normals: Vec<DVec3> = faces
            .iter()
            .map(|p| (p[1] - p[0]).cross(p[2] - p[0]).normalize())
            .collect();
        for (i, a) in normals.iter().enumerate() {
            // A NaN (a degenerate face) is no number at or above `cos`:
            // refused.
            let apart = |b: &DVec3| a.dot(*b).partial_cmp(&cos).is_none_or(|o| o.is_lt());
            if normals[i + 1..].iter().any(apart) {
                return Err(OpError::NotApplicable("the boundary there has a crease"));
            }
        }
    }
    if surfaces_within(&old, &new, limits.hausd) && surfaces_within(&new, &old, limits.hausd) {
        Ok(())
    } else {
        Err(OpError::NotApplicable("beyond the Hausdorff bound"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;

    /// An octahedron (±1 on each axis) split into eight tets around an
    /// interior point `c`, each tet positively oriented: points ±x, ±y,
    /// ±z, then `c` (point 6).
    fn octahedron(c: DVec3) -> TetMesh {
        octahedron_with(c, 1.0)
    }

    /// [`octahedron`] with the top corner at height `top`.
    fn octahedron_with(c: DVec3, top: f64) -> TetMesh {
        let pts = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::new(0.0, 0.0, top),
            DVec3::NEG_Z,
            c,
        ];
        let mut tets = Vec::new();
        for &x in &[0u32, 1] {
            for &y in &[2u32, 3] {
                for &z in &[4u32, 5] {
                    let mut t = [6, x, y, z];
                    let p = t.map(|i| pts[i as usize]);
                    if crate::geom::orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
                        t.swap(2, 3);
                    }
                    tets.push(t);
                }
            }
        }
        let data = MeshData {
            points: pts.iter().map(|p| p.to_array()).collect(),
            tets,
            ..Default::default()
        };
        TetMesh::from_data(&data).unwrap().0
    }

    fn volume(m: &TetMesh) -> f64 {
        m.tet_ids()
            .map(|t| {
                let p = m.tet_points(t);
                (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
            })
            .sum()
    }

    #[test]
    fn a_centre_point_merges_into_a_corner_of_the_octahedron() {
        // The octahedron with corners at ±1 has volume 4/3. Merging the
        // centre into +x leaves the four tets (+x, -x, ±y, ±z): the four
        // holding +x vanish.
        let mut m = octahedron(DVec3::new(0.9, 0.0, 0.0));
        let mut ball = Vec::new();
        let new = contract_edge(&mut m, 6, 0, -1.0, &mut ball).unwrap();
        assert_eq!(new.len(), 4);
        assert_eq!(m.n_tets(), 4);
        m.check().unwrap();
        assert!((volume(&m) - 4.0 / 3.0).abs() < 1e-12);
        assert!(m.tet_ids().all(|t| !m.tet(t).contains(&6)));
        assert_eq!(m.tet_of_vertex(6), None);
        m.compact();
        assert_eq!(m.n_points(), 6);
    }

    #[test]
    fn refused_when_quality_would_not_beat_the_bar_or_a_tet_would_invert() {
        let mut m = octahedron(DVec3::new(0.2, 0.1, 0.05));
        let before = m.tet_slots().to_vec();
        let mut ball = Vec::new();
        // Merged into +x the four tets are regular-ish octants (min sine of
        // the octant tet (1,0,0),(-1,0,0),(0,1,0),(0,0,1): well below 1).
        assert_eq!(
            contract_edge(&mut m, 6, 0, 0.99, &mut ball),
            Err(OpError::NoImprovement)
        );
        assert_eq!(m.tet_slots(), &before[..]);
        // A vertex that is on the boundary is refused.
        assert!(matches!(
            contract_edge(&mut m, 0, 6, -1.0, &mut ball),
            Err(OpError::NotApplicable(_))
        ));
        assert_eq!(m.tet_slots(), &before[..]);
    }

    #[test]
    fn refused_when_a_cone_would_be_inverted() {
        // The top corner pushed below the square (z = -0.1) dents the ball;
        // the centre, at z = -0.5, still sees every face of it. From +x,
        // though, the dent's faces on the -x side are seen from behind:
        // the cone from (1,0,0) over (-1,0,0),(0,±1,0),(0,0,-0.1) lies on
        // the other side of the face's plane -x ± y - 10z = 1 than the
        // centre (-1 against 5), so it is inverted.
        let mut m = octahedron_with(DVec3::new(0.0, 0.0, -0.5), -0.1);
        m.check().unwrap();
        let before = m.tet_slots().to_vec();
        let mut ball = Vec::new();
        assert_eq!(
            contract_edge(&mut m, 6, 0, f64::NEG_INFINITY, &mut ball),
            Err(OpError::WouldInvert)
        );
        assert_eq!(m.tet_slots(), &before[..]);
        m.check().unwrap();
    }

    /// Boundary faces as (corners, marker).
    fn boundary(m: &TetMesh) -> Vec<([DVec3; 3], Option<i32>)> {
        let mut out = Vec::new();
        for t in m.tet_ids() {
            for f in 0..4 {
                if m.is_boundary_face(t, f) {
                    let fv = m.face_vertices(t, f);
                    out.push((fv.map(|x| m.point(x)), m.face_marker(fv)));
                }
            }
        }
        out
    }

    fn area(p: &[DVec3; 3]) -> f64 {
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    }

    #[test]
    fn a_face_vertex_of_the_cube_merges_inside_its_face_and_the_domain_stays() {
        let n = 4;
        let (mut m, _) = TetMesh::from_data(&crate::mesh::generate::cube_grid(n)).unwrap();
        let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
        // The bottom face (z = 0) carries marker 7.
        for (t, f) in m
            .tet_ids()
            .flat_map(|t| (0..4).map(move |f| (t, f)))
            .collect::<Vec<_>>()
        {
            let fv = m.face_vertices(t, f);
            if m.is_boundary_face(t, f) && fv.iter().all(|&x| m.point(x).z == 0.0) {
                m.set_face_marker(fv, Some(7));
            }
        }
        let before = boundary(&m);
        let marked = before.iter().filter(|b| b.1 == Some(7)).count();
        let exact = BoundaryFlipLimits {
            exact: true,
            hausd: 0.0,
            crease_angle: 0.0,
        };
        let mut ball = Vec::new();
        // On a cube edge the star is not flat: refused, exactly or within a
        // bound (the 90° crease).
        let bent = BoundaryFlipLimits {
            exact: false,
            hausd: 0.1,
            crease_angle: 45.0,
        };
        for limits in [exact, bent] {
            assert!(matches!(
                contract_boundary_edge(&mut m, id(2, 0, 0), id(3, 0, 0), -1.0, limits, &mut ball),
                Err(OpError::NotApplicable(_))
            ));
        }
        let tets = m.n_tets();
        contract_boundary_edge(&mut m, id(2, 2, 0), id(3, 2, 0), -1.0, exact, &mut ball).unwrap();
        m.check().unwrap();
        // The unit cube: volume 1 and boundary area 6; the six faces at the
        // merged vertex became a fan of four from its neighbour, all marked.
        assert!((volume(&m) - 1.0).abs() < 1e-12);
        let after = boundary(&m);
        assert_eq!(after.len(), before.len() - 2);
        assert!((after.iter().map(|b| area(&b.0)).sum::<f64>() - 6.0).abs() < 1e-12);
        assert_eq!(after.iter().filter(|b| b.1 == Some(7)).count(), marked - 2);
        assert!(after
            .iter()
            .all(|b| (b.1 == Some(7)) == b.0.iter().all(|p| p.z == 0.0)));
        assert!(m.n_tets() < tets);
    }
}
