//! `host-sim hil` against serial ports that are not a healthy board, without hardware or
//! QEMU: a port that does not exist, a pseudo-terminal nobody writes to (a silent board) and
//! one that carries only noise (a wrong baud rate); a scripted board that refuses the set-up,
//! reports another mounting or thrust unit, signs when this end does not, or goes silent,
//! changes its unit or hangs up mid-mission. Each must end, within a bound, with the runner's
//! error variant for it ([`board::Error`]) and, mid-mission, a run that lost its board
//! ([`Outcome::LostBoard`]) — never one that diverged. And a board made of the firmware's own
//! supervisor on a host thread, whose UART takes one frame a period (real time's period 0).
//! (The QEMU boards, and a QEMU port that goes away mid-mission, are flown by `cargo xtask pil`.)

#[path = "common/soft_board.rs"]
mod soft_board;

use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use auv_link::sign::{Direction, LinkKey, Signer};
use auv_link::{
    encode, encode_signed, BoardStatus, Command as LinkCommand, Envelope, FrameDecoder, Msg,
    Refusal, Telemetry, ThrustUnit, UploadStatus, MAX_FRAME, PROTOCOL_VERSION,
};
use host_sim::board::{self, BoardComparison, BoardInTheLoop, Pacing};
use host_sim::cli::Cases;
use host_sim::scenario::{load_scenario, LinkFaults, Scenario};
use host_sim::sim::{self, BoardLoss, Outcome, Recording};
use serialport::{SerialPort, TTYPort};
use soft_board::{pty, SoftBoard};

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
    let t0 = Instant::now();
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    let (output, out) = hil_kept(port, name, &scenario, extra);
    let _ = std::fs::remove_dir_all(&out);
    (output, t0.elapsed())
}

/// [`hil`] on `scenario`, its output folder kept (the caller removes it).
fn hil_kept(
    port: &str,
    name: &str,
    scenario: &std::path::Path,
    extra: &[&str],
) -> (Output, PathBuf) {
    let out = out_dir(name);
    let output = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["hil", "--port", port, "--reply-timeout", REPLY_TIMEOUT])
        .args(extra)
        .arg("--scenario")
        .arg(scenario)
        .args(["--duration", "1", "--json", "--out"])
        .arg(&out)
        .output()
        .expect("running host-sim");
    (output, out)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The one-second lawn-mower mission the tests fly.
fn short_mission() -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    load_scenario(&path)
        .and_then(|s| s.with(|c| c.duration = 1.0))
        .expect("the lawn-mower scenario")
}

/// The runner on `port` (lock-step, the tests' reply timeout, unsigned unless `key`), and how
/// long its set-up took.
fn connect(port: &str, key: Option<&LinkKey>) -> (Result<BoardInTheLoop, board::Error>, Duration) {
    let t0 = Instant::now();
    let timeout = Duration::from_secs_f64(REPLY_TIMEOUT.parse().expect("a number"));
    let b = BoardInTheLoop::over_serial(
        port,
        115_200,
        &short_mission(),
        LinkFaults::default(),
        Pacing::Lockstep,
        timeout,
        key,
    );
    (b, t0.elapsed())
}

/// A missing port is named as such, and `hil` exits 2 with the runner's message.
#[test]
fn a_missing_port_is_named() {
    let port = "/dev/auv150-no-such-port";
    let (b, t) = connect(port, None);
    let e = match b {
        Err(e @ board::Error::NoPort { .. }) => e,
        other => panic!("expected NoPort, got {:?}", other.err()),
    };
    assert!(t < BOUND, "took {t:?}");
    let (o, _) = hil(port, "missing", &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&e.to_string()), "{err}");
}

#[test]
fn a_silent_board_times_out() {
    let (_master, path) = pty();
    let (b, t) = connect(&path, None);
    match b {
        Err(board::Error::Silent { waited, .. }) => {
            assert_eq!(waited, Duration::from_millis(500))
        }
        other => panic!("expected Silent, got {:?}", other.err()),
    }
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
    let (b, t) = connect(&path, None);
    stop.store(true, Ordering::Relaxed);
    let written = noise.join().expect("the noise thread");
    assert!(written > 0);
    // The decoder's refusals are counted: noise with delimiters in it makes frames that fail.
    match b {
        Err(board::Error::Noise { bytes, refused, .. }) => {
            assert!(bytes > 0 && refused > 0, "{bytes} bytes, {refused} refused")
        }
        other => panic!("expected Noise, got {:?}", other.err()),
    }
    assert!(t < BOUND, "took {t:?}");
}

