//! What the tests share: the shipped scenarios' folder and scenario texts with their errors;
//! the binary, a scratch folder, a scenario file, a run, and signals to a running child.
// Each test file uses some of these.
#![allow(dead_code)]

pub mod chatter;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use host_sim::scenario::{parse_scenario, real_vehicle, Scenario, ScenarioError};

pub fn host_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

pub fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-cmd-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn scenario(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

pub fn run(args: &[&str], scenario: &Path, out: &Path) -> Output {
    host_sim()
        .arg("run")
        .args(args)
        .arg("--scenario")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `host-sim run --scenario s --out out`, started with its output piped.
pub fn spawn_run(s: &Path, out: &Path) -> std::process::Child {
    host_sim()
        .args(["run", "--scenario"])
        .arg(s)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `signal` to `pid`.
pub fn signal(pid: u32, signal: libc::c_int) {
    // SAFETY: kill(2) with a child's pid.
    assert_eq!(unsafe { libc::kill(pid as libc::pid_t, signal) }, 0);
}

/// The entries of `dir` whose name starts with `prefix`.
pub fn entries(dir: &Path, prefix: &str) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(prefix))
                .collect()
        })
        .unwrap_or_default()
}

pub fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

/// A minimal valid scenario followed by `extra` (tables appended after [trajectory]).
pub fn circle_with(extra: &str) -> String {
    format!("name = \"t\"\n[trajectory]\nkind = \"circle\"\nradius = 10.0\n{extra}")
}

#[track_caller]
pub fn invalid_key(text: &str) -> (String, String) {
    match parse_scenario(text) {
        Err(ScenarioError::Invalid { key, message }) => (key, message),
        other => panic!("expected Invalid, got {other:?}"),
    }
}

#[track_caller]
pub fn toml_error(text: &str) -> String {
    match parse_scenario(text) {
        Err(e @ ScenarioError::Toml(_)) => e.to_string(),
        other => panic!("expected a Toml error, got {other:?}"),
    }
}

/// A one-second circle.
pub const SHORT: &str = "duration = 1\n[trajectory]\nkind = \"circle\"\nradius = 10\n";

/// The shipped real mission named `name` (its `name` key, e.g. `real-circular-10R`).
pub fn real_mission(name: &str) -> Scenario {
    real_vehicle::real_scenarios()
        .unwrap()
        .into_iter()
        .find(|s| s.config().name == name)
        .unwrap_or_else(|| panic!("no shipped real mission {name}"))
}
