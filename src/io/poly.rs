//! TetGen's surface formats `.poly` and `.smesh` (TetGen 1.5 manual, §5.2),
//! read into a [`Plc`].
//!
//! Both are line oriented, `#` starts a comment:
//!
//! 1. points: `<#points> <dim = 3> <#attributes> <markers 0|1>`, then one
//!    line per point `<index> <x> <y> <z> [attributes] [marker]`. The index
//!    of the first point (0 or 1) is the numbering base of the whole file.
//!    With 0 points they come from the `.node` file of the same name.
//! 2. facets: `<#facets> <markers 0|1>`, then per facet
//!    * `.poly`: `<#polygons> [#holes] [marker]`, one line per polygon
//!      `<#corners> <c1> … <cn>`, one line per facet hole `<index> <x> <y> <z>`;
//!    * `.smesh`: one line `<#corners> <c1> … <cn> [marker]`.
//! 3. holes: `<#holes>`, then `<index> <x> <y> <z>` (optional at the end).
//! 4. regions: `<#regions>`, then `<index> <x> <y> <z> <attribute> [max volume]`
//!    (optional). Attributes must be integers (they become region ids); a
//!    maximum volume that is missing or not positive means no constraint.

use super::plc::{Facet, Plc, Region};
use super::text::as_text;
use super::{read_bytes, IoError};
use std::path::Path;
use std::str::FromStr;

/// Non-empty lines of a file with comments removed, each with its 1-based
/// line number and tokens.
struct Lines<'a> {
    path: &'a Path,
    lines: Vec<(usize, Vec<&'a str>)>,
    pos: usize,
    /// Line of the last line returned (for errors after the end).
    last: usize,
    /// `tokens_from[i]`: the number of tokens on lines `i..` (a count may not
    /// promise more items than there are tokens left).
    tokens_from: Vec<usize>,
}

