//! Subcommands, one file each. Every command returns `Err(message)` for the
//! user; `main` prints it on one line and exits non-zero.

pub mod bisect;
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

/// `println!` that ignores a closed pipe (`tetrefine quality … | head`):
/// standard output is a courtesy, the files are the product, and a reader
/// that stopped early must not turn into a panic.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

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

/// A per-tet integer of a mesh, for [`write_refined`].
pub type TetValue<'a> = dyn Fn(&TetMesh, u32) -> i32 + Sync + 'a;

/// Writes a refined mesh: compacted, and for `.vtu` with the cell arrays
/// `level` and `parent` (plus `extra`, named integers per tet) besides the
/// standard quality arrays.
pub fn write_refined(
    path: &Path,
    mesh: &mut TetMesh,
    extra: &[(&str, &TetValue<'_>)],
) -> CliResult {
    mesh.compact();
    let is_vtu = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("vtu"));
    if is_vtu {
        // After compaction the i-th live tet is slot i: the arrays are
        // computed as they are written rather than held.
        let mesh = &*mesh;
        let n = mesh.n_tets();
        let level = |i: usize| i32::from(mesh.level(i as u32));
        let parent = |i: usize| mesh.parent(i as u32) as i32;
        let extra: Vec<_> = extra
            .iter()
            .map(|&(name, f)| (name, move |i: usize| f(mesh, i as u32)))
            .collect();
        let mut cells = vec![
            CellArray::Int32With("level".into(), n, &level),
            CellArray::Int32With("parent".into(), n, &parent),
        ];
        cells.extend(
            extra
                .iter()
                .map(|(name, f)| CellArray::Int32With(name.to_string(), n, f)),
        );
        tetrefine::io::vtk::write_vtu(path, mesh, &cells).map_err(|e| e.to_string())
    } else {
        tetrefine::io::write_mesh(path, mesh).map_err(|e| e.to_string())
    }
}

/// Applies `--features auto|none|FILE` to a freshly loaded mesh and tells the
/// user on stderr what it found.
pub fn apply_feature_option(mesh: &mut TetMesh, spec: &str, angle_deg: f64) -> CliResult {
    use tetrefine::refine::features::{detect_features, read_edge_list};
    match spec {
        "none" => mesh.clear_features(),
        "auto" => {
            let r = detect_features(mesh, angle_deg);
            eprintln!(
                "features: {} edges ({} by angle > {angle_deg}°, {} between patches, {} at junctions, the rest from the input), {} corners",
                r.feature_edges, r.by_angle, r.by_patch, r.by_junction, r.corners
            );
        }
        file => {
            let n = read_edge_list(mesh, Path::new(file)).map_err(|e| e.to_string())?;
            eprintln!(
                "features: {n} edges from {file}; {} feature edges and {} corners in all",
                mesh.feature_edges().len(),
                mesh.corners().len()
            );
        }
    }
    Ok(())
}

/// Writes the feature edges of `mesh` as two-point polylines (.vtp or .csv).
pub fn write_feature_lines(path: &Path, mesh: &TetMesh) -> CliResult {
    let mut edges: Vec<[u32; 2]> = mesh.feature_edges().keys().copied().collect();
    edges.sort_unstable();
    let lines: Vec<Vec<glam::DVec3>> = edges
        .iter()
        .map(|e| vec![mesh.point(e[0]), mesh.point(e[1])])
        .collect();
    tetrefine_surface::ifs::write_polylines(path, &lines).map_err(|e| e.to_string())
}
