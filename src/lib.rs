//! # tetrefine
//!
//! Adaptive, feature-preserving √3-inspired refinement of tetrahedral meshes
//! for finite-element simulation.

#![warn(missing_docs)]

pub mod geom;
pub mod io;
pub mod mesh;
pub mod ops;
pub mod refine;
pub mod report;
pub mod smooth;
pub mod surface;
#[cfg(feature = "tetgen")]
pub mod tetgen;

pub use mesh::{MeshData, TetMesh};
pub use report::MeshStats;
