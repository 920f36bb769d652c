//! Marking strategies: which tets an adaptive step refines, from a per-tet
//! error indicator (see [`crate::io::indicator`]) or from geometry.
//!
//! This is the "mark" of the solve–estimate–mark–refine loop of adaptive
//! finite elements, feeding the adaptive √3 step of Burkhart, Hamann and
//! Umlauf (§6 of "Adaptive and feature-preserving subdivision for
//! high-quality tetrahedral meshes", CGF 2010), where only the selected tets
//! are split. The strategies are the usual ones of adaptive FEM codes:
//!
//! | spec | selects |
//! |---|---|
//! | `fraction:F`, 0 < F ≤ 1 | exactly k = ⌈F·n⌉ tets with the largest values (the fixed-number strategy of deal.II's `GridRefinement::refine_and_coarsen_fixed_number`); see [`fraction_count`] |
//! | `doerfler:θ`, 0 < θ ≤ 1 | a smallest set M with Σ_{t∈M} η_t² ≥ θ·Σ_t η_t² (Dörfler's bulk criterion, W. Dörfler, "A convergent adaptive algorithm for Poisson's equation", SIAM J. Numer. Anal. 33, 1996) |
//! | `max:γ`, 0 ≤ γ ≤ 1 | η_t ≥ γ·max η (the maximum strategy of Babuška and Rheinboldt, 1978) |
//! | `threshold:X` | η_t ≥ X |
//! | `region:ID[,ID…]` | tets whose region is one of the ids |
//! | `box:x0,y0,z0,x1,y1,z1` | tets whose centroid lies in the closed axis-aligned box from the lower corner `x0,y0,z0` to the upper `x1,y1,z1` (an inverted box, `x0 > x1`, is an error) |
//! | `sphere:x,y,z,r`, r > 0 | tets whose centroid lies in the closed ball |
//! | `A+B+…` | the union of the selections |
//!
//! **Order and ties.** `fraction` and `doerfler` rank the tets by value,
//! descending, and among equal values by tet id, ascending (the tet listed
//! first in the mesh file wins). So the result is deterministic and
//! `fraction` always selects exactly ⌈F·n⌉ tets, even when values tie at the
//! cut.
//!
//! **Why greedy is minimal for Dörfler.** Let s₁ ≥ s₂ ≥ … ≥ sₙ be the squared
//! values in the order above (squaring keeps the order of non-negative
//! numbers). Any set of m tets has a sum of squares at most s₁ + … + sₘ,
//! the sum of the m largest. So if some set of m tets reaches θ·S, the first
//! m in the order reach it too. The greedy rule takes the first k tets for
//! the smallest k whose prefix reaches θ·S: no prefix shorter than k reaches
//! θ·S, hence no set of fewer than k tets does, and the chosen set is a
//! smallest one. Values are scaled by a power of two before squaring (exact in
//! binary floating point), so that squares neither overflow nor underflow;
//! if every value is 0 the empty set already reaches θ·0 and nothing is
//! selected.
//!
//! Values are given per live tet in [`TetMesh::tet_ids`] order (as
//! [`crate::io::indicator::read_indicator`] returns them); "tet id" above is
//! that position, which for a mesh fresh from a file is the 0-based tet number
//! of the file. The selection returned by [`select`] is indexed by tet slot,
//! as [`RefineOptions::selection`](super::RefineOptions::selection) wants it.

use crate::mesh::TetMesh;
use glam::DVec3;
use std::cmp::Ordering;
use std::fmt;
use std::str::FromStr;

