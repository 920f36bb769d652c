//! Binary Medit / MMG files: `.meshb` meshes and `.solb` solutions, in the
//! layout of Gamma's libMeshb (L. Maréchal), versions 1 to 4, either byte
//! order; also ASCII `.sol` solutions as fields ([`read_sol`]).
//!
//! A binary file is the integer 1 (which tells the byte order), the version,
//! then keywords: each is a 4-byte keyword code and the file offset of the
//! next keyword, then for keywords with entries their count, then the
//! entries. What the version sets:
//!
//! | version | reals | integers | offsets | entry counts |
//! |---|---|---|---|---|
//! | 1 | 4 bytes | 4 bytes | 4 bytes | 4 bytes |
//! | 2 | 8 bytes | 4 bytes | 4 bytes | 4 bytes |
//! | 3 | 8 bytes | 4 bytes | 8 bytes | 4 bytes |
//! | 4 | 8 bytes | 8 bytes | 8 bytes | 8 bytes |
//!
//! `Dimension` holds one 4-byte integer and no count; solution keywords
//! (`SolAtVertices`, `SolAtTetrahedra`) have, after their count, the number
//! of solutions and a 4-byte type each (1 scalar, 2 vector, 3 symmetric
//! tensor, 4 full tensor); `End` has offset 0. The mesh keywords read are
//! those of the ASCII reader ([`super::medit`]); any other keyword is jumped
//! over through its offset, with one note on stderr naming them.

use super::meta::Field;
use super::{read_bytes, write_atomic, IoError};
use crate::mesh::{MeshData, TetMesh};
use std::io::Write;
use std::path::Path;

const KW_DIMENSION: i32 = 3;
const KW_VERTICES: i32 = 4;
const KW_EDGES: i32 = 5;
const KW_TRIANGLES: i32 = 6;
const KW_TETRAHEDRA: i32 = 8;
const KW_CORNERS: i32 = 13;
const KW_RIDGES: i32 = 14;
const KW_REQUIRED_VERTICES: i32 = 15;
const KW_REQUIRED_EDGES: i32 = 16;
const KW_END: i32 = 54;
const KW_SOL_AT_VERTICES: i32 = 62;
const KW_SOL_AT_TETRAHEDRA: i32 = 66;

/// Where a solution lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolAt {
    /// `SolAtVertices`: one entry per point.
    Vertices,
    /// `SolAtTetrahedra`: one entry per tet.
    Tetrahedra,
}

/// One solution of a `.sol` / `.solb` file: its libMeshb type (1 scalar, 2
/// vector, 3 symmetric tensor in MMG's order xx, xy, yy, xz, yz, zz, 4 full
/// tensor) and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// libMeshb type code (1 to 4).
    pub kind: i32,
    /// The values as a field (`components` = 1, 3, 6 or 9).
    pub field: Field,
}

/// The solutions of one `SolAt…` keyword of a solution file.
#[derive(Clone, Debug, PartialEq)]
pub struct SolFile {
    /// Where the entries live.
    pub at: SolAt,
    /// Number of entries (points or tets).
    pub entries: usize,
    /// The solutions, in file order.
    pub solutions: Vec<Solution>,
    /// The line of the entry count (ASCII files), for messages.
    pub line: Option<usize>,
}

/// Values per entry of a solution type in 3-D.
fn width(kind: i64) -> Option<usize> {
    match kind {
        1 => Some(1),
        2 => Some(3),
        3 => Some(6),
        4 => Some(9),
        _ => None,
    }
}

/// A cursor over a binary libMeshb file.
struct Bin<'a> {
    path: &'a Path,
    b: &'a [u8],
    pos: usize,
    swap: bool,
    ver: i32,
}

