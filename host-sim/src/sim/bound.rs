//! The bound a real-vehicle run must fly within (docs/design.md §9).

use super::record::{Outcome, RunResult};

/// The bound every mission `check` calls feasible must fly within (docs/design.md §9): max
/// path error (m).
pub const MAX_PATH_ERROR: f64 = 0.05;
/// … and the largest fraction of control periods with a thruster saturated.
pub const MAX_SATURATED_FRACTION: f64 = 0.01;

/// True when a run's metrics are within [`MAX_PATH_ERROR`] and [`MAX_SATURATED_FRACTION`] and
/// it completed.
pub fn within_bound(run: &RunResult) -> bool {
    matches!(run.outcome, Outcome::Completed)
        && run.metrics.max_path <= MAX_PATH_ERROR
        && run.metrics.saturated_fraction <= MAX_SATURATED_FRACTION
}
