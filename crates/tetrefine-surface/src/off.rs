//! Geomview Object File Format `.off` (ASCII).
//!
//! Read by the core's one OFF reader ([`tetrefine::io::read_off`]: the
//! `OFF` header, also `COFF`, `NOFF`, `CNOFF`…, whose extra per-vertex values
//! are skipped; the counts; one vertex per line; one face per line as
//! `k i0 … i(k−1)` with 0-based ids, a colour after them ignored). Written:
//! `OFF`, counts, vertices and faces.

use super::io::{check_face, write_counted_faces, write_xyz_lines, SurfaceFile};
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{read_off, write_atomic, IoError};

/// Reads an `.off` file with the core's OFF reader
/// ([`tetrefine::io::read_off`]), refusing a face that visits a vertex twice.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let off = read_off(path)?;
    let nv = off.points.len();
    for (face, &l) in off.faces.iter().zip(&off.face_lines) {
        check_face(path, l as usize, face, nv, 0)?;
    }
    Ok(SurfaceFile {
        mesh: PolyMesh {
            points: off.points.into_iter().map(DVec3::from_array).collect(),
            faces: off.faces,
        },
        face_lines: off.face_lines,
    })
}

/// Writes an `.off` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    let ne = mesh.edge_list().len();
    write_atomic(path, |w| {
        writeln!(w, "OFF")?;
        writeln!(w, "{} {} {}", mesh.points.len(), mesh.faces.len(), ne)?;
        write_xyz_lines(w, &mesh.points)?;
        write_counted_faces(w, &mesh.faces)?;
        Ok(())
    })
}
