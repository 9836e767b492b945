//! The board flies the law the scenario sets (protocol 8, Choice 508): `hil` against the
//! firmware's own supervisor on a host thread (lock-step, over a pseudo-terminal) flies a
//! real-chain scenario with μ = 0.15 and changed K₁, K₂, and its max path error is SIL's, bit
//! for bit. Before protocol 8 the link carried no law: `pil`/`hil` refused the scenario
//! (Choice 497), and before that refusal the board flew its built-in μ = 0.1 and the paper's
//! gains (the real figure-eight's 3 s: 0.015972 m on the board against 0.016140 in SIL).
//! (The QEMU board flies the same case in `cargo xtask pil`.)

#[path = "common/soft_board.rs"]
mod soft_board;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use host_sim::board::BoardComparison;
use host_sim::cli::Cases;
use serialport::TTYPort;
use soft_board::{pty, SoftBoard};

/// The real-chain mission (the one `cargo xtask pil` flies on the real chain).
const REAL: &str = "scenarios/real/figure-eight-30x30.toml";
/// Seconds flown: 150 lock-step periods (the files' `duration`).
const SECONDS: &str = "1.5";

/// The law a team tuned: μ = 0.15 and other K₁ (surge) and K₂ (yaw) than the paper's.
const TUNED: &str =
    "mu = 0.15\nk1 = [5.0, 4.0, 4.0, 0.0, 4.0, 4.0]\nk2 = [4.0, 4.0, 4.0, 0.0, 4.0, 3.0]\n";

fn tempdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("auv150-law-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The real figure-eight flown for [`SECONDS`], with `law` (keys) in its `[controller]` table.
fn scenario(dir: &Path, name: &str, law: &str) -> PathBuf {
    let real = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(REAL);
    let text = std::fs::read_to_string(real).unwrap();
    assert!(
        text.contains("\n[controller]\n"),
        "the file has a [controller] table"
    );
    let (head, rest) = text.split_once("\nduration = ").expect("a duration key");
    let (_, rest) = rest.split_once('\n').unwrap();
    let text = format!("{head}\nduration = {SECONDS}\n{rest}");
    let text = text.replacen("\n[controller]\n", &format!("\n[controller]\n{law}"), 1);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The board as `firmware::board::period` runs it in lock-step: it decodes whole frames until
/// a state frame is fresh or its period's timer passes, then runs one supervisor step and
/// sends its telemetry. It boots on the core's defaults, as the flying images do: every law
/// setting it flies comes over the link.
fn lockstep_board(port: TTYPort, stop: Arc<AtomicBool>) {
    let mut board = SoftBoard::new(port);
    let mut next = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        loop {
            if board.take_frame() {
                if board.sup.lockstep() && board.sup.state_fresh() {
                    break;
                }
                continue;
            }
            if Instant::now() >= next || stop.load(Ordering::Relaxed) {
                break;
            }
            board.listen();
        }
        next = Instant::now() + board.period();
        board.step_and_answer();
    }
}

fn host_sim(args: &[&str], scenario: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .arg("--scenario")
        .arg(scenario)
        .args(["--json", "--out"])
        .arg(out)
        .output()
        .expect("running host-sim")
}

/// SIL's max path error of `scenario` (`host-sim run`).
fn sil_max_path(scenario: &Path, out: &Path) -> f64 {
    let o = host_sim(&["run"], scenario, out);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "no JSON from run ({e}): {}",
            String::from_utf8_lossy(&o.stderr)
        )
    });
    v["cases"][0]["max_path"].as_f64().expect("a max path")
}

#[test]
fn a_tuned_law_flies_on_the_board_bit_for_bit_as_in_sil() {
    let dir = tempdir("tuned");
    let tuned = scenario(&dir, "tuned", TUNED);
    let (master, path) = pty();
    let stop = Arc::new(AtomicBool::new(false));
    let board = {
        let stop = stop.clone();
        std::thread::spawn(move || lockstep_board(master, stop))
    };
    let o = host_sim(
        &["hil", "--port", &path, "--reply-timeout", "10"],
        &tuned,
        &dir.join("hil"),
    );
    stop.store(true, Ordering::Relaxed);
    let _ = board.join();
    let stderr = String::from_utf8_lossy(&o.stderr);
    let report: Cases<BoardComparison> = serde_json::from_slice(&o.stdout)
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stderr:\n{stderr}"));
    assert_eq!(o.status.code(), Some(0), "stderr:\n{stderr}");
    let case = &report.cases[0];
    assert!(case.pil.telemetry_frames > 150, "{case:?}");
    // The board's run and SIL's, the same bits.
    assert_eq!(
        case.run.metrics.max_path.to_bits(),
        case.sil_max_path.to_bits(),
        "board {} m, SIL {} m",
        case.run.metrics.max_path,
        case.sil_max_path
    );
    // `run` flies the tuned law to the same figure, and the law matters on this mission: the
    // board's defaults (the shipped file's law) fly another one.
    let run = sil_max_path(&tuned, &dir.join("run-tuned"));
    assert_eq!(run.to_bits(), case.sil_max_path.to_bits());
    let shipped = scenario(&dir, "shipped", "");
    let defaults = sil_max_path(&shipped, &dir.join("run-defaults"));
    assert_ne!(defaults.to_bits(), run.to_bits(), "{defaults} m both");
    let _ = std::fs::remove_dir_all(&dir);
}
