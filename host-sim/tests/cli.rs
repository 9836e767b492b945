//! The CLI's paths from the README, run as a user would, with their messages and exit codes.

use std::process::Command;

fn host_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

fn scenario_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios")
}

#[test]
fn table1_json_has_the_twelve_cases_in_the_documented_schema() {
    let out_dir = tempdir("table1");
    let out = host_sim()
        .args([
            "table1",
            "--contract",
            "none",
            "--tune",
            "none",
            "--json",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON object");
    let cases = v["cases"].as_array().unwrap();
    // The twelve Table-1 runs, then the six real missions and the three waypoint missions, and
    // the paper's six through the real chain (with Δu), each of the fifteen missions with its
    // preflight check.
    assert_eq!(cases.len(), 27);
    assert_eq!(v["preflight"].as_array().unwrap().len(), 15);
    for c in &cases[12..21] {
        assert!(c["case"].as_str().unwrap().starts_with("real-"), "{c}");
    }
    let waypoint_missions = ["real-survey-200x100", "real-harbour-wall", "real-pipeline"];
    for (c, name) in cases[18..21].iter().zip(waypoint_missions) {
        assert_eq!(c["case"], name);
    }
    for name in [
        "circular-10R",
        "circular-20R",
        "figure-eight-30x30",
        "figure-eight-40x40",
        "lawn-mower-20x10",
        "lawn-mower-30x15",
    ] {
        for robust in [true, false] {
            let c = cases
                .iter()
                .find(|c| c["case"] == name && c["robust"] == robust)
                .unwrap_or_else(|| panic!("{name} robust={robust} missing"));
            for key in host_sim::sim::Metrics::NAMES {
                assert!(c[key].is_f64(), "{name}: {key}");
            }
            // The paper's path definition.
            let p = (c["max_x"].as_f64().unwrap().powi(2)
                + c["max_y"].as_f64().unwrap().powi(2)
                + c["max_z"].as_f64().unwrap().powi(2))
            .sqrt();
            assert!((p - c["max_path"].as_f64().unwrap()).abs() < 1e-12);
        }
    }
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(report.contains("circular-10R") && report.contains(".png"));
    assert!(out_dir.join("circular-10R-with.csv").exists());
    // The waypoint missions' path over the waypoints and speed over time, written and linked
    // (docs/simulator.md#plots-of-a-waypoint-mission); a closed-form mission has neither.
    for name in waypoint_missions {
        for plot in ["waypoints", "speed"] {
            let file = format!("{name}-{plot}.png");
            assert!(out_dir.join(&file).is_file(), "{file}");
            assert!(report.contains(&format!("]({file})")), "{file} not linked");
        }
    }
    assert!(!out_dir.join("real-circular-10R-waypoints.png").exists());
    assert!(!out_dir.join("real-circular-10R-speed.png").exists());
}

#[test]
fn run_with_a_shipped_scenario_writes_csv_plots_and_report() {
    let out_dir = tempdir("run");
    let out = host_sim()
        .args(["run", "--scenario"])
        .arg(scenario_dir().join("lawn-mower-20x10.toml"))
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "lawn-mower-20x10-with.csv",
        "lawn-mower-20x10-xy.png",
        "report.md",
    ] {
        assert!(out_dir.join(f).exists(), "{f} missing");
    }
}

#[test]
fn a_bad_scenario_file_names_the_file_and_the_key_and_exits_2() {
    let dir = tempdir("bad");
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        "[trajectory]\nkind = \"circle\"\nradius = 10\n[controller]\nmu = -1\n",
    )
    .unwrap();
    let out = host_sim()
        .args(["run", "--scenario"])
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("controller.mu"),
        "{err}"
    );

    let out = host_sim()
        .args(["run", "--scenario", "/nonexistent/x.toml"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/x.toml"));
}

#[test]
fn a_diverging_run_says_so_keeps_its_data_and_exits_1() {
    let dir = tempdir("diverge");
    let path = dir.join("runaway.toml");
    // Without Δu and with a thousandth of the paper's gains the vehicle cannot hold the
    // circle against the payload: the error grows past the 2 m limit.
    std::fs::write(
        &path,
        "name = \"runaway\"\ndivergence_limit = 2.0\n[trajectory]\nkind = \"circle\"\nradius = 20\n\
         [variation]\nprofile = \"constant\"\n\
         [controller]\nrobust = false\nk1 = [0.004, 0.004, 0.004, 0, 0.004, 0.004]\nk2 = [0.004, 0.004, 0.004, 0, 0.004, 0.004]\n",
    )
    .unwrap();
    let out = host_sim()
        .args(["run", "--json", "--scenario"])
        .arg(&path)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &v["cases"][0]["diverged"];
    assert!(
        d["reason"].as_str().unwrap().contains("divergence limit"),
        "{v}"
    );
    let t = d["t"].as_f64().unwrap();
    assert!(t > 0.0 && t < 70.0);
    // Everything up to the stop is on disk, under the name of a run without Δu.
    let csv = std::fs::read_to_string(dir.join("out").join("runaway-without.csv")).unwrap();
    assert!(csv.lines().count() > 10);
    let report = std::fs::read_to_string(dir.join("out").join("report.md")).unwrap();
    assert!(report.contains("DIVERGED"), "{report}");
}

#[test]
fn monte_carlo_is_deterministic_per_seed() {
    let run = |seed: &str| {
        let dir = tempdir(&format!("mc{seed}"));
        let out = host_sim()
            .args([
                "monte-carlo",
                "--runs",
                "4",
                "--seed",
                seed,
                "--json",
                "--out",
            ])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v
    };
    let a = run("7");
    let b = run("7");
    assert_eq!(a, b);
    assert_eq!(a["runs"], 4);
    assert!(a["metrics"]
        .as_array()
        .unwrap()
        .iter()
        .any(|m| m["name"] == "max_path"));
}

fn tempdir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-cli-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The commands are library functions: run one in-process and read what it printed and wrote.
#[test]
fn the_run_command_runs_in_process() {
    use host_sim::cli::Cases;
    use host_sim::cli::{self, Exit, RunArgs};
    use host_sim::sim::record::RunSummary;

    let dir = tempdir("in-process");
    let path = dir.join("short.toml");
    std::fs::write(
        &path,
        "name = \"short\"\ntable1_case = \"figure-eight-30x30\"\nduration = 3\n\
         [trajectory]\nkind = \"figure-eight\"\namplitude = 15\n\
         [variation]\nprofile = \"constant\"\n",
    )
    .unwrap();
    let args = RunArgs {
        scenario: path.clone(),
        json: true,
        out: Some(dir.join("out")),
        allow_long_run: false,
    };
    let mut stdout = Vec::new();
    assert_eq!(cli::run(&args, &mut stdout).unwrap(), Exit::Success);
    let printed: Cases<RunSummary> = serde_json::from_slice(&stdout).unwrap();
    // With Δu, then its companion without.
    assert_eq!(printed.cases.len(), 2);
    assert_eq!(printed.cases[0].name, "short");
    assert!(printed.cases[0].robust && !printed.cases[1].robust);
    assert!(printed.cases.iter().all(|c| c.diverged.is_none()));
    let m = &printed.cases[0].metrics;
    assert!(
        (m.max_path - (m.max_x.powi(2) + m.max_y.powi(2) + m.max_z.powi(2)).sqrt()).abs() < 1e-12
    );
    // The report knows the case: the paper's numbers for the figure-eight 30x30.
    let report = std::fs::read_to_string(dir.join("out/report.md")).unwrap();
    assert!(
        report.contains("(1.738)") && report.contains("(0.031)"),
        "{report}"
    );
    for f in ["short-with.csv", "short-without.csv", "short-xy.png"] {
        assert!(dir.join("out").join(f).exists(), "{f}");
    }

    // A bad value is an Err naming the file and the key (the binary exits 2 on it).
    std::fs::write(
        &path,
        "[trajectory]\nkind = \"circle\"\nradius = 10\n[controller]\nbeta = 2\n",
    )
    .unwrap();
    let e = cli::run(&args, &mut Vec::new()).unwrap_err();
    let text = format!("{e:#}");
    assert!(
        text.contains("short.toml") && text.contains("controller.beta"),
        "{text}"
    );
}

/// The usage block of `host_sim::cli`'s documentation names every command the binary has (as
/// `host-sim --help` lists them): it used to miss `validate-preflight` and `import-plan`.
#[test]
fn the_usage_block_names_every_command() {
    let help = host_sim().arg("--help").output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 9, "{help}");
    let module = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/cli/mod.rs"),
    )
    .unwrap();
    let usage: Vec<&str> = module
        .lines()
        .filter_map(|l| l.strip_prefix("//! host-sim "))
        .collect();
    for c in commands {
        assert!(
            usage.iter().any(|u| u.split_whitespace().next() == Some(c)),
            "`host-sim {c}` is not in the usage block of src/cli/mod.rs"
        );
    }
}
