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
//! The crate root re-exports what a library user needs: reading and writing
//! meshes ([`load_mesh`], [`read_mesh`], [`write_mesh`]), the store
//! ([`TetMesh`]: read access and checked operations; the primitives that
//! could break its invariants are crate-private), refinement ([`refine`],
//! [`refine_with`] with a per-step callback, [`RefineOptions`],
//! [`StepReport`]), marking ([`MarkStrategy`], [`select`]), improvement
//! ([`improve`]) and statistics ([`MeshStats`], [`format_table`]). TetGen is
//! behind the `tetgen` feature.
//!
//! ```
//! use std::path::Path;
//! use tetrefine::{format_table, load_mesh, MeshStats};
//!
//! let (mesh, _report) = load_mesh(Path::new("meshes/tripod.mesh"))?;
//! mesh.check()?; // adjacency, exact orientation, manifold boundary, tags
//! let stats = MeshStats::compute(&mesh);
//! assert_eq!(stats.tets, 2799);
//! println!(
//!     "{} tets, worst minimum dihedral angle {:.2}°",
//!     stats.tets, stats.min_dihedral_deg.worst
//! );
//! print!("{}", format_table(&[("tripod", &stats)]));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod file;
pub mod geom;
pub mod improve;
pub mod io;
pub mod mesh;
pub mod ops;
pub mod polyline;
pub mod refine;
pub mod report;
pub mod rng;
pub mod stencil;
#[cfg(feature = "tetgen")]
pub mod tetgen;
pub mod topo;

pub use file::IoError;
pub use improve::{improve, ImproveOptions, ImproveReport};
pub use io::{load_mesh, read_mesh, write_mesh};
pub use mesh::{BuildReport, CheckError, MeshData, MeshError, Remap, TetMesh, Where};
pub use ops::{split_edge, OpError};
pub use refine::marking::{select, MarkStrategy};
pub use refine::size::{
    is_positive_definite, size_pass, worst_quality, SizeMap, SizeOptions, SizeReport, SPLIT_ABOVE,
};
pub use refine::{
    copy_cell_field, interpolate_point_field, locate_parents, locate_points, refine, refine_step,
    refine_with, NoProgress, Phase, PhaseReport, PointParent, Progress, RefineOptions, StepReport,
};
pub use report::{format_table, write_histogram, MeshStats};
pub use stencil::Sqrt3Rule;

/// The README's Rust examples, compiled and run as doctests so that they stay
/// true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
