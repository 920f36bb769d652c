//! Subcommands, one file each. Every command returns `Err(message)` for the
//! user; `main` prints it on one line and exits non-zero.

pub mod bisect;
pub mod convert;
#[cfg(feature = "mpi")]
pub mod distributed;
pub mod guard;
pub mod improve;
pub mod mesh;
pub mod outputs;
#[cfg(feature = "mpi")]
pub mod piece_fields;
pub mod progress;
#[cfg(feature = "mpi")]
pub mod pvtu_input;
pub mod pvtu_merge;
pub mod quality;
pub mod refine;
pub mod size;
pub mod steps;
pub mod surface;
pub mod transfer;

use std::path::Path;
use tetrefine::io::{CellArray, PointArray, VtuSummary};
use tetrefine::report::MeshStats;
use tetrefine::report::{write_histogram as write_hist_file, HistogramFormat};
use tetrefine::TetMesh;

/// `println!` that never panics: a failed write (a closed pipe, a full
/// disk) is remembered and fails the command at its end, so that no output
/// file appears and the exit status is non-zero.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        $crate::cli::outputs::say_line(format_args!($($arg)*));
    }};
}

/// A one-line error for the user.
pub type CliResult = Result<(), String>;

/// Loads a mesh, telling the user on stderr what building changed.
pub fn load(path: &std::path::Path) -> Result<tetrefine::TetMesh, String> {
    load_with_meta(path).map(|(m, _)| m)
}

/// [`load`] with the file's side table (physical names, tag lists, fields).
pub fn load_with_meta(
    path: &std::path::Path,
) -> Result<(tetrefine::TetMesh, tetrefine::io::MeshMeta), String> {
    let (mesh, report, meta, notes) = if pvtu_merge::is_pvtu(path) {
        // Every piece, joined (see `pvtu_merge`).
        let (data, meta) = pvtu_merge::read_pvtu(path)?;
        let (mesh, report) =
            tetrefine::TetMesh::from_data(&data).map_err(|e| format!("{}: {e}", path.display()))?;
        (mesh, report, meta, Vec::new())
    } else {
        tetrefine::io::load_mesh_with_meta_noted(path).map_err(|e| e.to_string())?
    };
    for n in notes {
        eprintln!("note: {}: {n}", path.display());
    }
    if let Some(n) = guard::nonmanifold_note(&mesh) {
        eprintln!("note: {}: {n}", path.display());
    }
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
    Ok((mesh, meta))
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
/// `level` and `parent` (plus `extra`, named integers per tet, and
/// `arrays`: transferred fields and the vertex parent map) besides the
/// standard quality arrays; other formats get the input's side table `meta`
/// (physical names and tags, fields for Gmsh) and the write `options` (the
/// MSH variant); a Medit output gets its fields in `.sol` files beside it.
pub fn write_refined(
    path: &Path,
    mesh: &mut TetMesh,
    extra: &[(&str, &TetValue<'_>)],
    meta: &tetrefine::io::MeshMeta,
    options: &tetrefine::io::WriteOptions,
    arrays: (Vec<PointArray>, Vec<CellArray<'static>>),
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
        let (points, field_cells) = arrays;
        cells.extend(field_cells);
        let (valence, stats) = (MeshStats::vertex_valence(mesh), MeshStats::compute(mesh));
        let summary = vtu_summary(&valence, &stats);
        tetrefine::io::write_vtu_with(path, mesh, Some(&summary), &cells, &points)
            .map_err(|e| e.to_string())
    } else {
        tetrefine::io::write_mesh_with(path, mesh, meta, options).map_err(|e| e.to_string())?;
        let (_written, skipped) =
            tetrefine::io::write_fields_beside(path, meta, mesh.n_points(), mesh.n_tets())
                .map_err(|e| e.to_string())?;
        if !skipped.is_empty() {
            eprintln!(
                "note: {}: fields {} not written (a Medit solution holds 1, 3, 6 or 9 components)",
                path.display(),
                skipped.join(", ")
            );
        }
        let has_fields = !meta.point_fields.is_empty() || !meta.cell_fields.is_empty();
        let fmt = tetrefine::io::Format::for_writing(path).map_err(|e| e.to_string())?;
        if has_fields && fmt == tetrefine::io::Format::Tetgen {
            eprintln!(
                "note: {}: TetGen files carry no fields; write .vtu, .msh or .mesh to keep them",
                path.display()
            );
        }
        Ok(())
    }
}

/// The figures a `.vtu` carries besides the mesh, from the statistics.
fn vtu_summary<'a>(valence: &'a [u32], stats: &'a MeshStats) -> VtuSummary<'a> {
    VtuSummary {
        valence,
        histogram_counts: &stats.histogram.counts,
        histogram_edges_deg: &stats.histogram.edges_deg,
    }
}

/// Writes `mesh` in the format of `path`'s extension; a `.vtu` also gets the
/// point valences and the minimum-dihedral histogram of the statistics.
pub fn write_mesh(path: &Path, mesh: &TetMesh) -> CliResult {
    let (meta, options) = Default::default();
    write_mesh_with(path, mesh, &meta, &options)
}

/// [`write_mesh`] with the input's side table `meta` (physical names and
/// tags, fields) and the write `options` (the MSH variant) for formats that
/// carry them.
pub fn write_mesh_with(
    path: &Path,
    mesh: &TetMesh,
    meta: &tetrefine::io::MeshMeta,
    options: &tetrefine::io::WriteOptions,
) -> CliResult {
    let is_vtu = tetrefine::io::Format::for_writing(path).map_err(|e| e.to_string())?
        == tetrefine::io::Format::Vtu;
    if is_vtu {
        let (valence, stats) = (MeshStats::vertex_valence(mesh), MeshStats::compute(mesh));
        let summary = vtu_summary(&valence, &stats);
        tetrefine::io::write_vtu(path, mesh, Some(&summary), &[]).map_err(|e| e.to_string())
    } else {
        tetrefine::io::write_mesh_with(path, mesh, meta, options).map_err(|e| e.to_string())
    }
}

/// Applies `--features auto|none|FILE` to a freshly loaded mesh (for the
/// refinement's interface rule) and tells the user on stderr what it found.
pub fn apply_feature_option(
    mesh: &mut TetMesh,
    spec: &str,
    angle_deg: f64,
    interfaces: tetrefine::InterfaceRule,
) -> CliResult {
    use tetrefine::detect_features_for;
    use tetrefine::io::read_edge_list;
    match spec {
        "none" => mesh.clear_features(),
        "auto" => {
            let r = detect_features_for(mesh, angle_deg, interfaces);
            eprintln!(
                "features: {} edges ({} by angle > {angle_deg}°, {} between patches, {} at junctions, {} where an interface bends, the rest from the input), {} corners",
                r.feature_edges, r.by_angle, r.by_patch, r.by_junction, r.curved_interface, r.corners
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
    tetrefine::write_feature_lines(path, mesh).map_err(|e| e.to_string())
}
