//! Stanford `.ply`, ASCII variant.
//!
//! Read: any header with a `vertex` element carrying `x`, `y`, `z` and a
//! `face` element carrying a list property `vertex_indices` (or
//! `vertex_index`); other properties and other elements are skipped, in
//! order. Binary PLY is refused with a clear message. Written: ASCII, double
//! coordinates, `uchar`/`int` face lists (`int` counts if a face has more
//! than 255 vertices).

use super::io::{
    check_face, parse_coord, read_text, short, write_counted_faces, write_xyz_lines, SurfaceFile,
};
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{write_atomic, IoError};

#[derive(Debug)]
enum Prop {
    Scalar(String),
    List(String),
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
    line: usize,
}

const TYPES: [&str; 16] = [
    "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16",
    "uint16", "int32", "uint32", "float32", "float64",
];

/// Reads an ASCII `.ply` file.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let text = read_text(path)?;
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, magic) = lines
        .next()
        .ok_or_else(|| IoError::at(path, 1, "empty file: expected 'ply'"))?;
    if magic.trim() != "ply" {
        return Err(IoError::at(
            path,
            1,
            format!(
                "expected 'ply' on the first line, found '{}'",
                short(magic.trim())
            ),
        ));
    }
    let mut elements: Vec<Element> = Vec::new();
    let mut saw_format = false;
    let mut last_line = 1;
    loop {
        let (l, raw) = lines.next().ok_or_else(|| {
            IoError::at(
                path,
                last_line,
                "file ends inside the header (no end_header)",
            )
        })?;
        last_line = l;
        let mut t = raw.split_whitespace();
        match t.next() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                match t.next() {
                    Some("ascii") => {}
                    Some(f @ ("binary_little_endian" | "binary_big_endian")) => {
                        return Err(IoError::at(
                            path,
                            l,
                            format!("{f} PLY is not supported; save the mesh as ASCII PLY"),
                        ))
                    }
                    other => {
                        return Err(IoError::at(
                            path,
                            l,
                            format!("unknown PLY format '{}'", short(other.unwrap_or(""))),
                        ))
                    }
                }
                saw_format = true;
            }
            Some("element") => {
                let name = t
                    .next()
                    .ok_or_else(|| IoError::at(path, l, "element without a name"))?;
                let count: usize = t.next().and_then(|c| c.parse().ok()).ok_or_else(|| {
                    IoError::at(path, l, format!("element '{name}' has no valid count"))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: l,
                });
            }
            Some("property") => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| IoError::at(path, l, "property before any element"))?;
                let ty = t.next().unwrap_or("");
                if ty == "list" {
                    let (ct, it) = (t.next().unwrap_or(""), t.next().unwrap_or(""));
                    if !TYPES.contains(&ct) || !TYPES.contains(&it) {
                        return Err(IoError::at(path, l, "list property with an unknown type"));
                    }
                    let name = t
                        .next()
                        .ok_or_else(|| IoError::at(path, l, "property without a name"))?;
                    el.props.push(Prop::List(name.to_string()));
                } else {
                    if !TYPES.contains(&ty) {
                        return Err(IoError::at(
                            path,
                            l,
                            format!("unknown property type '{}'", short(ty)),
                        ));
                    }
                    let name = t
                        .next()
                        .ok_or_else(|| IoError::at(path, l, "property without a name"))?;
                    el.props.push(Prop::Scalar(name.to_string()));
                }
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(IoError::at(
                    path,
                    l,
                    format!("unknown PLY header keyword '{}'", short(other)),
                ))
            }
        }
    }
    if !saw_format {
        return Err(IoError::at(path, last_line, "header has no 'format' line"));
    }
    let mut out = SurfaceFile::default();
    let vertex = elements.iter().position(|e| e.name == "vertex");
    let Some(vi) = vertex else {
        return Err(IoError::at(
            path,
            last_line,
            "header declares no 'vertex' element",
        ));
    };
    let vpos = |n: &str| {
        elements[vi]
            .props
            .iter()
            .position(|p| matches!(p, Prop::Scalar(s) if s == n))
    };
    let (Some(ix), Some(iy), Some(iz)) = (vpos("x"), vpos("y"), vpos("z")) else {
        return Err(IoError::at(
            path,
            elements[vi].line,
            "the vertex element lacks one of the properties x, y, z",
        ));
    };
    let nv = elements[vi].count;
    for el in &elements {
        let is_face = el.name == "face";
        let list_at = if is_face {
            let p = el.props.iter().position(
                |p| matches!(p, Prop::List(s) if s == "vertex_indices" || s == "vertex_index"),
            );
            if p.is_none() {
                return Err(IoError::at(
                    path,
                    el.line,
                    "the face element lacks a list property 'vertex_indices'",
                ));
            }
            p
        } else {
            None
        };
        for i in 0..el.count {
            let (l, raw) = lines.next().ok_or_else(|| {
                IoError::at(
                    path,
                    last_line,
                    format!(
                        "file ends after {i} of {} '{}' entries (truncated?)",
                        el.count, el.name
                    ),
                )
            })?;
            last_line = l;
            let mut t = raw.split_whitespace();
            let mut xyz = [0.0; 3];
            let mut face = Vec::new();
            for (k, p) in el.props.iter().enumerate() {
                match p {
                    Prop::Scalar(name) => {
                        let v = parse_coord(path, l, t.next(), &format!("the value of '{name}'"))?;
                        if el.name == "vertex" {
                            if k == ix {
                                xyz[0] = v;
                            } else if k == iy {
                                xyz[1] = v;
                            } else if k == iz {
                                xyz[2] = v;
                            }
                        }
                    }
                    Prop::List(name) => {
                        let n = parse_coord(
                            path,
                            l,
                            t.next(),
                            &format!("the length of list '{name}'"),
                        )?;
                        if n < 0.0 || n.fract() != 0.0 {
                            return Err(IoError::at(path, l, format!("bad list length {n}")));
                        }
                        for _ in 0..n as usize {
                            let v = parse_coord(path, l, t.next(), "a list entry")?;
                            if Some(k) == list_at {
                                if v < 0.0 || v.fract() != 0.0 || v >= nv as f64 {
                                    return Err(IoError::at(
                                        path,
                                        l,
                                        format!("vertex index {v} is out of range 0..{nv}"),
                                    ));
                                }
                                face.push(v as u32);
                            }
                        }
                    }
                }
            }
            if el.name == "vertex" {
                out.mesh.points.push(DVec3::from_array(xyz));
            } else if is_face {
                check_face(path, l, &face, nv, 0)?;
                out.mesh.faces.push(face);
                out.face_lines.push(l as u32);
            }
        }
    }
    Ok(out)
}

/// Writes an ASCII `.ply` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    let count_type = if mesh.faces.iter().any(|f| f.len() > 255) {
        "int"
    } else {
        "uchar"
    };
    write_atomic(path, |w| {
        writeln!(w, "ply")?;
        writeln!(w, "format ascii 1.0")?;
        writeln!(w, "comment written by tetrefine")?;
        writeln!(w, "element vertex {}", mesh.points.len())?;
        writeln!(w, "property double x")?;
        writeln!(w, "property double y")?;
        writeln!(w, "property double z")?;
        writeln!(w, "element face {}", mesh.faces.len())?;
        writeln!(w, "property list {count_type} int vertex_indices")?;
        writeln!(w, "end_header")?;
        write_xyz_lines(w, &mesh.points)?;
        write_counted_faces(w, &mesh.faces)?;
        Ok(())
    })
}