/// A rule that selects tets for refinement. Parse one with [`str::parse`]
/// (`fraction:F`, `doerfler:θ`, `max:γ`, `threshold:X`, `region:ID,…`, `box:x0,y0,z0,x1,y1,z1`, `sphere:x,y,z,r`) and apply it with [`select`].
#[derive(Clone, Debug, PartialEq)]
pub enum MarkStrategy {
    /// `fraction:F`: the ⌈F·n⌉ tets with the largest values, 0 < F ≤ 1.
    Fraction(f64),
    /// `doerfler:θ`: a smallest set holding θ of the sum of squared values, 0 < θ ≤ 1.
    Doerfler(f64),
    /// `max:γ`: values ≥ γ times the largest value, 0 ≤ γ ≤ 1.
    Max(f64),
    /// `threshold:X`: values ≥ X.
    Threshold(f64),
    /// `region:ID[,ID…]`: tets in one of these regions.
    Region(Vec<i32>),
    /// `box:…`: tets whose centroid lies in the closed box `min..=max`.
    Box {
        /// Smallest corner.
        min: DVec3,
        /// Largest corner.
        max: DVec3,
    },
    /// `sphere:x,y,z,r`: tets whose centroid lies in the closed ball.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius, > 0.
        radius: f64,
    },
    /// `A+B+…`: the union of the selections.
    Union(Vec<MarkStrategy>),
}

/// The names a strategy spec may start with (`NAME:`).
const NAMES: [&str; 8] = [
    "fraction",
    "doerfler",
    "dorfler",
    "max",
    "threshold",
    "region",
    "box",
    "sphere",
];

const SYNTAX: &str = "fraction:F, doerfler:θ, max:γ, threshold:X, region:ID[,ID…], box:x0,y0,z0,x1,y1,z1 or sphere:x,y,z,r (join several with '+')";

impl MarkStrategy {
    /// Whether the strategy ranks indicator values (and so needs an indicator file).
    pub fn needs_indicator(&self) -> bool {
        match self {
            MarkStrategy::Fraction(_)
            | MarkStrategy::Doerfler(_)
            | MarkStrategy::Max(_)
            | MarkStrategy::Threshold(_) => true,
            MarkStrategy::Region(_) | MarkStrategy::Box { .. } | MarkStrategy::Sphere { .. } => {
                false
            }
            MarkStrategy::Union(parts) => parts.iter().any(MarkStrategy::needs_indicator),
        }
    }

    /// The union of `parts` (one part is returned as it is).
    pub fn union(mut parts: Vec<MarkStrategy>) -> MarkStrategy {
        if parts.len() == 1 {
            parts.pop().unwrap_or(MarkStrategy::Union(Vec::new()))
        } else {
            MarkStrategy::Union(parts)
        }
    }
}

fn numbers(spec: &str, body: &str, n: usize, what: &str) -> Result<Vec<f64>, String> {
    let v: Vec<&str> = body.split(',').map(str::trim).collect();
    if v.len() != n {
        return Err(format!(
            "'{spec}': {what} needs {n} comma-separated numbers, found {}",
            v.len()
        ));
    }
    v.iter()
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("'{spec}': '{s}' is not a finite number"))
        })
        .collect()
}

fn one_number(spec: &str, body: &str, what: &str) -> Result<f64, String> {
    let b = body.trim();
    b.parse::<f64>()
        .map_err(|_| format!("'{spec}': {what}, found '{b}'"))
}

