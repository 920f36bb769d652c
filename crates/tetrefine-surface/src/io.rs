//! Reading and writing polygon meshes: the format follows the extension.
//!
//! | extension | read | write | module |
//! |-----------|------|-------|--------|
//! | `.obj`    | yes  | yes   | [`super::obj`] (Wavefront) |
//! | `.off`    | yes  | yes   | [`super::off`] (Geomview) |
//! | `.ply`    | yes (ASCII, binary) | yes (binary little-endian by default, or ASCII) | [`super::ply`] (Stanford) |
//! | `.stl`    | yes (ASCII, binary) | yes (binary by default, or ASCII; triangles only: faces are fanned) | [`super::stl`] |
//! | `.vtp`    | no   | yes   | [`super::vtp`] (VTK XML PolyData, for ParaView) |
//! | `.vtk`    | no   | yes   | [`super::vtk_legacy`] (legacy VTK POLYDATA, ASCII) |
//!
//! [`write_surface_with`] takes [`WriteOptions`]: the [`Encoding`] of `.stl`
//! and `.ply` (the other formats have one) and the per-face attributes of
//! [`super::lineage`], written as face properties (`.ply`) and cell data
//! (`.vtp`, `.vtk`); `.obj`, `.off` and `.stl` have no place for them.
//!
//! Readers return a [`SurfaceFile`]: the mesh plus the line of every face, so
//! that [`load_surface`], which also validates manifoldness and orientation,
//! can name the line of the offending face. Every writer goes through
//! [`tetrefine::io::write_atomic`]: a failed write leaves no partial file.

use super::lineage::FaceAttributes;
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::IoError;

/// A mesh as read from a file, with the 1-based line of each face.
#[derive(Clone, Debug, Default)]
pub struct SurfaceFile {
    /// The mesh.
    pub mesh: PolyMesh,
    /// Line of each face in the file (0 where there is none).
    pub face_lines: Vec<u32>,
}

/// Surface mesh formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceFormat {
    /// Wavefront `.obj`.
    Obj,
    /// Geomview `.off`.
    Off,
    /// Stanford `.ply` (ASCII or binary).
    Ply,
    /// Stereolithography `.stl` (ASCII or binary; triangles).
    Stl,
    /// VTK XML PolyData `.vtp` (write only).
    Vtp,
    /// Legacy VTK `.vtk` POLYDATA (write only).
    VtkLegacy,
}

impl SurfaceFormat {
    /// The format of `path` from its extension.
    pub fn of(path: &Path) -> Result<SurfaceFormat, IoError> {
        match lowercase_extension(path).as_str() {
            "obj" => Ok(SurfaceFormat::Obj),
            "off" => Ok(SurfaceFormat::Off),
            "ply" => Ok(SurfaceFormat::Ply),
            "stl" => Ok(SurfaceFormat::Stl),
            "vtp" => Ok(SurfaceFormat::Vtp),
            "vtk" => Ok(SurfaceFormat::VtkLegacy),
            "" => Err(IoError::file(
                path,
                "has no extension; use .obj, .off, .ply, .stl, .vtp or .vtk",
            )),
            other => Err(IoError::file(
                path,
                format!(
                    "unknown surface mesh extension '.{other}'; use .obj, .off, .ply, .stl, .vtp or .vtk"
                ),
            )),
        }
    }
}

/// Reads a surface mesh (index ranges and face sizes checked, topology not).
pub fn read_surface(path: &Path) -> Result<SurfaceFile, IoError> {
    match SurfaceFormat::of(path)? {
        SurfaceFormat::Obj => super::obj::read(path),
        SurfaceFormat::Off => super::off::read(path),
        SurfaceFormat::Ply => super::ply::read(path),
        SurfaceFormat::Stl => super::stl::read(path),
        SurfaceFormat::Vtp | SurfaceFormat::VtkLegacy => Err(IoError::file(
            path,
            "reading .vtp/.vtk surfaces is not supported; use .obj, .off, .ply or .stl",
        )),
    }
}

/// Reads a surface mesh and validates it as an oriented manifold (with
/// boundary); a topology error names the line of the face involved.
pub fn load_surface(path: &Path) -> Result<PolyMesh, IoError> {
    let file = read_surface(path)?;
    if file.mesh.faces.is_empty() {
        return Err(IoError::file(path, "contains no faces"));
    }
    match file.mesh.validate() {
        Ok(()) => Ok(file.mesh),
        Err(e) => {
            let line = e
                .face()
                .and_then(|f| file.face_lines.get(f).copied())
                .filter(|&l| l > 0);
            Err(match line {
                Some(l) => IoError::at(path, l as usize, e.to_string()),
                None => IoError::file(path, e.to_string()),
            })
        }
    }
}

/// How `.stl` and `.ply` files are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Binary (little-endian): smaller and exact for `.ply` (doubles);
    /// `.stl` holds `f32` coordinates.
    #[default]
    Binary,
    /// Text.
    Ascii,
}

