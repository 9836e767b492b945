//! Two missions the `falsify` search found false feasible against main 5422ed3 (issue 30,
//! docs/search.md#against-the-real-preflight), both in restart 2 of
//! `host-sim falsify --budget 250 --restarts 20 --shard 2/20 --seed 1 --duration 20`, both on
//! ideal navigation with the estimator off, thrusters of lag 0.17–0.26 s, a 1–2 cm start offset
//! and a 0.18–0.25 m/s current:
//!
//! - a lawn-mower `check` calls feasible at time scale 24.55, which flies 68 mm of path error
//!   (64 mm of it in depth) at 0.6 % saturated: the start offset's transient through the lag;
//! - a figure-eight `check` calls feasible at 1.37 (its peak at 80 % of horz fore's envelope, the
//!   margin), which flies 1.5 % of its periods saturated (bound 1 %).
//!
//! The flights' misses are asserted here (the independent fact); the preflight's refusal is the
//! open half, ignored until the preflight gives it:
//! `cargo test --profile host -p host-sim --test falsified_open -- --ignored`.

#[path = "common/falsified.rs"]
mod falsified;

use falsified::{fly, mission};
use host_sim::sim::bound;
use host_sim::studies::preflight::{self, DEFAULT_MARGIN};

const FILES: [&str; 2] = [
    "falsified-open-lawn-mower-lag-random-r2.toml",
    "falsified-open-figure-eight-lag-ce-r2.toml",
];

#[test]
fn each_open_falsifier_misses_its_bound_at_the_scale_written() {
    for file in FILES {
        let m = mission(file);
        let flown = fly(&m);
        assert!(!bound::within_bound(&flown), "{file}: {:?}", flown.metrics);
    }
}

#[test]
#[ignore = "open (issue 30): the preflight calls both feasible at the scale they miss at"]
fn the_preflight_refuses_each_open_falsifier_at_the_scale_it_misses_at() {
    for file in FILES {
        let p = preflight::check_as_written(&mission(file), DEFAULT_MARGIN).unwrap();
        assert!(!p.feasible(), "{file}: {p}");
    }
}
