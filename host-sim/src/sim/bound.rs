//! A run against its bound (docs/real-vehicle.md#the-bound-and-the-start-in-trim): the real vehicle's, or a scenario's `[bound]`.

use super::record::{Metrics, Outcome, RunResult};
use crate::scenario::Bound;

/// The real vehicle's bound on the max path error (m): [`Bound::REAL_VEHICLE`].
pub const MAX_PATH_ERROR: f64 = Bound::REAL_VEHICLE.max_path;
/// … and on the fraction of control periods with a thruster saturated.
pub const MAX_SATURATED_FRACTION: f64 = Bound::REAL_VEHICLE.saturated;

/// Why `metrics` lie outside `bound`, if they do: every limit exceeded, and by how much.
pub fn miss(bound: &Bound, metrics: &Metrics) -> Option<String> {
    let mut reasons = Vec::new();
    if beyond(metrics.max_path, bound.max_path) {
        reasons.push(format!(
            "max path error {:.4} m > {} m ({:.1}× the bound)",
            metrics.max_path,
            bound.max_path,
            metrics.max_path / bound.max_path
        ));
    }
    if beyond(metrics.saturated_fraction, bound.saturated) {
        reasons.push(format!(
            "saturated in {:.1} % of the periods > {} %",
            100.0 * metrics.saturated_fraction,
            100.0 * bound.saturated
        ));
    }
    (!reasons.is_empty()).then(|| reasons.join("; "))
}

/// True when a run completed within the real vehicle's bound ([`Bound::REAL_VEHICLE`]),
/// whatever bound its scenario set.
pub fn within_bound(run: &RunResult) -> bool {
    matches!(run.outcome, Outcome::Completed | Outcome::Missed { .. })
        && miss(&Bound::REAL_VEHICLE, &run.metrics).is_none()
}

/// `x` is above `limit`, or not a number (NaN is never within a bound).
fn beyond(x: f64, limit: f64) -> bool {
    !matches!(
        x.partial_cmp(&limit),
        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
    )
}
