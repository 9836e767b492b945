//! Hardware in the loop without hardware: a flying image with its link UART on a
//! pseudo-terminal (`scripts/qemu-run.sh` with `QEMU_SERIAL=pty`, [`QemuPty`]), flown by
//! `host-sim hil --port /dev/pts/N` through the same serial path a USB-serial adapter takes.
//! Two boards ([`Board`]): the QEMU image on mps2-an386 (UART0, unsigned) and the STM32F405
//! board code's emulator build on netduinoplus2 (USART2 and its interrupt, signed; see
//! `firmware/src/stm32f405/emulator.rs`). Checks 1 and 2 run on both, 3 on the first:
//!
//! 1. lock-step over the pty must equal SIL bit for bit (as PIL over TCP does), with a clean
//!    link at both ends;
//! 2. real time over the pty (QEMU without `-icount`, so the board's SysTick follows the wall
//!    clock): the run's timing figures are reported — frames/s, late frames, latency, jitter,
//!    missed periods — and must be present; they are not held to a bound (they measure this
//!    machine's load as much as the loop);
//! 3. the board's port goes away mid-mission (QEMU killed): `hil` must end within
//!    [`LOST_BOUND_S`] with a non-zero exit, the partial run kept (its CSV, and its JSON case
//!    marked as having lost the board with the link gone) and the reason on stderr.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context};
use auv_link::sign::LinkKey;
use auv_link::{BoardStatus, FailSafeReason};
use firmware::qemu_runner;
use host_sim::board::emulator::QemuPty;
use host_sim::board::Pacing;
use host_sim::board::{BoardComparison, Mode};
use host_sim::cli::Cases;
use host_sim::sim::BoardLoss;
use xtask::ci::Ci;

/// The mission HIL flies (workspace-relative), and for how long (s): 500 periods.
const SCENARIO: &str = "host-sim/scenarios/lawn-mower-20x10.toml";
const SECONDS: &str = "5";
/// The mission flown when the port goes away: long enough to be cut short.
const LONG_SECONDS: &str = "60";
/// The most `hil` may take to notice a port that went away (s); it notices at its next read.
const LOST_BOUND_S: u64 = 30;
/// The most a real-time board may take to log its stale-state fail-safe once the host has
/// stopped (s): 2 periods of its timer, and the log's way out through QEMU.
const QUIET_BOUND_S: u64 = 5;

/// A board HIL flies: its ELF, a name for the logs and messages, and the link key both ends
/// are provisioned with (`None`: unsigned).
pub struct Board<'a> {
    pub name: &'a str,
    pub elf: &'a Path,
    pub key_file: Option<&'a Path>,
}

pub fn checks(ci: &mut Ci, host_sim: &Path, boards: &[Board]) {
    ci.step(
        "hardware in the loop over QEMU's pty (the QEMU image; the STM32 board code, emulated): lock-step equals SIL, real-time figures, the port going away mid-mission",
    );
    for (i, board) in boards.iter().enumerate() {
        checks_of(ci, host_sim, board, i == 0);
    }
}

/// Checks 1 and 2 on `board`, and 3 if `port_lost`.
fn checks_of(ci: &mut Ci, host_sim: &Path, board: &Board, port_lost: bool) {
    let key = match board.key_file.map(read_key).transpose() {
        Ok(k) => k,
        Err(e) => {
            ci.fail(format!("HIL {}: {e:#}", board.name));
            return;
        }
    };
    let hil = Hil {
        host_sim,
        board,
        key,
        runner: ci.root.join(qemu_runner::SCRIPT),
        scratch: ci.scratch(),
    };
    lock_step(ci, &hil);
    real_time(ci, &hil);
    // 3. The port goes away mid-mission (host-sim's side of the port: one board suffices).
    if port_lost {
        port_goes_away(ci, &hil);
    }
}

/// `host-sim hil` against one board.
struct Hil<'a> {
    host_sim: &'a Path,
    board: &'a Board<'a>,
    key: Option<LinkKey>,
    runner: PathBuf,
    scratch: PathBuf,
}

