//! `host-sim hil` against serial ports that are not a healthy board, without hardware or
//! QEMU: a port that does not exist, a pseudo-terminal nobody writes to (a silent board) and
//! one that carries only noise (a wrong baud rate). Each must end, within a bound, with a
//! message that says which it is and a non-zero exit. And a board made of the firmware's own
//! supervisor on a host thread, whose UART takes one frame a period (real time's period 0).
//! (The QEMU boards, and a port that goes away mid-mission, are flown by `cargo xtask pil`.)

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use controller_core::{Controller, ControllerConfig};
use firmware::board::{receive, LinkBuffers};
use firmware::supervisor::{BoardInfo, Supervisor};
use host_sim::board::BoardComparison;
use host_sim::cli::Cases;
use serialport::{SerialPort, TTYPort};

/// The reply timeout the tests give `hil` (s).
const REPLY_TIMEOUT: &str = "0.5";
/// What "bounded" means here: the reply timeout, the scenario's load and the SIL run, with
/// room for a loaded machine. The point is that the command ends at all.
const BOUND: Duration = Duration::from_secs(60);

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("auv150-hil-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `host-sim hil --port PORT` on a one-second mission, with `extra` flags, and its wall time.
fn hil(port: &str, name: &str, extra: &[&str]) -> (Output, Duration) {
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    let out = out_dir(name);
    let t0 = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["hil", "--port", port, "--reply-timeout", REPLY_TIMEOUT])
        .args(extra)
        .arg("--scenario")
        .arg(&scenario)
        .args(["--duration", "1", "--json", "--out"])
        .arg(&out)
        .output()
        .expect("running host-sim");
    let _ = std::fs::remove_dir_all(&out);
    (output, t0.elapsed())
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A pty pair: the master (the test's end, the "board") and the slave's path, free for
/// `hil` to open (the pair's own slave handle is closed: it holds the port exclusively).
fn pty() -> (TTYPort, String) {
    let (master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    let path = slave.name().expect("the slave's path");
    drop(slave);
    (master, path)
}

#[test]
fn a_missing_port_is_named() {
    let (o, t) = hil("/dev/auv150-no-such-port", "missing", &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("/dev/auv150-no-such-port does not exist"),
        "{err}"
    );
    assert!(t < BOUND, "took {t:?}");
}

#[test]
fn a_silent_board_times_out() {
    let (_master, path) = pty();
    let (o, t) = hil(&path, "silent", &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no telemetry from the board for 0.5 s: it sent nothing"),
        "{err}"
    );
    assert!(t < BOUND, "took {t:?}");
}

#[test]
fn noise_on_the_line_is_counted_and_named() {
    let (mut master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let noise = {
        let stop = Arc::clone(&stop);
        // What a board at another baud rate looks like: a steady stream of bytes with frame
        // delimiters among them, none of which decodes.
        std::thread::spawn(move || {
            let mut x: u32 = 0x1234_5678;
            let mut written = 0u64;
            while !stop.load(Ordering::Relaxed) {
                let mut chunk = [0u8; 64];
                for b in chunk.iter_mut() {
                    // xorshift32
                    x ^= x << 13;
                    x ^= x >> 17;
                    x ^= x << 5;
                    *b = (x >> 24) as u8;
                }
                if master.write_all(&chunk).is_ok() {
                    written += chunk.len() as u64;
                }
                let _ = master.clear(serialport::ClearBuffer::Input);
                std::thread::sleep(Duration::from_millis(5));
            }
            written
        })
    };
    let (o, t) = hil(&path, "noise", &[]);
    stop.store(true, Ordering::Relaxed);
    let written = noise.join().expect("the noise thread");
    let err = stderr(&o);
    assert!(written > 0);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no valid telemetry from the board for 0.5 s"),
        "{err}"
    );
    // The decoder's refusals are counted: noise with delimiters in it makes frames that fail.
    let refused: u64 = err
        .split(" frames that did not decode")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count of refused frames in: {err}"));
    assert!(refused > 0, "{err}");
    assert!(err.contains("wrong baud rate"), "{err}");
    assert!(t < BOUND, "took {t:?}");
}

/// The board: every period of its own timer, the bytes of at most one whole frame (up to its
/// `0x00` delimiter) go to the supervisor, then one supervisor step and its telemetry.
fn one_frame_a_period_board(mut port: TTYPort, stop: Arc<AtomicBool>) {
    let controller = Controller::new(ControllerConfig::default()).expect("default config");
    let info = BoardInfo {
        supply_voltage: controller_core::DEFAULT_V_LIMIT,
        signing: false,
    };
    let mut sup = Supervisor::new(controller, info);
    let mut bufs = LinkBuffers::new();
    let _ = port.set_timeout(Duration::from_millis(1));
    let mut inbox: VecDeque<u8> = VecDeque::new();
    let mut chunk = [0u8; 256];
    let mut next = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        // Until the boundary, the "UART" fills the inbox.
        while Instant::now() < next {
            match port.read(&mut chunk) {
                Ok(n) => inbox.extend(&chunk[..n]),
                // A master reads EIO while no one holds the slave (before `hil` opens it).
                Err(_) => std::thread::sleep(Duration::from_millis(1)),
            }
        }
        next += Duration::from_secs_f64(1.0 / f64::from(sup.rate_hz().max(1)));
        // One frame's bytes, if a whole one is there.
        if let Some(end) = inbox.iter().position(|&b| b == 0) {
            let frame: Vec<u8> = inbox.drain(..=end).collect();
            receive(&mut sup, &mut bufs, &frame);
        }
        let step = sup.step(false, &|| 0);
        let env = sup.envelope(step.telemetry);
        if let Ok(frame) = bufs.encode(&env) {
            // Nobody listening yet (or any more): the frame is lost, as on a real line.
            let _ = port.write_all(frame);
        }
    }
}

/// At the start of a real-time mission the host sends the first state frame and
/// `StartMission` together (state first, Choice 68); a board that takes one frame a period
/// takes the state in one period and `StartMission` in the next, so its first answer names the
/// state while it is still `armed`. The run must start on the answer from the period that took
/// both (`BoardInTheLoop::realtime_reply`, Choice 83), not fly a period with the thrusters off.
#[test]
fn a_mission_start_that_straddles_a_board_period_flies_no_period_disarmed() {
    let (master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = stop.clone();
        std::thread::spawn(move || one_frame_a_period_board(master, stop))
    };
    let (output, _) = hil(&path, "soft-board", &["--pacing", "realtime"]);
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    let stderr = String::from_utf8_lossy(&output.stderr);
    let report: Cases<BoardComparison> = serde_json::from_slice(&output.stdout)
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stderr:\n{stderr}"));
    let case = &report.cases[0];
    assert!(
        case.pil.telemetry_frames > 90,
        "the board answered: {case:?}"
    );
    // The defect's signature: a period flown on an `armed` answer. (A stale-state fail-safe
    // is the board's answer to a host or thread that stalled on a loaded machine: another
    // matter, and not held against this test.)
    let armed = case.run.faults.periods.get("board:armed");
    assert_eq!(
        armed,
        None,
        "periods flown with the board armed but not running the mission; all fault periods: {:?}; stderr:\n{stderr}",
        case.run.faults.periods
    );
    let others: u64 = case.run.faults.periods.values().sum();
    let want = if others == 0 { Some(0) } else { Some(3) };
    assert_eq!(output.status.code(), want, "stderr:\n{stderr}");
}

/// The board's set-up waits up to the reply timeout (here an hour) for a
/// silent board; Ctrl-C ends the wait and the command, as any other phase: exit 130, the
/// report says partial.
#[test]
fn an_interrupt_ends_the_wait_for_a_silent_board() {
    let (_master, path) = pty();
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    let out = out_dir("interrupted");
    let child = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args([
            "hil",
            "--port",
            &path,
            "--reply-timeout",
            "3600",
            "--scenario",
        ])
        .arg(&scenario)
        .args(["--duration", "1", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("running host-sim");
    std::thread::sleep(Duration::from_millis(1500));
    let t0 = Instant::now();
    // SAFETY: kill(2) with the child's pid.
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) },
        0
    );
    let o = child.wait_with_output().unwrap();
    let t = t0.elapsed();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(t < Duration::from_secs(10), "took {t:?}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("(PARTIAL)") || report.contains("hardware in the loop"),
        "{report}"
    );
    let _ = std::fs::remove_dir_all(&out);
}
