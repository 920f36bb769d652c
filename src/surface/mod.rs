//! Secondary module: polygon-mesh subdivision schemes of the seed papers and
//! the √3 stencils shared with the tetrahedral step.

pub mod io;
pub mod obj;
pub mod off;
pub mod ply;
pub mod polymesh;
pub mod vtk_legacy;
pub mod vtp;

pub use io::{load_surface, read_surface, write_surface, SurfaceFile, SurfaceFormat};
pub use polymesh::{Component, HalfEdges, PolyMesh, TopologyError, NO_TWIN};
pub mod sqrt3;
