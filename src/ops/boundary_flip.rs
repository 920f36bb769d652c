//! Boundary edge flips: a boundary edge between two faces of one surface
//! patch is replaced by the other diagonal of the quadrilateral the two faces
//! form, and the tets under it are reconnected to match.
//!
//! ```text
//!   the boundary, seen from outside          after the flip
//!
//!              p0                                 p0
//!             /  \                               /|\
//!            /    \        faces (a,p0,b)       / | \       faces (a,p0,pm)
//!           a------b       and (a,b,pm)        a  |  b      and (b,pm,p0)
//!            \    /        (outward), edge      \ | /       (outward), edge
//!             \  /         a-b                   \|/        p0-pm
//!              pm                                 pm
//!
//!   inside: the open ring of the edge, tets T_i = (a, b, p_i, p_i+1) for
//!   i = 0 … m-1 (p_1 … p_m-1 lie under the surface). Its polygon
//!   p0 p1 … pm, closed by the chord pm-p0, is triangulated (one programme,
//!   `super::edge_removal`) and every triangle (p_i, p_k, p_j) coned to a
//!   and to b: tets (a, p_i, p_k, p_j) and (b, p_j, p_k, p_i), m → 2m − 2.
//!   The triangle on the chord gives the new boundary faces. With m = 2 this
//!   is the 2-2 flip: (a,b,p0,p1), (a,b,p1,p2) → (a,p0,p1,p2), (b,p2,p1,p0).
//! ```
//!
//! MMG3D swaps boundary edges the same way where the two faces are close to
//! coplanar and the Hausdorff distance allows it (Dapogny, Dobrzynski and
//! Frey, JCP 2014; its "swap of boundary edges"), and Stellar's edge removal
//! works on boundary edges with the surface triangulation changing alongside
//! (Klingner and Shewchuk, "Aggressive tetrahedral mesh improvement", IMR
//! 2007). This is the √3 step's boundary flip (seed paper §4) offered as an
//! improvement move: the implementation is our own.

use super::edge_removal::{
    apply_ring_triangulation, best_ring_triangulation_above, EdgeRing, RingScratch,
};
use super::OpError;
use crate::geom::closest::surfaces_within;
use crate::geom::orient3d;
use crate::mesh::TetMesh;
use glam::DVec3;

/// How far the surface may change under a boundary flip.
#[derive(Clone, Copy, Debug)]
pub struct BoundaryFlipLimits {
    /// Only exactly coplanar faces (exact `orient3d` of the four corners is
    /// zero): the domain does not change at all. The linear rule's choice.
    pub exact: bool,
    /// Otherwise: largest distance between the old and the new pair of
    /// faces, both ways (a Hausdorff bound, measured from above as the
    /// boundary cap removal measures it).
    pub hausd: f64,
    /// Otherwise: the two old faces, and the two new ones, must not meet at
    /// a crease: their outward normals differ by at most this many degrees.
    pub crease_angle: f64,
}

