//! `refine --size FILE.sol | --hsiz H | --hmax H | --size-array NAME`:
//! size-driven refinement as MMG reads a size map (long edges split until
//! every edge meets its target), and `--steps N|auto`.

use tetrefine::io::MeshMeta;
use tetrefine::{SizeMap, TetMesh};

/// `--steps N` or `--steps auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Steps {
    /// Exactly this many steps (or size passes).
    N(usize),
    /// Size passes until no edge is longer than its target, at most
    /// [`AUTO_CAP`].
    Auto,
}

/// Size passes `--steps auto` runs at most.
pub const AUTO_CAP: usize = 20;

impl std::str::FromStr for Steps {
    type Err = String;
    fn from_str(s: &str) -> Result<Steps, String> {
        if s == "auto" {
            return Ok(Steps::Auto);
        }
        s.parse::<usize>()
            .map(Steps::N)
            .map_err(|_| format!("'{s}' is neither a number of steps nor 'auto'"))
    }
}

/// The size map of the options, over the points of `input`, or `None`
/// when none is given.
pub fn size_map(
    size: Option<&std::path::Path>,
    size_array: Option<&str>,
    hsiz: Option<f64>,
    hmax: Option<f64>,
    input: &TetMesh,
    meta: &MeshMeta,
) -> Result<Option<SizeMap>, String> {
    for (name, h) in [("--hsiz", hsiz), ("--hmax", hmax)] {
        if let Some(h) = h {
            if !(h > 0.0 && h.is_finite()) {
                return Err(format!("{name} {h} must be a positive length"));
            }
        }
    }
    let given = usize::from(size.is_some())
        + usize::from(size_array.is_some())
        + usize::from(hsiz.is_some());
    if given > 1 {
        return Err("give one size: --size FILE.sol, --size-array NAME or --hsiz H (--hmax caps any of them)".into());
    }
    let n = input.n_points();
    let from = |components: usize, values: Vec<f64>| match components {
        1 => SizeMap::Iso(values),
        _ => SizeMap::Aniso(
            values
                .chunks_exact(6)
                .map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]])
                .collect(),
        ),
    };
    let mut map = if let Some(path) = size {
        let s = tetrefine::io::read_size_sol(path, n).map_err(|e| e.to_string())?;
        Some(from(s.components, s.values))
    } else if let Some(name) = size_array {
        let f = meta
            .point_fields
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = meta.point_fields.iter().map(|f| f.name.as_str()).collect();
                format!(
                    "--size-array {name}: the input has no point array of that name (it has: {})",
                    names.join(", ")
                )
            })?;
        if f.components != 1 && f.components != 6 {
            return Err(format!(
                "--size-array {name}: {} components; a size is 1 (length) or 6 (metric m11 m12 m22 m13 m23 m33)",
                f.components
            ));
        }
        for k in 0..f.len() {
            let e = f.entry(k);
            let ok = if f.components == 1 {
                e[0] > 0.0 && e[0].is_finite()
            } else {
                tetrefine::is_positive_definite(&[e[0], e[1], e[2], e[3], e[4], e[5]])
            };
            if !ok {
                return Err(format!(
                    "--size-array {name}: the value of point {} ({e:?}) is not a positive size or a positive-definite metric",
                    k + 1
                ));
            }
        }
        Some(from(f.components, f.values.clone()))
    } else {
        hsiz.map(|h| SizeMap::Iso(vec![h; n]))
    };
    if let Some(h) = hmax {
        match map.as_mut() {
            Some(m) => m.cap(h),
            None => map = Some(SizeMap::Iso(vec![h; n])),
        }
    }
    Ok(map)
}
