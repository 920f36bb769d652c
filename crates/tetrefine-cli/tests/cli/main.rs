//! The `tetrefine` command line end to end, one binary.

#[path = "../../../../tests/support/mod.rs"]
mod support;

#[path = "../../../tetrefine-surface/tests/surface/shapes.rs"]
mod shapes;

mod adaptive;
mod bad_input;
mod bisect;
mod determinism;
mod gmsh_tags;
mod medit_meshb;
mod mesh_without_tetgen;
mod quality;
mod readme_commands;
mod refine;
mod size_map;
mod strict;
mod surface;
mod transfer;

use std::process::Command;

/// The `tetrefine` binary, run from the repository root so that the tests'
/// relative paths (`meshes/…`) name the repository's files.
pub fn tetrefine_command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tetrefine"));
    c.current_dir(support::root());
    c
}
