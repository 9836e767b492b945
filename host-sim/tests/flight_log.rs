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
use host_sim::output::log::schema::{self, Rate, Topic, CHANNELS, TRUTH_HZ};
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

/// `git rev-parse HEAD` of this checkout, or `None` outside one (or without git).
fn git_head() -> Option<String> {
    let out = Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    let head = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (out.status.success() && !head.is_empty()).then_some(head)
}

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
            // No `[navigation]` model (no sources) and no board in the loop: declared, empty.
            _ if spec.board_only || spec.rate == Rate::Arrival => 0,
            _ => rows.len(),
        };
        assert_eq!(n, want, "{}", spec.topic);
        assert_eq!(
            found["summary"]["channel_message_counts"][spec.topic]
                .as_u64()
                .unwrap_or(0),
            want as u64,
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
    // A chunk per second of flight (12 s and the last period), each with messages: the
    // channels are declared in the first second's chunk, not in one of their own that
    // Foxglove's reader refuses (Choice 481).
    let chunks = found["summary"]["chunk_count"].as_u64().unwrap();
    assert_eq!(chunks, 13, "{chunks} chunks");
    assert_eq!(found["summary"]["chunks_without_messages"], 0);

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
    // The version names the commit the program was built from, as git itself says (when the
    // test runs in a checkout with git).
    let version = found["metadata"]["run"]["version"].as_str().unwrap();
    if let Some(head) = git_head() {
        let described = version
            .split("(git ")
            .nth(1)
            .and_then(|g| g.strip_suffix(')'))
            .unwrap_or_else(|| panic!("no git revision in {version}"));
        let hash = described.trim_end_matches("-dirty");
        // `describe` gives the hash alone, or `tag-N-g<hash>` after a tag.
        let hash = hash.rsplit_once("-g").map_or(hash, |(_, h)| h);
        assert!(
            hash.len() >= 7 && head.starts_with(hash),
            "{version} is not HEAD {head}"
        );
    }
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

/// A 12 s circle at 50 Hz on the low-cost navigation model with every source at a rate and
/// latency of its own, a DVL outage and fixes.
const NAVIGATED: &str = "name = \"navlog\"\nduration = 12\n\
    [trajectory]\nkind = \"circle\"\nradius = 10\n\
    [controller]\nrate_hz = 50\n\
    [navigation]\npreset = \"low-cost\"\n\
    [navigation.ins]\nrate_hz = 50.0\nlatency = 0.02\n\
    [navigation.dvl]\nrate_hz = 10.0\nlatency = 0.04\noutages = [[4.0, 6.0]]\n\
    [navigation.depth]\nrate_hz = 5.0\nlatency = 0.0\n\
    [navigation.fix]\nrate_hz = 1.0\nlatency = 0.2\n";

/// Flies [`NAVIGATED`] with `run` and returns its log.
fn navigated_log(tag: &str) -> std::path::PathBuf {
    let dir = tempdir(tag);
    let s = scenario(&dir, "navlog", NAVIGATED);
    let out = dir.join("out");
    let o = host_sim()
        .args(["run", "--scenario"])
        .arg(&s)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out.join("navlog-with.mcap")
}

/// Each navigation source is a channel of its own at its own rate (Choice 381), as the
/// scenario configures it: a message per sample, the samples 1/rate apart, each arriving its
/// latency after it was taken, none taken in an outage; the measurements near the truth.
#[test]
fn each_navigation_source_is_logged_at_its_own_rate_and_latency() {
    let log = navigated_log("flight-log-nav");
    let Some(found) = read_with_python(&log) else {
        return;
    };
    assert_eq!(
        found["problems"],
        Value::Array(vec![]),
        "{}",
        found["problems"]
    );
    let duration = 12.0;
    // (topic, rate Hz, latency s, outage): the scenario's figures.
    for (topic, rate, latency, outage) in [
        ("/navigation/ins", 50.0, 0.02, None),
        ("/navigation/dvl", 10.0, 0.04, Some((4.0, 6.0))),
        ("/navigation/depth", 5.0, 0.0, None),
        ("/navigation/fix", 1.0, 0.2, None),
    ] {
        let arrived = times(&found, topic);
        let sampled: Vec<f64> = found["all"][topic]
            .as_array()
            .unwrap_or_else(|| panic!("{topic} has messages"))
            .iter()
            .map(|m| m["t_sampled"].as_f64().expect("t_sampled"))
            .collect();
        assert_eq!(arrived.len(), sampled.len());
        // The samples a source takes in the flight: every 1/rate s, from its first after the
        // start (the INS and DVL also report the vehicle at rest at 0), up to the last that
        // arrives before the end, none in an outage.
        let out = |t: f64| outage.is_some_and(|(a, b)| a <= t + 1e-9 && t < b - 1e-9);
        let at_start = matches!(topic, "/navigation/ins" | "/navigation/dvl");
        let mut want: Vec<f64> = (1..)
            .map(|i| f64::from(i) / rate)
            .take_while(|t| t + latency <= duration + 1e-9)
            .filter(|t| !out(*t))
            .collect();
        if at_start {
            want.insert(0, 0.0);
        }
        assert_eq!(sampled.len(), want.len(), "{topic}");
        for (i, (s, w)) in sampled.iter().zip(&want).enumerate() {
            assert!((s - w).abs() < 1e-9, "{topic} sample {i}: {s} != {w}");
            let lag = if i == 0 && at_start { 0.0 } else { latency };
            assert!(
                (arrived[i] - s - lag).abs() < 1e-9,
                "{topic} sample {i} taken at {s} arrived at {}",
                arrived[i]
            );
        }
    }
    // The measurements against the truth logged at 20 Hz at the same times: within a few σ of
    // the low-cost preset (docs/navigation.md: DVL 0.01 m/s white + 0.005 bias; fixes exact
    // when added to a preset without them).
    let truth: Vec<&Value> = found["all"]["/plant/truth"]
        .as_array()
        .unwrap()
        .iter()
        .collect();
    let truth_at = |t: f64| {
        let i = (t * 50.0).round() as usize;
        i.is_multiple_of(3).then(|| truth[i / 3])
    };
    let mut compared = 0;
    for m in found["all"]["/navigation/dvl"].as_array().unwrap() {
        let t = m["t_sampled"].as_f64().unwrap();
        assert_eq!(m["bottom_lock"], true, "no seabed: always in range");
        if let Some(truth) = truth_at(t) {
            let (u, tu) = (
                m["velocity"]["u"].as_f64().unwrap(),
                truth["nu"]["u"].as_f64().unwrap(),
            );
            assert!((u - tu).abs() < 0.06, "DVL u {u} against {tu} at {t}");
            compared += 1;
        }
    }
    for m in found["all"]["/navigation/fix"].as_array().unwrap() {
        let t = m["t_sampled"].as_f64().unwrap();
        // The truth is logged every third period: at 0.06 s steps, on whole seconds every 3 s.
        let Some(truth) = truth_at(t) else { continue };
        for k in ["x", "y"] {
            assert!(
                (m[k].as_f64().unwrap() - truth["eta"][k].as_f64().unwrap()).abs() < 1e-9,
                "exact fix {k} at {t}"
            );
        }
        compared += 1;
    }
    assert!(compared > 20, "{compared}");
}

/// The shipped layouts (layouts/) name only series a real log has: every Foxglove message path
/// and every PlotJuggler series resolves, by an independent parser (host-sim/tests/
/// layout_check.py: json, xml.etree and the Python `mcap` reader), to a field of a channel's
/// JSON Schema; each is a number (a text only in Foxglove's state panel); every channel a
/// SIL flight has carries messages there; and the two layouts show the same numeric series.
#[test]
fn every_series_the_layouts_name_is_in_a_real_log() {
    let log = navigated_log("flight-log-layouts");
    let Some(_) = read_with_python(&log) else {
        return;
    };
    let layouts = Path::new(env!("CARGO_MANIFEST_DIR")).join("../layouts");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/layout_check.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(&layouts)
        .arg(&log)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let found: Value = serde_json::from_slice(&out.stdout).unwrap();
    let by_layout = found["layouts"].as_object().unwrap();
    assert_eq!(
        by_layout.len(),
        2,
        "a Foxglove and a PlotJuggler layout: {by_layout:?}"
    );
    let mut numeric = Vec::new();
    for (layout, refs) in by_layout {
        let refs = refs.as_array().unwrap();
        assert!(refs.len() >= 20, "{layout}: {} series", refs.len());
        let mut series = std::collections::BTreeSet::new();
        for r in refs {
            let topic = r["topic"]
                .as_str()
                .unwrap_or_else(|| panic!("{layout}: {r} names no channel"));
            let types = r["type"]
                .as_array()
                .unwrap_or_else(|| panic!("{layout}: {r} names no field of its schema"));
            let is = |t: &str| types.iter().any(|x| x == t);
            if r["panel"] == "StateTransitions" {
                assert!(is("string"), "{layout}: {r}");
            } else {
                assert!(
                    is("number") || is("integer") || is("boolean"),
                    "{layout}: {r}"
                );
                series.insert(format!("{topic} {}", r["field"].as_str().unwrap()));
            }
            if !schema::board_only(topic) {
                assert!(
                    r["messages"].as_u64().unwrap() > 0,
                    "{layout}: {r} has no message"
                );
            }
        }
        // The standard views: the path, the errors, the thrusters, V and the Eq 40 ball.
        for must in [
            "/plant/truth eta.x",
            "/plant/truth error.yaw",
            "/thrusters voltage.main",
            "/law lyapunov",
            "/law ball_radius",
        ] {
            assert!(series.contains(must), "{layout} lacks {must}");
        }
        numeric.push(series);
    }
    assert_eq!(
        numeric[0], numeric[1],
        "the two layouts show the same series"
    );
}
