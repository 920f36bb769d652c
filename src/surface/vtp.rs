//! VTK XML PolyData `.vtp` (ASCII data arrays), the surface format ParaView
//! opens directly. Points are `Float64`; polygons are written as VTK's
//! `connectivity` and `offsets` arrays (`Int64`).

use super::polymesh::PolyMesh;
use crate::io::{write_atomic, IoError};
use std::io::Write;
use std::path::Path;

/// Writes a `.vtp` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(w, "  <PolyData>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">",
            mesh.points.len(),
            mesh.faces.len()
        )?;
        writeln!(w, "      <Points>")?;
        writeln!(
            w,
            "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
        )?;
        for p in &mesh.points {
            writeln!(w, "          {} {} {}", p.x, p.y, p.z)?;
        }
        writeln!(w, "        </DataArray>")?;
        writeln!(w, "      </Points>")?;
        writeln!(w, "      <Polys>")?;
        writeln!(
            w,
            "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
        )?;
        for f in &mesh.faces {
            write!(w, "         ")?;
            for &v in f {
                write!(w, " {v}")?;
            }
            writeln!(w)?;
        }
        writeln!(w, "        </DataArray>")?;
        writeln!(
            w,
            "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
        )?;
        let mut off = 0usize;
        for (i, f) in mesh.faces.iter().enumerate() {
            off += f.len();
            if i % 16 == 0 {
                write!(w, "         ")?;
            }
            write!(w, " {off}")?;
            if i % 16 == 15 || i + 1 == mesh.faces.len() {
                writeln!(w)?;
            }
        }
        writeln!(w, "        </DataArray>")?;
        writeln!(w, "      </Polys>")?;
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </PolyData>")?;
        writeln!(w, "</VTKFile>")?;
        Ok(())
    })
}
