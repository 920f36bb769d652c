//! Mesh file formats, one file each. The format is chosen by file extension
//! (and, for the ambiguous `.msh`, by the first keyword: Gmsh's `$MeshFormat`
//! or GiD's `MESH`).
//!
//! Readers return [`MeshData`]; writers take a [`TetMesh`]. Every error names
//! the file and, where there is one, the line. Writers go through
//! [`write_atomic`], so a failed write never leaves a partial file behind.

pub(crate) mod edges;
pub(crate) mod fields;
pub(crate) mod gid;
pub(crate) mod gmsh;
pub(crate) mod indicator;
pub(crate) mod medit;
pub(crate) mod meshb;
pub(crate) mod meta;
pub(crate) mod off;
pub(crate) mod plc;
pub(crate) mod poly;
pub(crate) mod stl;
pub(crate) mod tetgen;
mod text;
pub(crate) mod vtk;

pub use text::Tokens;

pub use edges::read_edge_list;
pub use fields::{
    add_sol_fields, fields_beside, read_size_sol, write_fields_beside, write_point_fields, SizeSol,
};
pub use gmsh::MshFormat;
pub use indicator::{read_indicator, IndicatorSource};
pub use meshb::{read_sol, write_sol, SolAt, SolFile, Solution};
pub use meta::{Field, MeshMeta};
pub use off::{read_off, OffFile};
pub use plc::{Facet, Plc, PlcError, PlcVolume, Region, SeedLines};
/// The pieces of a VTK XML PolyData (`.vtp`) file, for writers of other
/// polygonal data (the surface schemes' meshes) that share the layout of
/// the feature-line files.
pub mod vtp {
    pub use crate::polyline::{write_cells, write_footer, write_header, write_points};
}
pub use vtk::{
    read_noted as read_vtu_noted, read_pvtu_pieces, read_tet_cell_array, write_pvtu, write_vtu,
    write_vtu_with, CellArray, PointArray, TetCellArray, VtuSummary, DERIVED_CELL_ARRAYS,
    DERIVED_POINT_ARRAYS,
};

pub(crate) use crate::file::open_message;
// The file helpers (errors, whole-file reads, atomic writes and output
// sets) live below every area, in `crate::file`, so that report and the
// surface schemes share them without going through `io`.
pub use crate::file::{
    install_signal_cleanup, remove_stale_temporaries, temporary_path, write_atomic, IoError,
    IoErrorKind, OutputSet, TEMP_MARKER,
};
pub use crate::file::{read_bytes, read_text};

use crate::mesh::{MeshData, TetMesh};
use std::fs::File;
use std::path::Path;

/// The mesh formats this crate reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Medit / MMG `.mesh` (ASCII).
    Medit,
    /// Medit / MMG binary `.meshb` (libMeshb versions 1–4; writes version 2).
    Meshb,
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
            "meshb" => Ok(Format::Meshb),
            "vtu" => Ok(Format::Vtu),
            "node" | "ele" | "face" | "edge" => Ok(Format::Tetgen),
            "msh" => {
                let mut head = Vec::with_capacity(4096);
                {
                    use std::io::Read;
                    let f = File::open(path).map_err(|e| IoError::os(path, None, e))?;
                    f.take(4096)
                        .read_to_end(&mut head)
                        .map_err(|e| IoError::os(path, None, e))?;
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
                "has no extension; use .mesh, .meshb, .msh, .vtu, .node or .ele",
            )),
            other => Err(IoError::file(
                path,
                format!("unknown mesh extension '.{other}'; use .mesh, .meshb, .msh, .vtu, .node or .ele"),
            )),
        }
    }

    /// The format of a file to write, from its extension.
    pub fn for_writing(path: &Path) -> Result<Format, IoError> {
        match extension(path).as_str() {
            "mesh" => Ok(Format::Medit),
            "meshb" => Ok(Format::Meshb),
            "vtu" => Ok(Format::Vtu),
            "msh" => Ok(Format::Gmsh),
            "node" | "ele" => Ok(Format::Tetgen),
            other => Err(IoError::file(
                path,
                format!("cannot write '.{other}'; use .mesh, .meshb, .msh (Gmsh), .vtu or .node/.ele (TetGen)"),
            )),
        }
    }
}

/// Reads a mesh, choosing the format by extension.
///
/// A file that is not a regular file (a named pipe, `/dev/stdin`) is read
/// once into a private temporary copy, which the reader then reads (and
/// sniffs, for `.msh`); errors still name `path`.
pub fn read_mesh(path: &Path) -> Result<MeshData, IoError> {
    read_mesh_noted(path).map(|(d, _)| d)
}

/// [`read_mesh`], and the reader's notes on what it dropped (cells of a
/// mixed-cell `.vtu` other than tetrahedra and triangles, say), one
/// sentence each.
pub fn read_mesh_noted(path: &Path) -> Result<(MeshData, Vec<String>), IoError> {
    read_once(path, read_mesh_file)
}

/// Runs `read` on the mesh file `path`; a stream is first copied once (see
/// [`spooled`]), before anything reads it: telling a Gmsh `.msh` from a GiD
/// one reads its first keyword.
fn read_once<T>(path: &Path, read: impl FnOnce(&Path) -> Result<T, IoError>) -> Result<T, IoError> {
    let meta = std::fs::metadata(path).map_err(|e| IoError::os(path, None, e))?;
    if meta.is_dir() {
        return Err(IoError::file(path, "is a directory, not a mesh file"));
    }
    if !meta.is_file() {
        return spooled(path, read);
    }
    read(path)
}

