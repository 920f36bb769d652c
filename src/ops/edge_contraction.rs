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

use super::{replace_cavity_raw, OpError};
use crate::geom::tet_min_sine;
use crate::mesh::{TetMesh, NO_ADJ};

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
            if h == NO_ADJ || mesh.is_interface_face(t, f) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;
    use glam::DVec3;

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
}
