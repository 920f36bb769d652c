//! Subcommands, one file each. Every command returns `Err(message)` for the
//! user; `main` prints it on one line and exits non-zero.

pub mod convert;
pub mod improve;
pub mod mesh;
pub mod progress;
pub mod quality;
pub mod refine;
pub mod surface;

use std::path::Path;
use tetrefine::io::vtk::CellArray;
use tetrefine::report::histogram::{write_histogram as write_hist_file, HistogramFormat};
use tetrefine::report::MeshStats;
use tetrefine::TetMesh;

/// A one-line error for the user.
pub type CliResult = Result<(), String>;

/// Loads a mesh, telling the user on stderr what building changed.
pub fn load(path: &std::path::Path) -> Result<tetrefine::TetMesh, String> {
    let (mesh, report) = tetrefine::io::load_mesh(path).map_err(|e| e.to_string())?;
    if report.reoriented > 0 {
        eprintln!(
            "note: {}: {} tetrahedra were negatively oriented and have been turned around",
            path.display(),
            report.reoriented
        );
    }
    if report.dropped_triangles > 0 || report.dropped_edges > 0 {
        eprintln!(
            "note: {}: dropped {} marked triangles and {} tagged edges that are not faces/edges of any tetrahedron",
            path.display(),
            report.dropped_triangles,
            report.dropped_edges
        );
    }
    Ok(mesh)
}

/// Checks a histogram path's extension before any work is done.
pub fn check_histogram_path(path: &Path) -> CliResult {
    HistogramFormat::from_path(path)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Writes the min-dihedral histogram of `stats` (CSV, SVG or PNG).
pub fn write_histogram(path: &Path, stats: &MeshStats) -> CliResult {
    let title = format!("minimum dihedral angle, {} tets", stats.tets);
    write_hist_file(path, &stats.histogram, &title).map_err(|e| e.to_string())
}

/// Writes a refined mesh: compacted, and for `.vtu` with the cell arrays
/// `level` and `parent` (plus `extra`) besides the standard quality arrays.
pub fn write_refined(path: &Path, mesh: &mut TetMesh, extra: Vec<CellArray>) -> CliResult {
    mesh.compact();
    let is_vtu = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
    if is_vtu {
        let ids: Vec<u32> = mesh.tet_ids().collect();
        let mut cells = vec![
            CellArray::Int32(
                "level".into(),
                ids.iter().map(|&t| i32::from(mesh.level(t))).collect(),
            ),
            CellArray::Int32(
                "parent".into(),
                ids.iter().map(|&t| mesh.parent(t) as i32).collect(),
            ),
        ];
        cells.extend(extra);
        tetrefine::io::vtk::write_vtu(path, mesh, &cells).map_err(|e| e.to_string())
    } else {
        tetrefine::io::write_mesh(path, mesh).map_err(|e| e.to_string())
    }
}
