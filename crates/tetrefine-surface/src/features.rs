//! Tagged creases and corners shared by the subdivision schemes, and the
//! error type of the schemes.
//!
//! A *curve edge* is an open-boundary edge or a tagged crease; a vertex with
//! exactly two curve edges is a *crease vertex* (it follows the curve rule of
//! its scheme), a vertex with one or more than two, or a tagged corner, is a
//! *corner* (it stays put).

use super::lineage::{observe, FaceAttributes, StepObserver, Subdivided};
use super::polymesh::{HalfEdges, PolyMesh, TopologyError, NO_TWIN};
use glam::DVec3;
use std::collections::HashSet;
use std::fmt;

/// Tagged features of an input mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Features {
    /// Crease edges as vertex pairs of the input (any order).
    pub creases: Vec<[u32; 2]>,
    /// Corner vertices of the input.
    pub corners: Vec<u32>,
    /// Also tag every edge whose two face normals differ by more than this
    /// angle (degrees).
    pub crease_angle: Option<f64>,
}

/// Why a subdivision scheme refused a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum SubdivisionError {
    /// A face that is not a triangle, for a triangle scheme.
    NotTriangles {
        /// The face.
        face: usize,
        /// Its number of vertices.
        len: usize,
    },
    /// The mesh is not an oriented manifold.
    Topology(TopologyError),
    /// A tagged crease that is not an edge of the mesh.
    NoSuchEdge([u32; 2]),
    /// A tagged vertex that is not a vertex of any face.
    NoSuchVertex(u32),
    /// A tagged face that is not a face of the mesh.
    NoSuchFace(u32),
    /// A parameter outside its domain.
    BadParameter(String),
}

