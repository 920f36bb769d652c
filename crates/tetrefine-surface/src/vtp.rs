//! VTK XML PolyData `.vtp` (ASCII data arrays), the surface format ParaView
//! opens directly. Points are `Float64`; cells are written as VTK's
//! `connectivity` and `offsets` arrays (`Int64`). [`write()`] writes a polygon
//! mesh (`Polys`) with the PolyData pieces of [`tetrefine::io::vtp`], which
//! also writes the points and polylines of [`super::ifs`] (`Verts`, `Lines`).
//! [`write_with`] adds the per-face attributes of [`super::lineage`] as
//! `UInt32` `CellData` arrays named `generation`, `origin` and `group`.

use super::io::{attribute_columns, ATTRIBUTE_NAMES};
use super::lineage::FaceAttributes;
use super::polymesh::PolyMesh;
use std::io::Write;
use std::path::Path;
use tetrefine::io::vtp::{write_cells, write_footer, write_header, write_points};
use tetrefine::io::{write_atomic, IoError};

/// Writes a `.vtp` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_with(path, mesh, None)
}

/// Writes a `.vtp` file with the face attributes as cell data (their length
/// is the caller's to check; [`super::io::write_surface_with`] does).
pub fn write_with(
    path: &Path,
    mesh: &PolyMesh,
    attributes: Option<&FaceAttributes>,
) -> Result<(), IoError> {
    write_atomic(path, |w| {
        write_header(w, mesh.points.len(), [0, 0, mesh.faces.len()])?;
        if let Some(a) = attributes {
            writeln!(w, "      <CellData Scalars=\"generation\">")?;
            for (name, col) in ATTRIBUTE_NAMES.iter().zip(attribute_columns(a)) {
                writeln!(
                    w,
                    "        <DataArray type=\"UInt32\" Name=\"{name}\" format=\"ascii\">"
                )?;
                write_numbers(w, col)?;
                writeln!(w, "        </DataArray>")?;
            }
            writeln!(w, "      </CellData>")?;
        }
        write_points(w, mesh.points.iter())?;
        let polys = mesh.faces.iter().map(|f| f.iter().map(|&v| v as u64));
        write_cells(w, "Polys", polys)?;
        write_footer(w)
    })
}

/// Numbers, 16 to a line.
pub(crate) fn write_numbers(w: &mut impl Write, values: &[u32]) -> std::io::Result<()> {
    for chunk in values.chunks(16) {
        write!(w, "         ")?;
        for v in chunk {
            write!(w, " {v}")?;
        }
        writeln!(w)?;
    }
    Ok(())
}