impl Bin<'_> {
    fn error(&self, at: usize, message: impl Into<String>) -> IoError {
        IoError::file(self.path, format!("at byte {at}: {}", message.into()))
    }

    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], IoError> {
        if self.pos + N > self.b.len() {
            return Err(self.error(
                self.b.len(),
                format!("file ends where {what} was expected (truncated?)"),
            ));
        }
        let mut a = [0u8; N];
        a.copy_from_slice(&self.b[self.pos..self.pos + N]);
        if self.swap {
            a.reverse();
        }
        self.pos += N;
        Ok(a)
    }

    fn i32(&mut self, what: &str) -> Result<i32, IoError> {
        Ok(i32::from_le_bytes(self.take::<4>(what)?))
    }

    fn i64(&mut self, what: &str) -> Result<i64, IoError> {
        Ok(i64::from_le_bytes(self.take::<8>(what)?))
    }

    /// An integer field of an entry.
    fn int(&mut self, what: &str) -> Result<i64, IoError> {
        if self.ver >= 4 {
            self.i64(what)
        } else {
            self.i32(what).map(i64::from)
        }
    }

    /// A real field of an entry.
    fn real(&mut self, what: &str) -> Result<f64, IoError> {
        if self.ver == 1 {
            Ok(f32::from_le_bytes(self.take::<4>(what)?) as f64)
        } else {
            Ok(f64::from_le_bytes(self.take::<8>(what)?))
        }
    }

    /// A finite coordinate or value.
    fn finite(&mut self, what: &str) -> Result<f64, IoError> {
        let at = self.pos;
        let x = self.real(what)?;
        if !x.is_finite() {
            return Err(self.error(at, format!("{what} is {x}, not a finite number")));
        }
        Ok(x)
    }

    /// The offset of the next keyword.
    fn offset(&mut self) -> Result<u64, IoError> {
        if self.ver >= 3 {
            Ok(self.i64("a keyword offset")? as u64)
        } else {
            Ok(self.i32("a keyword offset")? as u32 as u64)
        }
    }

    /// An entry count, checked against what the rest of the file can hold.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize, IoError> {
        let at = self.pos;
        let n = if self.ver >= 4 {
            self.i64(what)?
        } else {
            self.i32(what)? as i64
        };
        let left = (self.b.len() - self.pos) / min_bytes.max(1);
        if n < 0 || n as u64 > left as u64 {
            return Err(self.error(
                at,
                format!(
                    "{what} {n} is more than the rest of the file can hold (corrupt or truncated)"
                ),
            ));
        }
        Ok(n as usize)
    }

    /// A 1-based index below `n`, as a 0-based id.
    fn index(&mut self, what: &str, n: usize) -> Result<u32, IoError> {
        let at = self.pos;
        let i = self.int(what)?;
        if i < 1 || i as u64 > n as u64 {
            return Err(self.error(at, format!("{what} {i} is not in 1..={n}")));
        }
        Ok((i - 1) as u32)
    }

    fn int_size(&self) -> usize {
        if self.ver >= 4 {
            8
        } else {
            4
        }
    }

    fn real_size(&self) -> usize {
        if self.ver == 1 {
            4
        } else {
            8
        }
    }
}

/// Opens a binary libMeshb file: byte order and version.
fn open<'a>(path: &'a Path, b: &'a [u8]) -> Result<Bin<'a>, IoError> {
    if b.len() < 8 {
        return Err(IoError::file(
            path,
            "too short for a binary Medit file (truncated?)",
        ));
    }
    let code = [b[0], b[1], b[2], b[3]];
    let swap = if i32::from_le_bytes(code) == 1 {
        false
    } else if i32::from_be_bytes(code) == 1 {
        true
    } else {
        return Err(IoError::file(
            path,
            "does not start with the binary Medit marker (the integer 1): not a .meshb/.solb file",
        ));
    };
    let mut c = Bin {
        path,
        b,
        pos: 4,
        swap,
        ver: 0,
    };
    let ver = c.i32("the version")?;
    if !(1..=4).contains(&ver) {
        return Err(c.error(4, format!("version {ver} is not 1, 2, 3 or 4")));
    }
    c.ver = ver;
    Ok(c)
}

/// Walks the keywords of a binary file, calling `body(cursor, code, start)`
/// with the cursor after each keyword's header; `body` returns whether it
/// knew the keyword. Unknown keywords are jumped over and named in one note.
fn walk(
    c: &mut Bin,
    mut body: impl FnMut(&mut Bin, i32, usize) -> Result<bool, IoError>,
) -> Result<(), IoError> {
    let mut unknown: Vec<i32> = Vec::new();
    let mut last = 0u64;
    loop {
        let start = c.pos;
        if start == c.b.len() {
            break; // no End keyword: tolerated, as libMeshb does
        }
        let code = c.i32("a keyword code")?;
        let next = c.offset()?;
        if next != 0 && (next <= start as u64 || next > c.b.len() as u64 || next <= last) {
            return Err(c.error(
                start,
                format!("keyword {code} gives the next keyword's offset as {next}, outside the file or not after it (corrupt)"),
            ));
        }
        last = next;
        if code == KW_END {
            break;
        }
        if code == KW_DIMENSION {
            let at = c.pos;
            let d = c.i32("the dimension")?;
            if d != 3 {
                return Err(c.error(at, format!("Dimension {d}: only 3-D meshes are supported")));
            }
        } else if !body(c, code, start)? && !unknown.contains(&code) {
            unknown.push(code);
        }
        if next == 0 {
            break;
        }
        if c.pos as u64 > next {
            return Err(c.error(
                start,
                format!("keyword {code}: its entries run past the next keyword (at byte {next}): the count does not match the data"),
            ));
        }
        c.pos = next as usize;
    }
    if !unknown.is_empty() {
        let list: Vec<String> = unknown.iter().map(i32::to_string).collect();
        eprintln!(
            "note: {}: skipped keywords with codes {} (not used by tetrefine)",
            c.path.display(),
            list.join(", ")
        );
    }
    Ok(())
}

