//! Missions `falsify --reach realities --navigation ideal` found false feasible
//! (docs/search.md#against-the-real-preflight): a payload the law's model does not have, a
//! thruster lag of 0.22–0.26 s and a start offset of 1–2 cm. Every saturated period was in the
//! first two seconds: the feedback taking up the mismatch through lagged thrusters overshoots
//! the steady demand (without the lag the same missions fly within bounds). The check now keeps
//! the lag's share of each thruster's envelope (Choice 509, docs/real-vehicle.md#the-lags-share).

#[path = "common/falsified.rs"]
mod falsified;

use falsified::{at_scale, mission};
use host_sim::scenario::Scenario;
use host_sim::sim::{self, bound, LocalController, Observer, Recording, Sample};
use host_sim::studies::preflight::{self, DEFAULT_MARGIN};

/// Watches nothing.
struct Nothing;
impl Observer for Nothing {
    fn sample(&mut self, _: &Sample) {}
}

fn within(s: &Scenario) -> bool {
    let run = sim::fly(
        s,
        &mut LocalController::new(s),
        &mut Nothing,
        Recording::MetricsOnly,
    );
    bound::within_bound(&run)
}

/// The mission at scale 1 (what the check proposed before) misses; without its lag it flies
/// (the lag is the cause); the check now refuses it at 1. It proposes 1.84, where the 70 s
/// mission the search wrote flies within bounds (0.9 % of its periods saturated) but this
/// 20 s span does not (the start's 1.3 s of saturation is 3 % of it): the reserve is short
/// of this start's overshoot (docs/real-vehicle.md#the-lags-share), so that is not asserted.
#[test]
fn a_lagged_start_is_refused_where_it_missed() {
    let m = mission("falsified-lag-start-r1.toml");
    assert!(!within(&m));
    assert!(within(&m.with(|c| c.thruster_lag = None).unwrap()));
    let p = preflight::check_as_written(&m, DEFAULT_MARGIN).unwrap();
    assert!(!p.feasible(), "{p}");
    let k = p.smallest_time_scale.unwrap();
    assert!(k > 1.0, "{k}");
}

/// A mission whose start transient saturates at every speed (it misses at scale 1 and at 4):
/// the check now refuses it at every scale.
#[test]
fn a_start_no_speed_cures_is_refused_at_every_scale() {
    let m = mission("falsified-lag-static-r0.toml");
    assert!(!within(&m));
    assert!(!within(&at_scale(&m, 4.0)));
    assert!(within(&m.with(|c| c.thruster_lag = None).unwrap()));
    let p = preflight::check_as_written(&m, DEFAULT_MARGIN).unwrap();
    assert!(p.smallest_time_scale.is_none(), "{p}");
}
