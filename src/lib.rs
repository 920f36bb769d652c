//! # tetrefine
//!
//! Adaptive, feature-preserving √3-inspired refinement of tetrahedral meshes
//! for finite-element simulation (Burkhart, Hamann and Umlauf, "Adaptive and
//! feature-preserving subdivision for high-quality tetrahedral meshes").
//!
//! Meshes are read into plain [`MeshData`] by [`io`], built into the indexed
//! store [`TetMesh`] (adjacency, exact orientation, tag side tables), and
//! judged by [`MeshStats`] — the figures of Table 1 of the paper.
//!
//! ```
//! use std::path::Path;
//! use tetrefine::io::load_mesh;
//! use tetrefine::MeshStats;
//!
//! let (mesh, _report) = load_mesh(Path::new("meshes/tripod.mesh"))?;
//! mesh.check()?; // adjacency, exact orientation, manifold boundary, tags
//! let stats = MeshStats::compute(&mesh);
//! assert_eq!(stats.tets, 2799);
//! println!(
//!     "{} tets, worst minimum dihedral angle {:.2}°",
//!     stats.tets, stats.min_dihedral_deg.worst
//! );
//! print!("{}", tetrefine::report::format_table(&[("tripod", &stats)]));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

pub mod file;
pub mod geom;
pub mod improve;
pub mod io;
pub mod mesh;
pub mod ops;
pub mod refine;
pub mod report;
pub mod stencil;
#[cfg(feature = "tetgen")]
pub mod tetgen;
pub mod topo;

pub use mesh::{MeshData, TetMesh};
pub use report::MeshStats;

/// The README's Rust examples, compiled and run as doctests so that they stay
/// true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
