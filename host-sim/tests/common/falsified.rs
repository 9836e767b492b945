//! What the tests of falsified missions share (tests/falsified_*.rs): a mission from
//! tests/data, the same path at another time scale, and a flight of it that keeps its metrics.

// Each test binary uses some of these.
#![allow(dead_code)]

use host_sim::scenario::{load_scenario, Scenario};
use host_sim::sim::{self, LocalController, Recording};

/// A falsifying mission as `falsify` wrote it, from `host-sim/tests/data`.
pub fn mission(file: &str) -> Scenario {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    load_scenario(&path).unwrap()
}

/// The same path at time scale `k`: its duration stretched with it.
pub fn at_scale(s: &Scenario, k: f64) -> Scenario {
    let span = s.config().duration / f64::from(s.config().time_scale);
    s.with(|c| {
        c.time_scale = k as f32;
        c.duration = span * k;
    })
    .unwrap()
}

/// `s` flown with the law on the host, metrics only.
pub fn fly(s: &Scenario) -> sim::RunResult {
    sim::fly(
        s,
        &mut LocalController::new(s),
        &mut (),
        Recording::MetricsOnly,
    )
}
