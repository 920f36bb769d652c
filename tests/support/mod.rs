//! Test support shared by every test binary of the workspace (each includes
//! it with `#[path]`): where the repository's files are, one seeded random
//! generator, a hand-built tet grid, and a numbering-free form of a mesh.

// Each test binary uses its own part of the support.
#![allow(dead_code, unused_imports)]

mod canon;
mod grid;

pub use canon::*;
pub use grid::*;

use std::path::{Path, PathBuf};

/// The repository's root (the folder holding `meshes/`), whichever crate of
/// the workspace the test belongs to.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .find(|d| d.join("meshes").is_dir())
        .expect("every crate of the workspace sits below the repository root, which holds meshes/")
}

/// A file of the repository, given relative to its root (`meshes/…`, `tests/…`).
pub fn path(rel: &str) -> PathBuf {
    root().join(rel)
}

/// A Medit ASCII solution, written by hand: `kw` with `rows` of values.
pub fn write_sol(path: &Path, kw: &str, types: &[u8], rows: &[Vec<f64>]) {
    let mut s = format!(
        "MeshVersionFormatted 2\n\nDimension 3\n\n{kw}\n{}\n{}",
        rows.len(),
        types.len()
    );
    for t in types {
        s += &format!(" {t}");
    }
    s += "\n";
    for r in rows {
        let line: Vec<String> = r.iter().map(|x| format!("{x:?}")).collect();
        s += &line.join(" ");
        s += "\n";
    }
    s += "\nEnd\n";
    std::fs::write(path, s).unwrap();
}
