//! Progress display for long phases (stderr, only on a terminal).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Mutex;
use tetrefine::{Phase, Progress};

/// A bar over all phases of all steps, with the running
/// phase and its tet count as message, on stderr; hidden when stderr is not
/// a terminal.
///
/// ```text
/// ⠙ [#########>-----------] 8/12 step 2/2: flip (13.9M tets) [00:00:41]
/// ```
pub struct BarProgress {
    bar: ProgressBar,
    steps: usize,
    phases_per_step: usize,
    phases_done: Mutex<usize>,
}

impl BarProgress {
    /// A progress display for `steps` steps of `phases_per_step` phases
    /// each (six, or fewer with `--stop-after`), with nothing shown yet.
    pub fn new(steps: usize, phases_per_step: usize) -> BarProgress {
        let phases_per_step = phases_per_step.max(1);
        let bar = ProgressBar::with_draw_target(
            Some((steps * phases_per_step) as u64),
            ProgressDrawTarget::stderr(),
        );
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{bar:24}] {pos}/{len} {msg} [{elapsed_precise}]",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("#>-"),
        );
        BarProgress {
            bar,
            steps,
            phases_per_step,
            phases_done: Mutex::new(0),
        }
    }

    /// Runs `f` (which prints) with the bar hidden, so lines do not mix.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }

    /// Clears the bar (call when the steps are over).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// `n` tets in a short form: 950, 41.3k, 13.9M.
fn short_count(n: u64) -> String {
    match n {
        0..=9_999 => n.to_string(),
        10_000..=9_999_999 => format!("{:.1}k", n as f64 / 1e3),
        _ => format!("{:.1}M", n as f64 / 1e6),
    }
}

impl Progress for BarProgress {
    fn phase_start(&self, phase: Phase, total: u64) {
        let done = self.phases_done.lock().map(|d| *d).unwrap_or(0);
        let step = done / self.phases_per_step + 1;
        self.bar.set_message(format!(
            "step {step}/{}: {phase} ({} tets)",
            self.steps,
            short_count(total)
        ));
        self.bar
            .enable_steady_tick(std::time::Duration::from_millis(120));
    }

    fn phase_end(&self) {
        if let Ok(mut d) = self.phases_done.lock() {
            *d += 1;
            self.bar.set_position(*d as u64);
        }
    }

    fn step_again(&self, phases: u64) {
        if let Ok(mut d) = self.phases_done.lock() {
            *d = d.saturating_sub(phases as usize);
            self.bar.set_position(*d as u64);
        }
    }
}