impl<'a> Lines<'a> {
    fn new(path: &'a Path, text: &'a str) -> Lines<'a> {
        let lines = text
            .lines()
            .enumerate()
            .filter_map(|(i, l)| {
                let l = l.split('#').next().unwrap_or("");
                let toks: Vec<&str> = l.split_whitespace().collect();
                (!toks.is_empty()).then_some((i + 1, toks))
            })
            .collect::<Vec<(usize, Vec<&str>)>>();
        let mut tokens_from = vec![0; lines.len() + 1];
        for i in (0..lines.len()).rev() {
            tokens_from[i] = tokens_from[i + 1] + lines[i].1.len();
        }
        Lines {
            path,
            lines,
            pos: 0,
            last: 1,
            tokens_from,
        }
    }

    fn at_end(&self) -> bool {
        self.pos >= self.lines.len()
    }

    /// The next line's number and tokens.
    fn next(&mut self, what: &str) -> Result<(usize, Vec<&'a str>), IoError> {
        match self.lines.get(self.pos) {
            Some((n, t)) => {
                self.pos += 1;
                self.last = *n;
                Ok((*n, t.clone()))
            }
            None => Err(IoError::at(
                self.path,
                self.last,
                format!("file ends where {what} was expected (truncated?)"),
            )),
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> IoError {
        IoError::at(self.path, line, message)
    }

    fn parse<T: FromStr>(&self, line: usize, tok: Option<&str>, what: &str) -> Result<T, IoError> {
        let tok = tok.ok_or_else(|| self.error(line, format!("{what} is missing")))?;
        tok.parse::<T>()
            .map_err(|_| self.error(line, format!("expected {what}, found '{}'", short(tok))))
    }

    fn count(&self, line: usize, tok: Option<&str>, what: &str) -> Result<usize, IoError> {
        let n: i64 = self.parse(line, tok, what)?;
        if !(0..=(u32::MAX / 4) as i64).contains(&n) {
            return Err(self.error(line, format!("{what} {n} is not valid")));
        }
        // Every item takes at least one token (of the count's own line or
        // the lines after it): checked before anything is allocated.
        let left = self.tokens_from[self.pos.saturating_sub(1).min(self.lines.len())];
        if n as usize > left {
            return Err(self.error(
                line,
                format!("{what} {n} is more than the {left} values left in the file (truncated or corrupt count)"),
            ));
        }
        Ok(n as usize)
    }

    fn coord(&self, line: usize, tok: Option<&str>, what: &str) -> Result<f64, IoError> {
        let x: f64 = self.parse(line, tok, what)?;
        if !x.is_finite() {
            return Err(self.error(line, format!("{what} is {x}, not a finite number")));
        }
        Ok(x)
    }

    fn point3(&self, line: usize, toks: &[&str], first: usize) -> Result<[f64; 3], IoError> {
        Ok([
            self.coord(line, toks.get(first).copied(), "an x coordinate")?,
            self.coord(line, toks.get(first + 1).copied(), "a y coordinate")?,
            self.coord(line, toks.get(first + 2).copied(), "a z coordinate")?,
        ])
    }

    /// A point index in the file's numbering, returned 0-based.
    fn index(&self, line: usize, tok: &str, base: i64, n: usize) -> Result<u32, IoError> {
        let i: i64 = self.parse(line, Some(tok), "a point index")?;
        if i < base || i - base >= n as i64 {
            return Err(self.error(
                line,
                format!(
                    "point index {i} is out of range {base}..={}",
                    base + n as i64 - 1
                ),
            ));
        }
        Ok((i - base) as u32)
    }

    /// `n` indices: the tokens of the current line from `from`, continued on
    /// the following lines when the line is short (TetGen allows that).
    fn indices(
        &mut self,
        line: usize,
        toks: &[&'a str],
        from: usize,
        n: usize,
        base: i64,
        np: usize,
    ) -> Result<(Vec<u32>, usize, Vec<&'a str>), IoError> {
        let mut out = Vec::with_capacity(n);
        let (mut line, mut toks, mut at) = (line, toks.to_vec(), from);
        while out.len() < n {
            if at >= toks.len() {
                let (l, t) = self.next("more polygon corners")?;
                line = l;
                toks = t;
                at = 0;
            }
            out.push(self.index(line, toks[at], base, np)?);
            at += 1;
        }
        Ok((out, line, toks[at..].to_vec()))
    }
}

fn short(s: &str) -> String {
    s.chars().take(24).collect()
}

/// Reads the point section (header and points). Returns the points and the
/// numbering base.
fn read_points(lines: &mut Lines, path: &Path) -> Result<(Vec<[f64; 3]>, i64), IoError> {
    let (l, h) = lines.next("the point count")?;
    let n = lines.count(l, h.first().copied(), "the point count")?;
    if let Some(d) = h.get(1) {
        let d: i64 = lines.parse(l, Some(d), "the dimension")?;
        if d != 3 {
            return Err(lines.error(l, format!("dimension {d}: only 3-D surfaces are supported")));
        }
    }
    if n == 0 {
        return read_node_file(&path.with_extension("node"), path);
    }
    let mut points = Vec::with_capacity(n);
    let mut base = 0;
    for i in 0..n {
        let (l, t) = lines.next("a point")?;
        let idx: i64 = lines.parse(l, t.first().copied(), "a point index")?;
        if i == 0 {
            if idx != 0 && idx != 1 {
                return Err(lines.error(
                    l,
                    format!("the first point is numbered {idx}; TetGen files number from 0 or 1"),
                ));
            }
            base = idx;
        }
        points.push(lines.point3(l, &t, 1)?);
    }
    Ok((points, base))
}

/// Points from a `.node` file (when the `.poly`/`.smesh` lists none).
fn read_node_file(node: &Path, from: &Path) -> Result<(Vec<[f64; 3]>, i64), IoError> {
    if !node.is_file() {
        return Err(IoError::file(
            from,
            format!(
                "lists 0 points, so they must come from {}, which does not exist",
                node.display()
            ),
        ));
    }
    let bytes = read_bytes(node)?;
    let text = as_text(node, &bytes)?;
    let mut lines = Lines::new(node, text);
    let (l, h) = lines.next("the point count")?;
    if lines.count(l, h.first().copied(), "the point count")? == 0 {
        return Err(lines.error(l, "the .node file lists 0 points"));
    }
    lines.pos = 0;
    read_points(&mut lines, node)
}

/// Reads the hole and region sections (both optional at the end of the file).
fn read_seeds(lines: &mut Lines, plc: &mut Plc) -> Result<(), IoError> {
    if lines.at_end() {
        return Ok(());
    }
    let (l, h) = lines.next("the hole count")?;
    let n = lines.count(l, h.first().copied(), "the hole count")?;
    for _ in 0..n {
        let (l, t) = lines.next("a hole")?;
        plc.holes.push(lines.point3(l, &t, 1)?);
        plc.seed_lines.holes.push(l);
    }
    if lines.at_end() {
        return Ok(());
    }
    let (l, h) = lines.next("the region count")?;
    let n = lines.count(l, h.first().copied(), "the region count")?;
    for _ in 0..n {
        let (l, t) = lines.next("a region")?;
        let point = lines.point3(l, &t, 1)?;
        let a = lines.coord(l, t.get(4).copied(), "a region attribute")?;
        if a.fract() != 0.0 || a < i32::MIN as f64 || a > i32::MAX as f64 {
            return Err(lines.error(
                l,
                format!("region attribute {a} is not an integer: attributes become region ids"),
            ));
        }
        let max_volume = match t.get(5) {
            Some(v) => {
                let v = lines.coord(l, Some(v), "a maximum volume")?;
                (v > 0.0).then_some(v)
            }
            None => None,
        };
        plc.regions.push(Region {
            point,
            attribute: a as i32,
            max_volume,
        });
        plc.seed_lines.regions.push(l);
    }
    Ok(())
}

/// What the facet readers of `.poly` and `.smesh` get from the shared part
/// of the file: the facet count, whether facets carry markers, the index
/// base and the number of points.
struct FacetSection {
    count: usize,
    markers: bool,
    base: i64,
    n_points: usize,
}

/// Reads a `.poly`-family file: the node section, the facet header, the
/// facets (by `read_facets`, whose layout differs between `.poly` and
/// `.smesh`), then holes and region seeds.
fn read_plc_file(
    path: &Path,
    read_facets: impl FnOnce(&mut Lines, &FacetSection, &mut Plc) -> Result<(), IoError>,
) -> Result<Plc, IoError> {
    let bytes = read_bytes(path)?;
    let text = as_text(path, &bytes)?;
    let mut lines = Lines::new(path, text);
    if lines.at_end() {
        return Err(IoError::file(path, "empty file"));
    }
    let (points, base) = read_points(&mut lines, path)?;
    let n_points = points.len();
    let mut plc = Plc {
        points,
        ..Default::default()
    };
    let (l, h) = lines.next("the facet count")?;
    let count = lines.count(l, h.first().copied(), "the facet count")?;
    let markers = match h.get(1) {
        Some(m) => lines.parse::<i64>(l, Some(m), "the facet marker flag")? != 0,
        None => false,
    };
    let section = FacetSection {
        count,
        markers,
        base,
        n_points,
    };
    read_facets(&mut lines, &section, &mut plc)?;
    read_seeds(&mut lines, &mut plc)?;
    Ok(plc)
}

/// Reads a TetGen `.poly` file.
pub fn read_poly(path: &Path) -> Result<Plc, IoError> {
    read_plc_file(path, |lines, fs, plc| {
        for _ in 0..fs.count {
            let (l, t) = lines.next("a facet")?;
            let npoly = lines.count(l, t.first().copied(), "the polygon count")?;
            if npoly == 0 {
                return Err(lines.error(l, "a facet must have at least one polygon"));
            }
            let nholes = match t.get(1) {
                Some(x) => lines.count(l, Some(x), "the facet hole count")?,
                None => 0,
            };
            let marker = match (fs.markers, t.get(2)) {
                (true, Some(m)) => lines.parse::<i32>(l, Some(m), "a facet marker")?,
                _ => 0,
            };
            let mut facet = Facet {
                marker,
                ..Default::default()
            };
            for _ in 0..npoly {
                let (l, t) = lines.next("a polygon")?;
                let nc = lines.count(l, t.first().copied(), "the corner count")?;
                if nc == 0 {
                    return Err(lines.error(l, "a polygon must have at least one corner"));
                }
                let (poly, _, _) = lines.indices(l, &t, 1, nc, fs.base, fs.n_points)?;
                facet.polygons.push(poly);
            }
            for _ in 0..nholes {
                let (l, t) = lines.next("a facet hole")?;
                facet.holes.push(lines.point3(l, &t, 1)?);
            }
            plc.facets.push(facet);
        }
        Ok(())
    })
}

/// Reads a TetGen `.smesh` file (one polygon per facet).
pub fn read_smesh(path: &Path) -> Result<Plc, IoError> {
    read_plc_file(path, |lines, fs, plc| {
        for _ in 0..fs.count {
            let (l, t) = lines.next("a facet")?;
            let nc = lines.count(l, t.first().copied(), "the corner count")?;
            if nc == 0 {
                return Err(lines.error(l, "a facet must have at least one corner"));
            }
            let (poly, last_line, rest) = lines.indices(l, &t, 1, nc, fs.base, fs.n_points)?;
            let marker = match (fs.markers, rest.first()) {
                (true, Some(m)) => lines.parse::<i32>(last_line, Some(m), "a facet marker")?,
                _ => 0,
            };
            plc.facets.push(Facet {
                polygons: vec![poly],
                holes: Vec::new(),
                marker,
            });
        }
        Ok(())
    })
}
