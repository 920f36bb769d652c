//! Sharp features: where feature edges and corners come from.
//!
//! The constrained surface of a mesh is the union of its boundary faces, the
//! faces between two regions (material interfaces) and marked interior faces.
//! An edge of it is a feature edge when
//! * it has other than two constrained faces (an interface meets the boundary
//!   or another interface);
//! * its two faces belong to different patches (different boundary markers or
//!   different region pairs);
//! * the normals of its two faces differ by more than the feature angle (45° by
//!   default, MMG's ridge angle);
//! * it lies on a material interface whose two faces there are not coplanar
//!   (with linear interfaces, [`InterfaceRule::Linear`], the default).
//!   A √3 flip of such an edge would cut a chord through one region into the
//!   other, so curved interfaces are refined by the crease rule instead and
//!   every region stays exactly what it was.
//!
//! Corners are the vertices with other than two incident feature edges (and
//! at least one), plus those tagged in the input. Tags read from the input
//! (Medit `Edges`/`Ridges`, `Corners`, `RequiredVertices`) are kept.

use super::InterfaceRule;
use crate::file::IoError;
use crate::mesh::{edge_key, TetMesh, NO_ADJ};
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// A constrained face seen from one side: outward normal (for an interface,
/// seen from the tet of the smaller region id) and its patch identity.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SideFace {
    normal: DVec3,
    patch: (i64, i64),
}

/// The faces of the constrained surface: `(vertices as oriented, patch)`.
fn constrained_faces(mesh: &TetMesh) -> Vec<([u32; 3], (i64, i64))> {
    let mut out = Vec::new();
    let has_markers = !mesh.face_markers().is_empty();
    for t in mesh.tet_ids() {
        let adj = mesh.adj(t);
        for (f, &h) in adj.iter().enumerate() {
            let fv = mesh.face_vertices(t, f);
            let marker = if has_markers {
                mesh.face_marker(fv)
            } else {
                None
            };
            if h == NO_ADJ {
                out.push((fv, (i64::MIN, marker.map_or(i64::MIN, i64::from))));
                continue;
            }
            let u = h >> 2;
            let (rt, ru) = (mesh.region(t), mesh.region(u));
            // Record each interior constrained face once, from the lower region
            // (or the lower tet id when the regions agree).
            let constrained = rt != ru || marker.is_some();
            if constrained && (rt < ru || (rt == ru && t < u)) {
                let patch = (
                    i64::from(rt) * (1 << 32) + i64::from(ru),
                    marker.map_or(i64::MIN, i64::from),
                );
                out.push((fv, patch));
            }
        }
    }
    out
}

/// What feature detection found.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct FeatureReport {
    /// Feature edges after detection (input tags included).
    pub feature_edges: usize,
    /// Corners after detection.
    pub corners: usize,
    /// Edges added by the angle criterion.
    pub by_angle: usize,
    /// Edges added because their faces are different patches.
    pub by_patch: usize,
    /// Edges added because other than two constrained faces meet there.
    pub by_junction: usize,
    /// Edges added because they bend a material interface.
    pub curved_interface: usize,
}

/// Tags feature edges (with marker 0 when new) and corners on `mesh` by the
/// rules of the module docs, keeping the tags already there; for linear
/// interfaces ([`detect_features_for`] with [`InterfaceRule::Linear`]).
pub fn detect_features(mesh: &mut TetMesh, angle_deg: f64) -> FeatureReport {
    detect_features_for(mesh, angle_deg, InterfaceRule::Linear)
}

