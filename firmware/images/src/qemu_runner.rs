//! What the cargo runner `scripts/qemu-run.sh` reads and returns, named once for the host
//! programs that start it (host-sim's QEMU board for PIL and HIL, the xtask's self-test runs).
//! The runner stays a shell script beside `scripts/setup.sh`; a host test checks that it reads
//! every variable named here.
//!
//! Core only (no std, no target code): the host crates use it as they are.

/// The runner, relative to the workspace root.
pub const SCRIPT: &str = "scripts/qemu-run.sh";

/// Seconds before a run counts as hung (the runner's default is 120).
pub const TIMEOUT_VAR: &str = "QEMU_TIMEOUT";

/// QEMU's `-serial` argument for the navigation link's UART (default: none).
pub const SERIAL_VAR: &str = "QEMU_SERIAL";

/// [`SERIAL_VAR`]'s value that puts the link on a pseudo-terminal, which the runner names on
/// stderr (`qemu-run: UART0 on pty /dev/pts/N`).
pub const SERIAL_PTY: &str = "pty";

/// With [`SERIAL_PTY`]: the symlink QEMU makes to the pty (default: a fresh name under /tmp).
pub const PTY_LINK_VAR: &str = "QEMU_PTY_LINK";

/// QEMU's `-icount` argument (default `shift=0`, see [`crate::qemu_clock::ICOUNT_SHIFT`]).
pub const ICOUNT_VAR: &str = "QEMU_ICOUNT";

/// [`ICOUNT_VAR`]'s value that runs QEMU without `-icount`, so that the board's SysTick follows
/// the wall clock (real-time HIL).
pub const ICOUNT_OFF: &str = "off";

/// The runner's exit status for a run that hit its timeout (`timeout`'s).
pub const TIMED_OUT: i32 = 124;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_runner_reads_every_variable_and_value_named_here() {
        let runner = include_str!("../../../scripts/qemu-run.sh");
        for var in [TIMEOUT_VAR, SERIAL_VAR, PTY_LINK_VAR, ICOUNT_VAR] {
            assert!(
                runner.contains(&std::format!("${{{var}:-")),
                "{SCRIPT} does not read {var}"
            );
        }
        assert!(runner.contains(&std::format!("\"${{{SERIAL_VAR}:-}}\" = {SERIAL_PTY}")));
        assert!(runner.contains(&std::format!("\"${{{ICOUNT_VAR}:-}}\" = {ICOUNT_OFF}")));
        assert!(runner.contains(&std::format!("-eq {TIMED_OUT}")));
    }
}
