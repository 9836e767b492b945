//! Fuzzes `Controller::update` with arbitrary bytes.
//!
//! Input layout (missing bytes read as zero, extra bytes ignored; all little-endian):
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
//! u32 → f32 is `f32::from_bits` (NaN, ±∞, subnormals, huge values all occur), or with the
//! *scaled* flag `(bits as i32) / i32::MAX × limit`: 1.05 × the controller's plausibility limit
//! of that input (`MAX_POSITION`, `MAX_ANGLE`, `MAX_LINEAR_SPEED`, `MAX_ANGULAR_RATE`) or of the
//! trajectory parameter, so that about half the inputs pass the input checks and run the law.
//! With the *relative* flag the decoded η and ν are offsets from the trajectory under test at
//! `ticks` (η_d and ν_d = J⁻¹(η_d) η̇_d), and the scaled limits are 0.5 m, 0.2 rad, 0.5 m/s and
//! 0.2 rad/s: the vehicle near its reference, where δ is often not clamped.
//!
//! Every output of `update` (on the Table-1 trajectory, and on the custom one if
//! `Trajectory::new` accepts it) must be finite, |voltage| ≤ `voltage_limit`,
//! 0 ≤ δ ≤ `delta_max`, ‖w‖ ≥ 0, only the five thruster bits may be saturated, a reported clamp
//! means Δu is on and δ = `delta_max`, a fault is exactly the fail-safe output, non-finite or
//! out-of-range inputs give exactly those faults, and a second call gives the same bits.

#![no_main]

// The byte layout and the checks live in one file, shared with the stable proptests.
#[path = "../../controller-core/tests/common/update_input.rs"]
mod update_input;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    update_input::run(data);
});
