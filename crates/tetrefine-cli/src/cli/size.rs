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

/// What `--steps` and the size options ask of `refine`.
pub struct Plan {
    /// A size map is given (`--size`, `--size-array`, `--hsiz`, `--hmax`).
    pub size_given: bool,
    /// √3 steps, or size passes with a size map.
    pub n_steps: usize,
    /// Size passes stop once every edge meets the map (`--steps auto`, the
    /// default with a size map).
    pub auto: bool,
}

/// The plan of `a`, or why its options do not go together.
pub fn plan(a: &super::refine::Args) -> Result<Plan, String> {
    let size_given =
        a.size.is_some() || a.size_array.is_some() || a.hsiz.is_some() || a.hmax.is_some();
    let n_steps = match (a.steps, size_given) {
        (Some(Steps::N(n)), _) => n,
        (None, false) => 1,
        (None, true) | (Some(Steps::Auto), true) => AUTO_CAP,
        (Some(Steps::Auto), false) => {
            return Err("--steps auto refines until every edge meets a size map: give --size FILE.sol, --size-array NAME, --hsiz H or --hmax H".into())
        }
    };
    let auto = size_given && a.steps.is_none_or(|s| s == Steps::Auto);
    if size_given {
        if let Some(p) = &a.size {
            super::outputs::refuse_shared_paths(&[
                ("-o", Some(a.output.as_path())),
                ("--size", Some(p.as_path())),
            ])?;
        }
        if a.indicator.is_some()
            || !a.marks.is_empty()
            || a.region.is_some()
            || a.select_box.is_some()
            || a.sphere.is_some()
        {
            return Err("a size map chooses what to refine itself: drop --indicator/--mark/--region/--box/--sphere, or the size options".into());
        }
        if a.stop_after.is_some() {
            return Err(
                "--stop-after names a phase of the √3 step; size-driven refinement has none".into(),
            );
        }
    }
    if n_steps == 0 && !a.allow_steps_zero {
        return Err("--steps 0 refines nothing; give --steps N ≥ 1 (or --allow-steps-zero to write the mesh unrefined)".into());
    }
    Ok(Plan {
        size_given,
        n_steps,
        auto,
    })
}

/// Tells the user, after the size passes, that `long` edges are still
/// longer than their target, and why: `stuck` (the last pass split
/// nothing), or the passes ran out.
pub fn note_still_long(long: u64, stuck: bool, plan: &Plan) {
    if long == 0 {
        return;
    }
    let why = if stuck {
        "no split was possible without inverting a tet or falling below the worst quality so far"
            .to_string()
    } else if plan.auto {
        format!("--steps auto stops at {} passes", plan.n_steps)
    } else {
        format!("--steps {} passes were run", plan.n_steps)
    };
    eprintln!(
        "note: {long} edges are still longer than {:.2}× their target: {why}",
        tetrefine::SPLIT_ABOVE
    );
}

/// [`size_map`] of `a`'s size options.
pub fn size_map_of(
    a: &super::refine::Args,
    input: &TetMesh,
    meta: &MeshMeta,
) -> Result<Option<SizeMap>, String> {
    size_map(
        a.size.as_deref(),
        a.size_array.as_deref(),
        a.hsiz,
        a.hmax,
        input,
        meta,
    )
}

/// The size passes' optimize phase from `a`'s `--effort`, `--opt-passes`,
/// `--threshold`, `--hausd` and `--boundary`.
pub fn improve_options_of(a: &super::refine::Args) -> tetrefine::ImproveOptions {
    tetrefine::size_improve_options(a.effort, a.opt_passes, a.threshold, a.hausd, a.boundary)
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
