//! The flight log (docs/logs.md) read by an independent reader: the official Python `mcap`
//! reader (PyPI `mcap`, installed by scripts/setup.sh) through tests/mcap_reader.py. Its
//! schemas, channels, message counts and rates are checked against the run's own figures (the
//! CSV's rows, the scenario's control rate), and the values against the CSV's; a log whose run
//! was killed with SIGKILL mid-flight reads up to the kill.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{host_sim, scenario, tempdir};
use host_sim::output::log::schema::{Topic, CHANNELS, TRUTH_HZ};
use serde_json::Value;

/// The Python reader's findings, or `None` (said on stderr) when python3 or its `mcap`
/// module is absent.
fn read_with_python(log: &Path) -> Option<Value> {
    let ok = Command::new("python3")
        .args(["-c", "import mcap"])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        eprintln!(
            "SKIPPED: python3 with the `mcap` module is absent (scripts/setup.sh installs it: \
             pip install mcap)"
        );
        return None;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mcap_reader.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(log)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "the reader failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).expect("the reader prints JSON"))
}

/// A 12 s circle at 50 Hz with sensor noise (the state told differs from the truth) and a
/// payload step.
const CIRCLE: &str = "name = \"logged\"\nduration = 12\n\
    [trajectory]\nkind = \"circle\"\nradius = 10\n\
    [controller]\nrate_hz = 50\n\
    [noise]\neta_sigma = [0.01, 0.01, 0.01, 0.001, 0.001, 0.001]\nnu_sigma = [0.01, 0.01, 0.01, 0.001, 0.001, 0.001]\nseed = 7\n";

fn csv_rows(path: &Path) -> Vec<csv::StringRecord> {
    let mut r = csv::Reader::from_path(path).expect("the CSV opens");
    r.records().map(|r| r.expect("a CSV row")).collect()
}

/// Every message time of `topic`, in seconds.
fn times(found: &Value, topic: &str) -> Vec<f64> {
    found["times"][topic]
        .as_array()
        .unwrap_or_else(|| panic!("{topic} has messages"))
        .iter()
        .map(|t| t.as_u64().expect("a log time") as f64 * 1e-9)
        .collect()
}