/// The board: every period of its own timer, the bytes of at most one whole frame (up to its
/// `0x00` delimiter) go to the supervisor, then one supervisor step and its telemetry.
fn one_frame_a_period_board(port: TTYPort, stop: Arc<AtomicBool>) {
    let mut board = SoftBoard::new(port);
    let mut next = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        // Until the boundary, the "UART" fills the inbox.
        while Instant::now() < next {
            board.listen();
        }
        next += board.period();
        board.take_frame();
        board.step_and_answer();
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

/// How the scripted board ([`scripted_board`]) departs from a healthy one.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Script {
    /// Not at all.
    Healthy,
    /// Refuses the `SetConfig` with this reason.
    RefuseConfig(Refusal),
    /// Flies this reversed-thruster mask, whatever it is told.
    Mounting(u8),
    /// Reports this thrust unit, whatever it is told.
    Unit(ThrustUnit),
    /// Answers `.0` state frames, then reports this thrust unit.
    UnitAfter(u64, ThrustUnit),
    /// Signs its telemetry with this key.
    Signs([u8; 32]),
    /// Answers `.0` state frames, then says nothing more.
    SilentAfter(u64),
    /// Answers `.0` state frames, then hangs up (its side of the pty closes).
    HangUpAfter(u64),
    /// Takes the `SetConfig` but flies its defaults (as a board its watchdog reset would):
    /// its unit and mounting are the ones sent, its configuration digest is not.
    Defaults,
}

/// The telemetry of a fresh board that has done nothing: disarmed, no counts, no output.
fn fresh_telemetry() -> Telemetry {
    // From the largest report, so that a field the protocol adds has a value here.
    let mut t = Telemetry::LARGEST;
    t.tick = 0;
    t.status = BoardStatus::Disarmed;
    t.voltages = [0.0; 5];
    t.thrusts = [0.0; 5];
    t.tau = [0.0; 6];
    t.saturated = 0;
    (t.delta, t.delta_clamped, t.w_norm) = (0.0, false, 0.0);
    (t.controller_fault, t.loop_overruns, t.worst_update_ticks) = (0, 0, 0);
    (
        t.rx_frames,
        t.rx_errors,
        t.rx_stale,
        t.rx_auth_errors,
        t.rx_ahead,
    ) = (0, 0, 0, 0, 0);
    (t.last_state_seq, t.last_rx_seq) = (0, 0);
    t.latched = None;
    (t.refused_commands, t.last_refusal) = (0, None);
    t.signing = false;
    (t.thrust_unit, t.reversed_thrusters) = (ThrustUnit::Kgf, 0);
    t.upload = UploadStatus::default();
    t
}

