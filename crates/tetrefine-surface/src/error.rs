//! [`SurfaceError`]: why a surface scheme refused its input.

use super::polymesh::TopologyError;
use thiserror::Error;

/// Why a surface scheme (Sierpinski, truncation, IFS) refused its input.
///
/// Every message is one line and names the offending face, edge or vertex by
/// its 0-based id in the input.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SurfaceError {
    /// A face has fewer than three vertices.
    #[error("face {face} has {len} vertices; a face needs at least 3")]
    FaceTooSmall {
        /// The face.
        face: usize,
        /// Its number of vertices.
        len: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but the mesh has {count} vertices")]
    VertexOutOfRange {
        /// The face.
        face: usize,
        /// The bad vertex id.
        vertex: u32,
        /// Number of vertices in the mesh.
        count: usize,
    },
    /// A face visits the same vertex twice.
    #[error("face {face} visits vertex {vertex} twice")]
    RepeatedVertex {
        /// The face.
        face: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A vertex has a coordinate that is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// Two faces use the same directed edge: they are not consistently
    /// oriented.
    #[error(
        "edge {from}->{to} is used in the same direction by faces {first} and {second}: \
         the faces are not consistently oriented"
    )]
    EdgeOrientation {
        /// Start vertex of the edge.
        from: u32,
        /// End vertex of the edge.
        to: u32,
        /// The first face using it.
        first: usize,
        /// The second face using it.
        second: usize,
    },
    /// An edge is shared by more than two faces.
    #[error("edge {}-{} is shared by {faces} faces (a manifold edge has at most 2)", edge[0], edge[1])]
    NonManifoldEdge {
        /// The edge (sorted vertex ids).
        edge: [u32; 2],
        /// How many face sides use it.
        faces: usize,
    },
    /// An edge lies in one face only: the surface has a boundary.
    #[error("edge {from}-{to} lies in face {face} only: the surface has a boundary, and this scheme needs a closed surface")]
    OpenEdge {
        /// Start vertex of the edge in its face.
        from: u32,
        /// End vertex of the edge in its face.
        to: u32,
        /// The face.
        face: usize,
    },
    /// The faces around a vertex form more than one fan (a pinched vertex).
    #[error("vertex {vertex} is non-manifold: its faces form more than one fan")]
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
    },
    /// The input has no faces.
    #[error("the mesh has no faces")]
    Empty,
    /// The requested number of steps would create more elements than 32-bit
    /// ids can count.
    #[error("{steps} steps would create about {estimate} {what}, more than this scheme supports")]
    TooLarge {
        /// The number of steps asked for.
        steps: usize,
        /// The estimated count.
        estimate: f64,
        /// What would overflow (vertices, faces, points).
        what: &'static str,
    },
    /// The input seems to hold a joint made by an earlier Sierpinski run
    /// (three quads forming a tube whose six rim vertices lie on edges that
    /// all point at one point), but removing its tubes and closing their
    /// rims does not give closed pieces, so the steps cannot go on from it.
    #[error(
        "faces {} look like the tube of a joint made by an earlier Sierpinski run (its edges meet at ({:.6}, {:.6}, {:.6})), \
         but undoing the tubes does not give closed pieces: run all the steps in one call on the original surface",
        faces.map(|f| f.to_string()).join(", "), point[0], point[1], point[2]
    )]
    SierpinskiJoint {
        /// The three quads of the first tube.
        faces: [usize; 3],
        /// Where the edges through its rims meet (the joint's position).
        point: [f64; 3],
    },
    /// A parameter is out of its range.
    #[error("{0}")]
    Parameter(String),
}

impl From<TopologyError> for SurfaceError {
    /// The same finding, in the terms of this error type.
    fn from(e: TopologyError) -> Self {
        match e {
            TopologyError::FaceTooSmall { face, len } => SurfaceError::FaceTooSmall { face, len },
            TopologyError::IndexOutOfRange {
                face,
                index,
                points,
            } => SurfaceError::VertexOutOfRange {
                face,
                vertex: index,
                count: points,
            },
            TopologyError::RepeatedVertex { face, vertex } => {
                SurfaceError::RepeatedVertex { face, vertex }
            }
            TopologyError::NonManifoldEdge { edge, faces } => {
                SurfaceError::NonManifoldEdge { edge, faces }
            }
            TopologyError::InconsistentOrientation { edge, faces } => {
                SurfaceError::EdgeOrientation {
                    from: edge[0],
                    to: edge[1],
                    first: faces[0],
                    second: faces[1],
                }
            }
            TopologyError::NonManifoldVertex { vertex, .. } => {
                SurfaceError::NonManifoldVertex { vertex }
            }
        }
    }
}