impl fmt::Display for SubdivisionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SubdivisionError::NotTriangles { face, len } => write!(
                f,
                "this scheme needs a triangle mesh, but face {face} has {len} vertices"
            ),
            SubdivisionError::Topology(e) => write!(f, "{e}"),
            SubdivisionError::NoSuchEdge(e) => {
                write!(
                    f,
                    "tagged edge {}-{} is not an edge of the mesh",
                    e[0], e[1]
                )
            }
            SubdivisionError::NoSuchVertex(v) => {
                write!(f, "tagged vertex {v} is not a vertex of the mesh")
            }
            SubdivisionError::NoSuchFace(x) => {
                write!(f, "tagged face {x} is not a face of the mesh")
            }
            SubdivisionError::BadParameter(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for SubdivisionError {}

impl From<TopologyError> for SubdivisionError {
    fn from(e: TopologyError) -> Self {
        SubdivisionError::Topology(e)
    }
}

/// A vertex pair in increasing order.
#[inline]
pub fn sorted_pair(a: u32, b: u32) -> [u32; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

/// Edges whose two face normals differ by more than `angle_deg` degrees.
pub fn edges_sharper_than(mesh: &PolyMesh, he: &HalfEdges, angle_deg: f64) -> Vec<[u32; 2]> {
    let cos_max = angle_deg.to_radians().cos();
    let normals: Vec<DVec3> = (0..mesh.faces.len())
        .map(|f| mesh.face_newell(f).normalize_or_zero())
        .collect();
    let mut out = Vec::new();
    for (e, &h) in he.edge_half.iter().enumerate() {
        let t = he.twin[h as usize];
        if t == NO_TWIN {
            continue;
        }
        let (a, b) = (
            normals[he.face[h as usize] as usize],
            normals[he.face[t as usize] as usize],
        );
        if a.dot(b) < cos_max {
            out.push(he.edges[e]);
        }
    }
    out
}

impl Features {
    /// Checks the tags against the mesh and returns the crease set (sorted
    /// pairs, with the edges found by `crease_angle`) and the corner set.
    pub fn resolve(
        &self,
        mesh: &PolyMesh,
        he: &HalfEdges,
    ) -> Result<(HashSet<[u32; 2]>, HashSet<u32>), SubdivisionError> {
        let edge_set: HashSet<[u32; 2]> = he.edges.iter().copied().collect();
        let mut creases = HashSet::new();
        for &[a, b] in &self.creases {
            let e = sorted_pair(a, b);
            if !edge_set.contains(&e) {
                return Err(SubdivisionError::NoSuchEdge(e));
            }
            creases.insert(e);
        }
        if let Some(angle) = self.crease_angle {
            if !(0.0..=180.0).contains(&angle) {
                return Err(SubdivisionError::BadParameter(format!(
                    "crease angle {angle} is not between 0 and 180 degrees"
                )));
            }
            creases.extend(edges_sharper_than(mesh, he, angle));
        }
        let mut corners = HashSet::new();
        for &c in &self.corners {
            if c as usize >= mesh.points.len() || he.vertex_out[c as usize] == NO_TWIN {
                return Err(SubdivisionError::NoSuchVertex(c));
            }
            corners.insert(c);
        }
        Ok((creases, corners))
    }
}

/// Role of a vertex with respect to the curve edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// In no face.
    Unused,
    /// No curve edge.
    Smooth,
    /// Two curve edges; the curve neighbours are stored.
    Crease([u32; 2]),
    /// Tagged, or one or more than two curve edges.
    Corner,
}

/// Curve flags per undirected edge of `he` and the role of every vertex.
pub(crate) fn classify(
    he: &HalfEdges,
    creases: &HashSet<[u32; 2]>,
    corners: &HashSet<u32>,
) -> (Vec<bool>, Vec<Role>) {
    let np = he.vertex_out.len();
    let curve: Vec<bool> = (0..he.edges.len())
        .map(|e| he.is_boundary_edge(e as u32) || creases.contains(&he.edges[e]))
        .collect();
    let mut deg = vec![0u32; np];
    let mut nb = vec![[u32::MAX; 2]; np];
    for (e, &c) in curve.iter().enumerate() {
        if c {
            let [a, b] = he.edges[e];
            for (x, y) in [(a, b), (b, a)] {
                let d = deg[x as usize] as usize;
                if d < 2 {
                    nb[x as usize][d] = y;
                }
                deg[x as usize] += 1;
            }
        }
    }
    let roles = (0..np)
        .map(|v| {
            if he.vertex_out[v] == NO_TWIN {
                Role::Unused
            } else if corners.contains(&(v as u32)) {
                Role::Corner
            } else {
                match deg[v] {
                    0 => Role::Smooth,
                    2 => Role::Crease(nb[v]),
                    _ => Role::Corner,
                }
            }
        })
        .collect();
    (curve, roles)
}

/// What one step of a scheme with tagged creases makes: the refined mesh,
/// its crease set, and for every new face its parent face in the previous
/// mesh and its group (see [`super::lineage`]).
pub(crate) struct Step {
    /// The refined mesh.
    pub mesh: PolyMesh,
    /// Its crease set.
    pub creases: HashSet<[u32; 2]>,
    /// Parent face of each new face.
    pub parent: Vec<u32>,
    /// Group of each new face.
    pub group: Vec<u32>,
}

/// Runs `steps` steps of a scheme with tagged creases from `mesh`, whose
/// adjacency `he` was built when the input was validated: step `k` gets the
/// current mesh, its adjacency (`he` for the first step, rebuilt for every
/// later mesh) and its crease set, and returns the refined mesh, the
/// refined crease set and the lineage of its faces, from which the face
/// attributes (`attributes` those of the input) follow. `observer` sees
/// the input and every step's mesh, and may stop the run.
pub(crate) fn run_steps(
    mesh: &PolyMesh,
    he: HalfEdges,
    mut creases: HashSet<[u32; 2]>,
    steps: usize,
    attributes: FaceAttributes,
    mut observer: Option<&mut StepObserver<'_>>,
    mut step: impl FnMut(usize, &PolyMesh, &HalfEdges, &HashSet<[u32; 2]>) -> Step,
) -> Result<Subdivided, SubdivisionError> {
    let mut cur = mesh.clone();
    let mut attrs = attributes;
    let mut first = Some(he);
    if !observe(&mut observer, 0, &cur, &attrs) {
        return Ok(Subdivided {
            mesh: cur,
            attributes: attrs,
            steps: 0,
        });
    }
    for k in 0..steps {
        let he = match first.take() {
            Some(he) => he,
            None => cur.half_edges()?,
        };
        let s = step(k, &cur, &he, &creases);
        attrs = attrs.children(k as u32 + 1, &s.parent, &s.group);
        (cur, creases) = (s.mesh, s.creases);
        if !observe(&mut observer, k + 1, &cur, &attrs) {
            return Ok(Subdivided {
                mesh: cur,
                attributes: attrs,
                steps: k + 1,
            });
        }
    }
    Ok(Subdivided {
        mesh: cur,
        attributes: attrs,
        steps,
    })
}

/// Parents and groups of a step in which face `f` of `n` vertices becomes
/// `n` faces in a row, child `k` in group `k` (Catmull–Clark).
pub(crate) fn corner_children(mesh: &PolyMesh) -> (Vec<u32>, Vec<u32>) {
    let n: usize = mesh.faces.iter().map(Vec::len).sum();
    let mut parent = Vec::with_capacity(n);
    let mut group = Vec::with_capacity(n);
    for (f, face) in mesh.faces.iter().enumerate() {
        for k in 0..face.len() as u32 {
            parent.push(f as u32);
            group.push(k);
        }
    }
    (parent, group)
}
