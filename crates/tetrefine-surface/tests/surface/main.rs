//! The surface schemes' integration tests, one binary.

#[path = "../../../../tests/support/mod.rs"]
mod support;

mod shapes;

mod formats;
mod io;
mod lineage;
mod polymesh;
mod schemes;
mod sqrt3;
mod tet_boundary;
mod weighted;
