//! Point and cell fields from and to Medit solutions (`--fields FILE.sol`,
//! `--fields-out FILE.solb`), and their transfer from an input mesh to its
//! refinement.

use super::meshb::{read_sol, write_sol, SolAt, SolFile, Solution};
use super::meta::MeshMeta;
use super::IoError;
use std::path::Path;

/// The libMeshb solution type of a field with `components` values.
fn kind_of(components: usize) -> Option<i32> {
    match components {
        1 => Some(1),
        3 => Some(2),
        6 => Some(3),
        9 => Some(4),
        _ => None,
    }
}

/// Adds the solutions of a Medit `.sol` / `.solb` to `meta`: a
/// `SolAtVertices` keyword's to the point fields (it must have `n_points`
/// entries), a `SolAtTetrahedra` keyword's to the cell fields (`n_tets`).
/// Fields are named after the file (`temperature.sol` → `temperature`,
/// several solutions → `temperature_0`, …).
pub fn add_sol_fields(
    path: &Path,
    meta: &mut MeshMeta,
    n_points: usize,
    n_tets: usize,
) -> Result<(), IoError> {
    let sol = read_sol(path)?;
    let (want, what) = match sol.at {
        SolAt::Vertices => (n_points, "points"),
        SolAt::Tetrahedra => (n_tets, "tetrahedra"),
    };
    if sol.entries != want {
        let message = format!(
            "the solution has {} entries but the mesh has {want} {what}",
            sol.entries
        );
        return Err(match sol.line {
            Some(l) => IoError::at(path, l, message),
            None => IoError::file(path, message),
        });
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "sol".into());
    let n = sol.solutions.len();
    for (i, s) in sol.solutions.into_iter().enumerate() {
        let mut f = s.field;
        f.name = if n == 1 {
            stem.clone()
        } else {
            format!("{stem}_{i}")
        };
        match sol.at {
            SolAt::Vertices => meta.point_fields.push(f),
            SolAt::Tetrahedra => meta.cell_fields.push(f),
        }
    }
    Ok(())
}

/// Writes the point fields of `meta` (those with `n_points` entries and 1,
/// 3, 6 or 9 components) as one `SolAtVertices` keyword: `.solb` binary
/// (libMeshb version 2, as MMG writes), any other extension ASCII.
pub fn write_point_fields(path: &Path, meta: &MeshMeta, n_points: usize) -> Result<(), IoError> {
    let solutions: Vec<Solution> = meta
        .point_fields
        .iter()
        .filter(|f| f.len() == n_points && f.values.len() == n_points * f.components)
        .filter_map(|f| {
            kind_of(f.components).map(|kind| Solution {
                kind,
                field: f.clone(),
            })
        })
        .collect();
    if solutions.is_empty() {
        return Err(IoError::file(
            path,
            "the mesh carries no point field to write (give one with --fields FILE.sol, or read a .vtu/.msh with point data)",
        ));
    }
    let sol = SolFile {
        at: SolAt::Vertices,
        entries: n_points,
        solutions,
        line: None,
    };
    write_sol(path, &sol, 2)
}

/// The solution files [`write_fields_beside`] writes for the mesh file
/// `mesh_path`, as MMG names them: `OUT.mesh` → `OUT.sol` (point fields,
/// `SolAtVertices`) and `OUT.tets.sol` (cell fields, `SolAtTetrahedra`);
/// `OUT.meshb` → `OUT.solb` and `OUT.tets.solb`. `None` for other formats.
pub fn fields_beside(mesh_path: &Path) -> Option<(std::path::PathBuf, std::path::PathBuf)> {
    let ext = mesh_path.extension()?.to_str()?.to_ascii_lowercase();
    let sol = match ext.as_str() {
        "mesh" => "sol",
        "meshb" => "solb",
        _ => return None,
    };
    Some((
        mesh_path.with_extension(sol),
        mesh_path.with_extension(format!("tets.{sol}")),
    ))
}

/// Writes the fields of `meta` beside a Medit mesh file (see
/// [`fields_beside`]): the point fields with `n_points` entries and the cell
/// fields with `n_tets` entries whose component count is a libMeshb type
/// (1, 3, 6 or 9). Returns the files written and the names of the fields
/// left out (other component counts).
pub fn write_fields_beside(
    mesh_path: &Path,
    meta: &MeshMeta,
    n_points: usize,
    n_tets: usize,
) -> Result<(Vec<std::path::PathBuf>, Vec<String>), IoError> {
    let Some((points_path, cells_path)) = fields_beside(mesh_path) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let mut written = Vec::new();
    let mut skipped = Vec::new();
    for (path, fields, at, n) in [
        (points_path, &meta.point_fields, SolAt::Vertices, n_points),
        (cells_path, &meta.cell_fields, SolAt::Tetrahedra, n_tets),
    ] {
        let mut solutions = Vec::new();
        for f in fields.iter().filter(|f| f.values.len() == n * f.components) {
            match kind_of(f.components) {
                Some(kind) => solutions.push(Solution {
                    kind,
                    field: f.clone(),
                }),
                None => skipped.push(f.name.clone()),
            }
        }
        if solutions.is_empty() {
            continue;
        }
        let sol = SolFile {
            at,
            entries: n,
            solutions,
            line: None,
        };
        write_sol(&path, &sol, 2)?;
        written.push(path);
    }
    Ok((written, skipped))
}

