//! Geomview Object File Format `.off` (ASCII).
//!
//! Read: the `OFF` header (also `COFF`, `NOFF`, `CNOFF`, whose extra
//! per-vertex values are skipped), the counts `vertices faces edges` (on the
//! header line or the next), one vertex per line, then one face per line as
//! `k i0 … i(k−1)` with 0-based ids; anything after the ids (a colour) is
//! ignored. `#` starts a comment. Written: `OFF`, counts, vertices and faces.

use super::io::{
    check_face, parse_coord, parse_int, read_text, short, write_counted_faces, write_xyz_lines,
    SurfaceFile,
};
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError};

/// Reads an `.off` file.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let text = read_text(path)?;
    // Non-empty lines with comments removed, with their numbers.
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let (hline, header) = lines
        .next()
        .ok_or_else(|| IoError::at(path, 1, "empty file: expected the OFF header"))?;
    let mut head = header.split_whitespace();
    let kw = head.next().unwrap_or("");
    if !matches!(kw, "OFF" | "COFF" | "NOFF" | "CNOFF" | "NCOFF") {
        let hint = if kw.contains("OFF") {
            " (only the ASCII 3-D variants OFF, COFF, NOFF, CNOFF are read)"
        } else {
            ""
        };
        return Err(IoError::at(
            path,
            hline,
            format!("expected the header 'OFF', found '{}'{hint}", short(kw)),
        ));
    }
    let rest: Vec<&str> = head.collect();
    let (cline, counts): (usize, Vec<&str>) = if rest.is_empty() {
        let (l, c) = lines
            .next()
            .ok_or_else(|| IoError::at(path, hline, "file ends before the vertex/face counts"))?;
        (l, c.split_whitespace().collect())
    } else {
        (hline, rest)
    };
    let nv = parse_int(path, cline, counts.first().copied(), "the vertex count")?;
    let nf = parse_int(path, cline, counts.get(1).copied(), "the face count")?;
    if nv < 0 || nf < 0 {
        return Err(IoError::at(path, cline, "negative vertex or face count"));
    }
    let (nv, nf) = (nv as usize, nf as usize);
    // A vertex line takes at least 6 bytes and a face line 8: counts the file
    // cannot hold are refused before anything is allocated.
    if nv.saturating_mul(6).saturating_add(nf.saturating_mul(8)) > text.len() {
        return Err(IoError::at(
            path,
            cline,
            format!(
                "{nv} vertices and {nf} faces cannot fit in the {} bytes of the file (truncated or corrupt counts)",
                text.len()
            ),
        ));
    }
    let mut out = SurfaceFile::default();
    out.mesh.points.reserve(nv);
    for i in 0..nv {
        let (l, s) = lines.next().ok_or_else(|| {
            IoError::at(
                path,
                text.lines().count(),
                format!("file ends after {i} of {nv} vertices (truncated?)"),
            )
        })?;
        let mut t = s.split_whitespace();
        let x = parse_coord(path, l, t.next(), "an x coordinate")?;
        let y = parse_coord(path, l, t.next(), "a y coordinate")?;
        let z = parse_coord(path, l, t.next(), "a z coordinate")?;
        out.mesh.points.push(DVec3::new(x, y, z));
    }
    for i in 0..nf {
        let (l, s) = lines.next().ok_or_else(|| {
            IoError::at(
                path,
                text.lines().count(),
                format!("file ends after {i} of {nf} faces (truncated?)"),
            )
        })?;
        let mut t = s.split_whitespace();
        let k = parse_int(path, l, t.next(), "the number of vertices of a face")?;
        if k < 3 {
            return Err(IoError::at(
                path,
                l,
                format!("face has {k} vertices; a face needs at least 3"),
            ));
        }
        // Each index takes at least two bytes of the line.
        if k as u64 > s.len() as u64 / 2 + 1 {
            return Err(IoError::at(
                path,
                l,
                format!("face declares {k} vertices, more than its line can hold"),
            ));
        }
        let mut face = Vec::with_capacity(k as usize);
        for _ in 0..k {
            let v = parse_int(path, l, t.next(), "a vertex index")?;
            if v < 0 || v as u64 >= nv as u64 {
                return Err(IoError::at(
                    path,
                    l,
                    format!("vertex index {v} is out of range 0..{nv}"),
                ));
            }
            face.push(v as u32);
        }
        check_face(path, l, &face, nv, 0)?;
        out.mesh.faces.push(face);
        out.face_lines.push(l as u32);
    }
    Ok(out)
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
