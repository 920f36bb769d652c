//! VTK XML PolyData `.vtp` (ASCII data arrays), the surface format ParaView
//! opens directly. Points are `Float64`; cells are written as VTK's
//! `connectivity` and `offsets` arrays (`Int64`). [`write()`] writes a polygon
//! mesh (`Polys`) with the PolyData pieces of [`tetrefine::polyline`], which
//! also writes the points and polylines of [`super::ifs`] (`Verts`, `Lines`).

use super::polymesh::PolyMesh;
use std::path::Path;
use tetrefine::io::vtp::{write_cells, write_footer, write_header, write_points};
use tetrefine::io::{write_atomic, IoError};

/// Writes a `.vtp` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_atomic(path, |w| {
        write_header(w, mesh.points.len(), [0, 0, mesh.faces.len()])?;
        write_points(w, mesh.points.iter())?;
        let polys = mesh.faces.iter().map(|f| f.iter().map(|&v| v as u64));
        write_cells(w, "Polys", polys)?;
        write_footer(w)
    })
}