/// A board that speaks the link the simplest way, as `script` says: it takes `Disarm`,
/// `SetConfig` (its unit and mounting), `Arm` and `StartMission`, answers each state frame at
/// once (lock-step) and sends its status every 5 ms otherwise. Its voltages are 0: nothing it
/// does makes the vehicle diverge in a second.
fn scripted_board(mut port: TTYPort, script: Script, stop: Arc<AtomicBool>) {
    let mut t = fresh_telemetry();
    let mut signer = match script {
        Script::Signs(key) => Some(Signer::new(&LinkKey::new(key), Direction::FromBoard)),
        _ => None,
    };
    let mut decoder = FrameDecoder::new();
    let (mut seq, mut states) = (0u16, 0u64);
    let _ = port.set_timeout(Duration::from_millis(1));
    let mut chunk = [0u8; 256];
    let mut next = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        let mut answer = false;
        // A master reads EIO while no one holds the slave (before the runner opens it).
        let n = port.read(&mut chunk).unwrap_or(0);
        for &b in &chunk[..n] {
            let Some(Ok(env)) = decoder.push(b) else {
                continue;
            };
            t.rx_frames += 1;
            t.last_rx_seq = env.seq;
            match env.msg {
                Msg::Command(LinkCommand::Disarm) => t.status = BoardStatus::Disarmed,
                Msg::Command(LinkCommand::SetConfig(c)) => match script {
                    Script::RefuseConfig(r) => {
                        t.refused_commands += 1;
                        t.last_refusal = Some(r);
                    }
                    _ => {
                        t.thrust_unit = c.thrust_unit.unwrap_or(t.thrust_unit);
                        t.reversed_thrusters = c.reversed_thrusters.unwrap_or(0);
                        // The digest of the whole configuration flown (protocol 6): the one
                        // sent, which is whole; a reset board reports another.
                        t.config_digest = match script {
                            Script::Defaults => !c.digest().unwrap_or(0),
                            _ => c.digest().unwrap_or(0),
                        };
                    }
                },
                Msg::Command(LinkCommand::Arm) => t.status = BoardStatus::Armed,
                Msg::Command(LinkCommand::StartMission(_)) => t.status = BoardStatus::Running,
                Msg::State(_) => {
                    t.last_state_seq = env.seq;
                    states += 1;
                    answer = true;
                }
                _ => {}
            }
        }
        match script {
            Script::Mounting(m) => t.reversed_thrusters = m,
            Script::Unit(unit) => t.thrust_unit = unit,
            Script::UnitAfter(n, unit) if states > n => t.thrust_unit = unit,
            Script::SilentAfter(n) if states > n => continue,
            Script::HangUpAfter(n) if states > n => return,
            _ => {}
        }
        if !answer && Instant::now() < next {
            continue;
        }
        next = Instant::now() + Duration::from_millis(5);
        t.tick += 1;
        let env = Envelope {
            version: PROTOCOL_VERSION,
            seq,
            msg: Msg::Telemetry(t),
        };
        seq = seq.wrapping_add(1);
        let mut buf = [0u8; MAX_FRAME];
        let n = match &mut signer {
            Some(s) => {
                s.advance_to(u64::from(seq));
                encode_signed(&env, s, &mut buf)
            }
            None => encode(&env, &mut buf),
        };
        if let Ok(n) = n {
            // Nobody listening yet: the frame is lost, as on a real line.
            let _ = port.write_all(&buf[..n]);
        }
    }
}

/// `script`'s board on a pty, and the runner connected to it (signed with `key`, if given).
fn with_scripted_board<R>(
    script: Script,
    key: Option<&LinkKey>,
    then: impl FnOnce(Result<BoardInTheLoop, board::Error>) -> R,
) -> R {
    let (master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || scripted_board(master, script, stop))
    };
    let (b, t) = connect(&path, key);
    let r = then(b);
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    assert!(t < BOUND, "the set-up took {t:?}");
    r
}

/// The set-up's failures, each its own variant: a refusal with the board's reason, another
/// mounting, another thrust unit, another configuration (Choice 228), and telemetry signed when
/// this end is not (or the reverse).
#[test]
fn a_set_up_the_board_does_not_take_says_why() {
    let err = |script, key| with_scripted_board(script, key, |b| b.err());
    let c = *short_mission().controller().config();
    let (unit, mounting) = (
        ThrustUnit::from(c.thrust_unit),
        c.geometry.auv150_reversed(),
    );
    let other_unit = match unit {
        ThrustUnit::Kgf => ThrustUnit::Newton,
        ThrustUnit::Newton => ThrustUnit::Kgf,
    };
    let other_mounting = mounting.expect("the AUV-150 layout") ^ 0b1;
    // A healthy board is flown: the script's board is one.
    assert!(err(Script::Healthy, None).is_none());
    let refused = err(Script::RefuseConfig(Refusal::RateTooHigh), None);
    assert!(
        matches!(
            refused,
            Some(board::Error::Refused {
                reason: Some(Refusal::RateTooHigh)
            })
        ),
        "{refused:?}"
    );
    let m = err(Script::Mounting(other_mounting), None);
    assert!(
        matches!(m, Some(board::Error::Mounting { board, .. }) if board == other_mounting),
        "{m:?}"
    );
    let u = err(Script::Unit(other_unit), None);
    assert!(
        matches!(u, Some(board::Error::ThrustUnit { board, plant, .. }) if board == other_unit && plant == unit),
        "{u:?}"
    );
    let d = err(Script::Defaults, None);
    assert!(
        matches!(
            d,
            Some(board::Error::Config {
                mismatch: auv_link::ConfigMismatch::Digest { .. }
            })
        ),
        "{d:?}"
    );
    let key = [7u8; 32];
    let signed = err(Script::Signs(key), None);
    assert!(
        matches!(signed, Some(board::Error::Signing { .. })),
        "{signed:?}"
    );
    let unsigned = err(Script::Healthy, Some(&LinkKey::new(key)));
    assert!(
        matches!(unsigned, Some(board::Error::Signing { .. })),
        "{unsigned:?}"
    );
}

