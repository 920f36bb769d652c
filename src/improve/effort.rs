//! `--effort fast|default|best`: how hard the optimize phase works, as a
//! preset of [`ImproveOptions`].

use super::boundary_smooth::BoundarySmoothOptions;
use super::long_edges::LengthCap;
use super::passes::ImproveOptions;
use std::fmt;
use std::str::FromStr;

/// An edge longer than this times the mean edge length at its ends is split
/// after a refinement step. Measured on four shipped meshes (one default
/// step): 1.4 raises the average minimum dihedral angle by 2.2°–3.0° for
/// 19 %–27 % more tets; in trials on finished steps 1.6 gained about half
/// of what 1.4 gained.
pub const LONG_EDGE_FACTOR: f64 = 1.4;

/// The long-edge rounds after the first also split every edge longer than
/// this times the median, over the step's points, of the mean edge length
/// at a point ([`LengthCap::MedianTimes`]): the relative test
/// ([`LONG_EDGE_FACTOR`]) leaves long edges among long neighbours, such as
/// a graded input's coarse part. Measured on one default step of the seven
/// shipped meshes (2026-12-07, `benches/compare.sh`), the 99th-percentile
/// edge length against MMG3D `-hsiz`'s at the same count: 1.19×–1.50×
/// without the cap (five meshes above issue 14's 1.25×), 1.18×–1.25× with
/// it, for
/// 0.4 %–17 % more tets and 77 % more on gmsh_t16 (a graded input, a
/// shortest-to-median edge ratio of 0.02). With the cap in every round,
/// 2.0 left gmsh_t16 at 1.26× (48 % more tets) and 1.8 took 83 % more.
pub const LONG_EDGE_CAP: f64 = 1.9;

/// Long-edge rounds of a default step: each splits the edges longer than
/// [`LONG_EDGE_FACTOR`] times the mean at their ends, then settles the new
/// balls with the passes. One round leaves edges that were not long against
/// the means before it, and edges its settling flips make; a second round
/// splits those. Measured on one default step of the seven shipped meshes
/// (2026-12-06, against one round): 11 %–16 % more tets, average +0.8° to
/// +1.9° (mmg_cube 44.23° → 46.14°, the tripod 47.63° → 49.05°),
/// 99th-percentile edge −7 % to −17 %, longest edge up to −13 % (mmg_cube's
/// longest, a chord whose split is refused, stays), for 19 %–47 % more step
/// time (+54 % on an already even cube grid).
pub const LONG_EDGE_ROUNDS: usize = 2;

/// The outlier round after the long-edge rounds of a second or later
/// `default` or `best` step splits the edges of the step's tets longer
/// than this times the mean edge length at their ends (see the
/// refinement step's outlier round): above [`LONG_EDGE_FACTOR`], so that
/// it takes the tail the rounds left, not a third round's worth of tets
/// (1.4 with the cap at 1.9 gave 22 %–27 % more tets).
pub const OUTLIER_FACTOR: f64 = 1.5;

/// The outlier round also splits every edge longer than this times the
/// median mean edge length at a point ([`LengthCap::MedianTimes`]), as
/// [`LONG_EDGE_CAP`] does for the rounds before. Measured on two default
/// steps of the seven shipped meshes (2026-12-07, 99th-percentile edge
/// against MMG3D `-hsiz`'s at the same count): with 2.0 it was 1.21×–1.24×
/// on six and 1.27× on gmsh_t16 (a graded input); with 1.9 it is
/// 1.18×–1.25×, gmsh_t16 at 1.246×, for 5 %–7 % more tets, the worst angles
/// the same and the averages within 0.07°.
pub const OUTLIER_CAP: f64 = 1.9;

/// How hard mesh improvement works.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Effort {
    /// Interior moves and edge removal only (the boundary stays fixed), a
    /// Laplacian move kept only where it raises its ball's worst tet: the
    /// behaviour before boundary-aware improvement.
    Fast,
    /// Interior and boundary moves (surface patches, feature lines).
    #[default]
    Default,
    /// More passes, a higher bar for optimisation-based smoothing, edge
    /// removal over larger rings and better tets.
    Best,
}