/// A size map as an MMG solution gives it: per point one target edge length
/// (`components` 1) or one metric `m11 m12 m22 m13 m23 m33` (`components` 6).
#[derive(Clone, Debug, PartialEq)]
pub struct SizeSol {
    /// 1 (scalar sizes) or 6 (symmetric metrics, MMG's order).
    pub components: usize,
    /// `components` values per point.
    pub values: Vec<f64>,
}

/// Whether the metric `m11 m12 m22 m13 m23 m33` is positive definite:
/// Sylvester's criterion, the three leading minors positive.
fn metric_is_positive_definite(m: &[f64]) -> bool {
    let (a, b, c, d, e, f) = (m[0], m[1], m[2], m[3], m[4], m[5]);
    let d2 = a * c - b * b;
    let d3 = a * (c * f - e * e) - b * (b * f - e * d) + d * (b * e - c * d);
    a > 0.0 && d2 > 0.0 && d3 > 0.0
}

/// The 1-based line of the first value of entry `k` of the first
/// `SolAtVertices` keyword of an ASCII solution, for messages.
fn sol_entry_line(path: &Path, k: usize, width: usize) -> Option<usize> {
    let bytes = super::read_bytes(path).ok()?;
    let text = std::str::from_utf8(&bytes).ok()?;
    let mut tok = super::Tokens::new(path, text, true);
    while let Some(t) = tok.next() {
        if t == "SolAtVertices" {
            tok.next()?;
            let ns: usize = tok.next()?.parse().ok()?;
            for _ in 0..ns {
                tok.next()?;
            }
            for _ in 0..k * width {
                tok.next()?;
            }
            tok.next()?;
            return Some(tok.line());
        }
    }
    None
}

/// Reads an MMG size map (`--size FILE.sol`): a `SolAtVertices` keyword with
/// one solution, of type 1 (a target edge length per point) or 3 (a
/// symmetric metric, `m11 m12 m22 m13 m23 m33`), one entry per mesh point.
/// A size must be finite and > 0, a metric positive definite; the error
/// names the file and the entry's line.
pub fn read_size_sol(path: &Path, n_points: usize) -> Result<SizeSol, IoError> {
    let sol = read_sol(path)?;
    let at_line = |l: Option<usize>, m: String| match l {
        Some(l) => IoError::at(path, l, m),
        None => IoError::file(path, m),
    };
    if sol.at != SolAt::Vertices {
        return Err(at_line(
            sol.line,
            "a size map is SolAtVertices (one size or metric per point), not SolAtTetrahedra"
                .into(),
        ));
    }
    if sol.solutions.len() != 1 {
        return Err(at_line(
            sol.line,
            format!(
                "a size map holds one solution (type 1 size or type 3 metric), not {}",
                sol.solutions.len()
            ),
        ));
    }
    if sol.entries != n_points {
        return Err(at_line(
            sol.line,
            format!(
                "the size map has {} entries but the mesh has {n_points} points",
                sol.entries
            ),
        ));
    }
    let s = &sol.solutions[0];
    let c = s.field.components;
    if c != 1 && c != 6 {
        return Err(at_line(
            sol.line,
            format!(
                "a size map is of type 1 (size) or 3 (metric), not type {}",
                s.kind
            ),
        ));
    }
    for k in 0..sol.entries {
        let e = s.field.entry(k);
        let bad = if c == 1 {
            (!(e[0] > 0.0 && e[0].is_finite()))
                .then(|| format!("size {} of point {} is not a positive length", e[0], k + 1))
        } else {
            (!(e.iter().all(|x| x.is_finite()) && metric_is_positive_definite(e))).then(|| {
                format!(
                    "the metric of point {} ({e:?}, MMG's order m11 m12 m22 m13 m23 m33) is not positive definite",
                    k + 1
                )
            })
        };
        if let Some(m) = bad {
            return Err(at_line(sol_entry_line(path, k, c), m));
        }
    }
    Ok(SizeSol {
        components: c,
        values: s.field.values.clone(),
    })
}