fn parse_one(spec: &str) -> Result<MarkStrategy, String> {
    let s = spec.trim();
    let Some((name, body)) = s.split_once(':') else {
        return Err(format!(
            "'{s}' is not a marking strategy NAME:PARAMETERS; use {SYNTAX}"
        ));
    };
    let in_unit =
        |x: f64, open_at_zero: bool| x <= 1.0 && if open_at_zero { x > 0.0 } else { x >= 0.0 };
    match name.trim().to_ascii_lowercase().as_str() {
        "fraction" => {
            const NEED: &str = "fraction:F needs F in (0,1]";
            let f = one_number(s, body, NEED)?;
            if !in_unit(f, true) {
                return Err(format!("'{s}': {NEED}, found {f}"));
            }
            Ok(MarkStrategy::Fraction(f))
        }
        "doerfler" | "dorfler" | "dörfler" => {
            const NEED: &str = "doerfler:θ needs θ in (0,1]";
            let t = one_number(s, body, NEED)?;
            if !in_unit(t, true) {
                return Err(format!("'{s}': {NEED}, found {t}"));
            }
            Ok(MarkStrategy::Doerfler(t))
        }
        "max" => {
            const NEED: &str = "max:γ needs γ in [0,1]";
            let g = one_number(s, body, NEED)?;
            if !in_unit(g, false) {
                return Err(format!("'{s}': {NEED}, found {g}"));
            }
            Ok(MarkStrategy::Max(g))
        }
        "threshold" => {
            const NEED: &str = "threshold:X needs a finite number X";
            let x = one_number(s, body, NEED)?;
            if !x.is_finite() {
                return Err(format!("'{s}': {NEED}, found {x}"));
            }
            Ok(MarkStrategy::Threshold(x))
        }
        "region" => {
            let ids = body
                .split(',')
                .map(|t| {
                    let t = t.trim();
                    t.parse::<i32>().map_err(|_| {
                        format!("'{s}': region:ID[,ID…] needs integer region ids, found '{t}'")
                    })
                })
                .collect::<Result<Vec<i32>, String>>()?;
            Ok(MarkStrategy::Region(ids))
        }
        "box" => {
            let v = numbers(s, body, 6, "box:x0,y0,z0,x1,y1,z1")?;
            // The lower corner comes first: swapped corners are far more
            // likely a typo than a request, so an inverted box is an error.
            for (axis, name) in ["x", "y", "z"].iter().enumerate() {
                let (lo, hi) = (v[axis], v[axis + 3]);
                if lo > hi {
                    return Err(format!(
                        "'{s}': the box is inverted along {name} ({name}0 = {lo} > {name}1 = {hi}); box:x0,y0,z0,x1,y1,z1 needs the lower corner first"
                    ));
                }
            }
            Ok(MarkStrategy::Box {
                min: DVec3::new(v[0], v[1], v[2]),
                max: DVec3::new(v[3], v[4], v[5]),
            })
        }
        "sphere" => {
            let v = numbers(s, body, 4, "sphere:x,y,z,r")?;
            if v[3] <= 0.0 {
                return Err(format!(
                    "'{s}': sphere:x,y,z,r needs a radius r > 0, found {}",
                    v[3]
                ));
            }
            Ok(MarkStrategy::Sphere {
                center: DVec3::new(v[0], v[1], v[2]),
                radius: v[3],
            })
        }
        other => Err(format!("unknown marking strategy '{other}'; use {SYNTAX}")),
    }
}

/// Splits `A+B+…` at each `+` that starts a new `NAME:` (so that exponents
/// such as `1e+5` stay whole).
fn split_union(s: &str) -> Vec<&str> {
    let mut parts = Vec::new();
    let mut start = 0;
    for (i, c) in s.char_indices() {
        if c != '+' {
            continue;
        }
        let rest = s[i + 1..].trim_start().to_ascii_lowercase();
        let starts_name = NAMES.iter().chain(std::iter::once(&"dörfler")).any(|n| {
            rest.strip_prefix(n)
                .is_some_and(|r| r.trim_start().starts_with(':'))
        });
        if starts_name {
            parts.push(&s[start..i]);
            start = i + 1;
        }
    }
    parts.push(&s[start..]);
    parts
}

impl FromStr for MarkStrategy {
    type Err = String;

    /// Parses a strategy (the syntax of [`MarkStrategy`]); `A+B` is a union.
    fn from_str(s: &str) -> Result<MarkStrategy, String> {
        let parts = split_union(s)
            .into_iter()
            .map(parse_one)
            .collect::<Result<Vec<_>, String>>()?;
        Ok(MarkStrategy::union(parts))
    }
}

