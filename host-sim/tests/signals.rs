//! The binary under SIGINT and SIGTERM (`interrupt.rs` tests the rules in process): progress
//! without a terminal, what a run and a Monte Carlo keep on Ctrl-C, an interrupt before the
//! first period, one signal delivered twice, a late second signal. Every test runs the binary
//! and signals it.

mod common;

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};

use common::{entries, host_sim, run, scenario, signal, spawn_run, stderr, tempdir, SHORT};

/// Starts `host-sim args…` with stderr piped, waits for a stderr line containing `ready`,
/// sends SIGINT, and returns the output (stderr lines included).
fn interrupt_after(args: &[&str], ready: &str) -> (Option<i32>, String, Vec<String>) {
    let mut child = host_sim()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = Vec::new();
    let mut err = BufReader::new(child.stderr.take().unwrap()).lines();
    for line in err.by_ref() {
        let line = line.unwrap();
        let go = line.contains(ready);
        lines.push(line);
        if go {
            break;
        }
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    lines.extend(err.map_while(Result::ok));
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        lines,
    )
}

#[test]
fn a_long_run_shows_progress_without_a_terminal_and_keeps_its_data_on_ctrl_c() {
    let dir = tempdir("sigint");
    // An hour at 500 Hz: the first progress line comes after 5 s (progress::LINE_INTERVAL), and
    // the simulator now flies an hour at 100 Hz in about that, so such a run could end before
    // the interrupt came (seen once in CI: 360 002 rows, the whole hour). At 500 Hz the run
    // takes five times as long; interrupted at the first line, it writes what the 100 Hz hour
    // did by then.
    let s = scenario(
        &dir,
        "hour",
        "name = \"hour\"\nduration = 3600\n[controller]\nrate_hz = 500\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let out = dir.join("out");
    let (code, stdout, lines) = interrupt_after(
        &[
            "run",
            "--scenario",
            s.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "control periods",
    );
    assert_eq!(code, Some(130), "{lines:?}");
    // The progress line (stderr is a pipe here, not a terminal).
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("host-sim: hour:") && l.contains("elapsed")),
        "{lines:?}"
    );
    // The run's CSV is complete up to the stop, and everything says it is partial.
    let csv = std::fs::read_to_string(out.join("hour-with.csv")).unwrap();
    let rows = csv.lines().count();
    assert!(rows > 100 && rows < 1_800_002, "{rows}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("(PARTIAL)") && report.contains("INTERRUPTED"),
        "{report}"
    );
    assert!(stdout.contains("INTERRUPTED"), "{stdout}");
    // No temporary file is left behind.
    assert!(std::fs::read_dir(&out).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .starts_with(".host-sim-tmp")));
}