/// A board started on its pty, and the `host-sim hil` command that flies it.
struct Flight {
    qemu: QemuPty,
    cmd: Command,
    /// host-sim's output folder.
    out: PathBuf,
    /// QEMU's log (the board's defmt log).
    log: PathBuf,
}

impl Hil<'_> {
    /// Starts the board on a pty and prepares `host-sim hil` for `what` (a name for files and
    /// messages) at `pacing` for `seconds`.
    fn start(&self, ci: &mut Ci, what: &str, pacing: Pacing, seconds: &str) -> Option<Flight> {
        let name = format!("{} {what}", self.board.name);
        let slug = format!("{}-{what}", self.board.name);
        let log = self.scratch.join(format!("hil-{slug}-qemu.log"));
        let qemu = match QemuPty::start(
            self.board.elf,
            &self.runner,
            &log,
            pacing,
            self.key.as_ref(),
        ) {
            Ok(q) => q,
            Err(e) => {
                ci.fail(format!("HIL {name}: {e}"));
                return None;
            }
        };
        let out = self.scratch.join(format!("hil-{slug}"));
        let _ = std::fs::remove_dir_all(&out);
        let mut cmd = Command::new(self.host_sim);
        cmd.current_dir(&ci.root)
            .arg("hil")
            .arg("--port")
            .arg(&qemu.port)
            .args(["--pacing", pacing.as_str()])
            .args([
                "--scenario",
                SCENARIO,
                "--duration",
                seconds,
                "--json",
                "--out",
            ])
            .arg(&out);
        if let Some(k) = self.board.key_file {
            cmd.arg("--link-key-file").arg(k);
        }
        println!(
            "{name}: {} hil --port {} --pacing {} --scenario {SCENARIO} --duration {seconds}{}",
            ci.rel(self.host_sim),
            qemu.port.display(),
            pacing.as_str(),
            if self.board.key_file.is_some() {
                " --link-key-file …"
            } else {
                ""
            }
        );
        Some(Flight {
            qemu,
            cmd,
            out,
            log,
        })
    }
}

/// host-sim's one-case JSON report, or a failure.
fn report(ci: &mut Ci, name: &str, output: &Output) -> Option<BoardComparison> {
    match serde_json::from_slice::<Cases<BoardComparison>>(&output.stdout) {
        Ok(r) if r.cases.len() == 1 => r.cases.into_iter().next(),
        other => {
            ci.fail(format!(
                "HIL {name}: host-sim exited {} without a one-case JSON report ({:?}); its messages:\n{}",
                output.status,
                other.err(),
                String::from_utf8_lossy(&output.stderr)
            ));
            None
        }
    }
}

/// 1. Lock-step over the pty: the PIL protocol on a tty; must equal SIL bit for bit.
fn lock_step(ci: &mut Ci, hil: &Hil) {
    let who = hil.board.name;
    let Some(mut f) = hil.start(ci, "lockstep", Pacing::Lockstep, SECONDS) else {
        return;
    };
    let output = f.cmd.output();
    drop(f.qemu);
    let o = match output {
        Ok(o) => o,
        Err(e) => return ci.fail(format!("HIL {who} lock-step: running host-sim: {e}")),
    };
    let Some(c) = report(ci, &format!("{who} lock-step"), &o) else {
        return;
    };
    println!(
        "{who} lock-step over {}: HIL max path {:.5} m, SIL {:.5} m, {:.0} frames/s",
        c.pil.link, c.run.metrics.max_path, c.sil_max_path, c.pil.frames_per_second
    );
    let clean = c.pil.board_rx_errors == 0
        && c.pil.board_rx_stale == 0
        && c.pil.board_refused_commands == 0
        && c.pil.telemetry_refused == 0;
    let signed = hil.board.key_file.is_some();
    if !o.status.success()
        || c.mode != Mode::Hil
        || !c.agrees()
        || c.run.metrics.max_path.to_bits() != c.sil_max_path.to_bits()
        || !clean
        || c.pil.signed != signed
    {
        ci.fail(format!(
            "HIL {who} lock-step over the pty: exit {}, max path {} m against SIL's {} m (must be bit for bit), board rx errors {}, dropped {}, refused {}, telemetry refused {}, signed {} (expected {signed}); the serial path must carry exactly what the socket does (raw mode: no echo, no line editing)",
            o.status,
            c.run.metrics.max_path,
            c.sil_max_path,
            c.pil.board_rx_errors,
            c.pil.board_rx_stale,
            c.pil.board_refused_commands,
            c.pil.telemetry_refused,
            c.pil.signed,
        ));
    }
}

