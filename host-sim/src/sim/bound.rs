//! A run against its bound (docs/real-vehicle.md#the-bound-and-the-start-in-trim): the real vehicle's, or a scenario's `[bound]`.

use controller_core::effectiveness::THRUSTER_NAMES;

use super::chatter::{ThrusterChatter, DEAD_BAND};
use super::record::{Metrics, Outcome, RunResult};
use crate::scenario::Bound;

/// The real vehicle's bound on the max path error (m): [`Bound::REAL_VEHICLE`].
pub const MAX_PATH_ERROR: f64 = Bound::REAL_VEHICLE.max_path;
/// … and on the fraction of control periods with a thruster saturated.
pub const MAX_SATURATED_FRACTION: f64 = Bound::REAL_VEHICLE.saturated;
/// … and on any thruster's sign reversals per second (Choice 322).
pub const MAX_REVERSALS_PER_S: f64 = Bound::REAL_VEHICLE.max_reversals_per_s;
/// … and on any thruster's command total variation per second (V/s).
pub const MAX_COMMAND_TV: f64 = Bound::REAL_VEHICLE.max_command_tv;

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
    chatter(
        metrics,
        |c| c.reversals_per_s,
        metrics.reversals_per_s,
        bound.max_reversals_per_s,
        &mut |who, x, limit| {
            format!("{who} reverses {x:.1} times/s through ±{DEAD_BAND} V > {limit} /s")
        },
        &mut reasons,
    );
    chatter(
        metrics,
        |c| c.command_tv,
        metrics.command_tv,
        bound.max_command_tv,
        &mut |who, x, limit| {
            format!("{who}'s command varies by {x:.0} V/s > {limit} V/s (total variation)")
        },
        &mut reasons,
    );
    (!reasons.is_empty()).then(|| reasons.join("; "))
}

/// Pushes a reason for each thruster whose figure `f` is beyond `limit`, by name (`thruster
/// horz aft`); when the per-thruster figures are not known (a campaign record keeps the worst
/// only), one reason for the worst, `worst`, as "a thruster".
fn chatter(
    metrics: &Metrics,
    f: fn(&ThrusterChatter) -> f64,
    worst: f64,
    limit: f64,
    reason: &mut dyn FnMut(&str, f64, f64) -> String,
    reasons: &mut Vec<String>,
) {
    let per_thruster = metrics.chatter.0.map(|c| f(&c));
    if per_thruster.iter().any(|x| x.is_nan()) {
        if beyond(worst, limit) {
            reasons.push(reason("a thruster", worst, limit));
        }
        return;
    }
    for (name, x) in THRUSTER_NAMES.iter().zip(per_thruster) {
        if beyond(x, limit) {
            reasons.push(reason(&format!("thruster {name}"), x, limit));
        }
    }
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