/// Copies the stream `path` once into a temporary regular file with the
/// same extension, runs `read` on it and names `path` in its errors.
pub(crate) fn spooled<T>(
    path: &Path,
    read: impl FnOnce(&Path) -> Result<T, IoError>,
) -> Result<T, IoError> {
    let bytes = read_bytes(path)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = std::env::temp_dir();
    let copy = dir.join(format!(
        "tetrefine-input{TEMP_MARKER}{}-{}.{ext}",
        std::process::id(),
        SPOOL.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    std::fs::write(&copy, &bytes)
        .map_err(|e| IoError::os(&copy, Some("cannot copy a piped input"), e))?;
    let r = read(&copy);
    let _ = std::fs::remove_file(&copy);
    r.map_err(|mut e| {
        if e.path == copy {
            e.path = path.to_path_buf();
        }
        e
    })
}

static SPOOL: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn read_mesh_file(path: &Path) -> Result<(MeshData, Vec<String>), IoError> {
    let plain = |d: MeshData| (d, Vec::new());
    match Format::for_reading(path)? {
        Format::Medit => medit::read(path).map(plain),
        Format::Meshb => meshb::read(path).map(plain),
        Format::Gmsh => gmsh::read(path).map(plain),
        Format::Gid => gid::read(path).map(plain),
        Format::Vtu => vtk::read_noted(path).map(|(d, n)| (d, n.into_iter().collect())),
        Format::Tetgen => tetgen::read(path).map(plain),
    }
}

/// Reads a mesh and builds the store; build errors name the file and line.
pub fn load_mesh(path: &Path) -> Result<(TetMesh, crate::mesh::BuildReport), IoError> {
    load_mesh_noted(path).map(|(m, r, _)| (m, r))
}

/// [`load_mesh`], and the reader's notes (see [`read_mesh_noted`]).
pub fn load_mesh_noted(
    path: &Path,
) -> Result<(TetMesh, crate::mesh::BuildReport, Vec<String>), IoError> {
    let (data, notes) = read_mesh_noted(path)?;
    let (mesh, report) = TetMesh::from_data(&data)
        .map_err(|e| IoError::content(path, e.line().map(|l| l as usize), e))?;
    Ok((mesh, report, notes))
}

/// Reads a mesh with its side table ([`meta::MeshMeta`]: Gmsh physical names
/// and tag lists, point and cell arrays); formats without one give an empty
/// table.
pub fn read_mesh_with_meta(path: &Path) -> Result<(MeshData, meta::MeshMeta), IoError> {
    read_mesh_with_meta_noted(path).map(|(d, m, _)| (d, m))
}

/// [`read_mesh_with_meta`], and the reader's notes (see [`read_mesh_noted`]).
pub fn read_mesh_with_meta_noted(
    path: &Path,
) -> Result<(MeshData, meta::MeshMeta, Vec<String>), IoError> {
    read_once(path, read_mesh_file_with_meta)
}

fn read_mesh_file_with_meta(
    path: &Path,
) -> Result<(MeshData, meta::MeshMeta, Vec<String>), IoError> {
    match Format::for_reading(path)? {
        Format::Gmsh => {
            let (d, m) = gmsh::read_with_meta(path)?;
            return Ok((d, m, Vec::new()));
        }
        Format::Vtu => {
            let (d, m, n) = vtk::read_with_meta_noted(path)?;
            return Ok((d, m, n.into_iter().collect()));
        }
        _ => {}
    }
    let (d, notes) = read_mesh_file(path)?;
    Ok((d, meta::MeshMeta::default(), notes))
}

/// [`load_mesh`] with the side table of [`read_mesh_with_meta`].
pub fn load_mesh_with_meta(
    path: &Path,
) -> Result<(TetMesh, crate::mesh::BuildReport, meta::MeshMeta), IoError> {
    load_mesh_with_meta_noted(path).map(|(m, r, t, _)| (m, r, t))
}

/// [`load_mesh_with_meta`], and the reader's notes (see [`read_mesh_noted`]).
pub fn load_mesh_with_meta_noted(
    path: &Path,
) -> Result<
    (
        TetMesh,
        crate::mesh::BuildReport,
        meta::MeshMeta,
        Vec<String>,
    ),
    IoError,
> {
    let (data, meta, notes) = read_mesh_with_meta_noted(path)?;
    let (mesh, report) = TetMesh::from_data(&data)
        .map_err(|e| IoError::content(path, e.line().map(|l| l as usize), e))?;
    Ok((mesh, report, meta, notes))
}

/// How [`write_mesh_with`] writes what the extension leaves open.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// The MSH variant of a `.msh` output.
    pub msh_format: gmsh::MshFormat,
}

/// [`write_mesh`] with a side table: Gmsh output gets its physical names,
/// tag lists and fields (`$NodeData`, `$ElementData`) back.
pub fn write_mesh_with(
    path: &Path,
    mesh: &TetMesh,
    meta: &meta::MeshMeta,
    options: &WriteOptions,
) -> Result<(), IoError> {
    match Format::for_writing(path)? {
        Format::Gmsh => gmsh::write_with(path, mesh, meta, options.msh_format),
        _ => write_mesh(path, mesh),
    }
}

/// Writes `mesh` in the format given by the extension of `path`.
pub fn write_mesh(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    match Format::for_writing(path)? {
        Format::Medit => medit::write(path, mesh),
        Format::Meshb => meshb::write(path, mesh, 2),
        Format::Gmsh => gmsh::write(path, mesh),
        Format::Vtu => vtk::write_vtu(path, mesh, None, &[]),
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