/// Reads a binary Medit `.meshb` file (libMeshb versions 1–4).
pub fn read(path: &Path) -> Result<MeshData, IoError> {
    let bytes = read_bytes(path)?;
    let mut c = open(path, &bytes)?;
    let mut d = MeshData::default();
    let mut n_edges = 0usize;
    walk(&mut c, |c, code, start| {
        let (is, rs) = (c.int_size(), c.real_size());
        match code {
            KW_VERTICES => {
                let n = c.count("the vertex count", 3 * rs + is)?;
                d.points.reserve(n);
                for _ in 0..n {
                    let x = c.finite("an x coordinate")?;
                    let y = c.finite("a y coordinate")?;
                    let z = c.finite("a z coordinate")?;
                    c.int("a vertex reference")?;
                    d.points.push([x, y, z]);
                }
            }
            KW_TETRAHEDRA | KW_TRIANGLES | KW_EDGES => {
                let k = match code {
                    KW_TETRAHEDRA => 4,
                    KW_TRIANGLES => 3,
                    _ => 2,
                };
                if d.points.is_empty() {
                    return Err(c.error(start, "elements come before Vertices"));
                }
                let n = c.count("the element count", (k + 1) * is)?;
                let np = d.points.len();
                let mut v = [0u32; 4];
                for _ in 0..n {
                    for x in v.iter_mut().take(k) {
                        *x = c.index("a vertex index", np)?;
                    }
                    let r = c.int("an element reference")?;
                    let r = i32::try_from(r).map_err(|_| {
                        c.error(c.pos, format!("reference {r} does not fit 32 bits"))
                    })?;
                    match k {
                        4 => {
                            d.tets.push(v);
                            d.tet_regions.push(r);
                        }
                        3 => d.triangles.push(([v[0], v[1], v[2]], r)),
                        _ => d.edges.push(([v[0], v[1]], r)),
                    }
                }
                if k == 2 {
                    n_edges = d.edges.len();
                }
            }
            KW_CORNERS | KW_REQUIRED_VERTICES => {
                let n = c.count("the vertex count", is)?;
                let np = d.points.len();
                for _ in 0..n {
                    let v = c.index("a vertex index", np)?;
                    if code == KW_CORNERS {
                        d.corners.push(v);
                    } else {
                        d.required_vertices.push(v);
                    }
                }
            }
            KW_RIDGES | KW_REQUIRED_EDGES => {
                let n = c.count("the edge count", is)?;
                for _ in 0..n {
                    c.index("an edge number", n_edges)?;
                }
            }
            _ => return Ok(false),
        }
        Ok(true)
    })?;
    if d.tets.is_empty() {
        return Err(IoError::file(
            path,
            "no Tetrahedra keyword: not a volume mesh",
        ));
    }
    Ok(d)
}

/// A binary libMeshb file being written: keyword offsets are patched in as
/// each next keyword starts.
struct Out {
    b: Vec<u8>,
    ver: i32,
    /// Where the offset of the open keyword goes.
    pending: Option<usize>,
}

