//! Per-tet error indicators, the input of adaptive refinement: one
//! non-negative number per tet of a mesh, as adaptive finite-element codes
//! (MFEM, libMesh, deal.II, DOLFINx) compute them after a solve.
//!
//! Tets are numbered as the mesh file lists them, **0-based**: tet `i` is the
//! `i`-th tetrahedron of the file, which is tet id `i` of the [`TetMesh`] that
//! [`TetMesh::from_data`] builds from it. (For a mesh with dead slots, the
//! values follow [`TetMesh::tet_ids`], ascending.) The format is chosen from
//! the file name by [`IndicatorSource::parse`]:
//!
//! | spec | format |
//! |---|---|
//! | `FILE.txt`, `FILE.dat`, `FILE` (no extension) | plain text: one number per line, in tet order; `#` starts a comment, blank lines are skipped |
//! | `FILE.csv` | CSV rows `tet,value` (0-based tet id), in any order, every tet exactly once; an optional header line names the columns |
//! | `FILE.sol` | MMG/Medit ASCII solution: `SolAtTetrahedra` with one scalar (type 1), or `SolAtVertices` with one scalar, where a tet takes the maximum of its 4 vertices |
//! | `FILE.vtu:NAME` | the one-component cell array `NAME` of a VTK XML unstructured grid, at its tetrahedra |
//!
//! Every value must be a finite number ≥ 0. Every error is an [`IoError`]
//! naming the file and, where the problem has one, the line, and says how
//! many values were expected.

use super::vtk::read_tet_cell_array;
use super::{read_bytes, IoError, Tokens};
use crate::mesh::TetMesh;
use std::fmt;
use std::path::{Path, PathBuf};

/// Where an indicator comes from: a file and its format.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IndicatorSource {
    /// Plain text, one number per line in tet order.
    Plain(PathBuf),
    /// CSV `tet,value` rows, 0-based tet ids.
    Csv(PathBuf),
    /// MMG/Medit `.sol` (`SolAtTetrahedra` or `SolAtVertices`, one scalar).
    Sol(PathBuf),
    /// The cell array with this name of a `.vtu` file.
    VtuArray(PathBuf, String),
}

const FORMATS_HINT: &str =
    "use FILE.txt or FILE.dat (one value per line), FILE.csv (tet,value rows), FILE.sol (MMG) or FILE.vtu:ARRAY";

impl IndicatorSource {
    /// Chooses the format of an indicator spec by its extension:
    /// `.txt`, `.dat` or none → plain, `.csv` → CSV, `.sol` → MMG solution,
    /// `FILE.vtu:NAME` → the cell array `NAME` of `FILE.vtu` (the name is
    /// everything after the first `.vtu:`, so it may hold colons, as meshio's
    /// `gmsh:physical` does). Extensions are matched case-insensitively.
    pub fn parse(spec: &str) -> Result<IndicatorSource, IoError> {
        if let Some(at) = spec.to_ascii_lowercase().find(".vtu:") {
            let path = PathBuf::from(&spec[..at + 4]);
            let name = &spec[at + 5..];
            if name.is_empty() {
                return Err(IoError::file(
                    &path,
                    "no cell array named after ':'; use FILE.vtu:ARRAY",
                ));
            }
            return Ok(IndicatorSource::VtuArray(path, name.to_string()));
        }
        let path = PathBuf::from(spec);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            None | Some("txt") | Some("dat") => Ok(IndicatorSource::Plain(path)),
            Some("csv") => Ok(IndicatorSource::Csv(path)),
            Some("sol") => Ok(IndicatorSource::Sol(path)),
            Some("solb") => Err(IoError::file(
                &path,
                "binary MMG solutions (.solb) are not supported; write an ASCII .sol",
            )),
            Some("vtu") => Err(IoError::file(
                &path,
                "name the cell array that holds the indicator: FILE.vtu:ARRAY",
            )),
            Some(other) => Err(IoError::file(
                &path,
                format!("unknown indicator extension '.{other}'; {FORMATS_HINT}"),
            )),
        }
    }

    /// The file.
    pub fn path(&self) -> &Path {
        match self {
            IndicatorSource::Plain(p)
            | IndicatorSource::Csv(p)
            | IndicatorSource::Sol(p)
            | IndicatorSource::VtuArray(p, _) => p,
        }
    }

    /// Reads the indicator for `mesh`: one value per live tet, in
    /// [`TetMesh::tet_ids`] order.
    pub fn read(&self, mesh: &TetMesh) -> Result<Vec<f64>, IoError> {
        let n = mesh.n_tets();
        match self {
            IndicatorSource::Plain(p) => read_plain(p, n),
            IndicatorSource::Csv(p) => read_csv(p, n),
            IndicatorSource::Sol(p) => read_sol(p, &tet_vertex_lists(mesh), mesh.n_points()),
            IndicatorSource::VtuArray(p, name) => read_vtu_array(p, name, n),
        }
    }
}

