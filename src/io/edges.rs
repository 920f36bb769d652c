//! Plain edge lists (`v0 v1` per line, 0-based; `#` comments): the feature
//! edges of `refine --features FILE`.

use super::{IoError, Tokens};
use crate::mesh::TetMesh;
use crate::refine::features::tag_edge_list;
use std::path::Path;

/// Reads a plain edge list and tags those edges; an edge that is not an
/// edge of the mesh is an error.
pub fn read_edge_list(mesh: &mut TetMesh, path: &Path) -> Result<usize, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::file(path, e.to_string()))?;
    let text = std::str::from_utf8(&bytes).map_err(|_| IoError::file(path, "not a text file"))?;
    let mut tok = Tokens::new(path, text, true);
    let n = mesh.n_points();
    let mut edges = Vec::new();
    while tok.peek().is_some() {
        let a: i64 = tok.parse("a vertex index")?;
        let line = tok.line();
        let b: i64 = tok.parse("a second vertex index")?;
        for x in [a, b] {
            if x < 0 || x as usize >= n {
                return Err(IoError::at(
                    path,
                    line,
                    format!("vertex {x} is out of range 0..{n} (0-based)"),
                ));
            }
        }
        edges.push(([a as u32, b as u32], line));
    }
    tag_edge_list(mesh, path, &edges)
}
