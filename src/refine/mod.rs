//! The √3 tetrahedral subdivision step of Burkhart, Hamann and Umlauf,
//! "Adaptive and feature-preserving subdivision for high-quality tetrahedral
//! meshes" (Computer Graphics Forum 2010), §3–4, as named phases:
//!
//! 1. `split` — 1-4 split of every selected tet at its barycentre;
//! 2. `flip` — 2-3 flip of every old interior face whose two tets were split;
//! 3. `boundary-split` — 1-3 split of every boundary face of a split tet;
//! 4. `boundary-flip` — every old boundary edge between two split faces is
//!    removed (m tets → 2m − 2), so the new boundary edge joins two face
//!    barycentres: the triangle √3 flip;
//! 5. `boundary-smooth` — the √3 stencils of [`crate::stencil`] move the
//!    boundary points; a move that would invert a tet is shortened or skipped;
//! 6. `optimize` — interior edge removal and vertex smoothing
//!    ([`crate::improve::improve`]).
//!
//! A step renumbers tets and points (it compacts the mesh and sorts it along
//! a space-filling curve before `optimize`), so ids held across a step are
//! stale; `parent` and `level` carry what callers need.

pub mod bisect;
pub mod features;
pub mod marking;
pub mod parents;
pub mod size;
pub mod step;
pub mod transfer;

pub use parents::locate_parents;
pub use step::{refine, refine_step, refine_step_with_progress, refine_with, refine_with_guard};
pub use transfer::{copy_cell_field, interpolate_point_field, locate_points, PointParent};

/// Progress callbacks for long phases (the CLI draws bars with them).
/// Every method has a no-op default.
pub trait Progress: Sync {
    /// A phase begins with `total` work items.
    fn phase_start(&self, _phase: Phase, _total: u64) {}
    /// `n` more items are done.
    fn advance(&self, _n: u64) {}
    /// The phase is over.
    fn phase_end(&self) {}
    /// The step runs again (holding tets back, see [`StepReport::held`]):
    /// the ends of its last `phases` phases are taken back.
    fn step_again(&self, _phases: u64) {}
}

/// Reports nothing.
pub struct NoProgress;

impl Progress for NoProgress {}

use crate::improve::ImproveReport;
pub use crate::stencil::Sqrt3Rule;
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// A phase of the step, in the paper's order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Phase {
    /// 1-4 splits.
    Split,
    /// 2-3 flips of old interior faces.
    Flip,
    /// 1-3 splits of boundary faces.
    BoundarySplit,
    /// √3 flips of old boundary edges by edge removal.
    BoundaryFlip,
    /// √3 stencils on the boundary points.
    BoundarySmooth,
    /// Edge removal and vertex smoothing.
    Optimize,
}

impl Phase {
    /// All phases in order.
    pub const ALL: [Phase; 6] = [
        Phase::Split,
        Phase::Flip,
        Phase::BoundarySplit,
        Phase::BoundaryFlip,
        Phase::BoundarySmooth,
        Phase::Optimize,
    ];

    /// The phase's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Split => "split",
            Phase::Flip => "flip",
            Phase::BoundarySplit => "boundary-split",
            Phase::BoundaryFlip => "boundary-flip",
            Phase::BoundarySmooth => "boundary-smooth",
            Phase::Optimize => "optimize",
        }
    }
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Phase {
    type Err = String;
    fn from_str(s: &str) -> Result<Phase, String> {
        Phase::ALL
            .iter()
            .copied()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown phase '{s}'; one of {}",
                    Phase::ALL.map(|p| p.name()).join(", ")
                )
            })
    }
}

/// How material interfaces (faces between two regions) are refined
/// (`--interfaces`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum InterfaceRule {
    /// Interface faces are split at their centroids and flipped only where
    /// flat, and interface points never move in the topological phases: every
    /// region keeps its exact volume, and a curved interface is tagged as
    /// creases wherever it bends ([`features::detect_features`]), so it stays
    /// faceted at its input resolution. The default.
    #[default]
    Linear,
    /// Interface faces are split and flipped by the √3 rule on both sides, and
    /// interface points move by the boundary's stencil ([`Sqrt3Rule`]):
    /// a curved interface converges to a smooth surface. Only bends sharper
    /// than the feature angle (and junctions) stay creases. Region volumes
    /// change by the smoothing (bounded in the README's measurements). Faces
    /// marked inside one region stay linear.
    Sqrt3,
}

