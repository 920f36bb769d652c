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
pub const AUTO_CAP: usize = tetrefine::AUTO_SIZE_PASSES;

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
        Some(
            SizeMap::from_values(f.components, &f.values)
                .map_err(|e| format!("--size-array {name}: {e}"))?,
        )
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
