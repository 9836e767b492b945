//! Time and instruction counts on QEMU's `mps2-an386`, as `scripts/qemu-run.sh` runs it.
//!
//! The machine's core clock is 25 MHz, and SysTick counts core clock cycles. The runner starts
//! QEMU with `-icount shift=0`: every instruction advances virtual time by 2⁰ ns = 1 ns, so one
//! SysTick count (40 ns) is exactly 40 instructions, repeatably. The QEMU board's
//! `firmware::board::Board::now` and the self-test time `update` in SysTick counts;
//! multiplied by [`INSTRUCTIONS_PER_TICK`] they are deterministic instruction counts (the
//! target's benchmark: QEMU has no cycle counter, DWT CYCCNT reads 0).
//!
//! Host-buildable: the xtask (and host-sim's PIL report) convert with the same constant.

/// Core clock of `mps2-an386` (Hz): what SysTick counts.
pub const CORE_HZ: u32 = 25_000_000;

/// QEMU's `-icount shift=N`: each instruction takes 2^N ns of virtual time. The runner
/// (`scripts/qemu-run.sh`) passes this value; a host test checks that it does.
pub const ICOUNT_SHIFT: u32 = 0;

/// Instructions per SysTick count: (10⁹ ns/s / 2^[`ICOUNT_SHIFT`] ns per instruction) /
/// [`CORE_HZ`] counts per second = 40.
pub const INSTRUCTIONS_PER_TICK: u32 = (1_000_000_000 >> ICOUNT_SHIFT) / CORE_HZ;

// The division above must be exact, or counts would be rounded.
const _: () = assert!((1_000_000_000u32 >> ICOUNT_SHIFT).is_multiple_of(CORE_HZ));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forty_instructions_a_systick_count() {
        // Measured on QEMU 10 (DEVELOPERS.md): 25 MHz SysTick under -icount shift=0.
        assert_eq!(INSTRUCTIONS_PER_TICK, 40);
    }

    #[test]
    fn the_runner_uses_this_icount_shift() {
        let runner = include_str!("../../../scripts/qemu-run.sh");
        // The default of its QEMU_ICOUNT (`off` is only for real-time HIL, which counts
        // nothing in instructions).
        let flag = std::format!("icount=(-icount \"${{QEMU_ICOUNT:-shift={ICOUNT_SHIFT}}}\")");
        assert!(
            runner.contains(&flag),
            "scripts/qemu-run.sh must pass `-icount shift={ICOUNT_SHIFT}` by default (`{flag}`; the instruction counts assume it)"
        );
    }
}
