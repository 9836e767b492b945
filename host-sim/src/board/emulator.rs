//! The QEMU flying image as a board in the loop: started through the runner
//! (`scripts/qemu-run.sh`) in its own process group, with UART0 on a socket (PIL, the
//! runner's [`super::BoardInTheLoop::start`]) or on a pseudo-terminal ([`QemuPty`]: HIL
//! without hardware).

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use auv_link::sign::LinkKey;
use firmware_images::qemu_runner;

use super::error::Error;
use super::image::check_flying_image;
use super::pacing::Pacing;
use crate::interrupt;

/// The longest the runner waits for QEMU to connect its UART or name its pty.
const QEMU_WAIT: Duration = Duration::from_secs(30);

/// What `poll` finds (polled every 20 ms), within [`QEMU_WAIT`] (else `timed_out(QEMU_WAIT)`);
/// a stop request ends the wait ([`Error::Interrupted`]).
pub(super) fn wait_for_qemu<T>(
    timed_out: impl FnOnce(Duration) -> Error,
    mut poll: impl FnMut() -> Result<Option<T>, Error>,
) -> Result<T, Error> {
    let deadline = Instant::now() + QEMU_WAIT;
    loop {
        if let Some(found) = poll()? {
            return Ok(found);
        }
        if interrupt::requested() {
            return Err(Error::Interrupted {
                waiting_for: "QEMU",
            });
        }
        if Instant::now() > deadline {
            return Err(timed_out(QEMU_WAIT));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// QEMU started by [`spawn_qemu`]: its process group, ended when this is dropped (or at
/// [`Qemu::stop`]).
pub struct Qemu {
    child: Child,
    stopped: bool,
}

impl Qemu {
    /// Ends QEMU's process group (bash runner, timeout, QEMU, defmt-print) and reaps its
    /// leader; once.
    pub fn stop(&mut self) {
        if std::mem::replace(&mut self.stopped, true) {
            return;
        }
        let _ = Command::new("kill")
            .arg("-TERM")
            .arg("--")
            .arg(format!("-{}", self.child.id()))
            .status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// QEMU's exit status, if it has ended.
    fn ended(&mut self) -> Option<std::process::ExitStatus> {
        self.child.try_wait().ok().flatten()
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Starts the QEMU flying image through `runner` (`scripts/qemu-run.sh`) in its own process
/// group, with UART0 on `serial` (QEMU's `-serial` argument: `tcp:…` for PIL, `pty` for HIL)
/// and its log (stdout and stderr) into `log`. Lock-step runs under `-icount shift=0` (the
/// runner's default: update timings are instruction counts); real time without `-icount`, so
/// that QEMU's SysTick follows the wall clock (`QEMU_ICOUNT=off`).
pub fn spawn_qemu(
    elf: &Path,
    runner: &Path,
    serial: &str,
    pacing: Pacing,
    log: std::fs::File,
    key: Option<&LinkKey>,
) -> Result<Qemu, Error> {
    let log_err = log.try_clone().map_err(|io| Error::QemuIo {
        op: "sharing QEMU's log between its stdout and stderr",
        io,
    })?;
    let mut qemu = Command::new("bash");
    qemu
        // Its own process group, so that ending it ends QEMU too (the runner starts QEMU
        // under `timeout`, two processes down).
        .process_group(0)
        .arg(runner)
        .arg(elf);
    if let Some(k) = key {
        // The QEMU image's provisioning (firmware::semihosting::link_key); visible to this
        // machine's process list, which is acceptable for a simulator's key.
        let hex: String = k.bytes().iter().map(|b| format!("{b:02x}")).collect();
        qemu.arg("-append").arg(format!("link-key={hex}"));
    }
    if pacing == Pacing::Realtime {
        qemu.env(qemu_runner::ICOUNT_VAR, qemu_runner::ICOUNT_OFF);
    }
    qemu.env(qemu_runner::SERIAL_VAR, serial)
        .env(qemu_runner::TIMEOUT_VAR, "3600")
        .stdin(Stdio::null())
        .stdout(Stdio::from(log))
        .stderr(Stdio::from(log_err))
        .spawn()
        .map(|child| Qemu {
            child,
            stopped: false,
        })
        .map_err(|io| Error::QemuStart {
            runner: runner.to_path_buf(),
            io,
        })
}

/// The QEMU flying image with its UART0 on a pseudo-terminal (`-serial pty`): a real tty that
/// `host-sim hil --port` opens as it would a USB-serial adapter (the CI's HIL without
/// hardware). Ends QEMU when dropped.
///
/// **Choice 70** (docs/board.md#hardware-in-the-loop): the runner makes the pty with `-chardev pty,path=…`
/// and names it on stderr, since QEMU prints its own `char device redirected to` line on
/// stdout, into the defmt stream; real time runs QEMU without `-icount`.
pub struct QemuPty {
    qemu: Qemu,
    /// The pty's device (`/dev/pts/N`).
    pub port: PathBuf,
}

/// The runner's line on stderr naming the pty: `qemu-run: UART0 on pty /dev/pts/N (link)`
/// (`USART2` on the STM32 emulator's machine; scripts/qemu-run.sh; QEMU's own line goes to its
/// stdout, the defmt stream).
const PTY_LINE: (&str, &str) = ("qemu-run: ", " on pty ");

impl QemuPty {
    /// Starts `elf` through `runner` with `QEMU_SERIAL=pty`, its log into `log_path`
    /// (created), and waits (at most 30 s) for the runner to name the pty in it.
    pub fn start(
        elf: &Path,
        runner: &Path,
        log_path: &Path,
        pacing: Pacing,
        key: Option<&LinkKey>,
    ) -> Result<Self, Error> {
        check_flying_image(elf)?;
        let log = std::fs::File::create(log_path).map_err(|io| Error::QemuLog {
            path: log_path.to_path_buf(),
            io,
        })?;
        let qemu = spawn_qemu(elf, runner, qemu_runner::SERIAL_PTY, pacing, log, key)?;
        let mut qemu = qemu;
        let port = wait_for_qemu(
            |waited| Error::QemuNoPty {
                waited,
                log: log_path.to_path_buf(),
            },
            || {
                let text = std::fs::read_to_string(log_path).unwrap_or_default();
                if let Some(port) = pty_of_log(&text) {
                    return Ok(Some(port));
                }
                match qemu.ended() {
                    Some(status) => Err(Error::QemuEnded {
                        status,
                        log: log_path.to_path_buf(),
                    }),
                    None => Ok(None),
                }
            },
        )?;
        Ok(QemuPty { qemu, port })
    }

    /// Ends QEMU now (the board's port goes away); dropping it does too.
    pub fn kill(&mut self) {
        self.qemu.stop();
    }
}

/// The pty QEMU's log names ([`PTY_LINE`]), if it does yet.
pub fn pty_of_log(log: &str) -> Option<PathBuf> {
    log.lines().find_map(|line| {
        let (_uart, rest) = line.strip_prefix(PTY_LINE.0)?.split_once(PTY_LINE.1)?;
        let path = rest.split_whitespace().next()?;
        path.starts_with("/dev/").then(|| PathBuf::from(path))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pty_is_read_from_the_runners_line() {
        let log = "INFO boot\nqemu-run: UART0 on pty /dev/pts/7 (/tmp/qemu-uart0.x)\nINFO tick 0";
        assert_eq!(pty_of_log(log), Some(PathBuf::from("/dev/pts/7")));
        assert_eq!(
            pty_of_log("char device redirected to /dev/pts/3 (label serial0)"),
            None
        );
        assert_eq!(pty_of_log("qemu-run: UART0 on pty "), None);
        // The STM32 emulator's link is USART2.
        let log = "qemu-run: USART2 on pty /dev/pts/12 (/tmp/qemu-uart0.y)\n";
        assert_eq!(pty_of_log(log), Some(PathBuf::from("/dev/pts/12")));
        assert_eq!(pty_of_log("INFO tick 3: UART0 on pty /dev/pts/1"), None);
    }
}
