//! Subcommands, one file each. Every command returns `Err(message)` for the
//! user; `main` prints it on one line and exits non-zero.

pub mod bisect;
pub mod convert;
pub mod quality;
pub mod surface;

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
