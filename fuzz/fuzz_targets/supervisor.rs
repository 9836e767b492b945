//! Fuzzes the board's supervisor through its end of the link: arbitrary sequences of frames
//! (valid and not, signed and not: in-order, repeated, old, jumped, replayed, corrupted,
//! forged, reflected, raw), commands (valid and not) and control periods (with overruns).
//!
//! The input layout, the navigation computer that builds the frames, the model of what the
//! board may accept and the invariants (no panic; only in-order, authentic frames reach the
//! supervisor; thrusters off unless armed with a fresh, in-order state; a latched fail-safe
//! never clears without disarm + arm; refused commands change nothing) live in one file,
//! shared with the stable proptests (firmware/tests/supervisor_fuzz.rs).

#![no_main]

#[path = "../../firmware/tests/common/supervisor_ops.rs"]
mod supervisor_ops;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    supervisor_ops::run(data);
});
