//! `host-sim hil` against serial ports that are not a healthy board, without hardware or
//! QEMU: a port that does not exist, a pseudo-terminal nobody writes to (a silent board) and
//! one that carries only noise (a wrong baud rate). Each must end, within a bound, with a
//! message that says which it is and a non-zero exit. (A board that answers, and one whose
//! port goes away mid-mission, are flown against QEMU by `cargo xtask pil`.)

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

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

/// `host-sim hil --port PORT` on a one-second mission, with its wall time.
fn hil(port: &str, name: &str) -> (Output, Duration) {
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/lawn-mower-20x10.toml");
    let out = out_dir(name);
    let t0 = Instant::now();
    let output = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["hil", "--port", port, "--reply-timeout", REPLY_TIMEOUT])
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
    let (o, t) = hil("/dev/auv150-no-such-port", "missing");
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
    let (o, t) = hil(&path, "silent");
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
    let (o, t) = hil(&path, "noise");
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