impl Out {
    fn new(ver: i32) -> Out {
        let mut o = Out {
            b: Vec::new(),
            ver,
            pending: None,
        };
        o.i32(1);
        o.i32(ver);
        o
    }
    fn i32(&mut self, v: i32) {
        self.b.extend_from_slice(&v.to_le_bytes());
    }
    fn int(&mut self, v: i64) {
        if self.ver >= 4 {
            self.b.extend_from_slice(&v.to_le_bytes());
        } else {
            self.i32(v as i32);
        }
    }
    fn real(&mut self, v: f64) {
        if self.ver == 1 {
            self.b.extend_from_slice(&(v as f32).to_le_bytes());
        } else {
            self.b.extend_from_slice(&v.to_le_bytes());
        }
    }
    /// Starts keyword `code` (with `count` entries unless `None`).
    fn keyword(&mut self, code: i32, count: Option<usize>) {
        let here = self.b.len() as u64;
        if let Some(p) = self.pending.take() {
            if self.ver >= 3 {
                self.b[p..p + 8].copy_from_slice(&here.to_le_bytes());
            } else {
                self.b[p..p + 4].copy_from_slice(&(here as u32).to_le_bytes());
            }
        }
        self.i32(code);
        self.pending = Some(self.b.len());
        if self.ver >= 3 {
            self.b.extend_from_slice(&0u64.to_le_bytes());
        } else {
            self.i32(0);
        }
        if let Some(n) = count {
            if self.ver >= 4 {
                self.b.extend_from_slice(&(n as i64).to_le_bytes());
            } else {
                self.i32(n as i32);
            }
        }
    }
    fn finish(mut self) -> Vec<u8> {
        self.keyword(KW_END, None);
        self.pending = None; // End's offset stays 0
        self.b
    }
}

fn check_version(path: &Path, version: i32) -> Result<(), IoError> {
    if (1..=4).contains(&version) {
        Ok(())
    } else {
        Err(IoError::file(
            path,
            format!("cannot write libMeshb version {version}: use 1 to 4"),
        ))
    }
}

/// Writes `mesh` as a binary `.meshb` of libMeshb `version` (1–4; MMG
/// writes 2).
pub fn write(path: &Path, mesh: &TetMesh, version: i32) -> Result<(), IoError> {
    write_data(path, &mesh.to_data(), version)
}

/// Writes plain mesh data as a binary `.meshb` of libMeshb `version`.
pub fn write_data(path: &Path, d: &MeshData, version: i32) -> Result<(), IoError> {
    check_version(path, version)?;
    if d.points.len() > i32::MAX as usize && version < 4 {
        return Err(IoError::file(
            path,
            "too many points for versions 1–3: use version 4",
        ));
    }
    let mut o = Out::new(version);
    o.keyword(KW_DIMENSION, None);
    o.i32(3);
    o.keyword(KW_VERTICES, Some(d.points.len()));
    for p in &d.points {
        for x in p {
            o.real(*x);
        }
        o.int(0);
    }
    if !d.edges.is_empty() {
        o.keyword(KW_EDGES, Some(d.edges.len()));
        for (e, m) in &d.edges {
            o.int(i64::from(e[0]) + 1);
            o.int(i64::from(e[1]) + 1);
            o.int((*m).into());
        }
        o.keyword(KW_RIDGES, Some(d.edges.len()));
        for i in 0..d.edges.len() {
            o.int(i as i64 + 1);
        }
    }
    if !d.triangles.is_empty() {
        o.keyword(KW_TRIANGLES, Some(d.triangles.len()));
        for (f, m) in &d.triangles {
            for v in f {
                o.int(i64::from(*v) + 1);
            }
            o.int((*m).into());
        }
    }
    for (code, list) in [
        (KW_CORNERS, &d.corners),
        (KW_REQUIRED_VERTICES, &d.required_vertices),
    ] {
        if !list.is_empty() {
            o.keyword(code, Some(list.len()));
            for v in list {
                o.int(i64::from(*v) + 1);
            }
        }
    }
    o.keyword(KW_TETRAHEDRA, Some(d.tets.len()));
    for (t, v) in d.tets.iter().enumerate() {
        for x in v {
            o.int(i64::from(*x) + 1);
        }
        o.int(d.region(t).into());
    }
    let bytes = o.finish();
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Whether `path` names a binary solution (`.solb`).
fn is_binary(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("solb"))
}

/// Names of the solutions of a file: `sol` for one, `sol_<i>` for several.
fn sol_name(i: usize, n: usize) -> String {
    if n == 1 {
        "sol".to_string()
    } else {
        format!("sol_{i}")
    }
}

/// Reads a Medit solution, `.sol` (ASCII) or `.solb` (binary, libMeshb 1–4):
/// its first `SolAtVertices` or `SolAtTetrahedra` keyword, with every
/// solution in it. Values must be finite.
pub fn read_sol(path: &Path) -> Result<SolFile, IoError> {
    if is_binary(path) {
        read_solb(path)
    } else {
        read_sol_ascii(path)
    }
}

