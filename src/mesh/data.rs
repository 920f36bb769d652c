//! [`MeshData`]: the plain, index-based form in which readers hand a mesh over
//! and writers take it back. It knows nothing of adjacency; building a
//! [`TetMesh`](super::TetMesh) from it validates everything.

/// A tetrahedral mesh as it stands in a file: points, tets and tags.
///
/// Indices are 0-based into `points`. Tags follow the Medit/Gmsh model:
/// a region id per tet, a marker per listed triangle (boundary or interface
/// faces), marked feature edges and corner vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex coordinates.
    pub points: Vec<[f64; 3]>,
    /// Tetrahedra as four vertex indices (any orientation; building fixes it).
    pub tets: Vec<[u32; 4]>,
    /// Region (material, physical volume, element attribute) per tet; empty
    /// means every tet is in region 0.
    pub tet_regions: Vec<i32>,
    /// Marked triangles: boundary faces or region interfaces with their marker
    /// (Medit triangle ref, Gmsh physical surface, TetGen face marker).
    pub triangles: Vec<([u32; 3], i32)>,
    /// Feature (ridge, crease) edges with their marker.
    pub edges: Vec<([u32; 2], i32)>,
    /// Corner vertices (Medit `Corners`).
    pub corners: Vec<u32>,
    /// Required vertices (Medit `RequiredVertices`): never moved.
    pub required_vertices: Vec<u32>,
    /// For text formats: the 1-based file line of each tet, so that errors found
    /// while building can name it. Empty when unknown.
    pub tet_lines: Vec<u32>,
}

impl MeshData {
    /// Region of tet `t` (0 when the file had none).
    pub fn region(&self, t: usize) -> i32 {
        self.tet_regions.get(t).copied().unwrap_or(0)
    }
}
