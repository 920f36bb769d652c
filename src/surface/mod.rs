//! Secondary module: polygon-mesh subdivision schemes of the seed papers and
//! the √3 stencils shared with the tetrahedral step.

pub mod polymesh;

mod closed_manifold;
pub mod error;
pub mod ifs;
pub mod sierpinski;
#[cfg(test)]
mod test_shapes;
pub mod truncate;

pub use error::SurfaceError;
pub use ifs::{ifs_attractor, Ifs, IfsKind};
pub use polymesh::PolyMesh;
pub use sierpinski::sierpinski;
pub use truncate::truncate;
