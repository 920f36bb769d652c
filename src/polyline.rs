//! Points and polylines as files: VTK XML PolyData `.vtp` (ASCII data
//! arrays, for ParaView) or CSV. Used for the feature edges of a tet mesh
//! ([`write_feature_lines`]) and by the surface schemes (their `.vtp` meshes
//! and IFS attractors) through the PolyData pieces below. Points are
//! `Float64`; cells are written as VTK's `connectivity` and `offsets`
//! arrays (`Int64`).

use crate::file::{write_atomic, IoError};
use crate::mesh::TetMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

/// Writes the feature edges of `mesh`, sorted, one two-point polyline each,
/// in the format of the extension of `path` (`.vtp` or `.csv`).
pub fn write_feature_lines(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    let mut edges: Vec<[u32; 2]> = mesh.feature_edges().keys().copied().collect();
    edges.sort_unstable();
    let lines: Vec<Vec<DVec3>> = edges
        .iter()
        .map(|e| vec![mesh.point(e[0]), mesh.point(e[1])])
        .collect();
    write_polylines(path, &lines)
}

/// File formats for points and polylines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolylineFormat {
    /// VTK XML PolyData `.vtp` (ASCII), for ParaView.
    Vtp,
    /// Comma-separated values `.csv`.
    Csv,
}

impl PolylineFormat {
    /// The format of `path` from its extension.
    pub fn of(path: &Path) -> Result<PolylineFormat, IoError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "vtp" => Ok(PolylineFormat::Vtp),
            "csv" => Ok(PolylineFormat::Csv),
            _ => Err(IoError::file(
                path,
                "points and polylines are written as .vtp or .csv",
            )),
        }
    }
}

/// Write polylines in the format of the extension of `path`
/// ([`write_polylines_vtp`] or [`write_polylines_csv`]).
pub fn write_polylines(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    match PolylineFormat::of(path)? {
        PolylineFormat::Vtp => write_polylines_vtp(path, polylines),
        PolylineFormat::Csv => write_polylines_csv(path, polylines),
    }
}

/// Write points as CSV (`x,y,z` header, one point a line).
pub fn write_points_csv(path: &Path, points: &[DVec3]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "x,y,z")?;
        for p in points {
            writeln!(w, "{},{},{}", p.x, p.y, p.z)?;
        }
        Ok(())
    })
}

/// Write polylines as CSV (`polyline,point,x,y,z` header, one point a line).
pub fn write_polylines_csv(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "polyline,point,x,y,z")?;
        for (l, line) in polylines.iter().enumerate() {
            for (i, p) in line.iter().enumerate() {
                writeln!(w, "{l},{i},{},{},{}", p.x, p.y, p.z)?;
            }
        }
        Ok(())
    })
}

/// Write points as VTK XML PolyData (`.vtp`, ASCII), one vertex cell each.
pub fn write_points_vtp(path: &Path, points: &[DVec3]) -> Result<(), IoError> {
    write_atomic(path, |w| {
        write_header(w, points.len(), [points.len(), 0, 0])?;
        write_points(w, points.iter())?;
        write_cells(w, "Verts", (0..points.len() as u64).map(std::iter::once))?;
        write_footer(w)
    })
}

/// Write polylines as VTK XML PolyData (`.vtp`, ASCII) for ParaView:
/// polylines of two or more points become `Lines` cells, single points
/// `Verts` cells. Every polyline has its own points.
pub fn write_polylines_vtp(path: &Path, polylines: &[Vec<DVec3>]) -> Result<(), IoError> {
    let total: usize = polylines.iter().map(Vec::len).sum();
    // Point ids of each polyline: consecutive, in polyline order.
    let mut first = Vec::with_capacity(polylines.len());
    let mut next = 0u64;
    for l in polylines {
        first.push(next);
        next += l.len() as u64;
    }
    let cells = |single: bool| {
        polylines
            .iter()
            .zip(&first)
            .filter(move |(l, _)| !l.is_empty() && (l.len() == 1) == single)
            .map(|(l, &f)| f..f + l.len() as u64)
    };
    write_atomic(path, |w| {
        write_header(w, total, [cells(true).count(), cells(false).count(), 0])?;
        write_points(w, polylines.iter().flatten())?;
        write_cells(w, "Verts", cells(true))?;
        write_cells(w, "Lines", cells(false))?;
        write_footer(w)
    })
}

/// The XML declaration and the opening tags up to the `Piece` of
/// `points` points and `[verts, lines, polys]` cells.
pub fn write_header(
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
pub fn write_points<'a>(
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
pub fn write_cells<C>(
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
pub fn write_footer(w: &mut impl Write) -> std::io::Result<()> {
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </PolyData>")?;
    writeln!(w, "</VTKFile>")
}