impl fmt::Display for MarkStrategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MarkStrategy::Fraction(x) => write!(f, "fraction:{x}"),
            MarkStrategy::Doerfler(x) => write!(f, "doerfler:{x}"),
            MarkStrategy::Max(x) => write!(f, "max:{x}"),
            MarkStrategy::Threshold(x) => write!(f, "threshold:{x}"),
            MarkStrategy::Region(ids) => {
                let ids: Vec<String> = ids.iter().map(i32::to_string).collect();
                write!(f, "region:{}", ids.join(","))
            }
            MarkStrategy::Box { min, max } => write!(
                f,
                "box:{},{},{},{},{},{}",
                min.x, min.y, min.z, max.x, max.y, max.z
            ),
            MarkStrategy::Sphere { center, radius } => {
                write!(f, "sphere:{},{},{},{radius}", center.x, center.y, center.z)
            }
            MarkStrategy::Union(parts) => {
                let p: Vec<String> = parts.iter().map(ToString::to_string).collect();
                f.write_str(&p.join("+"))
            }
        }
    }
}

/// The number of tets `fraction:F` selects out of `n`: k = ⌈F·n⌉, where a
/// product within a relative 1e-9 of an integer counts as that integer (so
/// 0.07·100, which is 7.000000000000001 in floating point, gives 7, not 8),
/// clamped to `1..=n` for n > 0.
pub fn fraction_count(f: f64, n: usize) -> usize {
    if n == 0 {
        return 0;
    }
    let x = f * n as f64;
    let r = x.round();
    let k = if (x - r).abs() <= 1e-9 * x.max(1.0) {
        r
    } else {
        x.ceil()
    };
    (k.max(1.0) as usize).min(n)
}

/// Tet positions `0..values.len()` ranked by value descending, then by
/// position ascending: the order `fraction` and `doerfler` take tets in.
/// Values must not be NaN.
pub fn ranking(values: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| {
        values[b]
            .partial_cmp(&values[a])
            .unwrap_or(Ordering::Equal)
            .then(a.cmp(&b))
    });
    order
}

/// The number of leading tets of [`ranking`] that Dörfler's criterion with
/// `theta` takes: the smallest k whose k largest squared values sum to at
/// least θ times the sum of all squared values. Values must be finite and ≥ 0.
pub fn doerfler_count(values: &[f64], theta: f64) -> usize {
    let order = ranking(values);
    let vmax = order.first().map_or(0.0, |&i| values[i]);
    if vmax <= 0.0 {
        return 0;
    }
    // A power of two near vmax: dividing by it is exact.
    let e = (vmax.log2().floor() as i32).clamp(-1000, 1000);
    let scale = f64::from_bits(((1023 - e) as u64) << 52);
    let squares: Vec<f64> = order
        .iter()
        .map(|&i| {
            let s = values[i] * scale;
            s * s
        })
        .collect();
    let total: f64 = squares.iter().sum();
    let goal = theta * total;
    let mut sum = 0.0;
    for (k, &s) in squares.iter().enumerate() {
        if sum >= goal {
            return k;
        }
        sum += s;
    }
    squares.len()
}

fn check_values(values: &[f64], n: usize) -> Result<(), String> {
    if values.len() != n {
        return Err(format!(
            "the indicator has {} values but the mesh has {n} tets",
            values.len()
        ));
    }
    if let Some((t, x)) = values
        .iter()
        .enumerate()
        .find(|(_, x)| !(x.is_finite() && **x >= 0.0))
    {
        return Err(format!(
            "indicator value {x} of tet {t} is not a finite number >= 0"
        ));
    }
    Ok(())
}

