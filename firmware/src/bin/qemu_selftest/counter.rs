//! Counting instructions with SysTick: under QEMU's `-icount shift=0` one count of the
//! free-running 24-bit down-counter at the core clock is exactly
//! [`INSTRUCTIONS_PER_TICK`] = 40 instructions (`firmware::qemu_clock`), and a call repeated
//! [`REPS`] = 40 times back to back is counted to one instruction ([`Counter`]).

use core::hint::black_box;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;

/// Free-running SysTick at the core clock: 24-bit down-counter, 40 instructions a count.
pub fn start_counter(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
}

/// SysTick counts from `t0` to `t1` (it counts down, 24 bits).
pub fn elapsed(t0: u32, t1: u32) -> u32 {
    t0.wrapping_sub(t1) & 0x00FF_FFFF
}

/// Calls per count: one SysTick count over `REPS` calls is one instruction per call.
pub const REPS: u32 = INSTRUCTIONS_PER_TICK;

/// Instructions of `REPS` calls of `f`, divided by `REPS`, loop included.
fn raw_per_call<R>(f: &mut impl FnMut() -> R) -> u32 {
    let t0 = SYST::get_current();
    for _ in 0..REPS {
        // A reference to the result where the call left it: the result must exist, but is not
        // moved (a move of update's 236-byte Output is a memcpy of ~170 instructions).
        black_box(&f());
    }
    let t1 = SYST::get_current();
    elapsed(t0, t1) * INSTRUCTIONS_PER_TICK / REPS
}

/// Counts per call, with the cost of the counting loop itself removed.
pub struct Counter {
    overhead: u32,
}

impl Counter {
    pub fn new() -> Self {
        Counter {
            overhead: raw_per_call(&mut || ()),
        }
    }

    /// Instructions of one call of `f`.
    pub fn count<R>(&self, mut f: impl FnMut() -> R) -> u32 {
        raw_per_call(&mut f).saturating_sub(self.overhead)
    }
}
