//! Legacy VTK `.vtk` POLYDATA, ASCII, file version 3.0 (`POLYGONS` with
//! per-face counts), readable by every ParaView and VTK release.

use super::io::{write_counted_faces, write_xyz_lines};
use super::polymesh::PolyMesh;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError};

/// Writes a legacy `.vtk` POLYDATA file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
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
        Ok(())
    })
}
