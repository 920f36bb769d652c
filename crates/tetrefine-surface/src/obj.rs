//! Wavefront `.obj` (polygonal geometry only).
//!
//! Read: `v x y z [w]` (a homogeneous `w` divides the coordinates), `f` with
//! `i`, `i/t`, `i//n` or `i/t/n` references, 1-based or negative (relative to
//! the last vertex). Texture coordinates, normals, groups, objects, materials,
//! smoothing groups, lines and points are skipped. Written: `v` and `f` lines
//! with shortest round-trip decimal coordinates, so a write and a read give the
//! same numbers back.

use super::io::{check_face, parse_coord, read_text, short, SurfaceFile};
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError};

/// Reads an `.obj` file.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let text = read_text(path)?;
    let mut out = SurfaceFile::default();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut tok = content.split_whitespace();
        let Some(kw) = tok.next() else { continue };
        match kw {
            "v" => {
                let x = parse_coord(path, line, tok.next(), "an x coordinate")?;
                let y = parse_coord(path, line, tok.next(), "a y coordinate")?;
                let z = parse_coord(path, line, tok.next(), "a z coordinate")?;
                let mut p = DVec3::new(x, y, z);
                if let Some(w) = tok.next() {
                    let w = parse_coord(path, line, Some(w), "a w coordinate")?;
                    if w == 0.0 {
                        return Err(IoError::at(
                            path,
                            line,
                            "vertex has w = 0 (a point at infinity)",
                        ));
                    }
                    p /= w;
                }
                out.mesh.points.push(p);
            }
            "f" | "fo" => {
                let n = out.mesh.points.len() as i64;
                let mut face = Vec::new();
                for t in tok {
                    let first = t.split('/').next().unwrap_or("");
                    let idx: i64 = first.parse().map_err(|_| {
                        IoError::at(
                            path,
                            line,
                            format!("expected a vertex reference, found '{}'", short(t)),
                        )
                    })?;
                    let v = if idx > 0 {
                        idx - 1
                    } else if idx < 0 {
                        n + idx
                    } else {
                        return Err(IoError::at(
                            path,
                            line,
                            "vertex reference 0 (OBJ counts from 1)",
                        ));
                    };
                    if v < 0 || v >= u32::MAX as i64 {
                        return Err(IoError::at(
                            path,
                            line,
                            format!(
                                "vertex reference {idx} is out of range (only {n} vertices so far)"
                            ),
                        ));
                    }
                    face.push(v as u32);
                }
                if face.len() < 3 {
                    return Err(IoError::at(
                        path,
                        line,
                        format!("face has {} vertices; a face needs at least 3", face.len()),
                    ));
                }
                out.mesh.faces.push(face);
                out.face_lines.push(line as u32);
            }
            "vt" | "vn" | "vp" | "g" | "o" | "s" | "usemtl" | "mtllib" | "l" | "p" | "cstype"
            | "deg" | "curv" | "curv2" | "surf" | "parm" | "end" | "trim" | "hole" | "bmat"
            | "step" | "lod" | "usemap" | "maplib" | "shadow_obj" | "trace_obj" | "bevel"
            | "c_interp" | "d_interp" | "ctech" | "stech" | "mg" | "con" | "sp" => {}
            other => {
                return Err(IoError::at(
                    path,
                    line,
                    format!("unknown OBJ statement '{}'", short(other)),
                ))
            }
        }
    }
    let np = out.mesh.points.len();
    for (f, face) in out.mesh.faces.iter().enumerate() {
        check_face(path, out.face_lines[f] as usize, face, np, 1)?;
    }
    Ok(out)
}

/// Writes an `.obj` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_atomic(path, |w| {
        writeln!(w, "# written by tetrefine")?;
        for p in &mesh.points {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for f in &mesh.faces {
            write!(w, "f")?;
            for &v in f {
                write!(w, " {}", v as u64 + 1)?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}
