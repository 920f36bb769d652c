//! Stanford `.ply`, ASCII and binary.
//!
//! Read: `format ascii 1.0`, `binary_little_endian 1.0` or
//! `binary_big_endian 1.0`; any header with a `vertex` element carrying `x`,
//! `y`, `z` and a `face` element carrying a list property `vertex_indices`
//! (or `vertex_index`); other properties and other elements are skipped, in
//! order. Errors name the file and, in ASCII, the line; in binary the entry
//! (a truncated binary file: how many entries of which element were read).
//! Written ([`write_with`]): binary little-endian (the default of
//! [`super::io::WriteOptions`]) or ASCII, double coordinates, `uchar`/`int`
//! face lists (`int` counts if a face has more than 255 vertices), and the
//! per-face attributes of [`super::lineage`] as `uint` face properties
//! `generation`, `origin` and `group` when given.

use super::io::{attribute_columns, check_face, parse_coord, short, SurfaceFile, ATTRIBUTE_NAMES};
use super::lineage::FaceAttributes;
use super::polymesh::PolyMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;
use tetrefine::io::{read_bytes, write_atomic, IoError, IoErrorKind};

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &str) -> Option<Ty> {
        Some(match name {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

#[derive(Debug)]
enum Prop {
    Scalar(String, Ty),
    List(String, Ty, Ty),
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Prop>,
    line: usize,
}

/// The data encoding a header declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary { little: bool },
}

/// Binary values read in turn.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    little: bool,
}

impl Cursor<'_> {
    /// The next value of type `ty`, or `None` at the end of the data.
    fn next(&mut self, ty: Ty) -> Option<f64> {
        let n = ty.size();
        let raw = self.bytes.get(self.pos..self.pos + n)?;
        self.pos += n;
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(raw);
        if !self.little {
            b[..n].reverse();
        }
        Some(match ty {
            Ty::I8 => b[0] as i8 as f64,
            Ty::U8 => b[0] as f64,
            Ty::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Ty::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Ty::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Ty::F64 => f64::from_le_bytes(b),
        })
    }
}

