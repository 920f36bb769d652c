//! Legacy VTK `.vtk` POLYDATA, ASCII, file version 3.0 (`POLYGONS` with
//! per-face counts), readable by every ParaView and VTK release.
//! [`write_with`] adds the per-face attributes of [`super::lineage`] as
//! `CELL_DATA` scalars (`unsigned_int`) named `generation`, `origin` and
//! `group`.

use super::io::{attribute_columns, write_counted_faces, write_xyz_lines, ATTRIBUTE_NAMES};
use super::lineage::FaceAttributes;
use super::polymesh::PolyMesh;
use super::vtp::write_numbers;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError};

/// Writes a legacy `.vtk` POLYDATA file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_with(path, mesh, None)
}

/// Writes a legacy `.vtk` POLYDATA file with the face attributes as cell
/// data (their length is the caller's to check;
/// [`super::io::write_surface_with`] does).
pub fn write_with(
    path: &Path,
    mesh: &PolyMesh,
    attributes: Option<&FaceAttributes>,
) -> Result<(), IoError> {
    let size: usize = mesh.faces.iter().map(|f| f.len() + 1).sum();
    write_atomic(path, |w| {
        writeln!(w, "# vtk DataFile Version 3.0")?;
        writeln!(w, "surface written by tetrefine")?;
        writeln!(w, "ASCII")?;
        writeln!(w, "DATASET POLYDATA")?;
        writeln!(w, "POINTS {} double", mesh.points.len())?;
        write_xyz_lines(w, &mesh.points)?;
        writeln!(w, "POLYGONS {} {}", mesh.faces.len(), size)?;
        write_counted_faces(w, &mesh.faces)?;
        if let Some(a) = attributes {
            writeln!(w, "CELL_DATA {}", mesh.faces.len())?;
            for (name, col) in ATTRIBUTE_NAMES.iter().zip(attribute_columns(a)) {
                writeln!(w, "SCALARS {name} unsigned_int 1")?;
                writeln!(w, "LOOKUP_TABLE default")?;
                write_numbers(w, col)?;
            }
        }
        Ok(())
    })
}