impl Effort {
    /// The improvement options of this effort with `passes` passes (the
    /// user's `--opt-passes`), optimisation below `threshold` (min sine) and
    /// Hausdorff bound `hausd` (`None`: relative to the local edge length).
    pub fn improve_options(
        self,
        passes: usize,
        threshold: f64,
        hausd: Option<f64>,
    ) -> ImproveOptions {
        let base = ImproveOptions {
            passes,
            threshold,
            ..Default::default()
        };
        match self {
            Effort::Fast => ImproveOptions {
                boundary: None,
                smooth_for_mean: false,
                ..base
            },
            Effort::Default => ImproveOptions {
                boundary: Some(BoundarySmoothOptions {
                    hausd,
                    ..Default::default()
                }),
                ..base
            },
            Effort::Best => ImproveOptions {
                passes: passes.max(6),
                threshold: threshold.max(0.45),
                edge_threshold: 0.7,
                max_ring: 24,
                boundary: Some(BoundarySmoothOptions {
                    hausd,
                    threshold: 0.6,
                    laplacian_threshold: 0.8,
                    ..Default::default()
                }),
                ..base
            },
        }
    }

    /// The long-edge factor of a refinement step at this effort: each of its
    /// long-edge rounds splits the edges of the step's tets longer than this
    /// times the mean edge length at their ends, then settles the new balls
    /// with the passes. `None` for `fast`, whose tet count is the √3 step's
    /// own.
    pub fn long_edge_factor(self) -> Option<f64> {
        match self {
            Effort::Fast => None,
            Effort::Default | Effort::Best => Some(LONG_EDGE_FACTOR),
        }
    }

    /// The long-edge rounds' cap ([`LONG_EDGE_CAP`]); off for `fast`, which
    /// has no rounds.
    pub(crate) fn long_edge_cap(self) -> LengthCap {
        match self {
            Effort::Fast => LengthCap::Off,
            Effort::Default | Effort::Best => LengthCap::MedianTimes(LONG_EDGE_CAP),
        }
    }

    /// The number of long-edge rounds of a refinement step at this effort:
    /// none for `fast`, two for `default` (`LONG_EDGE_ROUNDS`), three for
    /// `best`.
    pub fn long_edge_rounds(self) -> usize {
        match self {
            Effort::Fast => 0,
            Effort::Default => LONG_EDGE_ROUNDS,
            Effort::Best => LONG_EDGE_ROUNDS + 1,
        }
    }

    /// The outlier round's factor and cap ([`OUTLIER_FACTOR`],
    /// [`OUTLIER_CAP`]); `None` for `fast`, which has no long-edge rounds.
    pub(crate) fn outlier_split(self) -> Option<(f64, LengthCap)> {
        match self {
            Effort::Fast => None,
            Effort::Default | Effort::Best => {
                Some((OUTLIER_FACTOR, LengthCap::MedianTimes(OUTLIER_CAP)))
            }
        }
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Effort::Fast => "fast",
            Effort::Default => "default",
            Effort::Best => "best",
        }
    }
}

impl fmt::Display for Effort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Effort {
    type Err = String;
    fn from_str(s: &str) -> Result<Effort, String> {
        match s {
            "fast" => Ok(Effort::Fast),
            "default" => Ok(Effort::Default),
            "best" => Ok(Effort::Best),
            _ => Err(format!("unknown effort '{s}'; one of fast, default, best")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_order_the_work() {
        let f = Effort::Fast.improve_options(3, 0.3, None);
        let d = Effort::Default.improve_options(3, 0.3, Some(0.01));
        let b = Effort::Best.improve_options(3, 0.3, None);
        assert!(f.boundary.is_none());
        assert_eq!(d.boundary.as_ref().and_then(|o| o.hausd), Some(0.01));
        assert!(b.passes > d.passes && b.max_ring > d.max_ring && b.threshold > d.threshold);
        assert_eq!(Effort::Fast.long_edge_rounds(), 0);
        assert!(Effort::Best.long_edge_rounds() > Effort::Default.long_edge_rounds());
        assert!(Effort::Fast.outlier_split().is_none());
        let (factor, _) = Effort::Default.outlier_split().expect("an outlier round");
        assert!(factor > LONG_EDGE_FACTOR, "the round takes the tail only");
        for e in ["fast", "default", "best"] {
            assert_eq!(e.parse::<Effort>().unwrap().name(), e);
        }
        assert!("most".parse::<Effort>().is_err());
    }
}
