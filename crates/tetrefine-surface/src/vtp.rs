//! VTK XML PolyData `.vtp` (ASCII data arrays), the surface format ParaView
//! opens directly. Points are `Float64`; cells are written as VTK's
//! `connectivity` and `offsets` arrays (`Int64`). [`write()`] writes a polygon
//! mesh (`Polys`); the pieces below it are shared with the point and polyline
//! writers of [`super::ifs`] (`Verts`, `Lines`).

use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::file::{write_atomic, IoError};

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

/// The XML declaration and the opening tags up to the `Piece` of
/// `points` points and `[verts, lines, polys]` cells.
pub(crate) fn write_header(
    w: &mut impl Write,
    points: usize,
    [verts, lines, polys]: [usize; 3],
) -> std::io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(w, "  <PolyData>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{points}\" NumberOfVerts=\"{verts}\" NumberOfLines=\"{lines}\" NumberOfStrips=\"0\" NumberOfPolys=\"{polys}\">"
    )
}

/// The `Points` element.
pub(crate) fn write_points<'a>(
    w: &mut impl Write,
    points: impl Iterator<Item = &'a DVec3>,
) -> std::io::Result<()> {
    writeln!(w, "      <Points>")?;
    writeln!(
        w,
        "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    for p in points {
        writeln!(w, "          {} {} {}", p.x, p.y, p.z)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </Points>")
}

/// A cell element (`tag` is `Verts`, `Lines` or `Polys`), each cell given by
/// its point ids; nothing when there are no cells. The iterator is walked
/// twice (connectivity, then offsets).
pub(crate) fn write_cells<C>(
    w: &mut impl Write,
    tag: &str,
    cells: impl Iterator<Item = C> + Clone,
) -> std::io::Result<()>
where
    C: Iterator<Item = u64>,
{
    if cells.clone().next().is_none() {
        return Ok(());
    }
    writeln!(w, "      <{tag}>")?;
    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )?;
    for cell in cells.clone() {
        write!(w, "         ")?;
        for v in cell {
            write!(w, " {v}")?;
        }
        writeln!(w)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(
        w,
        "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    let mut end = 0usize;
    let mut on_line = 0;
    for cell in cells {
        end += cell.count();
        if on_line == 0 {
            write!(w, "         ")?;
        }
        write!(w, " {end}")?;
        on_line += 1;
        if on_line == 16 {
            writeln!(w)?;
            on_line = 0;
        }
    }
    if on_line > 0 {
        writeln!(w)?;
    }
    writeln!(w, "        </DataArray>")?;
    writeln!(w, "      </{tag}>")
}

/// The closing tags.
pub(crate) fn write_footer(w: &mut impl Write) -> std::io::Result<()> {
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </PolyData>")?;
    writeln!(w, "</VTKFile>")
}