#[test]
fn the_python_reader_agrees_with_the_run() {
    let dir = tempdir("flight-log");
    let s = scenario(&dir, "logged", CIRCLE);
    let out = dir.join("out");
    let o = host_sim()
        .args(["run", "--scenario"])
        .arg(&s)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let Some(found) = read_with_python(&out.join("logged-with.mcap")) else {
        return;
    };
    assert_eq!(
        found["problems"],
        Value::Array(vec![]),
        "{}",
        found["problems"]
    );
    assert_eq!(found["ended"], "end of file");

    // Schemas and channels: every declared channel, JSON Schema, JSON messages, source sil.
    let channels = found["channels"].as_array().unwrap();
    assert_eq!(channels.len(), CHANNELS.len());
    for spec in &CHANNELS {
        let c = channels
            .iter()
            .find(|c| c["topic"] == spec.topic)
            .unwrap_or_else(|| panic!("{} is in the log", spec.topic));
        assert_eq!(c["schema"], spec.schema);
        assert_eq!(c["encoding"], "json");
        assert_eq!(c["metadata"]["source"], "sil");
    }
    for schema in found["schemas"].as_array().unwrap() {
        assert_eq!(schema["encoding"], "jsonschema");
        assert_eq!(schema["schema"]["type"], "object");
    }

    // Counts and rates against the run's own figures: one control-rate message per CSV row,
    // 50 Hz apart; the truth at 20 Hz of it (every ⌈50/20⌉ = 3rd period); the summary's
    // statistics say the same.
    let rows = csv_rows(&out.join("logged-with.csv"));
    assert_eq!(rows.len(), 12 * 50 + 1);
    let rate = 50.0;
    for spec in &CHANNELS {
        let n = found["counts"][spec.topic].as_u64().unwrap_or(0) as usize;
        let want = match spec.topic {
            "/plant/truth" => rows.len().div_ceil(3),
            "/events" => 2, // the status at the start, the outcome at the end
            _ => rows.len(),
        };
        assert_eq!(n, want, "{}", spec.topic);
        assert_eq!(
            found["summary"]["channel_message_counts"][spec.topic].as_u64(),
            Some(want as u64),
            "{}",
            spec.topic
        );
    }
    for (topic, hz) in [("/law", rate), ("/plant/truth", rate / 3.0)] {
        let t = times(&found, topic);
        for pair in t.windows(2) {
            assert!(
                ((pair[1] - pair[0]) * hz - 1.0).abs() < 1e-6,
                "{topic} {pair:?}"
            );
        }
        assert_eq!(t[0], 0.0);
    }
    assert!(f64::from(TRUTH_HZ) >= rate / 3.0);
    // A chunk per second of flight (12 s and the last period), and the metadata's chunk.
    let chunks = found["summary"]["chunk_count"].as_u64().unwrap();
    assert!((13..=14).contains(&chunks), "{chunks} chunks");

    // Values: the CSV's, as the Python reader parses them from JSON (the first message).
    let first = &found["first"];
    let row = &rows[0];
    let col = |name: &str| -> f64 {
        let i = host_sim::output::CSV_COLUMNS
            .iter()
            .position(|c| *c == name)
            .unwrap();
        row[i].parse().unwrap()
    };
    // f64 values (the plant) as the f64; f32 values (the law's) as the f32 (docs/logs.md).
    let f32_of = |v: &Value| v.as_f64().map(|x| x as f32);
    assert_eq!(first["/plant/truth"]["eta"]["y"].as_f64(), Some(col("y")));
    assert_eq!(first["/plant/truth"]["nu"]["u"].as_f64(), Some(1.0));
    assert_eq!(
        f32_of(&first["/reference"]["eta_d"]["z"]),
        Some(col("z_d") as f32)
    );
    assert_eq!(
        f32_of(&first["/control/tau"]["demanded"]["N"]),
        Some(col("tau_N") as f32)
    );
    assert_eq!(
        f32_of(&first["/thrusters"]["voltage"]["main"]),
        Some(col("volt_main") as f32)
    );
    assert_eq!(f32_of(&first["/law"]["delta"]), Some(col("delta") as f32));
    assert_eq!(first["/law"]["status"], "ok");
    // The state told is not the truth (noise), and the law saw it.
    assert_ne!(
        first["/navigation/told"]["eta"]["x"].as_f64(),
        first["/plant/truth"]["eta"]["x"].as_f64()
    );

    // Metadata and attachments: the run's rate and outcome, the scenario file as written.
    assert_eq!(found["metadata"]["run"]["rate_hz"], "50");
    assert_eq!(found["metadata"]["run"]["name"], "logged");
    assert_eq!(found["metadata"]["outcome"]["outcome"], "completed");
    assert_eq!(found["attachments"]["scenario.toml"], CIRCLE);
    let events = found["first"]["events"].as_array().unwrap();
    assert_eq!(events[1]["kind"], "outcome");
    assert_eq!(events[1]["text"], "completed");
    assert_eq!(Topic::ALL.len(), CHANNELS.len());
}

/// A run killed with SIGKILL mid-flight leaves a log the Python reader reads up to the kill:
/// the schemas, the channels and whole seconds of messages (a chunk per second), no summary.
#[test]
fn a_killed_run_leaves_a_log_read_up_to_the_kill() {
    let dir = tempdir("flight-log-killed");
    // Long enough not to end before the kill.
    let s = scenario(
        &dir,
        "long",
        "name = \"long\"\nduration = 3000\n\
         [trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let out = dir.join("out");
    let mut child = common::spawn_run(&s, &out);
    let log = out.join("long-with.mcap");
    // Wait for a few chunks (a few seconds of flight) on disk.
    let start = Instant::now();
    while std::fs::metadata(&log).map_or(0, |m| m.len()) < 300_000 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the log did not grow"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    common::signal(child.id(), libc::SIGKILL);
    let status = child.wait().unwrap();
    assert!(!status.success());
    let Some(found) = read_with_python(&log) else {
        return;
    };
    assert_eq!(
        found["problems"],
        Value::Array(vec![]),
        "{}",
        found["problems"]
    );
    assert!(found["summary"].is_null(), "a killed run has no summary");
    assert_eq!(found["channels"].as_array().unwrap().len(), CHANNELS.len());
    // Whole seconds of flight at 100 Hz, the same on every control-rate channel.
    let law = found["counts"]["/law"].as_u64().unwrap();
    assert!(law >= 100, "{law} messages");
    assert_eq!(law % 100, 0, "{law}: whole chunks of a second");
    for topic in [
        "/navigation/told",
        "/reference",
        "/control/tau",
        "/thrusters",
    ] {
        assert_eq!(found["counts"][topic].as_u64(), Some(law), "{topic}");
    }
    let t = times(&found, "/law");
    assert_eq!(t.len() as u64, law);
    assert!((t[t.len() - 1] - (law as f64 - 1.0) / 100.0).abs() < 1e-9);
}