/// A board lost mid-mission ends the run [`Outcome::LostBoard`] with the cause — silent, its
/// unit changed, hung up — after the periods it answered, never [`Outcome::Diverged`].
#[test]
fn a_board_lost_mid_mission_ends_the_run_as_lost_not_diverged() {
    let s = short_mission();
    let other_unit = match ThrustUnit::from(s.controller().config().thrust_unit) {
        ThrustUnit::Kgf => ThrustUnit::Newton,
        ThrustUnit::Newton => ThrustUnit::Kgf,
    };
    for (script, cause) in [
        (Script::SilentAfter(30), BoardLoss::Silent),
        (Script::UnitAfter(30, other_unit), BoardLoss::Misconfigured),
        (Script::HangUpAfter(30), BoardLoss::LinkGone),
    ] {
        let run = with_scripted_board(script, None, |b| {
            let mut b = b.unwrap_or_else(|e| panic!("{script:?}: the set-up failed: {e}"));
            let run = sim::fly(&s, &mut b, &mut (), Recording::MetricsOnly);
            b.finish();
            run
        });
        match &run.outcome {
            Outcome::LostBoard { t, cause: c, .. } => {
                assert_eq!(*c, cause, "{script:?}: {}", run.outcome);
                // Period 30 is the first the board did not answer as it should.
                assert_eq!(
                    (t / s.period()).round(),
                    30.0,
                    "{script:?}: {}",
                    run.outcome
                );
            }
            other => panic!("{script:?}: expected a lost board, got {other}"),
        }
        assert!(run.lost_board() && !run.diverged(), "{script:?}");
        let summary = run.summary();
        assert!(summary.diverged.is_none(), "{script:?}");
        assert_eq!(summary.lost_board.map(|l| l.cause), Some(cause));
    }
}

/// `hil` on a board that hangs up mid-mission: exit 1, the partial run in the JSON marked as
/// having lost the board with the link gone (not diverged), its reason on stderr.
#[test]
fn hil_reports_a_lost_board_in_its_json_and_exits_1() {
    let (master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || scripted_board(master, Script::HangUpAfter(30), stop))
    };
    let (o, _) = hil(&path, "hang-up", &[]);
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let report: Cases<BoardComparison> = serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stderr:\n{err}"));
    let run = &report.cases[0].run;
    assert!(run.diverged.is_none(), "{run:?}");
    let lost = run.lost_board.as_ref().expect("the run lost its board");
    assert_eq!(lost.cause, BoardLoss::LinkGone, "{lost:?}");
    assert!(err.contains(&lost.reason), "{err}");
}

