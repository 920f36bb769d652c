//! Mesh file formats, one file each. The format is chosen by file extension
//! (and, for the ambiguous `.msh`, by the first keyword: Gmsh's `$MeshFormat`
//! or GiD's `MESH`).
//!
//! Readers return [`MeshData`]; writers take a [`TetMesh`]. Every error names
//! the file and, where there is one, the line. Writers go through
//! [`write_atomic`], so a failed write never leaves a partial file behind.

pub mod gid;
pub mod gmsh;
pub mod indicator;
pub mod medit;
pub mod off;
pub mod plc;
pub mod poly;
pub mod stl;
pub mod tetgen;
mod text;
pub mod vtk;

pub use text::Tokens;

pub(crate) use crate::file::{open_message, read_bytes};
/// The file helpers (errors, whole-file reads, atomic writes) live below
/// every area, in [`crate::file`], so that report and the surface schemes
/// share them without going through `io`.
pub use crate::file::{write_atomic, IoError};

use crate::mesh::{MeshData, TetMesh};
use std::fs::File;
use std::path::Path;

/// The mesh formats this crate reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Medit / MMG `.mesh` (ASCII).
    Medit,
    /// Gmsh `.msh`, 2.2 or 4.1, ASCII or binary (writes 4.1 ASCII).
    Gmsh,
    /// GiD `.msh` (reads only).
    Gid,
    /// VTK XML unstructured grid `.vtu`.
    Vtu,
    /// TetGen `.node` / `.ele` / `.face` / `.edge`.
    Tetgen,
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

impl Format {
    /// The format of a file to read, from its extension (and content for `.msh`).
    pub fn for_reading(path: &Path) -> Result<Format, IoError> {
        match extension(path).as_str() {
            "mesh" => Ok(Format::Medit),
            "vtu" => Ok(Format::Vtu),
            "node" | "ele" | "face" | "edge" => Ok(Format::Tetgen),
            "msh" => {
                let mut head = Vec::with_capacity(4096);
                {
                    use std::io::Read;
                    let f = File::open(path).map_err(|e| IoError::file(path, open_message(&e)))?;
                    f.take(4096)
                        .read_to_end(&mut head)
                        .map_err(|e| IoError::file(path, e.to_string()))?;
                }
                // The first word outside GiD's `#` comment lines.
                let text = String::from_utf8_lossy(&head);
                let first = text
                    .lines()
                    .map(|l| l.split('#').next().unwrap_or(""))
                    .flat_map(str::split_whitespace)
                    .next()
                    .unwrap_or("");
                if first.eq_ignore_ascii_case("MESH") {
                    Ok(Format::Gid)
                } else {
                    Ok(Format::Gmsh)
                }
            }
            "" => Err(IoError::file(
                path,
                "has no extension; use .mesh, .msh, .vtu, .node or .ele",
            )),
            other => Err(IoError::file(
                path,
                format!("unknown mesh extension '.{other}'; use .mesh, .msh, .vtu, .node or .ele"),
            )),
        }
    }

    /// The format of a file to write, from its extension.
    pub fn for_writing(path: &Path) -> Result<Format, IoError> {
        match extension(path).as_str() {
            "mesh" => Ok(Format::Medit),
            "vtu" => Ok(Format::Vtu),
            "msh" => Ok(Format::Gmsh),
            "node" | "ele" => Ok(Format::Tetgen),
            other => Err(IoError::file(
                path,
                format!("cannot write '.{other}'; use .mesh, .msh (Gmsh 4.1), .vtu or .node/.ele (TetGen)"),
            )),
        }
    }
}

/// Reads a mesh, choosing the format by extension.
pub fn read_mesh(path: &Path) -> Result<MeshData, IoError> {
    match Format::for_reading(path)? {
        Format::Medit => medit::read(path),
        Format::Gmsh => gmsh::read(path),
        Format::Gid => gid::read(path),
        Format::Vtu => vtk::read(path),
        Format::Tetgen => tetgen::read(path),
    }
}

/// Reads a mesh and builds the store; build errors name the file and line.
pub fn load_mesh(path: &Path) -> Result<(TetMesh, crate::mesh::BuildReport), IoError> {
    let data = read_mesh(path)?;
    TetMesh::from_data(&data).map_err(|e| IoError {
        path: path.to_path_buf(),
        line: e.line().map(|l| l as usize),
        message: e.to_string(),
    })
}

/// Writes `mesh` in the format given by the extension of `path`.
pub fn write_mesh(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    match Format::for_writing(path)? {
        Format::Medit => medit::write(path, mesh),
        Format::Gmsh => gmsh::write(path, mesh),
        Format::Vtu => vtk::write_vtu(path, mesh, &[]),
        Format::Tetgen => tetgen::write(path, mesh),
        Format::Gid => Err(IoError::file(path, "writing GiD is not supported")),
    }
}

/// Drops the points that no tet, marked triangle, tagged edge or vertex tag
/// uses and renumbers the rest densely, in their old order (for files that
/// carry the mid-side nodes of quadratic elements).
pub(crate) fn drop_unused_points(d: &mut MeshData) {
    let mut used = vec![false; d.points.len()];
    let mark = |used: &mut Vec<bool>, v: u32| {
        if let Some(u) = used.get_mut(v as usize) {
            *u = true;
        }
    };
    for t in &d.tets {
        t.iter().for_each(|&v| mark(&mut used, v));
    }
    for (f, _) in &d.triangles {
        f.iter().for_each(|&v| mark(&mut used, v));
    }
    for (e, _) in &d.edges {
        e.iter().for_each(|&v| mark(&mut used, v));
    }
    for &v in d.corners.iter().chain(&d.required_vertices) {
        mark(&mut used, v);
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut new_id = vec![u32::MAX; d.points.len()];
    let mut points = Vec::with_capacity(used.iter().filter(|&&u| u).count());
    for (i, p) in d.points.iter().enumerate() {
        if used[i] {
            new_id[i] = points.len() as u32;
            points.push(*p);
        }
    }
    let map = |v: &mut u32| {
        if let Some(&n) = new_id.get(*v as usize) {
            *v = n;
        }
    };
    d.tets.iter_mut().for_each(|t| t.iter_mut().for_each(map));
    d.triangles
        .iter_mut()
        .for_each(|(f, _)| f.iter_mut().for_each(map));
    d.edges
        .iter_mut()
        .for_each(|(e, _)| e.iter_mut().for_each(map));
    d.corners.iter_mut().for_each(map);
    d.required_vertices.iter_mut().for_each(map);
    d.points = points;
}