fn read_solb(path: &Path) -> Result<SolFile, IoError> {
    let bytes = read_bytes(path)?;
    let mut c = open(path, &bytes)?;
    let mut found: Option<SolFile> = None;
    walk(&mut c, |c, code, start| {
        let at = match code {
            KW_SOL_AT_VERTICES => SolAt::Vertices,
            KW_SOL_AT_TETRAHEDRA => SolAt::Tetrahedra,
            _ => return Ok(false),
        };
        if found.is_some() {
            return Ok(true);
        }
        let n = c.count("the entry count", c.real_size())?;
        let ns = c.i32("the number of solutions")?;
        if !(1..=64).contains(&ns) {
            return Err(c.error(start, format!("{ns} solutions per entry is not valid")));
        }
        let mut kinds = Vec::new();
        for _ in 0..ns {
            let p = c.pos;
            let k = c.i32("a solution type")?;
            let w = width(k.into()).ok_or_else(|| {
                c.error(p, format!("solution type {k} is not 1 (scalar), 2 (vector), 3 (symmetric tensor) or 4 (tensor)"))
            })?;
            kinds.push((k, w));
        }
        let total: usize = kinds.iter().map(|k| k.1).sum();
        if n.saturating_mul(total).saturating_mul(c.real_size()) > c.b.len() - c.pos {
            return Err(c.error(start, format!("{n} entries of {total} values are more than the rest of the file holds (truncated?)")));
        }
        let mut sols: Vec<Solution> = kinds
            .iter()
            .enumerate()
            .map(|(i, &(k, w))| Solution {
                kind: k,
                field: Field {
                    name: sol_name(i, kinds.len()),
                    components: w,
                    values: Vec::with_capacity(n * w),
                },
            })
            .collect();
        for _ in 0..n {
            for s in sols.iter_mut() {
                for _ in 0..s.field.components {
                    let x = c.finite("a solution value")?;
                    s.field.values.push(x);
                }
            }
        }
        found = Some(SolFile {
            at,
            entries: n,
            solutions: sols,
            line: None,
        });
        Ok(true)
    })?;
    found.ok_or_else(|| IoError::file(path, "no SolAtVertices or SolAtTetrahedra keyword"))
}

fn read_sol_ascii(path: &Path) -> Result<SolFile, IoError> {
    let bytes = read_bytes(path)?;
    let text = super::text::as_text(path, &bytes)?;
    let mut tok = super::Tokens::new(path, text, true);
    let count = |tok: &mut super::Tokens, what: &str| -> Result<usize, IoError> {
        let n: i64 = tok.parse(what)?;
        if n < 0 || n as usize > text.len() {
            return Err(tok.error(format!("{what} {n} is not valid")));
        }
        Ok(n as usize)
    };
    while let Some(kw) = tok.next() {
        match kw {
            "MeshVersionFormatted" => super::medit::read_version(&mut tok)?,
            "Dimension" => {
                let d: i64 = tok.parse("the dimension")?;
                if d != 3 {
                    return Err(
                        tok.error(format!("Dimension {d}: only 3-D solutions are supported"))
                    );
                }
            }
            "SolAtVertices" | "SolAtTetrahedra" => {
                let at = if kw == "SolAtVertices" {
                    SolAt::Vertices
                } else {
                    SolAt::Tetrahedra
                };
                let n = count(&mut tok, "the entry count")?;
                let line = tok.line();
                let ns = count(&mut tok, "the number of solutions")?;
                if !(1..=64).contains(&ns) {
                    return Err(tok.error(format!("{ns} solutions per entry is not valid")));
                }
                let mut sols = Vec::with_capacity(ns);
                for i in 0..ns {
                    let k: i64 = tok.parse("a solution type")?;
                    let w = width(k).ok_or_else(|| {
                        tok.error(format!("solution type {k} is not 1 (scalar), 2 (vector), 3 (symmetric tensor) or 4 (tensor)"))
                    })?;
                    sols.push(Solution {
                        kind: k as i32,
                        field: Field {
                            name: sol_name(i, ns),
                            components: w,
                            values: Vec::with_capacity(n.min(text.len()) * w),
                        },
                    });
                }
                for _ in 0..n {
                    for s in sols.iter_mut() {
                        for _ in 0..s.field.components {
                            let x: f64 = match tok.next() {
                                Some(t) => t.parse().map_err(|_| {
                                    tok.error(format!("expected a solution value, found '{t}'"))
                                })?,
                                None => {
                                    return Err(tok.error(format!(
                                        "file ends inside {kw}: fewer than the {n} entries announced (truncated?)"
                                    )))
                                }
                            };
                            if !x.is_finite() {
                                return Err(
                                    tok.error(format!("solution value {x} is not a finite number"))
                                );
                            }
                            s.field.values.push(x);
                        }
                    }
                }
                return Ok(SolFile {
                    at,
                    entries: n,
                    solutions: sols,
                    line: Some(line),
                });
            }
            "End" => break,
            _ => {}
        }
    }
    Err(IoError::file(
        path,
        "no SolAtVertices or SolAtTetrahedra keyword",
    ))
}