/// The board's own channels in the log of a board's run (Choice 382), read by the official
/// Python `mcap` reader (tests/mcap_reader.py) against the run's own figures in its JSON: a
/// `/board/link` message per answer, the last one's counters the run's; the supervisor's state
/// at its first answer and at each change, as many as the law's status changes; the refusals
/// as the board counted them; and the upload's rounds of a waypoint mission whose first chunk
/// is lost on its first sending (two rounds).
#[test]
fn the_board_channels_agree_with_the_runs_figures() {
    let ok = Command::new("python3")
        .args(["-c", "import mcap"])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        eprintln!("SKIPPED: python3 with the `mcap` module is absent (scripts/setup.sh)");
        return;
    }
    let (master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = stop.clone();
        std::thread::spawn(move || one_frame_a_period_board(master, stop))
    };
    let dir = out_dir("board-channels-scenario");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/waypoints-short.toml"),
    )
    .unwrap();
    let scenario = dir.join("waypoints-short.toml");
    std::fs::write(
        &scenario,
        format!("{text}\n[link_faults]\nlose_upload_chunks = [0]\n"),
    )
    .unwrap();
    let (output, out) = hil_kept(
        &path,
        "board-channels",
        &scenario,
        &["--pacing", "realtime"],
    );
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    let stderr = String::from_utf8_lossy(&output.stderr);
    let report: serde_json::Value = serde_json::from_slice(&output.stdout)
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stderr:\n{stderr}"));
    let pil = &report["cases"][0]["pil"];
    let name = report["cases"][0]["case"]
        .as_str()
        .unwrap_or("")
        .to_string();
    let log = out.join(format!("{name}-with.mcap"));
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/mcap_reader.py");
    let read = Command::new("python3")
        .arg(script)
        .arg(&log)
        .output()
        .unwrap();
    assert!(
        read.status.success(),
        "{}",
        String::from_utf8_lossy(&read.stderr)
    );
    let found: serde_json::Value = serde_json::from_slice(&read.stdout).unwrap();
    assert_eq!(
        found["problems"],
        serde_json::json!([]),
        "{}",
        found["problems"]
    );
    let count = |topic: &str| found["counts"][topic].as_u64().unwrap_or(0);
    let all = |topic: &str| found["all"][topic].as_array().cloned().unwrap_or_default();
    // One answer per period: as many link messages as the law's.
    assert!(count("/law") > 10, "{}", found["counts"]);
    assert_eq!(count("/board/link"), count("/law"));
    let last = all("/board/link").last().cloned().expect("link messages");
    assert_eq!(last["state_frames_sent"], pil["state_frames_sent"]);
    assert_eq!(last["rx_errors"], pil["board_rx_errors"]);
    assert_eq!(last["rx_stale"], pil["board_rx_stale"]);
    assert_eq!(last["refused_commands"], pil["board_refused_commands"]);
    assert_eq!(last["rearms"], pil["rearms"]);
    assert!(
        last["telemetry_frames"].as_u64().unwrap() <= pil["telemetry_frames"].as_u64().unwrap()
    );
    // The supervisor: its first answer, then each change; the law's status (its CSV column)
    // changes at the same periods.
    let states = all("/board/supervisor");
    assert_eq!(states[0]["previous"], "");
    for pair in states.windows(2) {
        assert_eq!(pair[1]["previous"], pair[0]["state"]);
        assert_ne!(pair[1]["state"], pair[0]["state"]);
    }
    let status_events = all("/events")
        .iter()
        .filter(|e| e["kind"] == "status")
        .count();
    assert_eq!(states.len(), status_events, "{states:?}");
    let enters = pil["failsafe_events"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["kind"] == "enter")
        .count();
    let into_failsafe = states
        .iter()
        .filter(|s| s["state"].as_str().unwrap().starts_with("fail-safe"))
        .count();
    assert_eq!(into_failsafe, enters);
    // Refusals: their growth adds up to the board's count.
    let refused: u64 = all("/board/refusals")
        .iter()
        .map(|r| r["refused"].as_u64().unwrap())
        .sum();
    assert_eq!(Some(refused), pil["board_refused_commands"].as_u64());
    // The upload's rounds, as its figures say: the lost chunk missing after the first, sent
    // again in the second, which the board verified.
    let up = pil["upload"]
        .as_object()
        .expect("a waypoint mission is uploaded");
    let rounds = all("/board/upload");
    assert_eq!(up["rounds"], 2);
    assert_eq!(rounds.len(), 2, "{rounds:?}");
    assert_eq!(rounds[0]["missing"], 1);
    assert_eq!(rounds[0]["verified"], false);
    assert_eq!(rounds[1]["chunks_sent"], 1);
    assert_eq!(rounds[1]["verified"], true);
    assert_eq!(rounds[1]["frames"], up["frames"]);
    assert_eq!(rounds[1]["bytes"], up["bytes"]);
    let _ = std::fs::remove_dir_all(&dir);
}
