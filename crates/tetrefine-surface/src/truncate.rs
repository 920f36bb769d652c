//! Chaikin vertex truncation (Akleman, Edmundson and Ozener,
//! "A generalized vertex truncation scheme to construct intriguing polyhedral
//! shapes").
//!
//! Every vertex is cut off by the polygon through the points at 1/4 of its
//! edges; equivalently every edge keeps its middle half, from 1/4 to 3/4, the
//! rule of Chaikin's corner-cutting curve scheme. One step on a closed mesh
//! with `V` vertices, `E` edges and `F` faces:
//!
//! - every edge gets two new vertices (at 1/4 and 3/4): `V' = 2E`;
//! - every `n`-sided face becomes a `2n`-sided face and every vertex of
//!   valence `m` becomes an `m`-sided face: `F' = F + V`;
//! - edges: the `E` shortened old edges plus one per face corner (`2E`):
//!   `E' = 3E`; every new vertex is 3-valent.
//!
//! From then on every vertex is 3-valent (`2E_k = 3V_k`), so after `k ≥ 1`
//! steps `E_k = 3^k E`, `V_k = 2·3^(k−1) E`, `F_k = F + V + (3^(k−1) − 1) E`.
//!
//! If the input faces are planar and its vertices 3-valent, every output face
//! is planar: old faces keep their plane (the new points lie on their edges)
//! and the face of a 3-valent vertex is a triangle; after the first step all
//! vertices are 3-valent, so this holds at every step.

use super::closed_manifold::closed_half_edges;
use super::error::SurfaceError;
use super::lineage::{observe, FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh};

/// `steps` steps of Chaikin vertex truncation (cut at 1/4 and 3/4 of every
/// edge) of a closed, consistently oriented manifold polygon mesh.
///
/// `steps = 0` returns the validated input unchanged. Vertices used by no
/// face are dropped.
pub fn truncate(mesh: &PolyMesh, steps: usize) -> Result<PolyMesh, SurfaceError> {
    truncate_with(mesh, steps, 0.25)
}

/// Checks a truncation cut: it lies strictly between 0 and 0.5.
pub fn check_cut(cut: f64) -> Result<(), SurfaceError> {
    if cut > 0.0 && cut < 0.5 {
        Ok(())
    } else {
        Err(SurfaceError::Parameter(format!(
            "the truncation cut must lie strictly between 0 and 0.5, got {cut}"
        )))
    }
}

/// Vertex truncation that cuts every edge at `cut` and `1 − cut` of its length
/// (`0 < cut < 0.5`; Chaikin's rule, and [`truncate`], is `cut = 0.25`).
pub fn truncate_with(mesh: &PolyMesh, steps: usize, cut: f64) -> Result<PolyMesh, SurfaceError> {
    truncate_tracked(mesh, steps, cut, None).map(|s| s.mesh)
}

/// [`truncate_with`] with the face attributes of [`super::lineage`] (the
/// shrunk old face continues its face: generation and group kept; the face
/// cut off a vertex is in group 1, from the face of the vertex's first
/// outgoing half-edge) and an observer of every generation.
pub fn truncate_tracked(
    mesh: &PolyMesh,
    steps: usize,
    cut: f64,
    mut observer: Option<&mut StepObserver<'_>>,
) -> Result<Subdivided, SurfaceError> {
    check_cut(cut)?;
    let he = closed_half_edges(mesh)?;
    let estimate = he.len() as f64 * 3f64.powi(steps.min(64) as i32);
    if estimate > i32::MAX as f64 {
        return Err(SurfaceError::TooLarge {
            steps,
            estimate,
            what: "half-edges",
        });
    }
    let mut current = mesh.clone();
    let mut attrs = FaceAttributes::input(mesh.faces.len());
    let mut done = 0;
    let mut he = Some(he);
    if observe(&mut observer, 0, &current, &attrs) {
        for k in 0..steps {
            let h = match he.take() {
                Some(h) => h,
                None => closed_half_edges(&current)?,
            };
            (current, attrs) = truncate_once(&current, &h, cut, &attrs, k as u32 + 1);
            done = k + 1;
            if !observe(&mut observer, done, &current, &attrs) {
                break;
            }
        }
    }
    Ok(Subdivided {
        mesh: current,
        attributes: attrs,
        steps: done,
    })
}

