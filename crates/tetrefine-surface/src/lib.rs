//! Polygon-mesh subdivision schemes of the √3 paper's companions, beside the
//! tetrahedral core `tetrefine`, whose √3 stencils ([`tetrefine::stencil`])
//! the [`sqrt3`] scheme reuses.
//!
//! * [`polymesh`]: the indexed polygon mesh, its half-edge adjacency,
//!   validation, components, Euler characteristic and genus;
//! * [`io`] and one module per format ([`obj`], [`off`], [`ply`], [`stl`],
//!   [`vtp`], [`vtk_legacy`]);
//! * [`lineage`]: per-face generation, origin face and group, followed
//!   through the steps, and the observer that sees every generation;
//! * schemes: [`sqrt3`] (Kobbelt; Labsik–Greiner), [`loop_scheme`] (Loop),
//!   [`catmull_clark`], [`doo_sabin`], [`catmull_clark_weighted`]
//!   (Hansmeyer's weighted and extruded Catmull–Clark), all with tagged
//!   creases and corners through [`features`];
//! * the other constructions of the √3 paper's companions: [`mod@sierpinski`] (Sierpinski
//!   polyhedra), [`mod@truncate`] (Chaikin vertex truncation) and [`ifs`]
//!   (subdivision as iterated function systems).

pub mod catmull_clark;
pub mod catmull_clark_weighted;
pub mod doo_sabin;
pub mod features;
pub mod io;
pub mod lineage;
pub mod loop_scheme;
pub mod obj;
pub mod off;
pub mod ply;
pub mod polymesh;
pub mod sqrt3;
pub mod stl;
pub mod vtk_legacy;
pub mod vtp;

mod closed_manifold;
pub mod error;
pub mod ifs;
pub mod sierpinski;
#[cfg(test)]
mod test_shapes;
pub mod truncate;

pub use error::SurfaceError;
pub use features::{Features, SubdivisionError};
pub use ifs::{ifs_attractor, Ifs, IfsKind};
pub use io::{
    load_surface, read_surface, write_surface, write_surface_with, Encoding, SurfaceFile,
    SurfaceFormat, WriteOptions,
};
pub use lineage::{FaceAttributes, StepObserver, Subdivided};
pub use polymesh::{Component, HalfEdges, PolyMesh, TopologyError, NO_TWIN};
pub use sierpinski::sierpinski;
pub use truncate::truncate;