impl fmt::Display for IndicatorSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IndicatorSource::VtuArray(p, name) => write!(f, "{}:{name}", p.display()),
            _ => write!(f, "{}", self.path().display()),
        }
    }
}

/// Reads the indicator `spec` (plain text, CSV `tet,value`, Medit `.sol` or `FILE.vtu:ARRAY`; the README lists them)
/// for `mesh`: one value per live tet, in [`TetMesh::tet_ids`] order, each
/// finite and ≥ 0.
pub fn read_indicator(spec: &str, mesh: &TetMesh) -> Result<Vec<f64>, IoError> {
    IndicatorSource::parse(spec)?.read(mesh)
}

/// Why `x` is not a valid indicator value, if it is not one.
fn bad_value(x: f64) -> Option<&'static str> {
    if x.is_nan() {
        Some("not a number")
    } else if x.is_infinite() {
        Some("infinite")
    } else if x < 0.0 {
        Some("negative")
    } else {
        None
    }
}

/// The message for an invalid value of `what` (e.g. "tet 3").
fn value_message(what: &str, x: f64, why: &str) -> String {
    format!("the value of {what} is {x} ({why}); an indicator must be a finite number >= 0")
}

/// A number as solvers write it: Rust syntax, or Fortran's `1.5D-3`.
fn parse_number(s: &str) -> Option<f64> {
    s.parse::<f64>()
        .ok()
        .or_else(|| s.replace(['D', 'd'], "e").parse::<f64>().ok())
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 24 {
        format!("{}…", s.chars().take(24).collect::<String>())
    } else {
        s.to_string()
    }
}

/// The file as text, or an error naming the line of the first byte that
/// cannot be text (invalid UTF-8 or a NUL byte). A leading byte-order mark
/// (spreadsheets write one) is dropped.
fn read_text(path: &Path) -> Result<String, IoError> {
    let bytes = read_bytes(path)?;
    let binary_at = |bytes: &[u8], valid: usize| {
        let line = bytes[..valid].iter().filter(|&&c| c == b'\n').count() + 1;
        IoError::at(
            path,
            line,
            "not a text file (binary data): expected an indicator, one number per tet",
        )
    };
    if let Some(i) = bytes.iter().position(|&c| c == 0) {
        return Err(binary_at(&bytes, i));
    }
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        binary_at(e.as_bytes(), valid)
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// The line to blame when a file ends early: its last line (1 for an empty file).
fn last_line(text: &str) -> usize {
    text.lines().count().max(1)
}

/// Reads plain text: one number per line, in tet order, for `n_tets` tets.
/// `#` starts a comment to the end of the line; blank lines are skipped.
pub fn read_plain(path: &Path, n_tets: usize) -> Result<Vec<f64>, IoError> {
    let text = read_text(path)?;
    let mut values = Vec::with_capacity(n_tets.min(text.len() / 2 + 1));
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut fields = content.split_whitespace();
        let Some(tok) = fields.next() else { continue };
        if let Some(extra) = fields.next() {
            return Err(IoError::at(
                path,
                line,
                format!(
                    "expected one number per line, found a second field '{}'",
                    shorten(extra)
                ),
            ));
        }
        let x = parse_number(tok).ok_or_else(|| {
            IoError::at(
                path,
                line,
                format!("expected a number, found '{}'", shorten(tok)),
            )
        })?;
        let tet = values.len();
        if tet == n_tets {
            return Err(IoError::at(
                path,
                line,
                format!("more values than tets: expected exactly {n_tets}, one per tet"),
            ));
        }
        if let Some(why) = bad_value(x) {
            return Err(IoError::at(
                path,
                line,
                value_message(&format!("tet {tet} (0-based)"), x, why),
            ));
        }
        values.push(x);
    }
    if values.len() != n_tets {
        return Err(IoError::at(
            path,
            last_line(&text),
            format!(
                "file ends after {} values; expected {n_tets}, one per tet",
                values.len()
            ),
        ));
    }
    Ok(values)
}