/// [`detect_features`] for the interface rule the refinement will use: with
/// [`InterfaceRule::Sqrt3`] a bending interface is no crease by itself (the
/// √3 rule refines it as a smooth surface); only the angle, patch and
/// junction rules tag its edges.
pub fn detect_features_for(
    mesh: &mut TetMesh,
    angle_deg: f64,
    interfaces: InterfaceRule,
) -> FeatureReport {
    let faces = constrained_faces(mesh);
    let mut by_edge: HashMap<[u32; 2], Vec<SideFace>> = HashMap::new();
    for (fv, patch) in &faces {
        let p = fv.map(|v| mesh.point(v));
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let n = if n.length_squared() > 0.0 {
            n.normalize()
        } else {
            n
        };
        for i in 0..3 {
            by_edge
                .entry(edge_key(fv[i], fv[(i + 1) % 3]))
                .or_default()
                .push(SideFace {
                    normal: n,
                    patch: *patch,
                });
        }
    }
    let cos_limit = angle_deg.to_radians().cos();
    let mut report = FeatureReport::default();
    let mut edges: Vec<[u32; 2]> = by_edge.keys().copied().collect();
    edges.sort_unstable();
    for e in edges {
        if mesh.is_feature_edge(e[0], e[1]) {
            continue;
        }
        let sides = &by_edge[&e];
        let why = if sides.len() != 2 {
            Some(&mut report.by_junction)
        } else if sides[0].patch != sides[1].patch {
            Some(&mut report.by_patch)
        } else if sides[0].normal.dot(sides[1].normal) < cos_limit {
            // Consistently oriented neighbours: the normal deviation is the
            // angle between the normals.
            Some(&mut report.by_angle)
        } else if interfaces == InterfaceRule::Linear
            && sides[0].patch.0 != i64::MIN
            && !coplanar(mesh, e, sides)
        {
            Some(&mut report.curved_interface)
        } else {
            None
        };
        if let Some(counter) = why {
            *counter += 1;
            mesh.set_feature_edge(e[0], e[1], Some(0));
        }
    }
    tag_corners(mesh);
    report.feature_edges = mesh.feature_edges().len();
    report.corners = mesh.corners().len();
    report
}

/// Whether the two faces at interface edge `e` lie in one plane (to a
/// relative 1e-12 in the cosine of the normals' angle, which only rounding of
/// exactly coplanar input stays within).
fn coplanar(_mesh: &TetMesh, _e: [u32; 2], sides: &[SideFace]) -> bool {
    sides[0].normal.dot(sides[1].normal) >= 1.0 - 1e-12
}

/// Adds as corners the vertices with other than two incident feature edges.
pub fn tag_corners(mesh: &mut TetMesh) {
    let mut count: HashMap<u32, usize> = HashMap::new();
    for e in mesh.feature_edges().keys() {
        *count.entry(e[0]).or_default() += 1;
        *count.entry(e[1]).or_default() += 1;
    }
    let mut corners: Vec<u32> = count
        .into_iter()
        .filter(|&(_, c)| c != 2)
        .map(|(v, _)| v)
        .collect();
    corners.sort_unstable();
    for v in corners {
        mesh.set_corner(v, true);
    }
}

/// Tags the edges of an edge list read from `path` (each with its line) as
/// feature edges and re-derives the corners; an edge that is not an edge of
/// the mesh is an error at its line, and then nothing is tagged.
pub fn tag_edge_list(
    mesh: &mut TetMesh,
    path: &Path,
    edges: &[([u32; 2], usize)],
) -> Result<usize, IoError> {
    let mut all: std::collections::HashSet<[u32; 2]> = std::collections::HashSet::new();
    for t in mesh.tet_ids() {
        let v = mesh.tet(t);
        for [i, j] in crate::topo::TET_EDGES {
            all.insert(edge_key(v[i], v[j]));
        }
    }
    if let Some(([a, b], line)) = edges
        .iter()
        .find(|([a, b], _)| !all.contains(&edge_key(*a, *b)))
    {
        return Err(IoError::at(
            path,
            *line,
            format!("({a}, {b}) is not an edge of the mesh"),
        ));
    }
    for ([a, b], _) in edges {
        mesh.set_feature_edge(*a, *b, Some(0));
    }
    tag_corners(mesh);
    Ok(edges.len())
}
