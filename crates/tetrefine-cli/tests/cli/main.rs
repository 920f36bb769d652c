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

/// Standard error of a run, as text (invalid UTF-8 replaced).
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `tetrefine refine INPUT -o OUT EXTRA…` from the repository root,
/// asserting success (the message carries stderr).
pub fn refine_ok(input: &str, out: &Path, extra: &[&str]) -> Output {
    let out = out.to_str().expect("a UTF-8 output path");
    let mut args = vec!["refine", input, "-o", out];
    args.extend_from_slice(extra);
    run_ok(&args)
}

/// The mesh a command wrote to `path`, loaded and checked (conforming,
/// positive, adjacency mutual).
pub fn load_checked(path: &Path) -> tetrefine::TetMesh {
    let (m, _) =
        tetrefine::io::load_mesh(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    m.check()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    m
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

pub use support::write_sol;
