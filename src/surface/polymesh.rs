//! [`PolyMesh`]: an indexed polygon mesh with faces of any size.

use glam::DVec3;

/// An indexed polygon mesh: points and faces as counter-clockwise (outward)
/// vertex loops.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    /// Vertex coordinates.
    pub points: Vec<DVec3>,
    /// Faces as vertex loops (at least three ids each).
    pub faces: Vec<Vec<u32>>,
}