/// 2. Real time over the pty: figures, reported; then the host goes quiet, and the board, on
///    its own timer, must go to the stale-state fail-safe by itself.
fn real_time(ci: &mut Ci, hil: &Hil) {
    let who = hil.board.name;
    let Some(mut f) = hil.start(ci, "realtime", Pacing::Realtime, SECONDS) else {
        return;
    };
    let output = f.cmd.output();
    let during = output
        .as_ref()
        .ok()
        .and_then(|o| report(ci, &format!("{who} real time"), o));
    let status = quiet_status(&f.log);
    drop(f.qemu);
    if output.is_ok() && during.is_some() {
        stale_state_reached(ci, who, status.as_deref(), &f.log);
    }
    let o = match output {
        Ok(o) => o,
        Err(e) => return ci.fail(format!("HIL {who} real time: running host-sim: {e}")),
    };
    let Some(c) = during else { return };
    match &c.pil.realtime {
        Some(r) if r.periods > 0 && c.pil.telemetry_frames > 0 => println!(
            "{who} real time over {}: {:.0} frames/s, {r}; max path {:.3} m (SIL {:.3} m), {} fail-safe events, exit {}",
            c.pil.link,
            c.pil.frames_per_second,
            c.run.metrics.max_path,
            c.sil_max_path,
            c.pil.failsafe_events.len(),
            o.status
        ),
        other => ci.fail(format!(
            "HIL {who} real time: no timing figures in the report ({other:?}, {} telemetry frames)",
            c.pil.telemetry_frames
        )),
    }
}

/// The board's last status in its `log` once it has become a fail-safe, or after
/// [`QUIET_BOUND_S`]. The board logs each change of its status (`tick N: <status>`,
/// firmware::rt::fly): once the host is gone, its last one must become a fail-safe, on its
/// own timer.
fn quiet_status(log: &Path) -> Option<String> {
    let last = || last_status(&std::fs::read_to_string(log).unwrap_or_default());
    let deadline = Instant::now() + Duration::from_secs(QUIET_BOUND_S);
    while !last().is_some_and(|s| s.starts_with("fail-safe")) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    last()
}

/// The board's last status after the host went quiet must be the stale-state fail-safe.
fn stale_state_reached(ci: &mut Ci, who: &str, status: Option<&str>, log: &Path) {
    let stale = BoardStatus::FailSafe(FailSafeReason::StaleState).as_str();
    match status {
        Some(s) if s == stale => {
            println!("{who} after the host went quiet: the board's last status is `{s}`, reached by itself")
        }
        // Already latched in another fail-safe before the host stopped (an overrun on a loaded
        // machine): the thrusters are off, but the stale-state path was not what put them
        // there.
        Some(s) if s.starts_with("fail-safe") => println!(
            "{who} after the host went quiet: the board was already in `{s}`; the stale-state fail-safe was not exercised this run"
        ),
        other => ci.fail(format!(
            "HIL {who} real time: the host stopped sending state frames, and {QUIET_BOUND_S} s later the board's last status in its log ({}) is {other:?}, not `{stale}`: its stale-state fail-safe did not act",
            ci.rel(log)
        )),
    }
}