fn truncate_once(
    mesh: &PolyMesh,
    he: &HalfEdges,
    cut: f64,
    attrs: &FaceAttributes,
    generation: u32,
) -> (PolyMesh, FaceAttributes) {
    let p = &mesh.points;
    // One new vertex per half-edge v -> w, at v + cut (w - v); its id is the
    // half-edge id.
    let points = (0..he.len() as u32)
        .map(|h| {
            let a = p[he.origin[h as usize] as usize];
            a + cut * (p[he.dest(h) as usize] - a)
        })
        .collect();
    let mut faces = Vec::with_capacity(mesh.faces.len() + p.len());
    let mut out = FaceAttributes::with_capacity(mesh.faces.len() + p.len());
    for f in 0..mesh.faces.len() {
        out.push_kept(attrs, f as u32);
        let (start, end) = (he.face_start[f], he.face_start[f + 1]);
        // u -> v -> w becomes cut(v->u) -> cut(v->w).
        faces.push(
            (start..end)
                .flat_map(|h| [he.twin[he.prev(h) as usize], h])
                .collect(),
        );
    }
    for v in 0..p.len() as u32 {
        // Around v, counter-clockwise: the face of outgoing[j] holds
        // cut(outgoing[j + 1]) -> cut(outgoing[j]), so the vertex face, which
        // runs the other way along that side, is the outgoing list itself.
        let ring = he.outgoing(v);
        if !ring.is_empty() {
            out.push_child(attrs, he.face[ring[0] as usize], generation, 1);
            faces.push(ring);
        }
    }
    (PolyMesh { points, faces }, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_shapes::*;
    use glam::DVec3;
    use std::collections::HashMap;

    fn shapes() -> Vec<(&'static str, PolyMesh)> {
        vec![
            ("tetrahedron", tetrahedron()),
            ("cube", cube(1.0)),
            ("octahedron", octahedron()),
            ("icosphere", icosphere(2)),
            ("dodecahedron", dodecahedron()),
            ("torus", torus(5, 4)),
        ]
    }

    #[test]
    fn every_vertex_is_3_valent_after_one_step() {
        for (name, mesh) in shapes() {
            for k in 1..=2 {
                let out = truncate(&mesh, k).expect("truncate");
                let val = valences(&out);
                assert_eq!(val.len(), out.points.len(), "{name}: every point used");
                assert!(val.values().all(|&d| d == 3), "{name}, {k} steps");
            }
        }
    }

    #[test]
    fn counts_follow_the_closed_form() {
        for (name, mesh) in shapes() {
            let t0 = closed_manifold_topology(&mesh).expect("input");
            let (v, e, f) = (t0.vertices as i64, t0.edges as i64, t0.faces as i64);
            for k in 1..=4u32 {
                let out = truncate(&mesh, k as usize).expect("truncate");
                let t = closed_manifold_topology(&out)
                    .unwrap_or_else(|err| panic!("{name}, {k} steps: {err}"));
                let p = 3i64.pow(k - 1);
                assert_eq!(t.edges as i64, 3 * p * e, "{name}, {k}: E");
                assert_eq!(t.vertices as i64, 2 * p * e, "{name}, {k}: V");
                assert_eq!(t.faces as i64, f + v + (p - 1) * e, "{name}, {k}: F");
                assert_eq!(t.euler, t0.euler, "{name}, {k}: χ kept");
                assert_eq!(t.components, t0.components);
            }
        }
    }

    #[test]
    fn faces_are_doubled_polygons_and_vertex_polygons() {
        // One step: an n-gon becomes a 2n-gon, a vertex of valence m an m-gon.
        for (name, mesh) in shapes() {
            let mut want: HashMap<usize, usize> = HashMap::new();
            for f in &mesh.faces {
                *want.entry(2 * f.len()).or_default() += 1;
            }
            for d in valences(&mesh).values() {
                *want.entry(*d).or_default() += 1;
            }
            let mut got: HashMap<usize, usize> = HashMap::new();
            for f in &truncate(&mesh, 1).expect("ok").faces {
                *got.entry(f.len()).or_default() += 1;
            }
            assert_eq!(got, want, "{name}");
        }
    }

    #[test]
    fn new_points_cut_every_edge_at_a_quarter() {
        let mesh = icosphere(1);
        let out = truncate(&mesh, 1).expect("ok");
        let mut cuts = Vec::new();
        for f in &mesh.faces {
            for i in 0..f.len() {
                let (a, b) = (
                    mesh.points[f[i] as usize],
                    mesh.points[f[(i + 1) % f.len()] as usize],
                );
                cuts.push(a + 0.25 * (b - a));
                cuts.push(a + 0.75 * (b - a));
            }
        }
        for p in &out.points {
            let d = cuts
                .iter()
                .map(|c| c.distance(*p))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-15, "{p} is not a quarter point");
        }
        // Two new points per old edge: V' = 2E.
        let t = closed_manifold_topology(&out).expect("manifold");
        assert_eq!(
            t.vertices,
            2 * closed_manifold_topology(&mesh).expect("in").edges
        );
    }

    /// The largest distance of a face's vertex to the face's best-fit plane.
    fn worst_plane_deviation(mesh: &PolyMesh) -> f64 {
        mesh.faces
            .iter()
            .map(|f| {
                let pts: Vec<DVec3> = f.iter().map(|&i| mesh.points[i as usize]).collect();
                plane_deviation(&pts)
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn planar_faces_with_3_valent_vertices_stay_planar() {
        let mut inputs = vec![
            ("cube", cube(1.0)),
            ("tetrahedron", tetrahedron()),
            ("dodecahedron", dodecahedron()),
            ("L-prism (non-convex faces)", l_prism()),
            // The paper: the regular octahedron stays planar although its
            // vertices are 4-valent.
            ("octahedron", octahedron()),
        ];
        for seed in 1..=4u64 {
            inputs.push(("random frustum", random_frustum(seed, 5 + seed as usize)));
        }
        for (name, mesh) in inputs {
            for f in &mesh.faces {
                let pts: Vec<DVec3> = f.iter().map(|&i| mesh.points[i as usize]).collect();
                assert!(
                    plane_deviation(&pts) < 1e-12,
                    "{name}: input face not planar"
                );
            }
            for k in 1..=4 {
                let worst = worst_plane_deviation(&truncate(&mesh, k).expect("ok"));
                assert!(
                    worst < 1e-12,
                    "{name}, {k} steps: face off its plane by {worst}"
                );
            }
        }
    }

    #[test]
    fn non_3_valent_vertices_give_non_planar_faces() {
        // The counter-case the paper describes: the icosphere's 5- and
        // 6-valent vertices are not coplanar with their quarter points.
        let worst = worst_plane_deviation(&truncate(&icosphere(1), 1).expect("ok"));
        assert!(worst > 1e-4, "{worst}");
    }

    #[test]
    fn outward_orientation_is_kept() {
        for (name, mesh) in [("cube", cube(1.0)), ("dodecahedron", dodecahedron())] {
            let v0 = signed_volume(&mesh);
            let v = signed_volume(&truncate(&mesh, 3).expect("ok"));
            assert!(v > 0.5 * v0 && v < v0, "{name}: {v} vs {v0}");
        }
        // Cutting the 8 corners of the unit cube at 1/4 removes 8 tetrahedra
        // with legs 1/4.
        let v = signed_volume(&truncate(&cube(1.0), 1).expect("ok"));
        assert!((v - (1.0 - 8.0 * (0.25f64).powi(3) / 6.0)).abs() < 1e-14);
    }

    #[test]
    fn bad_input_is_refused() {
        let mut open = cube(1.0);
        open.faces.remove(2);
        assert!(matches!(
            truncate(&open, 1),
            Err(SurfaceError::OpenEdge { .. })
        ));
        let mut small = cube(1.0);
        small.faces[0].truncate(2);
        assert!(matches!(
            truncate(&small, 1),
            Err(SurfaceError::FaceTooSmall { face: 0, len: 2 })
        ));
        let mut rep = cube(1.0);
        rep.faces[0][1] = rep.faces[0][0];
        assert!(matches!(
            truncate(&rep, 1),
            Err(SurfaceError::RepeatedVertex { face: 0, .. })
        ));
        assert!(matches!(
            truncate_with(&cube(1.0), 1, 0.5),
            Err(SurfaceError::Parameter(_))
        ));
        assert!(matches!(
            truncate(&PolyMesh::default(), 1),
            Err(SurfaceError::Empty)
        ));
        assert!(matches!(
            truncate(&cube(1.0), 30),
            Err(SurfaceError::TooLarge { .. })
        ));
        assert_eq!(truncate(&cube(1.0), 0).expect("ok"), cube(1.0));
    }
}
