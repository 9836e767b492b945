//! Running an image in QEMU through the cargo runner, `scripts/qemu-run.sh` (QEMU's
//! `mps2-an386` with `-icount`, its log decoded by `defmt-print`); the runner's variables and
//! exit status are named in `firmware::qemu_runner`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use firmware::qemu_runner;
use xtask::ci::Ci;

/// What one QEMU run left.
pub struct Run {
    /// QEMU's exit status (the image's semihosting exit code),
    /// [`TIMED_OUT`](qemu_runner::TIMED_OUT) on a hang; `None` if the runner was killed by a
    /// signal.
    pub status: Option<i32>,
    /// Everything the runner printed (the decoded defmt log, then QEMU's and the runner's own
    /// messages), in order.
    pub log: String,
    /// Where that log is kept.
    pub log_path: PathBuf,
}

/// Runs `elf` in QEMU for at most `timeout_s` seconds, with `args` after QEMU's own (e.g.
/// `-append inject=panic`). The log goes to `target/xtask/<name>.log`.
pub fn run(ci: &Ci, elf: &Path, args: &[&str], timeout_s: u32, name: &str) -> Result<Run, String> {
    let log_path = ci.scratch().join(format!("{name}.log"));
    let log = std::fs::File::create(&log_path)
        .map_err(|e| format!("creating {}: {e}", log_path.display()))?;
    let log_err = log.try_clone().map_err(|e| e.to_string())?;
    let runner = ci.root.join(qemu_runner::SCRIPT);
    // Relative to the root where it can be (the runner runs there), as `cargo fw-test` from
    // the root passes it: the self-test scans its command line (the ELF path, then
    // `-append`'s text) before it times `update`, so the path's length moves the start of the
    // timing within a SysTick count, and a maximum can move by one count (40 instructions).
    let elf = elf.strip_prefix(&ci.root).unwrap_or(elf);
    let status = Command::new("bash")
        .arg(&runner)
        .arg(elf)
        .args(args)
        .current_dir(&ci.root)
        .env(qemu_runner::TIMEOUT_VAR, timeout_s.to_string())
        // UART0 stays unconnected: only defmt frames may reach QEMU's stdout.
        .env_remove(qemu_runner::SERIAL_VAR)
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(log_err)
        .status()
        .map_err(|e| format!("running {}: {e}", runner.display()))?;
    let log = std::fs::read_to_string(&log_path)
        .map_err(|e| format!("reading {}: {e}", log_path.display()))?;
    Ok(Run {
        status: status.code(),
        log,
        log_path,
    })
}
