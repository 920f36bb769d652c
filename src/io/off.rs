//! Object File Format `.off` (Geomview), ASCII: the one OFF reader, read
//! into an [`OffFile`] (also by the `tetrefine-surface` crate) or a [`Plc`].
//!
//! `OFF` (or `COFF`, `NOFF`, `CNOFF`, `STOFF`…: per-vertex extras are
//! ignored), then `<#vertices> <#faces> <#edges>` (on the header line or the
//! next), one line per vertex `x y z [extras]`, one line per face
//! `k i1 … ik [colour]` with 0-based indices. `#` starts a comment. In a
//! [`Plc`] every face becomes a facet with marker 0 (OFF has no markers).

use super::plc::{Facet, Plc};
use super::text::as_text;
use super::{read_bytes, IoError};
use std::path::Path;

/// The points and faces of an OFF file, with the line of each face.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OffFile {
    /// Vertex coordinates, all finite.
    pub points: Vec<[f64; 3]>,
    /// Faces as 0-based vertex ids, each with at least three, all in range.
    pub faces: Vec<Vec<u32>>,
    /// The 1-based line of each face.
    pub face_lines: Vec<u32>,
}

/// Reads an ASCII OFF file into a [`Plc`], one facet per face.
pub fn read(path: &Path) -> Result<Plc, IoError> {
    let off = read_off(path)?;
    Ok(Plc {
        points: off.points,
        facets: off
            .faces
            .into_iter()
            .map(|poly| Facet {
                polygons: vec![poly],
                holes: Vec::new(),
                marker: 0,
            })
            .collect(),
        ..Default::default()
    })
}

/// Reads an ASCII OFF file: points, faces and the line of each face.
pub fn read_off(path: &Path) -> Result<OffFile, IoError> {
    let bytes = read_bytes(path)?;
    let text = as_text(path, &bytes)?;
    let mut lines = text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.split('#').next().unwrap_or("");
        let toks: Vec<&str> = l.split_whitespace().collect();
        (!toks.is_empty()).then_some((i + 1, toks))
    });
    let err = |line: usize, m: String| IoError::at(path, line, m);
    let (l, head) = lines
        .next()
        .ok_or_else(|| IoError::file(path, "empty file"))?;
    let kw = head[0];
    let is_off = kw.ends_with("OFF")
        && kw[..kw.len() - 3]
            .chars()
            .all(|c| matches!(c, 'C' | 'N' | 'S' | 'T'));
    if !is_off {
        return Err(err(
            l,
            format!(
                "expected the OFF header keyword, found '{}' (4OFF and nOFF are not supported)",
                kw.chars().take(24).collect::<String>()
            ),
        ));
    }
    let (l, counts) = if head.len() > 1 {
        (l, head[1..].to_vec())
    } else {
        lines.next().ok_or_else(|| {
            err(
                l,
                "file ends where the vertex and face counts were expected".into(),
            )
        })?
    };
    let count = |tok: Option<&&str>, what: &str| -> Result<usize, IoError> {
        let tok = tok.ok_or_else(|| err(l, format!("{what} is missing")))?;
        match tok.parse::<i64>() {
            Ok(n) if (0..=(u32::MAX / 4) as i64).contains(&n) => Ok(n as usize),
            _ => Err(err(l, format!("expected {what}, found '{tok}'"))),
        }
    };
    let nv = count(counts.first(), "the vertex count")?;
    let nf = count(counts.get(1), "the face count")?;
    // A vertex line takes at least 6 bytes ("0 0 0\n") and a face line 8:
    // a count the file cannot hold is refused before anything is allocated.
    if nv.saturating_mul(6).saturating_add(nf.saturating_mul(8)) > text.len() {
        return Err(err(
            l,
            format!(
                "{nv} vertices and {nf} faces cannot fit in the {} bytes of the file (truncated or corrupt counts)",
                text.len()
            ),
        ));
    }
    let mut points = Vec::with_capacity(nv);
    let mut last = l;
    for _ in 0..nv {
        let (l, t) = lines.next().ok_or_else(|| {
            err(
                last,
                "file ends where a vertex was expected (truncated?)".into(),
            )
        })?;
        last = l;
        let mut p = [0.0; 3];
        for (k, what) in ["an x", "a y", "a z"].iter().enumerate() {
            let tok = t
                .get(k)
                .ok_or_else(|| err(l, format!("{what} coordinate is missing")))?;
            let x: f64 = tok
                .parse()
                .map_err(|_| err(l, format!("expected {what} coordinate, found '{tok}'")))?;
            if !x.is_finite() {
                return Err(err(
                    l,
                    format!("{what} coordinate is {x}, not a finite number"),
                ));
            }
            p[k] = x;
        }
        points.push(p);
    }
    let mut faces = Vec::with_capacity(nf);
    let mut face_lines = Vec::with_capacity(nf);
    for _ in 0..nf {
        let (l, t) = lines.next().ok_or_else(|| {
            err(
                last,
                "file ends where a face was expected (truncated?)".into(),
            )
        })?;
        last = l;
        let k: i64 = t[0]
            .parse()
            .map_err(|_| err(l, format!("expected a face size, found '{}'", t[0])))?;
        if k < 3 {
            return Err(err(
                l,
                format!("a face has {k} vertices; at least 3 are needed"),
            ));
        }
        let k = k as usize;
        if t.len() < 1 + k {
            return Err(err(
                l,
                format!("the face lists {} of its {k} vertices", t.len() - 1),
            ));
        }
        let mut poly = Vec::with_capacity(k);
        for tok in &t[1..=k] {
            match tok.parse::<i64>() {
                Ok(i) if (0..nv as i64).contains(&i) => poly.push(i as u32),
                Ok(i) => {
                    return Err(err(
                        l,
                        format!("vertex index {i} is out of range 0..={}", nv as i64 - 1),
                    ))
                }
                Err(_) => return Err(err(l, format!("expected a vertex index, found '{tok}'"))),
            }
        }
        faces.push(poly);
        face_lines.push(u32::try_from(l).expect("a line number fits in u32"));
    }
    Ok(OffFile {
        points,
        faces,
        face_lines,
    })
}