#[test]
fn monte_carlo_bounds_its_runs_estimates_their_time_and_writes_a_partial_report_on_ctrl_c() {
    let dir = tempdir("mc");
    let out = dir.join("out");
    let (code, _, lines) = interrupt_after(
        &[
            "monte-carlo",
            "--runs",
            "5000",
            "--out",
            out.to_str().unwrap(),
        ],
        "calibration run",
    );
    assert_eq!(code, Some(130), "{lines:?}");
    assert!(
        lines
            .iter()
            .any(|l| l.contains("5000 runs") && l.contains("about")),
        "{lines:?}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("Partial: interrupted after"), "{report}");
    assert!(report.contains("of 5000 runs"), "{report}");

    // Beyond the bound, refused before anything runs.
    let o = host_sim()
        .args(["monte-carlo", "--runs", "20000", "--out"])
        .arg(dir.join("big"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--allow-long-run"), "{}", stderr(&o));
}

/// Waits for `child` at most `limit`; kills it and panics (naming `what`) if it is still running.
fn wait_at_most(
    mut child: std::process::Child,
    limit: std::time::Duration,
    what: &str,
) -> std::process::Output {
    let t0 = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {limit:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// `validate-preflight --random N` had no cap and made every mission before flying the first,
/// not looking at the interrupt (`--random 20000` was still making missions 40 s after
/// SIGINT): beyond `monte-carlo`'s cap it is refused before anything is made, and with
/// `--allow-long-run` the missions are made as they are flown, so the first SIGINT acts within
/// seconds and the partial report is written. The limits are generous for a loaded machine.
#[test]
fn validate_preflight_bounds_its_random_missions_and_acts_on_ctrl_c_while_making_them() {
    let dir = tempdir("validate-random");
    let spawn = |extra: &[&str], out: &str| {
        host_sim()
            .args([
                "validate-preflight",
                "--mountings",
                "team",
                "--random",
                "20000",
            ])
            .args(extra)
            .arg("--out")
            .arg(dir.join(out))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let limit = std::time::Duration::from_secs(20);
    let o = wait_at_most(spawn(&[], "capped"), limit, "--random 20000");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--random 20000") && stderr(&o).contains("--allow-long-run"),
        "{}",
        stderr(&o)
    );
    let child = spawn(&["--allow-long-run", "--json"], "long");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    signal(child.id(), libc::SIGINT);
    let o = wait_at_most(child, limit, "--random 20000 --allow-long-run after SIGINT");
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let report = std::fs::read_to_string(dir.join("long/report.md")).unwrap();
    assert!(report.contains("PARTIAL"), "{report}");
}

/// `check --json` printed nothing when interrupted (exit 130): stdout is exactly one JSON
/// object, `"interrupted": true` with the verdict when it was made (a waypoint mission
/// interrupted in its speed profile's search) and without one when it was not (a ten-hour
/// lawn-mower interrupted in the check itself).
#[test]
fn check_json_prints_the_verdict_so_far_when_interrupted() {
    let one_object = |stdout: &str| -> serde_json::Value {
        let mut objects =
            serde_json::Deserializer::from_str(stdout).into_iter::<serde_json::Value>();
        let v = objects.next().expect("an object on stdout").unwrap();
        assert!(objects.next().is_none(), "more than one object: {stdout}");
        v
    };
    let pipeline =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/real/pipeline.toml");
    let (code, stdout, lines) = interrupt_after(
        &["check", "--json", "--scenario", pipeline.to_str().unwrap()],
        "searching the speed profile",
    );
    assert_eq!(code, Some(130), "{lines:?}");
    let v = one_object(&stdout);
    assert_eq!(v["interrupted"], true, "{v}");
    // The verdict reached before the profile search (the pipeline's depends on the default
    // navigation's share: docs/real-vehicle.md).
    assert!(
        ["feasible", "needs-time-scale"].contains(&v["verdict"].as_str().unwrap_or("")),
        "{v}"
    );
    assert!(
        v["thrusters"].is_array() && v["speed_profile"].is_null(),
        "{v}"
    );

    let dir = tempdir("check-int");
    let s = scenario(&dir, "day", LONG);
    let child = host_sim()
        .args(["check", "--json", "--scenario"])
        .arg(&s)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    signal(child.id(), libc::SIGINT);
    let o = wait_at_most(
        child,
        std::time::Duration::from_secs(20),
        "check of a ten-hour mission",
    );
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let v = one_object(&String::from_utf8_lossy(&o.stdout));
    assert_eq!(v, serde_json::json!({"interrupted": true}));
}

/// A ten-hour lawn-mower whose payload varies (|sin| at 0.1 rad/s): a path that does not
/// repeat, so its preflight sweeps it as written (7.2·10⁵ samples × 2⁹ corners), tens of
/// seconds of work. A day-long circle is no longer one: a periodic path flown for many periods is
/// checked on one period (Choices 393, 538), in milliseconds to seconds.
const LONG: &str = "name = \"day\"\nduration = 36000\n[trajectory]\nkind = \"lawn-mower\"\nscale = 1\n[variation]\nprofile = \"abs-sin\"\n";

/// [`LONG`]'s path at half its size flown for twenty hours (at full size it would leave the
/// ±10 km the controller accepts): its preflight as written takes about 12 s of an idle
/// machine's CPU, twice [`LONG`]'s since Choices 579–580 took that to about 6 s, where a SIGINT
/// at 6 s could land after it, in the flight.
const LONGER: &str = "name = \"day\"\nduration = 72000\n[trajectory]\nkind = \"lawn-mower\"\nscale = 0.5\n[variation]\nprofile = \"abs-sin\"\n";

/// SIGINT 1.5 s into a ten-hour run used to act after about 80 s (the preflight did
/// not look at the flag). Measured after the fix: ≈ 0.1 s. The bound is generous for a loaded
/// machine and still fails the old behaviour.
#[test]
fn an_interrupt_before_the_first_period_acts_at_once() {
    interrupted_in_the_preflight("early-int", LONG, 1500);
}

/// The same 6 s into [`LONGER`]'s: there the preflight matched each of the mission's 7.2·10⁵ samples to its
/// plant by searching every plant before it (quadratic, no look at the flag: hours), and a
/// SIGINT went unanswered (CI hung on the test above under load, 2026-12-05). Now by the
/// parameters' bits.
#[test]
fn an_interrupt_while_the_preflight_matches_samples_to_plants_acts_at_once() {
    interrupted_in_the_preflight("match-int", LONGER, 6000);
}

/// SIGINT `after_ms` into a `run` of `mission` (a long one), still in its preflight: the run
/// stops within 10 s, exit 130, its report says nothing was simulated, nothing half-written.
fn interrupted_in_the_preflight(tag: &str, mission: &str, after_ms: u64) {
    let dir = tempdir(tag);
    let s = scenario(&dir, "day", mission);
    let out = dir.join("out");
    let child = spawn_run(&s, &out);
    std::thread::sleep(std::time::Duration::from_millis(after_ms));
    let t0 = std::time::Instant::now();
    signal(child.id(), libc::SIGINT);
    let o = child.wait_with_output().unwrap();
    let took = t0.elapsed();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    assert!(took < std::time::Duration::from_secs(10), "took {took:?}");
    // The report says what happened; nothing half-written, no CSV of a run never started.
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("(PARTIAL)") && report.contains("nothing was simulated"),
        "{report}"
    );
    assert!(entries(&out, "day-").is_empty(), "{:?}", entries(&out, ""));
    assert!(entries(&out, ".host-sim-tmp").is_empty());
}

/// An hour at 500 Hz (long enough to be streaming when the signals come) and its output.
fn streaming_run(
    tag: &str,
) -> (
    std::process::Child,
    PathBuf,
    BufReader<std::process::ChildStderr>,
) {
    let dir = tempdir(tag);
    let s = scenario(
        &dir,
        "hour",
        "name = \"hour\"\nduration = 3600\n[controller]\nrate_hz = 500\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let out = dir.join("out");
    let mut child = spawn_run(&s, &out);
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    // The first progress line: the run is streaming its CSV.
    while err.read_line(&mut line).unwrap() > 0 && !line.contains("control periods") {
        line.clear();
    }
    (child, out, err)
}

/// GNU `timeout` and batch schedulers deliver one request twice; the second used to
/// be taken as "quit at once", losing the streamed CSV. Two deliveries a moment apart are one.
/// (Two `kill`s back to back can merge in the kernel into one pending signal, so the second is
/// sent once the first has been taken: milliseconds later, well inside the 1 s window.)
#[test]
fn one_signal_delivered_twice_is_one_interrupt() {
    let (child, out, mut err) = streaming_run("twice-int");
    signal(child.id(), libc::SIGINT);
    let mut line = String::new();
    while err.read_line(&mut line).unwrap() > 0 && !line.contains("interrupted:") {
        line.clear();
    }
    signal(child.id(), libc::SIGINT);
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut err, &mut rest);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{rest}");
    assert!(!rest.contains("exiting now"), "{rest}");
    let rows = std::fs::read_to_string(out.join("hour-with.csv"))
        .unwrap()
        .lines()
        .count();
    assert!(rows > 100, "{rows}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("(PARTIAL)"), "{report}");
    assert!(entries(&out, ".host-sim-tmp").is_empty());
}

/// A deliberate second signal, later than the first, still quits at once, and what
/// was streamed survives it: either the run had put its CSV in place, or the rows are kept as
/// `hour-with.partial.csv`; never only under a temporary name. The process is stopped right
/// after the first signal is taken, so that the second comes while the run is still
/// finishing; the next run into the folder removes the partial file.
#[test]
fn a_late_second_signal_keeps_what_was_streamed() {
    let (child, out, mut err) = streaming_run("late-int");
    signal(child.id(), libc::SIGINT);
    let mut line = String::new();
    while err.read_line(&mut line).unwrap() > 0 && !line.contains("interrupted:") {
        line.clear();
    }
    signal(child.id(), libc::SIGSTOP);
    std::thread::sleep(std::time::Duration::from_millis(1500));
    signal(child.id(), libc::SIGINT);
    signal(child.id(), libc::SIGCONT);
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut err, &mut rest);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{rest}");
    assert!(entries(&out, ".host-sim-tmp").is_empty(), "{rest}");
    let kept = ["hour-with.csv", "hour-with.partial.csv"]
        .iter()
        .map(|n| out.join(n))
        .find(|p| p.exists())
        .unwrap_or_else(|| panic!("nothing streamed is left: {:?} {rest}", entries(&out, "")));
    let text = std::fs::read_to_string(&kept).unwrap();
    assert!(text.lines().count() > 100, "{}", kept.display());
    assert!(text.starts_with("t,x,y,z,"));
    if kept.ends_with("hour-with.partial.csv") {
        assert!(rest.contains("kept what was streamed as"), "{rest}");
    }
    // The next run into the folder starts clean.
    let s = out.parent().unwrap().join("hour.toml");
    std::fs::write(&s, format!("name = \"next\"\n{SHORT}")).unwrap();
    assert!(run(&[], &s, &out).status.success());
    assert!(entries(&out, "hour").is_empty(), "{:?}", entries(&out, ""));
}