/// Column names taken for the tet id in a CSV header (case-insensitive).
const TET_COLUMNS: [&str; 9] = [
    "tet", "tet_id", "tetid", "id", "cell", "cell_id", "element", "elem", "index",
];
/// Column names taken for the value in a CSV header (case-insensitive).
const VALUE_COLUMNS: [&str; 7] = [
    "value",
    "indicator",
    "error",
    "eta",
    "estimate",
    "estimator",
    "err",
];

fn csv_fields(line: &str) -> Vec<&str> {
    line.split(',')
        .map(|f| {
            let f = f.trim();
            f.strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .unwrap_or(f)
                .trim()
        })
        .collect()
}

/// The (tet, value) columns named by a header, or an error message.
fn csv_columns(fields: &[&str]) -> Result<(usize, usize), String> {
    let find = |names: &[&str]| {
        fields
            .iter()
            .position(|f| names.iter().any(|n| f.eq_ignore_ascii_case(n)))
    };
    let (tet, value) = (find(&TET_COLUMNS), find(&VALUE_COLUMNS));
    match (tet, value, fields.len()) {
        (Some(t), Some(v), _) if t != v => Ok((t, v)),
        (Some(t), None, 2) => Ok((t, 1 - t)),
        (None, Some(v), 2) => Ok((1 - v, v)),
        (None, None, 2) => Ok((0, 1)),
        _ => Err(format!(
            "header '{}' does not name a tet column ({}) and a value column ({})",
            shorten(&fields.join(",")),
            TET_COLUMNS.join(", "),
            VALUE_COLUMNS.join(", ")
        )),
    }
}

/// Reads CSV `tet,value` rows for `n_tets` tets: tet ids are **0-based**
/// (`0..n_tets`), rows may come in any order, and every tet must appear
/// exactly once. An optional first line naming the columns is a header (a line
/// none of whose fields is a number); it may put the columns in any order and
/// hold more columns: the tet column is the one named `tet`, `tet_id`, `id`,
/// `cell`, `element`, … and the value column the one named `value`,
/// `indicator`, `error`, `eta`, … (with two columns, naming one is enough;
/// naming neither means `tet,value`). `#` starts a comment; blank lines are
/// skipped; fields may be quoted.
pub fn read_csv(path: &Path, n_tets: usize) -> Result<Vec<f64>, IoError> {
    let text = read_text(path)?;
    let mut values = vec![f64::NAN; n_tets];
    let mut first_line: Vec<usize> = vec![0; n_tets];
    let mut seen = 0usize;
    let mut columns: Option<(usize, usize)> = None;
    let mut width = 2usize;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields = csv_fields(content);
        let at = |m: String| IoError::at(path, line, m);
        if columns.is_none() {
            if fields.iter().all(|f| parse_number(f).is_none()) {
                columns = Some(csv_columns(&fields).map_err(at)?);
                width = fields.len();
                continue;
            }
            columns = Some((0, 1));
        }
        let (tc, vc) = columns.unwrap_or((0, 1));
        if fields.len() != width {
            return Err(at(format!(
                "expected {width} comma-separated fields (tet,value), found {}",
                fields.len()
            )));
        }
        let (tf, vf) = (fields[tc], fields[vc]);
        let id: i64 = tf.parse().map_err(|_| {
            at(format!(
                "tet id '{}' is not an integer (ids are 0-based, 0..={})",
                shorten(tf),
                n_tets as i64 - 1
            ))
        })?;
        if id < 0 || id as u64 >= n_tets as u64 {
            return Err(at(format!(
                "unknown tet id {id}: the mesh has {n_tets} tets, ids 0..={} (0-based)",
                n_tets as i64 - 1
            )));
        }
        let id = id as usize;
        if first_line[id] != 0 {
            return Err(at(format!(
                "tet {id} is listed twice (first on line {}); expected each of the {n_tets} tets once",
                first_line[id]
            )));
        }
        let x = parse_number(vf)
            .ok_or_else(|| at(format!("expected a number, found '{}'", shorten(vf))))?;
        if let Some(why) = bad_value(x) {
            return Err(at(value_message(&format!("tet {id}"), x, why)));
        }
        values[id] = x;
        first_line[id] = line;
        seen += 1;
    }
    if seen != n_tets {
        let missing: Vec<String> = first_line
            .iter()
            .enumerate()
            .filter(|(_, &l)| l == 0)
            .take(5)
            .map(|(t, _)| t.to_string())
            .collect();
        let more = if n_tets - seen > missing.len() {
            ", …"
        } else {
            ""
        };
        return Err(IoError::at(
            path,
            last_line(&text),
            format!(
                "file ends after {seen} rows; expected {n_tets}, one per tet (missing tet ids, 0-based: {}{more})",
                missing.join(", ")
            ),
        ));
    }
    Ok(values)
}

