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

use std::path::Path;
use std::process::{Command, Output};

/// The `tetrefine` binary, run from the repository root so that the tests'
/// relative paths (`meshes/…`) name the repository's files.
pub fn tetrefine_command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tetrefine"));
    c.current_dir(support::root());
    c
}

/// Runs `tetrefine ARGS` from the repository root.
pub fn run(args: &[&str]) -> Output {
    tetrefine_command().args(args).output().unwrap()
}

/// [`run`], asserting success (the message carries stderr).
pub fn run_ok(args: &[&str]) -> Output {
    let o = run(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// The names of the files in `dir`, sorted: what a command left behind.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
