//! `host-sim hil --pacing realtime` against a board made of the firmware's own supervisor, on a
//! host thread with its own 10 ms timer, behind a pseudo-terminal: a board whose UART hands the
//! supervisor at most one frame per period. At the start of a real-time mission the host sends
//! the first state frame and `StartMission` together (state first, Choice 68); such a board
//! takes the state in one period and `StartMission` in the next, so its first answer names the
//! state while it is still `armed`. The run must start on the answer from the period that took
//! both (`BoardInTheLoop::realtime_reply`), not fly a period with the thrusters off.

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use controller_core::{Controller, ControllerConfig};
use firmware::board::{receive, LinkBuffers};
use firmware::supervisor::{BoardInfo, Supervisor};
use host_sim::pil::PilComparison;
use host_sim::record::Cases;
use serialport::{SerialPort, TTYPort};

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

#[test]
fn a_mission_start_that_straddles_a_board_period_flies_no_period_disarmed() {
    let (master, slave) = TTYPort::pair().expect("a pseudo-terminal pair");
    let path = slave.name().expect("the slave's path");
    drop(slave);
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = stop.clone();
        std::thread::spawn(move || one_frame_a_period_board(master, stop))
    };
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    let out = std::env::temp_dir().join(format!("auv150-hil-soft-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let output = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["hil", "--port", &path, "--pacing", "realtime"])
        .arg("--scenario")
        .arg(&scenario)
        .args(["--duration", "1", "--json", "--out"])
        .arg(&out)
        .output()
        .expect("running host-sim");
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    let _ = std::fs::remove_dir_all(&out);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let report: Cases<PilComparison> = serde_json::from_slice(&output.stdout)
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