/// Values per entry of a solution of MMG/Medit `type` in dimension `dim`
/// (1 scalar, 2 vector, 3 symmetric tensor).
fn sol_width(ty: i64, dim: usize) -> Option<usize> {
    match ty {
        1 => Some(1),
        2 => Some(dim),
        3 => Some(dim * (dim + 1) / 2),
        _ => None,
    }
}

fn sol_type_name(ty: i64) -> &'static str {
    match ty {
        1 => "scalar",
        2 => "vector",
        3 => "tensor",
        _ => "unknown",
    }
}

/// A non-negative count no larger than the file could hold.
fn sol_count(tok: &mut Tokens, what: &str, text_len: usize) -> Result<usize, IoError> {
    let n: i64 = tok.parse(what)?;
    if n < 0 {
        return Err(tok.error(format!("{what} {n} is negative")));
    }
    if n as u64 > text_len as u64 {
        return Err(tok.error(format!(
            "{what} {n} is more than the file can hold (corrupt or truncated)"
        )));
    }
    Ok(n as usize)
}

/// Reads an MMG/Medit ASCII `.sol` for a mesh with these tets (vertex ids
/// 0-based into `n_points` points, in the order of the mesh file).
///
/// The file must hold exactly one of `SolAtTetrahedra` (one entry per tet) or
/// `SolAtVertices` (one entry per mesh point; a tet takes the maximum of its
/// four vertices), with one solution of type 1 (scalar). Other `SolAt…`
/// sections are skipped; `Dimension` must be 3.
pub fn read_sol(path: &Path, tets: &[[u32; 4]], n_points: usize) -> Result<Vec<f64>, IoError> {
    let text = read_text(path)?;
    let mut tok = Tokens::new(path, &text, true);
    const DIM: usize = 3;
    if let Some((t, &v)) = tets
        .iter()
        .enumerate()
        .find_map(|(t, vs)| vs.iter().find(|&&v| v as usize >= n_points).map(|v| (t, v)))
    {
        return Err(IoError::file(
            path,
            format!("tet {t} refers to vertex {v} of a mesh with {n_points} vertices"),
        ));
    }
    let mut at_tets: Option<Vec<f64>> = None;
    let mut at_vertices: Option<Vec<f64>> = None;
    let mut saw_any = false;
    while let Some(kw) = tok.next() {
        saw_any = true;
        match kw {
            "MeshVersionFormatted" => super::medit::read_version(&mut tok)?,
            "Dimension" => {
                let d: i64 = tok.parse("the dimension")?;
                if d != 3 {
                    return Err(tok.error(format!(
                        "Dimension {d}: a solution on a tetrahedral mesh has Dimension 3"
                    )));
                }
            }
            "Time" => {
                let _: f64 = tok.parse("a time")?;
            }
            "End" => break,
            kw if kw.starts_with("SolAt") => {
                let (expected, entity) = match kw {
                    "SolAtTetrahedra" => (Some(tets.len()), "tets"),
                    "SolAtVertices" => (Some(n_points), "vertices"),
                    _ => (None, "entries"),
                };
                let n = sol_count(&mut tok, &format!("{kw} count"), text.len())?;
                if let Some(want) = expected {
                    if n != want {
                        return Err(tok.error(format!(
                            "{kw} has {n} entries; the mesh has {want} {entity}"
                        )));
                    }
                }
                let nsol = sol_count(&mut tok, "number of solutions", text.len())?;
                let mut widths = Vec::with_capacity(nsol.min(16));
                for _ in 0..nsol {
                    let ty: i64 = tok.parse("a solution type (1 scalar, 2 vector, 3 tensor)")?;
                    let w = sol_width(ty, DIM).ok_or_else(|| {
                        tok.error(format!(
                            "solution type {ty} is not 1 (scalar), 2 (vector) or 3 (tensor)"
                        ))
                    })?;
                    if expected.is_some() && ty != 1 {
                        return Err(tok.error(format!(
                            "{kw} holds a solution of type {ty} ({}); an indicator needs type 1 (scalar)",
                            sol_type_name(ty)
                        )));
                    }
                    widths.push(w);
                }
                if expected.is_none() {
                    let per: usize = widths.iter().sum();
                    for _ in 0..n.saturating_mul(per) {
                        let _: f64 = tok.parse(&format!("a value of {kw}"))?;
                    }
                    continue;
                }
                if nsol != 1 {
                    return Err(tok.error(format!(
                        "{kw} holds {nsol} solutions; an indicator needs exactly one, of type 1 (scalar)"
                    )));
                }
                let mut values = Vec::with_capacity(n);
                for i in 0..n {
                    let what = if kw == "SolAtTetrahedra" {
                        format!("the value of tet {i} (0-based)")
                    } else {
                        format!("the value of vertex {} (1-based)", i + 1)
                    };
                    let x: f64 = match tok.next() {
                        None => {
                            return Err(IoError::at(
                                path,
                                last_line(&text),
                                format!(
                                    "file ends where {what} was expected (truncated?): {kw} announces {n}, found {i}"
                                ),
                            ))
                        }
                        Some(t) => parse_number(t).ok_or_else(|| {
                            tok.error(format!("expected {what}, found '{}'", shorten(t)))
                        })?,
                    };
                    if let Some(why) = bad_value(x) {
                        let whom = what.trim_start_matches("the value of ");
                        return Err(tok.error(value_message(whom, x, why)));
                    }
                    values.push(x);
                }
                let slot = if kw == "SolAtTetrahedra" {
                    &mut at_tets
                } else {
                    &mut at_vertices
                };
                if slot.is_some() {
                    return Err(tok.error(format!("a second {kw} section")));
                }
                *slot = Some(values);
            }
            other => {
                return Err(tok.error(format!(
                    "unknown keyword '{}' in an MMG solution file",
                    shorten(other)
                )))
            }
        }
    }
    if !saw_any {
        return Err(IoError::file(path, "empty file"));
    }
    match (at_tets, at_vertices) {
        (Some(v), None) => Ok(v),
        (None, Some(pv)) => Ok(tets
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| pv[v as usize])
                    .fold(f64::NEG_INFINITY, f64::max)
            })
            .collect()),
        (Some(_), Some(_)) => Err(IoError::file(
            path,
            "holds both SolAtTetrahedra and SolAtVertices; keep the one that is the indicator",
        )),
        (None, None) => Err(IoError::file(
            path,
            format!(
                "no SolAtTetrahedra or SolAtVertices section; expected {} values (one scalar per tet) or {n_points} (one per vertex)",
                tets.len()
            ),
        )),
    }
}

