//! Secondary module: polygon-mesh subdivision schemes of the seed papers and
//! the √3 stencils shared with the tetrahedral step.

pub mod polymesh;
pub mod sqrt3;

pub use polymesh::PolyMesh;