/// Options of [`write_surface_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct WriteOptions<'a> {
    /// Binary or ASCII, for `.stl` and `.ply`.
    pub encoding: Encoding,
    /// Per-face attributes to write (`.ply`, `.vtp`, `.vtk`), one entry per
    /// face.
    pub attributes: Option<&'a FaceAttributes>,
}

/// Writes a surface mesh in the format given by the extension of `path`,
/// with the default [`WriteOptions`] (binary `.stl` and `.ply`, no
/// attributes).
pub fn write_surface(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_surface_with(path, mesh, &WriteOptions::default())
}

/// Writes a surface mesh in the format given by the extension of `path`.
/// Attributes whose length is not the number of faces are refused.
pub fn write_surface_with(
    path: &Path,
    mesh: &PolyMesh,
    options: &WriteOptions,
) -> Result<(), IoError> {
    let format = SurfaceFormat::of(path)?;
    let attributes = options.attributes;
    if let Some(a) = attributes {
        let n = mesh.faces.len();
        if a.generation.len() != n || a.origin.len() != n || a.group.len() != n {
            return Err(IoError::file(
                path,
                format!(
                    "internal: face attributes for {}/{}/{} faces, the mesh has {n}",
                    a.generation.len(),
                    a.origin.len(),
                    a.group.len()
                ),
            ));
        }
    }
    let ascii = options.encoding == Encoding::Ascii;
    match format {
        SurfaceFormat::Obj => super::obj::write(path, mesh),
        SurfaceFormat::Off => super::off::write(path, mesh),
        SurfaceFormat::Ply => super::ply::write_with(path, mesh, ascii, attributes),
        SurfaceFormat::Stl => super::stl::write(path, mesh, ascii),
        SurfaceFormat::Vtp => super::vtp::write_with(path, mesh, attributes),
        SurfaceFormat::VtkLegacy => super::vtk_legacy::write_with(path, mesh, attributes),
    }
}

/// The names of the per-face attributes in the files, in the order written.
pub const ATTRIBUTE_NAMES: [&str; 3] = ["generation", "origin", "group"];

/// The attribute vectors in the order of [`ATTRIBUTE_NAMES`].
pub(crate) fn attribute_columns(a: &FaceAttributes) -> [&[u32]; 3] {
    [&a.generation, &a.origin, &a.group]
}

/// The file as UTF-8 text, or an error naming the file (and the first bad
/// line).
pub(crate) use tetrefine::io::read_text;

/// The extension of `path` in lower case (empty when there is none).
pub(crate) fn lowercase_extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Parses a finite coordinate, with an error at `line`.
pub(crate) fn parse_coord(
    path: &Path,
    line: usize,
    tok: Option<&str>,
    what: &str,
) -> Result<f64, IoError> {
    let tok = tok.ok_or_else(|| IoError::at(path, line, format!("missing {what}")))?;
    let x: f64 = tok.parse().map_err(|_| {
        IoError::at(
            path,
            line,
            format!("expected {what}, found '{}'", short(tok)),
        )
    })?;
    if !x.is_finite() {
        return Err(IoError::at(
            path,
            line,
            format!("{what} is {x}, not a finite number"),
        ));
    }
    Ok(x)
}

/// A token shortened for messages.
pub(crate) fn short(s: &str) -> String {
    if s.chars().count() > 24 {
        format!("{}…", s.chars().take(24).collect::<String>())
    } else {
        s.to_string()
    }
}

/// Checks a face read at `line`: at least three vertices, ids in range, no
/// vertex twice. Ids are 0-based; messages add `base` (1 for 1-based files).
pub(crate) fn check_face(
    path: &Path,
    line: usize,
    face: &[u32],
    points: usize,
    base: u32,
) -> Result<(), IoError> {
    if face.len() < 3 {
        return Err(IoError::at(
            path,
            line,
            format!("face has {} vertices; a face needs at least 3", face.len()),
        ));
    }
    for (k, &v) in face.iter().enumerate() {
        if v as usize >= points {
            return Err(IoError::at(
                path,
                line,
                format!(
                    "face uses vertex {}, but there are only {points} vertices",
                    v as u64 + base as u64
                ),
            ));
        }
        if face[..k].contains(&v) {
            return Err(IoError::at(
                path,
                line,
                format!("face visits vertex {} twice", v + base),
            ));
        }
    }
    Ok(())
}

/// Writes one `x y z` line per point (shortest round-trip decimals), the
/// vertex block of `.off`, `.ply` and legacy `.vtk`.
pub(crate) fn write_xyz_lines(w: &mut impl Write, points: &[DVec3]) -> std::io::Result<()> {
    for p in points {
        writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
    }
    Ok(())
}

/// Writes one line per face: its vertex count, then its 0-based vertex ids,
/// the face block of `.off`, `.ply` and legacy `.vtk`.
pub(crate) fn write_counted_faces(w: &mut impl Write, faces: &[Vec<u32>]) -> std::io::Result<()> {
    for f in faces {
        write!(w, "{}", f.len())?;
        for &v in f {
            write!(w, " {v}")?;
        }
        writeln!(w)?;
    }
    Ok(())
}
