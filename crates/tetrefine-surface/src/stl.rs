//! Stereolithography `.stl`, ASCII and binary.
//!
//! Written: every face as triangles, a face of `n` vertices as the fan
//! `(v0, vk, vk+1)`, `k = 1 … n − 2` (STL holds triangles only; faces stay in
//! order, the fan of a face in `k` order), each with the unit normal of the
//! triangle's cross product (zero for a degenerate triangle). Binary: an
//! 80-byte header that does not start with `solid`, the triangle count as a
//! little-endian `u32`, then 50 bytes per triangle (normal and the three
//! vertices as `f32`, a zero `u16`): `84 + 50 t` bytes for `t` triangles.
//! Binary STL rounds the coordinates to `f32`; ASCII writes the shortest
//! decimals that read back to the same `f64`.
//!
//! Read with the core's STL reader ([`tetrefine::io::Plc::read`]): ASCII or
//! binary (a file of exactly `84 + 50 t` bytes is binary), vertices with
//! bitwise-equal coordinates merged into one indexed vertex, and truncated or
//! malformed files refused with the file (and, in ASCII, the line) named.

use super::io::SurfaceFile;
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError, Plc};

/// Reads an STL file (ASCII or binary) into an indexed mesh, merging
/// vertices with exactly equal coordinates.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let plc = Plc::read(path)?;
    let mut faces = Vec::with_capacity(plc.facets.len());
    for (i, f) in plc.facets.into_iter().enumerate() {
        match <[Vec<u32>; 1]>::try_from(f.polygons) {
            Ok([tri]) => faces.push(tri),
            Err(_) => {
                return Err(IoError::file(
                    path,
                    format!("internal: STL facet {} is not one triangle", i + 1),
                ))
            }
        }
    }
    let n = faces.len();
    Ok(SurfaceFile {
        mesh: PolyMesh {
            points: plc.points.into_iter().map(DVec3::from_array).collect(),
            faces,
        },
        face_lines: vec![0; n],
    })
}

/// The fan triangles of every face, in face order.
pub fn fan_triangles(mesh: &PolyMesh) -> impl Iterator<Item = [u32; 3]> + '_ {
    mesh.faces
        .iter()
        .flat_map(|f| (1..f.len().saturating_sub(1)).map(move |k| [f[0], f[k], f[k + 1]]))
}

/// Number of triangles [`fan_triangles`] gives: `Σ (|f| − 2)`.
pub fn fan_triangle_count(mesh: &PolyMesh) -> usize {
    mesh.faces.iter().map(|f| f.len().saturating_sub(2)).sum()
}

/// The unit normal of a triangle (zero when it is degenerate).
fn normal(p: &[DVec3], t: [u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|v| p[v as usize]);
    (b - a).cross(c - a).normalize_or_zero()
}

/// Writes an `.stl` file, binary or (`ascii`) text.
pub fn write(path: &Path, mesh: &PolyMesh, ascii: bool) -> Result<(), IoError> {
    let count = fan_triangle_count(mesh);
    if !ascii && count > u32::MAX as usize {
        return Err(IoError::file(
            path,
            format!("{count} triangles are more than binary STL can count"),
        ));
    }
    let p = &mesh.points;
    write_atomic(path, |w| {
        if ascii {
            writeln!(w, "solid tetrefine")?;
            for t in fan_triangles(mesh) {
                let n = normal(p, t);
                writeln!(w, "  facet normal {} {} {}", n.x, n.y, n.z)?;
                writeln!(w, "    outer loop")?;
                for v in t {
                    let q = p[v as usize];
                    writeln!(w, "      vertex {} {} {}", q.x, q.y, q.z)?;
                }
                writeln!(w, "    endloop")?;
                writeln!(w, "  endfacet")?;
            }
            writeln!(w, "endsolid tetrefine")?;
        } else {
            let mut header = [b' '; 80];
            let text = b"binary STL written by tetrefine";
            header[..text.len()].copy_from_slice(text);
            w.write_all(&header)?;
            w.write_all(&(count as u32).to_le_bytes())?;
            for t in fan_triangles(mesh) {
                let mut rec = [0u8; 50];
                let n = normal(p, t);
                let vals = [n, p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]];
                for (k, v) in vals.iter().enumerate() {
                    for (c, x) in v.to_array().iter().enumerate() {
                        let o = 12 * k + 4 * c;
                        rec[o..o + 4].copy_from_slice(&(*x as f32).to_le_bytes());
                    }
                }
                w.write_all(&rec)?;
            }
        }
        Ok(())
    })
}