/// The open ring of a boundary edge that may be flipped, and its surface
/// faces: the checks of [`flip_boundary_edge`] that do not look at quality.
///
/// Refuses ([`OpError::NotApplicable`]) an interior edge, an edge with one
/// tet (a cap: [`super::remove_boundary_cap`]), a feature edge, two faces of
/// different markers, a ring crossing a constrained face (an interface or a
/// marked face: the edge is on a region boundary), a new edge `p0-pm`
/// that exists already or a `p0` or `pm` where the domain touches itself
/// (the boundary would become non-manifold there; `counts` must be the
/// mesh's own) and faces beyond `limits`.
pub fn boundary_flip_ring(
    mesh: &TetMesh,
    t: u32,
    e: usize,
    limits: BoundaryFlipLimits,
    counts: &TetsAtVertex,
) -> Result<EdgeRing, OpError> {
    let mut ring = EdgeRing::gather(mesh, t, e);
    if ring.closed {
        return Err(OpError::NotApplicable("not a boundary edge"));
    }
    let m = ring.tets.len();
    if m < 2 {
        return Err(OpError::NotApplicable(
            "one tet on the edge: a cap, not a flip",
        ));
    }
    let (a, b) = (ring.a, ring.b);
    let (p0, pm) = (ring.verts[0], ring.verts[m]);
    if p0 == pm {
        return Err(OpError::NotApplicable("the ring closes on itself"));
    }
    if mesh.is_feature_edge(a, b) {
        return Err(OpError::NotApplicable("a feature edge"));
    }
    if mesh.face_marker([a, b, p0]) != mesh.face_marker([a, b, pm]) {
        return Err(OpError::NotApplicable("faces of two markers"));
    }
    if mesh
        .face_marker([a, b, p0])
        .is_some_and(crate::mesh::partition::is_partition_marker)
    {
        return Err(OpError::NotApplicable("a partition face must stay"));
    }
    for i in 1..m {
        let (t0, t1) = (ring.tets[i - 1], ring.tets[i]);
        if mesh.face_is_constrained(t0, Some(t1), [a, b, ring.verts[i]]) {
            return Err(OpError::NotApplicable("the edge is on an interface"));
        }
    }
    // The new boundary edge must be new: were p0-pm an edge already (the
    // domain touching itself there, or a vertex of boundary valence three),
    // it would end in four boundary faces, or its tets would overlap. The
    // balls found by walking faces hold every tet at p0 and at pm unless the
    // domain touches itself at that vertex (a pinch), which `counts` tells.
    let mut ball = Vec::new();
    for (v, w) in [(p0, pm), (pm, p0)] {
        mesh.ball(v, &mut ball);
        if ball.len() != counts.at(v) as usize {
            return Err(OpError::NotApplicable("the domain touches itself here"));
        }
        if ball.iter().any(|&u| mesh.tet(u).contains(&w)) {
            return Err(OpError::NotApplicable("the new edge exists already"));
        }
    }
    let [pa, pb, q0, qm] = [a, b, p0, pm].map(|v| mesh.point(v));
    if limits.exact {
        if orient3d(pa, pb, q0, qm) != 0.0 {
            return Err(OpError::NotApplicable("the faces are not coplanar"));
        }
    } else {
        // Outward orientations (see the sketch): both pairs are judged as
        // the surface sees them.
        let old = [[pa, q0, pb], [pa, pb, qm]];
        let new = [[pa, q0, qm], [pb, qm, q0]];
        let normal = |f: &[DVec3; 3]| (f[1] - f[0]).cross(f[2] - f[0]).normalize();
        let cos_bar = limits.crease_angle.to_radians().cos();
        for pair in [&old, &new] {
            let c = normal(&pair[0]).dot(normal(&pair[1]));
            // NaN (a degenerate face) refuses as a crease does.
            if c.is_nan() || c < cos_bar {
                return Err(OpError::NotApplicable("a crease"));
            }
        }
        if !(surfaces_within(&old, &new, limits.hausd) && surfaces_within(&new, &old, limits.hausd))
        {
            return Err(OpError::NotApplicable("beyond the Hausdorff bound"));
        }
    }
    canonicalize_open_ring(&mut ring);
    Ok(ring)
}

/// Puts an open ring in a form that does not depend on the tet it was
/// gathered from: `a < b` (swapping the ends reverses the ring: tet
/// `(a, b, p_i, p_i+1)` is `(b, a, p_i+1, p_i)`). An open ring always starts
/// at a boundary face, so its start is fixed once its direction is.
fn canonicalize_open_ring(ring: &mut EdgeRing) {
    if ring.a > ring.b {
        std::mem::swap(&mut ring.a, &mut ring.b);
        ring.tets.reverse();
        ring.verts.reverse();
    }
}

/// Flips the boundary edge `e` (local edge of tet `t`) when it may go (see
/// [`boundary_flip_ring`]) and the best reconnection of its ring has a worst
/// tet of min sine strictly above `beat` (`f64::NEG_INFINITY`: any valid
/// one). Every new tet is positive by the exact `orient3d`, or nothing is
/// done ([`OpError::WouldInvert`] with `beat = −∞`, else
/// [`OpError::NoImprovement`]). The new boundary faces take the marker of
/// the old ones; the new tets the region of the ring, and level and parent
/// of its highest-level tet ([`super::replace_cavity`]). Returns the new
/// tets; on `Err` the mesh is unchanged.
pub fn flip_boundary_edge(
    mesh: &mut TetMesh,
    t: u32,
    e: usize,
    limits: BoundaryFlipLimits,
    beat: f64,
    counts: &mut TetsAtVertex,
) -> Result<Vec<u32>, OpError> {
    let ring = boundary_flip_ring(mesh, t, e, limits, counts)?;
    let tri = best_ring_triangulation_above(mesh, &ring, beat, &mut RingScratch::default());
    if tri.quality == f64::NEG_INFINITY {
        return Err(if beat == f64::NEG_INFINITY {
            OpError::WouldInvert
        } else {
            OpError::NoImprovement
        });
    }
    let new = apply_ring_triangulation(mesh, &ring, &tri)?;
    counts.replace(&ring, &new, mesh);
    Ok(new)
}

