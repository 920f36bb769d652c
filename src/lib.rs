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
//! could break its invariants are crate-private), refinement ([`refine`](fn@refine),
//! [`refine_with`] with a per-step callback, [`RefineOptions`],
//! [`StepReport`]), marking ([`MarkStrategy`], [`select`]), improvement
//! ([`improve`](fn@improve)) and statistics ([`MeshStats`], [`format_table`]). TetGen is
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

// Private areas, in dependency order (each uses only those above it):
// local tables → seeded RNG → file helpers → geometry → mesh store →
// local operations → improvement → √3 stencils → refinement → report; io,
// polylines and TetGen are leaves. What a user needs is re-exported below
// or through the public facade modules (`geom`, `io`, `ops`, `report`,
// `stencil`, `topo`, `tetgen`), whose own submodules stay private.
#[cfg(feature = "mpi")]
pub mod distributed;
mod file;
pub mod geom;
mod improve;
pub mod io;
mod mesh;
pub mod ops;
mod polyline;
mod refine;
pub mod report;
mod rng;
pub mod stencil;
#[cfg(feature = "tetgen")]
pub mod tetgen;
pub mod topo;

pub use file::IoError;
pub use improve::{
    improve, BoundarySmoothOptions, Effort, ImproveOptions, ImproveReport, DEFAULT_THRESHOLD,
};
pub use io::{load_mesh, read_mesh, write_mesh};
pub use mesh::generate::cube_grid;
pub use mesh::partition::{
    canonical_centroid, is_partition_marker, partition_marker, PartitionMarker,
};
pub use mesh::{
    ball_stays_positive, BuildReport, CheckError, MeshData, MeshError, Remap, TetMesh, Where, DEAD,
    NO_ADJ,
};
pub use ops::{split_edge, OpError};
pub use polyline::{
    write_feature_lines, write_points_csv, write_points_vtp, write_polylines, write_polylines_csv,
    write_polylines_vtp, PolylineFormat,
};
pub use refine::bisect::{bisect, bisect_steps, BisectError};
pub use refine::features::{detect_features, detect_features_for};
pub use refine::marking::{doerfler_count, fraction_count, ranking, select, MarkStrategy};
pub use refine::parents::{contains, walk_to};
pub use refine::size::{
    is_positive_definite, size_improve_options, size_pass, worst_quality, SizeMap, SizeOptions,
    SizeReport, AUTO_SIZE_PASSES, SPLIT_ABOVE,
};
pub use refine::{
    copy_cell_field, interpolate_point_field, locate_parents, locate_points, refine, refine_step,
    refine_step_with_progress, refine_with, refine_with_guard, InterfaceRule, NoProgress, Phase,
    PhaseReport, PointParent, Progress, RefineOptions, StepReport,
};
pub use report::{format_table, write_histogram, MeshStats};
pub use rng::SplitMix64;
pub use stencil::Sqrt3Rule;

/// The README's Rust examples, compiled and run as doctests so that they stay
/// true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
