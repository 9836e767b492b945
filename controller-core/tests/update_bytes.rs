//! The `controller_update` fuzz target (fuzz/fuzz_targets/controller_update.rs) as property
//! tests, so that the stable test suite checks the same properties without nightly or
//! libFuzzer. Arbitrary bytes are read exactly as the fuzz target reads them (both include
//! `tests/common/update_input.rs`):
//!
//! | bytes  | meaning |
//! |--------|---------|
//! | 0..8   | `ticks: u64` |
//! | 8..32  | η: 6 × u32 → f32 |
//! | 32..56 | ν: 6 × u32 → f32 |
//! | 56     | Table-1 case: `Table1Case::ALL[b % 6]` (`% Table1Case::ALL.len()`) |
//! | 57     | flags: bit 0 robust (Δu on), bit 1 custom trajectory, bit 2 `ticks %= 2²⁰`, |
//! |        | bit 3 scaled, bit 4 relative (see below) |
//! | 58     | custom trajectory kind: `b % n`, the n closed forms of `TrajectoryKind::EXAMPLES` in order |
//! |        | (today n = 4: circle, figure-eight, lawn-mower, helix) |
//! | 59..   | its parameters in field order (`TrajectoryKind::parameters`), one u32 → f32 each, as |
//! |        | many words as the most any closed form has (today 4: 59..75; size, ω, depth, depth rate) |
//!
//! Missing bytes read as zero, extra bytes are ignored, all little-endian.
//!
//! u32 → f32 is `f32::from_bits` (NaN, ±∞, subnormals, huge values all occur), or with the
//! *scaled* flag `(bits as i32) / i32::MAX × limit`: 1.05 × the controller's plausibility limit
//! of that input (`MAX_POSITION`, `MAX_ANGLE`, `MAX_LINEAR_SPEED`, `MAX_ANGULAR_RATE`) or of the
//! trajectory parameter, so that about half the inputs pass the input checks and run the law.
//! With the *relative* flag the decoded η and ν are offsets from the trajectory under test at
//! `ticks` (η_d and ν_d = J⁻¹(η_d) η̇_d), and the scaled limits are 0.5 m, 0.2 rad, 0.5 m/s and
//! 0.2 rad/s: the vehicle near its reference, where δ is often not clamped.
//!
//! Every output (on the Table-1 trajectory, and on the custom one when `Trajectory::new` accepts
//! it) is finite, |voltage| ≤ `voltage_limit`, 0 ≤ δ ≤ `delta_max`, ‖w‖ ≥ 0, only the five
//! thruster bits are set in `saturated`, a reported clamp means Δu is on and δ = `delta_max`, a
//! fault is exactly the fail-safe output, non-finite or implausible inputs give exactly those
//! faults, and a second call gives the same bits.

#[path = "common/update_input.rs"]
mod update_input;

use controller_core::Status;
use proptest::prelude::*;
use update_input::run;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    /// Arbitrary bytes, any length (short inputs are zero-padded).
    #[test]
    fn arbitrary_bytes_give_finite_bounded_outputs(data in prop::collection::vec(any::<u8>(), 0..96)) {
        run(&data);
    }

    /// Full-length inputs with the scaled flag (bit 3) set in the flags byte and the custom,
    /// short-time and relative flags (bits 1, 2, 4) arbitrary: the same interpretation, biased
    /// towards inputs that pass the input checks and run the law.
    #[test]
    fn scaled_inputs_give_finite_bounded_outputs(
        mut data in prop::collection::vec(any::<u8>(), 75..=75),
        extra_flags in 0u8..16,
    ) {
        data[57] |= 8 | (extra_flags << 1);
        run(&data);
    }
}

/// The scaled interpretation must actually reach the law (`Status::Ok`) often (absolute: with
/// both Table-1 and custom trajectories; relative: mostly with δ inside the clamp), or the
/// properties above check little beyond the fail-safe output and the clamp. (Random custom
/// trajectories rarely run in the relative mode: R·ω up to 10⁵ m/s exceeds the speed limit.)
#[test]
fn scaled_inputs_mostly_run_the_law() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = prop::collection::vec(any::<u8>(), 75..=75);
    let n = 400;
    // [absolute, relative] × [Table-1 Ok, custom Ok, Ok and δ not clamped]
    let mut counts = [[0usize; 3]; 2];
    for i in 0..n {
        let mut data = strategy.new_tree(&mut runner).unwrap().current();
        let relative = i % 2;
        data[57] = 8 | 4 | 2 | 1 | (16 * relative as u8);
        for (k, &(status, clamped)) in run(&data).iter().enumerate() {
            if status == Status::Ok {
                counts[relative][k] += 1;
                counts[relative][2] += usize::from(!clamped);
            }
        }
    }
    let [absolute, relative] = counts;
    let half = n / 2;
    assert!(3 * absolute[0] > half, "absolute: {absolute:?} of {half}");
    assert!(absolute[1] > 10, "absolute: {absolute:?} of {half}");
    assert!(2 * relative[0] > half, "relative: {relative:?} of {half}");
    assert!(5 * relative[2] > half, "relative: {relative:?} of {half}");
}