/// The number of tets at each vertex, over the whole mesh: where it is more
/// than the ball found by walking faces, the domain touches itself at the
/// vertex. Kept up to date by [`flip_boundary_edge`].
#[derive(Clone, Debug, Default)]
pub struct TetsAtVertex(Vec<u32>);

impl TetsAtVertex {
    /// Counts the tets at every vertex of `mesh`.
    pub fn new(mesh: &TetMesh) -> TetsAtVertex {
        let mut c = vec![0u32; mesh.n_points()];
        for t in mesh.tet_ids() {
            for v in mesh.tet(t) {
                c[v as usize] += 1;
            }
        }
        TetsAtVertex(c)
    }

    /// Tets at vertex `v`.
    pub fn at(&self, v: u32) -> u32 {
        self.0.get(v as usize).copied().unwrap_or(0)
    }

    /// The tets `old` (their corners) were replaced by the tets `new` of
    /// `mesh`.
    pub(crate) fn replaced(&mut self, old: &[[u32; 4]], new: &[u32], mesh: &TetMesh) {
        for v in old.iter().flatten() {
            self.0[*v as usize] -= 1;
        }
        for &t in new {
            for v in mesh.tet(t) {
                self.0[v as usize] += 1;
            }
        }
    }

    /// The ring's tets were replaced by the tets `new` of `mesh`: the old
    /// tets were (a, b, p_i, p_i+1) along the open ring.
    fn replace(&mut self, ring: &EdgeRing, new: &[u32], mesh: &TetMesh) {
        debug_assert_eq!(ring.verts.len(), ring.tets.len() + 1, "an open ring");
        let old: Vec<[u32; 4]> = ring
            .verts
            .windows(2)
            .map(|p| [ring.a, ring.b, p[0], p[1]])
            .collect();
        self.replaced(&old, new, mesh);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::boundary_face_count;
    use crate::mesh::generate::total_volume as volume;
    use crate::mesh::MeshData;
    use crate::topo::TET_EDGES;

    const EXACT: BoundaryFlipLimits = BoundaryFlipLimits {
        exact: true,
        hausd: 0.0,
        crease_angle: 0.0,
    };

    /// A pyramid under the rhombus a (0,0,0), p0 (2,-1,0), b (4,0,0),
    /// pm (2,1,0), apexes below at `apexes`; the top is split along the
    /// long diagonal a-b. Point ids: a 0, b 1, p0 2, pm 3, apexes 4, 5, ….
    /// One apex: tets (a,b,p0,c), (a,b,c,pm), the ring p0 c pm (m = 2);
    /// two apexes c1, c2 under a-b: the ring p0 c1 c2 pm (m = 3).
    ///
    /// ```text
    ///            pm (2,1)
    ///           /  \          top view, z = 0
    ///   a (0,0)------b (4,0)
    ///           \  /
    ///            p0 (2,-1)
    /// ```
    fn rhombus(apexes: &[[f64; 3]], top_marker: i32) -> TetMesh {
        let mut points = vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [2.0, -1.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        points.extend_from_slice(apexes);
        let mut tets = Vec::new();
        let ring: Vec<u32> = std::iter::once(2)
            .chain(4..4 + apexes.len() as u32)
            .chain(std::iter::once(3))
            .collect();
        for w in ring.windows(2) {
            tets.push([0, 1, w[0], w[1]]);
        }
        let data = MeshData {
            points,
            tets,
            triangles: vec![([0, 1, 2], top_marker), ([0, 1, 3], top_marker)],
            ..Default::default()
        };
        TetMesh::from_data(&data).unwrap().0
    }

    /// A tet and local edge holding the edge (u, v).
    fn edge_of(m: &TetMesh, u: u32, v: u32) -> (u32, usize) {
        m.tet_ids()
            .find_map(|t| {
                let tv = m.tet(t);
                let (i, j) = (
                    tv.iter().position(|&x| x == u)?,
                    tv.iter().position(|&x| x == v)?,
                );
                let e = TET_EDGES
                    .iter()
                    .position(|&[p, q]| (p, q) == (i, j) || (p, q) == (j, i))?;
                Some((t, e))
            })
            .unwrap()
    }

    /// [`flip_boundary_edge`] with the mesh's own counts.
    fn flip(
        m: &mut TetMesh,
        t: u32,
        e: usize,
        limits: BoundaryFlipLimits,
        beat: f64,
    ) -> Result<Vec<u32>, OpError> {
        let mut counts = TetsAtVertex::new(m);
        flip_boundary_edge(m, t, e, limits, beat, &mut counts)
    }

    fn has_edge(m: &TetMesh, u: u32, v: u32) -> bool {
        m.tet_ids()
            .any(|t| m.tet(t).contains(&u) && m.tet(t).contains(&v))
    }

    #[test]
    fn a_two_two_flip_keeps_the_volume_and_moves_the_marker() {
        let mut m = rhombus(&[[2.0, 0.0, -1.0]], 5);
        let (t, e) = edge_of(&m, 0, 1);
        let new = flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).unwrap();
        m.check().unwrap();
        assert_eq!(new.len(), 2);
        assert_eq!(m.n_tets(), 2);
        // Rhombus of diagonals 4 and 2 (area 4), height 1: volume 4/3.
        assert!((volume(&m) - 4.0 / 3.0).abs() < 1e-14, "{}", volume(&m));
        // 8 faces of two tets, one shared: 6 on the boundary, as before.
        assert_eq!(boundary_face_count(&m), 6);
        assert!(!has_edge(&m, 0, 1) && has_edge(&m, 2, 3));
        assert_eq!(m.face_marker([0, 2, 3]), Some(5));
        assert_eq!(m.face_marker([1, 2, 3]), Some(5));
        assert_eq!(m.face_marker([0, 1, 2]), None);
        assert_eq!(m.face_marker([0, 1, 3]), None);
    }

    #[test]
    fn a_flip_over_three_tets_makes_four() {
        // Apexes c1 (1.5,-0.3,-1), c2 (2.5,0.3,-1) under a-b: ring p0 c1 c2 pm.
        let mut m = rhombus(&[[1.5, -0.3, -1.0], [2.5, 0.3, -1.0]], 5);
        let before = volume(&m);
        let (t, e) = edge_of(&m, 0, 1);
        let mut counts = TetsAtVertex::new(&m);
        flip_boundary_edge(&mut m, t, e, EXACT, f64::NEG_INFINITY, &mut counts).unwrap();
        m.check().unwrap();
        // The counts kept up to date are the counts of the new mesh.
        let fresh = TetsAtVertex::new(&m);
        assert!((0..m.n_points() as u32).all(|v| counts.at(v) == fresh.at(v)));
        // Two triangles of the polygon p0 c1 c2 pm, each coned to a and b:
        // a and b in 2 tets each; the chord's triangle holds p0 and pm, the
        // other one of them and both c1 and c2, or one of them: 3 triangle
        // corners, 6 tets, on each side.
        assert_eq!([fresh.at(0), fresh.at(1)], [2, 2]);
        assert_eq!(fresh.at(2) + fresh.at(3), 6);
        assert_eq!(fresh.at(4) + fresh.at(5), 6);
        assert_eq!(m.n_tets(), 4, "m = 3 tets become 2m - 2");
        assert!((volume(&m) - before).abs() < 1e-14);
        assert!(has_edge(&m, 2, 3));
    }

    #[test]
    fn a_cube_face_diagonal_flips() {
        // The crate's six Kuhn tets of the unit cube: every cube face is
        // split by one diagonal; flip one of z = 0 (points 0..4 there).
        let (mut m, _) = TetMesh::from_data(&crate::mesh::generate::cube_grid(1)).unwrap();
        let bottom: Vec<u32> = (0..8).filter(|&v| m.point(v).z == 0.0).collect();
        assert_eq!(bottom.len(), 4);
        let diag = bottom
            .iter()
            .flat_map(|&u| bottom.iter().map(move |&v| (u, v)))
            .find(|&(u, v)| u < v && has_edge(&m, u, v) && m.point(u).distance(m.point(v)) > 1.2)
            .unwrap();
        let (t, e) = edge_of(&m, diag.0, diag.1);
        flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).unwrap();
        m.check().unwrap();
        assert!(!has_edge(&m, diag.0, diag.1));
        let other: Vec<u32> = bottom
            .iter()
            .copied()
            .filter(|&v| v != diag.0 && v != diag.1)
            .collect();
        assert!(has_edge(&m, other[0], other[1]));
        assert!((volume(&m) - 1.0).abs() < 1e-15);
        assert_eq!(boundary_face_count(&m), 12);
    }

