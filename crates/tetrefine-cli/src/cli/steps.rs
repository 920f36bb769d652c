//! The entries of `refine --stats` (`{"steps":[…]}`, the first entry being
//! the input): a mesh's statistics joined with what the step did.

use serde::Serialize;
use tetrefine::MeshStats;
use tetrefine::{PhaseReport, StepReport};

/// One entry of `--stats`: the quality JSON of the mesh after the step, plus
/// the step's phases and wall time (empty / 0 for the input entry).
#[derive(Clone, Debug, Serialize)]
pub struct StepStats {
    /// The statistics (flattened: the same keys as `quality --json`).
    #[serde(flatten)]
    pub stats: MeshStats,
    /// Phases with tets after each and their wall time.
    pub phases: Vec<PhaseReport>,
    /// Wall time of the step.
    pub seconds: f64,
    /// Peak resident memory of the process so far (`VmHWM` of
    /// `/proc/self/status`; absent where that file does not exist).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_rss_bytes: Option<u64>,
    /// What the step did, operation by operation (absent for the input).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub report: Option<StepReport>,
}

/// Peak resident set size of this process in bytes, from `/proc/self/status`.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

impl StepStats {
    /// The input entry.
    pub fn input(stats: MeshStats) -> StepStats {
        StepStats {
            stats,
            phases: Vec::new(),
            seconds: 0.0,
            peak_rss_bytes: peak_rss_bytes(),
            report: None,
        }
    }

    /// The entry of a refinement step.
    pub fn step(stats: MeshStats, report: &StepReport) -> StepStats {
        StepStats {
            stats,
            phases: report.phases.clone(),
            seconds: report.seconds,
            peak_rss_bytes: peak_rss_bytes(),
            report: Some(report.clone()),
        }
    }
}