/// Writes a solution file: `.solb` binary of libMeshb `version` (1–4), any
/// other extension ASCII `.sol`.
pub fn write_sol(path: &Path, sol: &SolFile, version: i32) -> Result<(), IoError> {
    check_version(path, version)?;
    for s in &sol.solutions {
        if width(s.kind.into()) != Some(s.field.components)
            || s.field.values.len() != sol.entries * s.field.components
        {
            return Err(IoError::file(
                path,
                format!(
                    "solution '{}' has {} values, not {} entries of type {}",
                    s.field.name,
                    s.field.values.len(),
                    sol.entries,
                    s.kind
                ),
            ));
        }
    }
    let code = match sol.at {
        SolAt::Vertices => KW_SOL_AT_VERTICES,
        SolAt::Tetrahedra => KW_SOL_AT_TETRAHEDRA,
    };
    if is_binary(path) {
        let mut o = Out::new(version);
        o.keyword(KW_DIMENSION, None);
        o.i32(3);
        o.keyword(code, Some(sol.entries));
        o.i32(sol.solutions.len() as i32);
        for s in &sol.solutions {
            o.i32(s.kind);
        }
        for i in 0..sol.entries {
            for s in &sol.solutions {
                for x in s.field.entry(i) {
                    o.real(*x);
                }
            }
        }
        let bytes = o.finish();
        write_atomic(path, |w| w.write_all(&bytes))
    } else {
        let name = match sol.at {
            SolAt::Vertices => "SolAtVertices",
            SolAt::Tetrahedra => "SolAtTetrahedra",
        };
        write_atomic(path, |w| {
            writeln!(
                w,
                "MeshVersionFormatted {version}\n\nDimension 3\n\n{name}\n{}",
                sol.entries
            )?;
            write!(w, "{}", sol.solutions.len())?;
            for s in &sol.solutions {
                write!(w, " {}", s.kind)?;
            }
            writeln!(w)?;
            for i in 0..sol.entries {
                let mut first = true;
                for s in &sol.solutions {
                    for x in s.field.entry(i) {
                        if !first {
                            write!(w, " ")?;
                        }
                        first = false;
                        write!(w, "{x:?}")?;
                    }
                }
                writeln!(w)?;
            }
            writeln!(w, "\nEnd")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    #[test]
    fn every_version_round_trips_a_mesh_and_a_solution() {
        let dir = tempfile_dir();
        let d = cube_grid(3);
        for ver in 1..=4 {
            let p = dir.join(format!("m{ver}.meshb"));
            write_data(&p, &d, ver).unwrap();
            let back = read(&p).unwrap();
            assert_eq!(back.tets, d.tets, "version {ver}");
            assert_eq!(back.triangles, d.triangles, "version {ver}");
            for (a, b) in back.points.iter().zip(&d.points) {
                for i in 0..3 {
                    let tol = if ver == 1 { 1e-6 } else { 0.0 };
                    assert!((a[i] - b[i]).abs() <= tol, "version {ver}");
                }
            }
            let sol = SolFile {
                at: SolAt::Vertices,
                entries: d.points.len(),
                solutions: vec![Solution {
                    kind: 3,
                    field: Field {
                        name: "sol".into(),
                        components: 6,
                        values: (0..d.points.len() * 6).map(|i| i as f64 * 0.5).collect(),
                    },
                }],
                line: None,
            };
            for ext in ["solb", "sol"] {
                let s = dir.join(format!("s{ver}.{ext}"));
                write_sol(&s, &sol, ver).unwrap();
                let mut back = read_sol(&s).unwrap();
                back.line = None;
                assert_eq!(back, sol, "version {ver} .{ext}");
            }
        }
    }

    fn tempfile_dir() -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("tetrefine-meshb-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }
}