    #[test]
    fn flips_stay_away_when_a_rule_forbids_them() {
        let c = [2.0, 0.0, -1.0];
        let (t, e) = edge_of(&rhombus(&[c], 5), 0, 1);
        // A feature edge.
        let mut m = rhombus(&[c], 5);
        m.set_feature_edge(0, 1, Some(1));
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        // Two markers.
        let mut m = rhombus(&[c], 5);
        m.set_face_marker([0, 1, 3], Some(6));
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        // Not coplanar: pm lifted by 0.01. Exact refuses; the Hausdorff
        // bound passes at 0.01 (every point of either pair is within the
        // lift of the other) and refuses at 0.001 (the middle of a-b stands
        // 0.005 below the new edge p0-pm).
        let lifted = |m: &mut TetMesh| m.set_point(3, DVec3::new(2.0, 1.0, 0.01));
        let mut m = rhombus(&[c], 5);
        lifted(&mut m);
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        let within = |hausd| BoundaryFlipLimits {
            exact: false,
            hausd,
            crease_angle: 45.0,
        };
        assert!(flip(&mut m, t, e, within(0.001), f64::NEG_INFINITY).is_err());
        assert_eq!(m.n_tets(), 2);
        flip(&mut m, t, e, within(0.01), f64::NEG_INFINITY).unwrap();
        m.check().unwrap();
        // A crease: pm lifted by 1.5 (the faces' normals 56° apart) passes
        // a loose bound but not the crease angle.
        let mut m = rhombus(&[c], 5);
        m.set_point(3, DVec3::new(2.0, 1.0, 1.5));
        assert!(flip(&mut m, t, e, within(10.0), f64::NEG_INFINITY).is_err());
        // No improvement asked beyond what is possible: beat 1.0.
        let mut m = rhombus(&[c], 5);
        assert_eq!(flip(&mut m, t, e, EXACT, 1.0), Err(OpError::NoImprovement));
        m.check().unwrap();
        assert!(has_edge(&m, 0, 1));
    }

