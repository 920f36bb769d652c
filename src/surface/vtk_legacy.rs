//! Legacy VTK `.vtk` POLYDATA, ASCII, file version 3.0 (`POLYGONS` with
//! per-face counts), readable by every ParaView and VTK release.

use super::polymesh::PolyMesh;
use crate::io::{write_atomic, IoError};
use std::io::Write;
use std::path::Path;

/// Writes a legacy `.vtk` POLYDATA file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    let size: usize = mesh.faces.iter().map(|f| f.len() + 1).sum();
    write_atomic(path, |w| {
        writeln!(w, "# vtk DataFile Version 3.0")?;
        writeln!(w, "surface written by tetrefine")?;
        writeln!(w, "ASCII")?;
        writeln!(w, "DATASET POLYDATA")?;
        writeln!(w, "POINTS {} double", mesh.points.len())?;
        for p in &mesh.points {
            writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
        }
        writeln!(w, "POLYGONS {} {}", mesh.faces.len(), size)?;
        for f in &mesh.faces {
            write!(w, "{}", f.len())?;
            for &v in f {
                write!(w, " {v}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}
