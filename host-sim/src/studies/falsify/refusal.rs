//! How far the preflight's refusal of a candidate is from feasible
//! (docs/search.md#refused-candidates, **Choice 551**): the graded score a refused candidate
//! gives the search, so that it is pulled towards the feasibility boundary, where a false
//! feasible can be, instead of learning nothing from it.
//!
//! A refused candidate is one for which `check` proposes no time scale. Each of the check's
//! limits that fits at no scale is taken where it is loosest — at rest for the force (the
//! static check, k = ∞), at the slowest scale the search tries
//! (`Trajectory::MAX_TIME_SCALE`) for the path-error budget and the chatter term (its mean
//! thrust held still between the reference's samples, Choice 560:
//! [`chatter::Chatter::slowest_held`], within a few per cent of the full pass at half the
//! search's time) — and its need is normalised by its own limit:
//! need / limit − 1, the fraction by which the slowest flight the check can name still misses
//! it (0: on the limit). A limit that fits at some scale adds nothing, so a refusal by the
//! joint search alone (every limit fits, but no common scale was found) is on the boundary.
//! The refusal's distance is the largest of these: the least of the per-limit robustness
//! terms 1 − need/limit, negated, as [`crate::sim::bound::robustness`] takes the least of the
//! flight's, so that no unit hides another.

use crate::scenario::Scenario;
use crate::studies::preflight::{chatter, CheckError, Preflight, Violation};

/// What a refused candidate scores before its distance is added: above every robustness a
/// flown candidate can have (each term is 1 − value/limit of a value ≥ 0, so at most 1), so
/// that any candidate the check calls feasible ranks before every refused one.
pub const REFUSED_BASE: f64 = 2.0;

/// Per limit of the check, how far beyond it the refused mission stays where the limit is
/// loosest, as a fraction of the limit (0: within it, or it fits at some scale).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Excess {
    /// The static check's worst thruster against its margin envelope.
    pub force: f64,
    /// The path-error budget's speed-independent part against the bound.
    pub path: f64,
    /// The chatter term's worst reversals per second, and command total variation, at the
    /// slowest scale (the mean held between samples, Choice 560), against the bound's limits.
    pub reversals: f64,
    pub command_tv: f64,
}

impl Excess {
    /// The distance from feasible: the largest excess (≥ 0).
    pub fn distance(&self) -> f64 {
        [self.force, self.path, self.reversals, self.command_tv]
            .into_iter()
            .fold(0.0, f64::max)
    }
}

/// `need / limit − 1`, at least 0 (a need not finite is infinitely far).
fn beyond(need: f64, limit: f64) -> f64 {
    let r = need / limit - 1.0;
    if r.is_nan() {
        f64::INFINITY
    } else {
        r.max(0.0)
    }
}

/// A violation's demand beyond the side of the margin envelope it crosses, as a fraction of
/// that side.
fn force_excess(v: &Violation) -> f64 {
    let [lo, hi] = v.limit;
    if v.demand > hi {
        beyond(v.demand, hi)
    } else if v.demand < lo {
        beyond(v.demand, lo)
    } else {
        0.0
    }
}

/// The excess of each limit of `mission`'s check `p` (see the module docs); all 0 for a
/// mission the check does not refuse.
///
/// # Errors
/// [`CheckError`] from the chatter term evaluated at the slowest scale.
pub fn excess(mission: &Scenario, p: &Preflight) -> Result<Excess, CheckError> {
    let mut out = Excess::default();
    if p.feasible() || p.smallest_time_scale.is_some() {
        return Ok(out);
    }
    if let Some(v) = &p.static_violation {
        out.force = force_excess(v);
    }
    if let Some(b) = p
        .path_budget
        .as_ref()
        .filter(|b| b.smallest_time_scale.is_none())
    {
        out.path = beyond(b.speed_independent, b.bound);
    }
    if p.chatter
        .as_ref()
        .is_some_and(|c| c.smallest_time_scale.is_none())
    {
        if let Some(model) = chatter::Chatter::new(mission)? {
            let slowest = model.slowest_held()?;

            out.reversals = beyond(slowest.worst_reversals().0, slowest.max_reversals_per_s);
            out.command_tv = beyond(slowest.worst_tv().0, slowest.max_command_tv);
        }
    }
    Ok(out)
}