/// The selection per live tet position (not slot) for one strategy.
fn select_live(
    strategy: &MarkStrategy,
    values: Option<&[f64]>,
    mesh: &TetMesh,
    ids: &[u32],
) -> Result<Vec<bool>, String> {
    let n = ids.len();
    let need = || {
        values.ok_or_else(|| {
            format!("marking strategy '{strategy}' ranks indicator values: give an indicator file")
        })
    };
    let centroid = |t: u32| {
        let p = mesh.tet_points(t);
        (p[0] + p[1] + p[2] + p[3]) * 0.25
    };
    Ok(match strategy {
        MarkStrategy::Fraction(f) => {
            let v = need()?;
            let mut sel = vec![false; n];
            for &i in ranking(v).iter().take(fraction_count(*f, n)) {
                sel[i] = true;
            }
            sel
        }
        MarkStrategy::Doerfler(theta) => {
            let v = need()?;
            let mut sel = vec![false; n];
            for &i in ranking(v).iter().take(doerfler_count(v, *theta)) {
                sel[i] = true;
            }
            sel
        }
        MarkStrategy::Max(gamma) => {
            let v = need()?;
            let vmax = v.iter().copied().fold(0.0, f64::max);
            let cut = gamma * vmax;
            v.iter().map(|&x| x >= cut).collect()
        }
        MarkStrategy::Threshold(x) => need()?.iter().map(|&y| y >= *x).collect(),
        MarkStrategy::Region(r) => ids.iter().map(|&t| r.contains(&mesh.region(t))).collect(),
        MarkStrategy::Box { min, max } => ids
            .iter()
            .map(|&t| {
                let c = centroid(t);
                c.cmpge(*min).all() && c.cmple(*max).all()
            })
            .collect(),
        MarkStrategy::Sphere { center, radius } => ids
            .iter()
            .map(|&t| centroid(t).distance_squared(*center) <= radius * radius)
            .collect(),
        MarkStrategy::Union(parts) => {
            let mut sel = vec![false; n];
            for p in parts {
                for (s, x) in sel.iter_mut().zip(select_live(p, values, mesh, ids)?) {
                    *s |= x;
                }
            }
            sel
        }
    })
}

/// Applies `strategy` to `mesh` with the indicator `values` (one per live tet
/// in [`TetMesh::tet_ids`] order, each finite and ≥ 0; needed only by the
/// value-ranking strategies, see [`MarkStrategy::needs_indicator`], but
/// checked whenever given).
///
/// Returns one flag per tet **slot** (`mesh.n_tet_slots()` entries, `false`
/// for dead slots), ready for
/// [`RefineOptions::selection`](super::RefineOptions::selection).
pub fn select(
    strategy: &MarkStrategy,
    values: Option<&[f64]>,
    mesh: &TetMesh,
) -> Result<Vec<bool>, String> {
    let ids: Vec<u32> = mesh.tet_ids().collect();
    if let Some(v) = values {
        check_values(v, ids.len())?;
    }
    let live = select_live(strategy, values, mesh, &ids)?;
    let mut slots = vec![false; mesh.n_tet_slots()];
    for (&t, s) in ids.iter().zip(live) {
        slots[t as usize] = s;
    }
    Ok(slots)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::cube_grid;

    fn chosen(sel: &[bool]) -> Vec<usize> {
        sel.iter()
            .enumerate()
            .filter(|(_, &s)| s)
            .map(|(i, _)| i)
            .collect()
    }

    /// Here rather than in the integration tests: a dead slot is made with
    /// the crate-private `kill_tet`.
    #[test]
    fn selection_is_indexed_by_slot_with_values_in_live_order() {
        let (mut mesh, _) = TetMesh::from_data(&cube_grid(1)).unwrap();
        // Kill slot 2: five live tets 0, 1, 3, 4, 5 take the five values in order.
        mesh.kill_tet(2);
        assert_eq!(mesh.n_tets(), 5);
        assert_eq!(mesh.n_tet_slots(), 6);
        let v = [0.0, 1.0, 5.0, 2.0, 3.0]; // tets 0, 1, 3, 4, 5
        let parse = |s: &str| s.parse::<MarkStrategy>().unwrap();
        let sel = select(&parse("fraction:0.4"), Some(&v), &mesh).unwrap();
        assert_eq!(sel.len(), 6);
        assert_eq!(chosen(&sel), vec![3, 5]);
        let all = select(&parse("max:0"), Some(&v), &mesh).unwrap();
        assert_eq!(chosen(&all), vec![0, 1, 3, 4, 5]);
    }
}