/// Reads the one-component cell array `name` of a `.vtu` at its tetrahedra
/// (see [`read_tet_cell_array`]) for a mesh of `n_tets` tets.
pub fn read_vtu_array(path: &Path, name: &str, n_tets: usize) -> Result<Vec<f64>, IoError> {
    let array = read_tet_cell_array(path, name)?;
    if array.values.len() != n_tets {
        let msg = format!(
            "cell array '{name}' has values for {} tetrahedra; the mesh has {n_tets} tets",
            array.values.len()
        );
        return Err(match array.lines.first() {
            Some(&l) => IoError::at(path, l as usize, msg),
            None => IoError::file(path, msg),
        });
    }
    for (t, (&x, &l)) in array.values.iter().zip(&array.lines).enumerate() {
        if let Some(why) = bad_value(x) {
            return Err(IoError::at(
                path,
                l as usize,
                format!(
                    "cell array '{name}': {}",
                    value_message(&format!("tet {t} (0-based)"), x, why)
                ),
            ));
        }
    }
    Ok(array.values)
}

/// The mesh's tets as vertex lists in [`TetMesh::tet_ids`] order (what
/// [`read_sol`] takes).
pub fn tet_vertex_lists(mesh: &TetMesh) -> Vec<[u32; 4]> {
    mesh.tet_ids().map(|t| mesh.tet(t)).collect()
}