    #[test]
    fn a_dart_would_invert() {
        // a at (3,0,0), inside the triangle p0 b pm: the quadrilateral
        // a p0 b pm is reflex at a, its diagonal p0-pm runs outside it, and
        // the new faces would overlap: some new tet is negative.
        let data = MeshData {
            points: vec![
                [3.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [2.0, -1.0, 0.0],
                [2.0, 1.0, 0.0],
                [3.5, 0.0, -1.0],
            ],
            tets: vec![[0, 1, 2, 4], [0, 1, 4, 3]],
            ..Default::default()
        };
        let (mut m, _) = TetMesh::from_data(&data).unwrap();
        let (t, e) = edge_of(&m, 0, 1);
        assert_eq!(
            flip(&mut m, t, e, EXACT, f64::NEG_INFINITY),
            Err(OpError::WouldInvert)
        );
        m.check().unwrap();
        assert_eq!(m.n_tets(), 2);
    }

    #[test]
    fn the_boundary_stays_manifold() {
        // A third tet above the rhombus touches it along p0-pm only (the
        // domain touches itself there): flipping a-b would put p0-pm in
        // four boundary faces.
        let data = MeshData {
            points: vec![
                [0.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [2.0, -1.0, 0.0],
                [2.0, 1.0, 0.0],
                [2.0, 0.0, -1.0],
                [1.0, 0.0, 1.0],
                [3.0, 0.0, 1.0],
            ],
            tets: vec![[0, 1, 2, 4], [0, 1, 4, 3], [2, 3, 5, 6]],
            ..Default::default()
        };
        let (mut m, _) = TetMesh::from_data(&data).unwrap();
        m.check().unwrap();
        let (t, e) = edge_of(&m, 0, 1);
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        assert_eq!(m.n_tets(), 3);
        m.check().unwrap();
    }

    #[test]
    fn interface_and_one_tet_edges_stay() {
        // The two tets in different regions: the face (a,b,c) between them
        // is an interface.
        let mut data = MeshData {
            points: vec![
                [0.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [2.0, -1.0, 0.0],
                [2.0, 1.0, 0.0],
                [2.0, 0.0, -1.0],
            ],
            tets: vec![[0, 1, 2, 4], [0, 1, 4, 3]],
            tet_regions: vec![1, 2],
            ..Default::default()
        };
        let (mut m, _) = TetMesh::from_data(&data).unwrap();
        let (t, e) = edge_of(&m, 0, 1);
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        // One region again, the face between marked: still an interface.
        data.tet_regions.clear();
        data.triangles = vec![([0, 1, 4], 3)];
        let (mut m, _) = TetMesh::from_data(&data).unwrap();
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        // An edge with one tet (a-p0): a cap's business.
        let (t, e) = edge_of(&m, 0, 2);
        assert!(flip(&mut m, t, e, EXACT, f64::NEG_INFINITY).is_err());
        m.check().unwrap();
        assert_eq!(m.n_tets(), 2);
    }
}
