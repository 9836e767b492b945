//! The workspace's property tests are deterministic (docs/ci.md#deterministic-tests-and-quick-rebuilds, Choice 91): every
//! `proptest!` starts from `ProptestConfig::default()` (directly, through `with_cases`, or as
//! `..ProptestConfig::default()`), and proptest applies the `PROPTEST_*` environment to it and
//! again to whatever config a test sets. Cargo sets `PROPTEST_RNG_SEED` and
//! `PROPTEST_DISABLE_FAILURE_PERSISTENCE` for every process it runs (`.cargo/config.toml`,
//! `[env]`), so every property test of every crate draws the same cases on every run and none
//! writes a `.proptest-regressions` file into the source tree. A developer's own
//! `PROPTEST_RNG_SEED` (scripts/fuzz.sh) is a fixed seed too.

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{RngSeed, TestRunner};

/// 16 cases drawn by a fresh runner from the default config.
fn draw() -> Vec<(u64, f32, Vec<u8>)> {
    let mut runner = TestRunner::new(ProptestConfig::default());
    let strategy = (
        any::<u64>(),
        -1.0f32..1.0,
        prop::collection::vec(any::<u8>(), 0..8),
    );
    (0..16)
        .map(|_| strategy.new_tree(&mut runner).expect("no filter").current())
        .collect()
}

#[test]
fn property_tests_draw_from_a_fixed_seed_and_write_no_regression_file() {
    let config = ProptestConfig::default();
    assert!(
        matches!(config.rng_seed, RngSeed::Fixed(_)),
        "proptest draws a random seed: run the tests through cargo, whose [env] in \
         .cargo/config.toml sets PROPTEST_RNG_SEED"
    );
    assert!(
        config.failure_persistence.is_none(),
        "failure persistence is on: a failing property test would write a .proptest-regressions \
         file into the source tree (.cargo/config.toml sets PROPTEST_DISABLE_FAILURE_PERSISTENCE)"
    );
    // Two runners from the same config draw the same cases (with a random seed they would not,
    // but for a chance of 2⁻⁶⁴ per u64).
    assert_eq!(draw(), draw());
}
