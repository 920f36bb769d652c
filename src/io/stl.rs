//! Stereolithography `.stl`, ASCII and binary, read into a [`Plc`].
//!
//! STL lists every triangle with its own three vertices; vertices with
//! exactly equal coordinates are merged (no tolerance: a surface that only
//! closes up to rounding stays open and is reported so). Every triangle
//! becomes a facet with marker 0 (STL has no markers).
//!
//! Binary: an 80-byte header, a little-endian `u32` triangle count, then 50
//! bytes per triangle (normal, three vertices as `f32`, a `u16`). A file whose
//! size is exactly `84 + 50 n` is binary, even if its header starts with
//! `solid` (many exporters write that); otherwise it must be ASCII:
//! `solid [name]`, then `facet normal nx ny nz`, `outer loop`, three
//! `vertex x y z`, `endloop`, `endfacet` per triangle, `endsolid [name]`.
//! Several solids in one file are read as one surface.

use super::plc::Plc;
use super::text::{as_text, Tokens};
use super::{read_bytes, IoError};
use std::collections::HashMap;
use std::path::Path;

/// Merges exactly equal vertices while the triangles are read.
#[derive(Default)]
struct Vertices {
    points: Vec<[f64; 3]>,
    index: HashMap<[u64; 3], u32>,
}

impl Vertices {
    fn get(&mut self, p: [f64; 3]) -> u32 {
        // `+ 0.0` turns -0.0 into 0.0 so that the two merge.
        let key = p.map(|c| (c + 0.0).to_bits());
        let n = self.points.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.points.push(p);
            n
        })
    }
}

/// Reads an STL file, ASCII or binary.
pub fn read(path: &Path) -> Result<Plc, IoError> {
    let bytes = read_bytes(path)?;
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return read_binary(path, &bytes, n as usize);
        }
    }
    let start = bytes
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    if bytes[start..].starts_with(b"solid") {
        return read_ascii(path, &bytes);
    }
    if bytes.is_empty() {
        return Err(IoError::file(path, "empty file"));
    }
    Err(IoError::file(
        path,
        if bytes.len() >= 84 {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            format!(
                "neither ASCII STL (no 'solid' at the start) nor binary STL \
                 ({n} triangles need {} bytes, the file has {})",
                84 + 50 * n,
                bytes.len()
            )
        } else {
            "neither ASCII STL (no 'solid' at the start) nor binary STL (shorter than 84 bytes)"
                .to_string()
        },
    ))
}

fn read_binary(path: &Path, bytes: &[u8], n: usize) -> Result<Plc, IoError> {
    let mut v = Vertices::default();
    let mut tris = Vec::with_capacity(n);
    for t in 0..n {
        let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
        let f = |k: usize| {
            let o = 12 + 4 * k;
            f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
        };
        let mut ids = [0u32; 3];
        for (c, id) in ids.iter_mut().enumerate() {
            let p = [f(3 * c), f(3 * c + 1), f(3 * c + 2)];
            if !p.iter().all(|x| x.is_finite()) {
                return Err(IoError::file(
                    path,
                    format!("triangle {} has a non-finite coordinate {p:?}", t + 1),
                ));
            }
            *id = v.get(p);
        }
        if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
            return Err(IoError::file(
                path,
                format!(
                    "triangle {} is degenerate: two of its vertices coincide",
                    t + 1
                ),
            ));
        }
        tris.push((ids, 0));
    }
    if tris.is_empty() {
        return Err(IoError::file(path, "the file holds no triangles"));
    }
    Ok(Plc::from_triangles(v.points, &tris))
}

fn expect(tok: &mut Tokens, word: &str) -> Result<(), IoError> {
    match tok.next() {
        Some(w) if w.eq_ignore_ascii_case(word) => Ok(()),
        Some(w) => Err(tok.error(format!(
            "expected '{word}', found '{}'",
            w.chars().take(24).collect::<String>()
        ))),
        None => Err(tok.error(format!(
            "file ends where '{word}' was expected (truncated?)"
        ))),
    }
}

fn read_ascii(path: &Path, bytes: &[u8]) -> Result<Plc, IoError> {
    let text = as_text(path, bytes)?;
    let mut tok = Tokens::new(path, text, false);
    let mut v = Vertices::default();
    let mut tris = Vec::new();
    expect(&mut tok, "solid")?;
    tok.skip_line(); // the solid's name
    loop {
        match tok.next() {
            Some(w) if w.eq_ignore_ascii_case("facet") => {
                let line = tok.line();
                expect(&mut tok, "normal")?;
                for _ in 0..3 {
                    let _: f64 = tok.parse("a normal component")?;
                }
                expect(&mut tok, "outer")?;
                expect(&mut tok, "loop")?;
                let mut ids = [0u32; 3];
                for id in &mut ids {
                    expect(&mut tok, "vertex")?;
                    let p = [
                        tok.coord("an x coordinate")?,
                        tok.coord("a y coordinate")?,
                        tok.coord("a z coordinate")?,
                    ];
                    *id = v.get(p);
                }
                expect(&mut tok, "endloop")?;
                expect(&mut tok, "endfacet")?;
                if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                    return Err(IoError::at(
                        path,
                        line,
                        "degenerate triangle: two of its vertices coincide",
                    ));
                }
                tris.push((ids, 0));
            }
            Some(w) if w.eq_ignore_ascii_case("endsolid") => {
                tok.skip_line();
                match tok.next() {
                    None => break,
                    Some(w) if w.eq_ignore_ascii_case("solid") => tok.skip_line(),
                    Some(w) => {
                        return Err(tok.error(format!(
                            "expected 'solid' or the end of the file, found '{}'",
                            w.chars().take(24).collect::<String>()
                        )))
                    }
                }
            }
            Some(w) => {
                return Err(tok.error(format!(
                    "expected 'facet' or 'endsolid', found '{}'",
                    w.chars().take(24).collect::<String>()
                )))
            }
            None => return Err(tok.error("file ends before 'endsolid' (truncated?)")),
        }
    }
    if tris.is_empty() {
        return Err(IoError::file(path, "the file holds no triangles"));
    }
    Ok(Plc::from_triangles(v.points, &tris))
}