impl FromStr for InterfaceRule {
    type Err = String;
    fn from_str(s: &str) -> Result<InterfaceRule, String> {
        match s {
            "linear" => Ok(InterfaceRule::Linear),
            "sqrt3" => Ok(InterfaceRule::Sqrt3),
            _ => Err(format!(
                "unknown interface rule '{s}'; one of linear, sqrt3"
            )),
        }
    }
}

/// Options of a refinement step.
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// Boundary rule of step 5: the √3 surface stencil the boundary points
    /// follow.
    pub boundary: Sqrt3Rule,
    /// Passes of the optimize phase (0 = skip it).
    pub opt_passes: usize,
    /// Quality (min sine) below which vertices are smoothed.
    pub threshold: f64,
    /// Stop after this phase (for inspection and tests).
    pub stop_after: Option<Phase>,
    /// Per tet slot: is it selected for splitting? `None` = every tet.
    pub selection: Option<Vec<bool>>,
    /// `--smooth refined`: the optimize phase moves only vertices of tets
    /// refined in this step and removes only their edges, so tets that share
    /// no vertex with a refined tet come out bit-identical.
    pub smooth_refined_only: bool,
    /// Refinement rounds done before this run (an adaptive loop that refines
    /// once per solve passes its round number): the crease rule keeps
    /// feature edges in odd global steps and trisects them in even ones, so
    /// without it every one-step run would keep them and the faces along
    /// them would thin out round after round.
    pub step_offset: usize,
    /// Run [`TetMesh::check`](crate::TetMesh::check) after every phase and
    /// record failures in [`StepReport::check_failures`] (tests, debugging).
    pub check_each_phase: bool,
    /// How hard the optimize phase works (`--effort`).
    pub effort: crate::improve::Effort,
    /// Hausdorff bound of boundary moves (`--hausd`; `None`: relative to the
    /// local edge length).
    pub hausd: Option<f64>,
    /// How material interfaces are refined (`--interfaces`). Feature
    /// detection must agree: [`features::detect_features_for`] with the same
    /// rule.
    pub interfaces: InterfaceRule,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            boundary: Sqrt3Rule::Interpolating,
            opt_passes: 3,
            threshold: crate::improve::DEFAULT_THRESHOLD,
            stop_after: None,
            selection: None,
            smooth_refined_only: false,
            step_offset: 0,
            check_each_phase: false,
            effort: crate::improve::Effort::Default,
            hausd: None,
            interfaces: InterfaceRule::Linear,
        }
    }
}

/// Time and size after one phase.
#[derive(Clone, Debug, Serialize)]
pub struct PhaseReport {
    /// Phase name.
    pub name: &'static str,
    /// Live tets after the phase.
    pub tets: usize,
    /// Wall time of the phase.
    pub seconds: f64,
}

/// What one step did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StepReport {
    /// Per phase, in order (only the phases that ran).
    pub phases: Vec<PhaseReport>,
    /// Tets split 1-4.
    pub split: usize,
    /// Interior faces flipped 2-3.
    pub flipped: usize,
    /// 2-3 flips refused (segment between the barycentres misses the face, or
    /// the face separates regions or carries a marker).
    pub refused_flips: usize,
    /// Barycentres moved towards a shared face so that its 2-3 flip is valid.
    pub moved_barycentres: usize,
    /// Boundary faces split 1-3.
    pub boundary_split: usize,
    /// Old boundary edges flipped.
    pub boundary_flipped: usize,
    /// Boundary edge flips refused (would invert, marker change, untagged
    /// junction, not all faces around the edge split, or, with the linear
    /// rule, faces not exactly coplanar).
    pub refused_boundary_flips: usize,
    /// Interface faces split 2-6.
    pub interface_split: usize,
    /// Feature edges kept (odd step).
    pub kept_feature_edges: usize,
    /// Feature edges trisected (even step).
    pub trisected_feature_edges: usize,
    /// Boundary points moved the full way.
    pub full_moves: usize,
    /// Boundary point moves shortened to avoid an inverted tet.
    pub shortened_moves: usize,
    /// Boundary point moves skipped entirely.
    pub skipped_moves: usize,
    /// The optimize phase.
    pub improve: ImproveReport,
    /// Input tets left unsplit (out of the selection) so that the step keeps
    /// its input's worst dihedral angle: where the phases left a tet below
    /// it, the step ran again without the input tets around it.
    pub held: usize,
    /// Wall time of the whole step.
    pub seconds: f64,
    /// With `check_each_phase`: `phase: error` for every phase after which
    /// the mesh failed its invariants.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub check_failures: Vec<String>,
}