/// 3. The board's port goes away mid-mission (QEMU killed): `hil` must end within
///    [`LOST_BOUND_S`] with a non-zero exit, the partial run kept, and the lost link named.
fn port_goes_away(ci: &mut Ci, hil: &Hil) {
    let who = hil.board.name;
    let Some(mut f) = hil.start(ci, "lost", Pacing::Lockstep, LONG_SECONDS) else {
        return;
    };
    let child = f.cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => return ci.fail(format!("HIL {who} port lost: running host-sim: {e}")),
    };
    // Let the mission fly a while (its CSV grows), then end QEMU.
    std::thread::sleep(Duration::from_secs(3));
    f.qemu.kill();
    let killed = Instant::now();
    if !ends_within(&mut child, killed + Duration::from_secs(LOST_BOUND_S)) {
        let _ = child.kill();
        let _ = child.wait();
        return ci.fail(format!(
            "HIL {who} port lost: host-sim was still running {LOST_BOUND_S} s after QEMU (its port) ended: a hang"
        ));
    }
    let noticed = killed.elapsed().as_secs_f64();
    match child.wait_with_output() {
        Ok(o) => stopped_early(ci, who, noticed, &o, &f.out),
        Err(e) => ci.fail(format!("HIL {who} port lost: host-sim's output: {e}")),
    }
}

/// True if `child` ends before `deadline`.
fn ends_within(child: &mut Child, deadline: Instant) -> bool {
    loop {
        match child.try_wait() {
            Ok(Some(_)) => return true,
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(50)),
            _ => return false,
        }
    }
}

/// A run that lost its board: a non-zero exit, the partial CSV in `out`, a JSON case whose
/// outcome is the lost board with the link gone (the port's going away noticed as such, not
/// as silence after the reply timeout), and that reason on stderr.
fn stopped_early(ci: &mut Ci, who: &str, noticed: f64, o: &Output, out: &Path) {
    let err = String::from_utf8_lossy(&o.stderr);
    let csv_rows = std::fs::read_dir(out)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.path().extension().is_some_and(|x| x == "csv"))
        .filter_map(|e| std::fs::read_to_string(e.path()).ok())
        .map(|t| t.lines().count().saturating_sub(1))
        .max()
        .unwrap_or(0);
    let lost = report(ci, &format!("{who} port lost"), o).and_then(|c| c.run.lost_board);
    println!(
        "{who} port lost: host-sim ended {noticed:.2} s after QEMU, exit {}, {csv_rows} CSV rows kept, run stopped at {:?} ({:?}): {}",
        o.status,
        lost.as_ref().map(|l| l.t),
        lost.as_ref().map(|l| l.cause),
        lost.as_ref().map_or("(no reason)", |l| l.reason.as_str())
    );
    let link_gone = lost
        .as_ref()
        .is_some_and(|l| l.cause == BoardLoss::LinkGone && err.contains(&l.reason));
    if o.status.success() || !link_gone || csv_rows == 0 {
        ci.fail(format!(
            "HIL {who} port lost: expected a non-zero exit, the partial CSV and a JSON case that lost its board with the link gone, its reason on stderr; got exit {}, {csv_rows} CSV rows, lost board {lost:?}; stderr:\n{err}",
            o.status
        ));
    }
}

/// The status in the last `tick N: <status>` line of a board's log (firmware::rt::fly logs
/// each change), if there is one.
fn last_status(log: &str) -> Option<String> {
    log.lines().rev().find_map(|line| {
        let rest = &line[line.find(" tick ")? + " tick ".len()..];
        let (tick, status) = rest.split_once(": ")?;
        tick.chars()
            .all(|c| c.is_ascii_digit())
            .then(|| status.trim().to_string())
    })
}

/// The link key in a key file (firmware/README.md, "Link key"), for QEMU's command line.
fn read_key(path: &Path) -> anyhow::Result<LinkKey> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    LinkKey::from_key_file(&text).map_err(|e| anyhow!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::last_status;

    #[test]
    fn the_last_status_line_of_a_board_log() {
        let log = "INFO  tick 0: disarmed\nINFO  tick 92: armed\nINFO  tick 102: running\n\
                   INFO  loop rate now 50 Hz\nINFO  tick 606: fail-safe: stale state\n\
                   qemu-system-arm: terminating on signal 15\n";
        assert_eq!(last_status(log).as_deref(), Some("fail-safe: stale state"));
        assert_eq!(
            last_status("INFO  tick 3: running\nINFO  the stick 4: no\n").as_deref(),
            Some("running")
        );
        assert_eq!(last_status("INFO  boot\n"), None);
    }
}