/// The header lines (1-based number, text) up to and including
/// `end_header`, and the offset of the data after it.
fn header_lines(path: &Path, bytes: &[u8]) -> Result<(Vec<(usize, String)>, usize), IoError> {
    let mut lines = Vec::new();
    let mut pos = 0;
    while pos < bytes.len() {
        let end = bytes[pos..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(bytes.len(), |k| pos + k);
        let l = lines.len() + 1;
        let text = std::str::from_utf8(&bytes[pos..end])
            .map_err(|_| IoError::at(path, l, "the header line is not text"))?
            .trim_end_matches('\r')
            .to_string();
        pos = (end + 1).min(bytes.len());
        if l == 1 && text.trim() != "ply" {
            return Err(IoError::at(
                path,
                1,
                format!(
                    "expected 'ply' on the first line, found '{}'",
                    short(text.trim())
                ),
            ));
        }
        let done = text.trim() == "end_header";
        lines.push((l, text));
        if done {
            return Ok((lines, pos));
        }
    }
    if lines.is_empty() {
        return Err(IoError::at(path, 1, "empty file: expected 'ply'"));
    }
    Err(IoError::at(
        path,
        lines.len(),
        "file ends inside the header (no end_header)",
    ))
}

/// Reads a `.ply` file, ASCII or binary.
pub fn read(path: &Path) -> Result<SurfaceFile, IoError> {
    let bytes = read_bytes(path)?;
    let (header, body) = header_lines(path, &bytes)?;
    let mut lines = header.iter().map(|(l, t)| (*l, t.as_str()));
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
    let mut format = None;
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
                format = Some(match t.next() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Binary { little: true },
                    Some("binary_big_endian") => Format::Binary { little: false },
                    other => {
                        return Err(IoError::at(
                            path,
                            l,
                            format!("unknown PLY format '{}'", short(other.unwrap_or(""))),
                        ))
                    }
                });
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
                    let (Some(ct), Some(it)) = (
                        Ty::parse(t.next().unwrap_or("")),
                        Ty::parse(t.next().unwrap_or("")),
                    ) else {
                        return Err(IoError::at(path, l, "list property with an unknown type"));
                    };
                    let name = t
                        .next()
                        .ok_or_else(|| IoError::at(path, l, "property without a name"))?;
                    el.props.push(Prop::List(name.to_string(), ct, it));
                } else {
                    let Some(ty) = Ty::parse(ty) else {
                        return Err(IoError::at(
                            path,
                            l,
                            format!("unknown property type '{}'", short(ty)),
                        ));
                    };
                    let name = t
                        .next()
                        .ok_or_else(|| IoError::at(path, l, "property without a name"))?;
                    el.props.push(Prop::Scalar(name.to_string(), ty));
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
    let Some(format) = format else {
        return Err(IoError::at(path, last_line, "header has no 'format' line"));
    };
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
            .position(|p| matches!(p, Prop::Scalar(s, _) if s == n))
    };
    let (Some(ix), Some(iy), Some(iz)) = (vpos("x"), vpos("y"), vpos("z")) else {
        return Err(IoError::at(
            path,
            elements[vi].line,
            "the vertex element lacks one of the properties x, y, z",
        ));
    };
    let nv = elements[vi].count;
    // The data: text lines after the header, or binary values.
    let body_text = match format {
        Format::Ascii => std::str::from_utf8(&bytes[body..])
            .map_err(|_| IoError::file(path, "an ASCII PLY whose data is not text"))?,
        Format::Binary { .. } => "",
    };
    let mut text = (header.len() + 1..).zip(body_text.lines());
    let mut cursor = Cursor {
        bytes: &bytes[body..],
        pos: 0,
        little: format == Format::Binary { little: true },
    };
    for el in &elements {
        if el.props.is_empty() && format != Format::Ascii {
            // No bytes per entry: nothing to read, however large the count.
            continue;
        }
        let is_face = el.name == "face";
        let list_at = if is_face {
            let p = el.props.iter().position(
                |p| matches!(p, Prop::List(s, _, _) if s == "vertex_indices" || s == "vertex_index"),
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
            let truncated = || {
                format!(
                    "file ends after {i} of {} '{}' entries (truncated?)",
                    el.count, el.name
                )
            };
            // The entry's tokens (ASCII) and line (0 in binary).
            let (l, mut tokens) = match format {
                Format::Ascii => {
                    let (l, raw) = text
                        .next()
                        .ok_or_else(|| IoError::at(path, last_line, truncated()))?;
                    last_line = l;
                    (l, Some(raw.split_whitespace()))
                }
                Format::Binary { .. } => (0, None),
            };
            let mut value = |ty: Ty, what: &str| -> Result<f64, IoError> {
                match tokens.as_mut() {
                    Some(t) => parse_coord(path, l, t.next(), what),
                    None => {
                        let v = cursor
                            .next(ty)
                            .ok_or_else(|| IoError::file(path, truncated()))?;
                        if v.is_finite() {
                            Ok(v)
                        } else {
                            Err(IoError::file(
                                path,
                                format!("'{}' entry {i}: {what} is {v}", el.name),
                            ))
                        }
                    }
                }
            };
            let at = |message: String| {
                if l > 0 {
                    IoError::at(path, l, message)
                } else {
                    IoError::file(path, format!("'{}' entry {i}: {message}", el.name))
                }
            };
            let mut xyz = [0.0; 3];
            let mut face = Vec::new();
            for (k, p) in el.props.iter().enumerate() {
                match p {
                    Prop::Scalar(name, ty) => {
                        let v = value(*ty, &format!("the value of '{name}'"))?;
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
                    Prop::List(name, ct, it) => {
                        let n = value(*ct, &format!("the length of list '{name}'"))?;
                        if n < 0.0 || n.fract() != 0.0 {
                            return Err(at(format!("bad list length {n}")));
                        }
                        for _ in 0..n as usize {
                            let v = value(*it, "a list entry")?;
                            if Some(k) == list_at {
                                if v < 0.0 || v.fract() != 0.0 || v >= nv as f64 {
                                    return Err(at(format!(
                                        "vertex index {v} is out of range 0..{nv}"
                                    )));
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
                check_face(path, l.max(1), &face, nv, 0).map_err(|e| match e.kind {
                    IoErrorKind::Invalid(m) => at(m),
                    _ => e,
                })?;
                out.mesh.faces.push(face);
                out.face_lines.push(l as u32);
            }
        }
    }
    if let Format::Binary { .. } = format {
        if cursor.pos != cursor.bytes.len() {
            return Err(IoError::file(
                path,
                format!(
                    "{} bytes after the last element (a wrong count in the header?)",
                    cursor.bytes.len() - cursor.pos
                ),
            ));
        }
    }
    Ok(out)
}

/// Writes a binary (little-endian) `.ply` file.
pub fn write(path: &Path, mesh: &PolyMesh) -> Result<(), IoError> {
    write_with(path, mesh, false, None)
}

/// Writes a `.ply` file, ASCII or binary little-endian, with the face
/// attributes as `uint` face properties (their length is the caller's to
/// check; [`super::io::write_surface_with`] does).
pub fn write_with(
    path: &Path,
    mesh: &PolyMesh,
    ascii: bool,
    attributes: Option<&FaceAttributes>,
) -> Result<(), IoError> {
    let wide = mesh.faces.iter().any(|f| f.len() > 255);
    let count_type = if wide { "int" } else { "uchar" };
    let columns = attributes.map(attribute_columns);
    write_atomic(path, |w| {
        writeln!(w, "ply")?;
        if ascii {
            writeln!(w, "format ascii 1.0")?;
        } else {
            writeln!(w, "format binary_little_endian 1.0")?;
        }
        writeln!(w, "comment written by tetrefine")?;
        writeln!(w, "element vertex {}", mesh.points.len())?;
        writeln!(w, "property double x")?;
        writeln!(w, "property double y")?;
        writeln!(w, "property double z")?;
        writeln!(w, "element face {}", mesh.faces.len())?;
        writeln!(w, "property list {count_type} int vertex_indices")?;
        if columns.is_some() {
            for name in ATTRIBUTE_NAMES {
                writeln!(w, "property uint {name}")?;
            }
        }
        writeln!(w, "end_header")?;
        if ascii {
            for p in &mesh.points {
                writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
            }
            for (i, f) in mesh.faces.iter().enumerate() {
                write!(w, "{}", f.len())?;
                for &v in f {
                    write!(w, " {v}")?;
                }
                if let Some(cols) = &columns {
                    for c in cols {
                        write!(w, " {}", c[i])?;
                    }
                }
                writeln!(w)?;
            }
        } else {
            for p in &mesh.points {
                for x in p.to_array() {
                    w.write_all(&x.to_le_bytes())?;
                }
            }
            for (i, f) in mesh.faces.iter().enumerate() {
                if wide {
                    w.write_all(&(f.len() as i32).to_le_bytes())?;
                } else {
                    w.write_all(&[f.len() as u8])?;
                }
                for &v in f {
                    w.write_all(&(v as i32).to_le_bytes())?;
                }
                if let Some(cols) = &columns {
                    for c in cols {
                        w.write_all(&c[i].to_le_bytes())?;
                    }
                }
            }
        }
        Ok(())
    })
}
