//! `host-sim campaign`: shards that merge bit for bit whatever the sharding, restart after a
//! kill, the merge's refusals, the campaign file's errors, worst cases that replay bit for bit,
//! the engines' environment, and the shipped Kubernetes manifest.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use controller_core::model::ParamVariation;
use host_sim::cli::resolve_shard;
use host_sim::studies::campaign::{Campaign, Record};

fn host_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-campaign-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 s real-chain circle with sensor noise: short, and every drawn value acts.
const BASE: &str = r#"
name = "short-base"
duration = 2.0
ideal_actuators = false
[trajectory]
kind = "circle"
radius = 10.0
heading = "tangent"
[variation]
profile = "none"
trimmed = true
[noise]
eta_sigma = [0.01, 0.01, 0.01, 0.002, 0.002, 0.002]
nu_sigma = [0.005, 0.005, 0.005, 0.001, 0.001, 0.001]
"#;

/// A campaign of `runs` runs that draws everything it can.
fn campaign_text(runs: u64, seed: u64) -> String {
    format!(
        r#"
name = "t"
runs = {runs}
seed = {seed}
bases = ["base.toml"]
metrics = ["max_path", "rms_path", "saturated_fraction"]
[draw]
parameters = "uniform"
current = 0.2
noise_seed = true
initial_offset = [0.02, 0.02, 0.02, 0.0, 0.0, 0.02]
time_scale = [1.0, 1.5]
mountings = [["vert fore", "horz fore", "horz aft"], ["vert fore", "horz fore"]]
[bound]
max_path = 0.2
saturated = 0.5
"#
    )
}

/// Writes the base and a campaign file into `dir`; returns the campaign's path.
fn write_campaign(dir: &Path, text: &str) -> PathBuf {
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let p = dir.join("c.campaign.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "exit {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn run_shard(file: &Path, shard: &str, out: &Path) -> Output {
    host_sim()
        .args(["campaign", "run"])
        .arg(file)
        .args(["--shard", shard, "--out"])
        .arg(out)
        .output()
        .unwrap()
}

fn merge(shards: &[PathBuf], out: &Path) -> Output {
    host_sim()
        .args(["campaign", "merge"])
        .args(shards)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// Runs the campaign in `n` shards (one process each) and merges them into `dir/merged-n`.
fn sharded(dir: &Path, file: &Path, n: u64) -> PathBuf {
    let shards: Vec<PathBuf> = (0..n)
        .map(|i| {
            let out = dir.join(format!("n{n}-shard{i}"));
            ok(run_shard(file, &format!("{i}/{n}"), &out));
            out
        })
        .collect();
    let merged = dir.join(format!("merged-{n}"));
    ok(merge(&shards, &merged));
    merged
}

/// Every file of a merged report but the folder's lock (which names the process).
fn report_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "host-sim.lock")
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect();
    v.sort();
    v
}

fn records(path: &Path) -> Vec<Record> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| Record::parse(l).unwrap_or_else(|| panic!("bad record {l:?}")))
        .collect()
}

#[test]
fn one_three_and_seven_shards_merge_to_the_same_bytes() {
    let dir = tempdir("shards");
    let file = write_campaign(&dir, &campaign_text(21, 5));
    let one = report_files(&sharded(&dir, &file, 1));
    let names: Vec<&str> = one.iter().map(|f| f.0.as_str()).collect();
    for expected in [
        "records.csv",
        "report.md",
        "histograms.png",
        "scatter.png",
        "worst-max_path.toml",
        "worst-rms_path.toml",
        "worst-saturated_fraction.toml",
        "summary.json",
    ] {
        assert!(names.contains(&expected), "{expected} missing: {names:?}");
    }
    for n in [3, 7] {
        let other = report_files(&sharded(&dir, &file, n));
        assert_eq!(
            other.iter().map(|f| &f.0).collect::<Vec<_>>(),
            one.iter().map(|f| &f.0).collect::<Vec<_>>()
        );
        for (a, b) in one.iter().zip(&other) {
            assert!(a.1 == b.1, "{} differs between 1 and {n} shards", a.0);
        }
    }
    // The merged records are every index once, in order.
    let r = records(&dir.join("merged-1/records.csv"));
    assert_eq!(
        r.iter().map(|r| r.index).collect::<Vec<_>>(),
        (0..21).collect::<Vec<_>>()
    );
}

#[test]
fn the_merge_verdict_is_the_required_fraction_within_bound() {
    let dir = tempdir("verdict");
    // A bound of 1 mm, which runs miss (the drawn current and payload push them off the path).
    let tight = campaign_text(12, 6).replace("max_path = 0.2", "max_path = 0.001");
    for (fraction, exit) in [("", 0), ("fraction = 0.0", 0), ("fraction = 1.0", 4)] {
        let file = write_campaign(
            &dir,
            &tight.replace("saturated = 0.5", &format!("saturated = 0.5\n{fraction}")),
        );
        let shard = dir.join(format!("s{exit}{}", fraction.len()));
        ok(run_shard(&file, "0/1", &shard));
        let out = host_sim()
            .args(["campaign", "merge"])
            .arg(&shard)
            .arg("--out")
            .arg(dir.join("m"))
            .arg("--json")
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(exit), "{fraction:?}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        // Against the records: outcomes add up, within = completed.
        let r = records(&dir.join("m/records.csv"));
        let completed = r.iter().filter(|r| r.within()).count() as u64;
        assert_eq!(v["runs"], 12);
        assert_eq!(v["within_bound"].as_u64(), Some(completed));
        assert_eq!(v["outcomes"]["completed"].as_u64(), Some(completed));
        let total: u64 = v["outcomes"]
            .as_object()
            .unwrap()
            .values()
            .map(|x| x.as_u64().unwrap())
            .sum();
        assert_eq!(total, 12);
        assert!(completed < 12, "the bound should be missed by some run");
        assert_eq!(
            v["required_met"].as_bool(),
            (exit == 4)
                .then_some(false)
                .or((!fraction.is_empty()).then_some(true))
        );
    }
}

#[test]
fn a_run_depends_on_seed_and_index_only_not_on_the_run_count() {
    let dir = tempdir("independent");
    let small = write_campaign(&dir, &campaign_text(6, 9));
    ok(run_shard(&small, "0/1", &dir.join("small")));
    let big_dir = dir.join("big-campaign");
    std::fs::create_dir_all(&big_dir).unwrap();
    let big = write_campaign(&big_dir, &campaign_text(13, 9));
    ok(run_shard(&big, "0/1", &dir.join("big")));
    let sorted = |p: PathBuf| {
        let mut r = records(&p);
        r.sort_by_key(|r| r.index);
        r
    };
    let a = sorted(dir.join("small/records.csv"));
    let b = sorted(dir.join("big/records.csv"));
    assert_eq!(a.len(), 6);
    assert_eq!(a[..], b[..6]);
    // Another seed draws something else.
    let other_dir = dir.join("other-seed");
    std::fs::create_dir_all(&other_dir).unwrap();
    let other = write_campaign(&other_dir, &campaign_text(6, 10));
    ok(run_shard(&other, "0/1", &dir.join("other")));
    let c = sorted(dir.join("other/records.csv"));
    assert!(a.iter().zip(&c).all(|(x, y)| x.draw != y.draw));
}

#[test]
fn drawn_values_lie_in_their_boxes() {
    let dir = tempdir("boxes");
    let file = write_campaign(&dir, &campaign_text(50, 3));
    let c = Campaign::load(&file).unwrap();
    let max = ParamVariation::TABLE3_MAX.to_array();
    let corners_file = write_campaign(
        &dir,
        &campaign_text(50, 3).replace("\"uniform\"", "\"corners\""),
    );
    let corners = Campaign::load(&corners_file).unwrap();
    for i in 0..50 {
        let d = c.draw(i);
        for (x, m) in d.variation.iter().zip(max) {
            assert!((0.0..=m).contains(x), "run {i}: {x} outside [0, {m}]");
        }
        let speed = d.current[0].hypot(d.current[1]);
        assert!(speed <= 0.2 + 1e-15 && d.current[2] == 0.0);
        assert!(d.initial_offset[3] == 0.0 && d.initial_offset[4] == 0.0);
        assert!(d.initial_offset[0].abs() <= 0.02);
        assert!((1.0..=1.5).contains(&d.time_scale));
        // The two mountings: fore vertical and both horizontals reversed, or without the aft.
        assert!([0b11010, 0b01010].contains(&d.mounting), "{}", d.mounting);
        for (x, m) in corners.draw(i).variation.iter().zip(max) {
            assert!(
                *x == 0.0 || *x == m,
                "run {i}: {x} not a corner of [0, {m}]"
            );
        }
    }
}

#[test]
fn a_rerun_skips_recorded_runs_and_redoes_a_torn_last_line() {
    let dir = tempdir("restart");
    let file = write_campaign(&dir, &campaign_text(12, 4));
    let whole = dir.join("whole");
    ok(run_shard(&file, "0/1", &whole));
    let full = std::fs::read_to_string(whole.join("records.csv")).unwrap();
    // A shard killed after five runs, half-way through writing the sixth line.
    let part = dir.join("part");
    ok(run_shard(&file, "0/1", &part));
    let lines: Vec<&str> = full.lines().collect();
    let torn = format!(
        "{}\n{}",
        lines[..6].join("\n"),
        &lines[6][..lines[6].len() / 2]
    );
    std::fs::write(part.join("records.csv"), torn).unwrap();
    let out = ok(run_shard(&file, "0/1", &part));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stdout.contains("shard 0/1: 7 runs in"), "{stdout}");
    assert!(stderr.contains("cut short"), "{stderr}");
    let mut a = records(&whole.join("records.csv"));
    let mut b = records(&part.join("records.csv"));
    a.sort_by_key(|r| r.index);
    b.sort_by_key(|r| r.index);
    assert_eq!(a, b);
    // Complete: a rerun does nothing.
    let out = ok(run_shard(&file, "0/1", &part));
    assert!(String::from_utf8_lossy(&out.stdout).contains("shard 0/1: 0 runs in"));
    // A shard folder of another shard is refused.
    let out = run_shard(&file, "1/2", &part);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("holds shard 0/1"));
}

#[test]
fn merge_names_missing_and_duplicate_shards_and_foreign_ones() {
    let dir = tempdir("merge-errors");
    let file = write_campaign(&dir, &campaign_text(9, 2));
    let s: Vec<PathBuf> = (0..3)
        .map(|i| {
            let out = dir.join(format!("s{i}"));
            ok(run_shard(&file, &format!("{i}/3"), &out));
            out
        })
        .collect();
    let out = merge(&[s[0].clone(), s[2].clone(), s[2].clone()], &dir.join("m"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("shard(s) missing: 1/3"), "{err}");
    assert!(err.contains("shard 2/3 given twice"), "{err}");
    assert!(
        err.contains("3 of 9 runs missing (indices 1, 4, 7)"),
        "{err}"
    );
    // A shard of the same name and shape but another seed: another campaign.
    let other_dir = dir.join("other");
    std::fs::create_dir_all(&other_dir).unwrap();
    let other = write_campaign(&other_dir, &campaign_text(9, 3));
    let foreign = dir.join("foreign1");
    ok(run_shard(&other, "1/3", &foreign));
    let out = merge(
        &[s[0].clone(), foreign.clone(), s[2].clone()],
        &dir.join("m"),
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("foreign1 is a shard of another campaign"),
        "{err}"
    );
    // A shard cut short (its last two runs lost, its manifest saying so) is named incomplete,
    // and its runs missing.
    let cut = dir.join("cut1");
    ok(run_shard(&file, "1/3", &cut));
    let text = std::fs::read_to_string(cut.join("records.csv")).unwrap();
    let kept: Vec<&str> = text.lines().take(2).collect();
    std::fs::write(cut.join("records.csv"), kept.join("\n") + "\n").unwrap();
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cut.join("shard.json")).unwrap()).unwrap();
    m["done"] = 1.into();
    m["complete"] = false.into();
    std::fs::write(cut.join("shard.json"), m.to_string()).unwrap();
    let out = merge(&[s[0].clone(), cut, s[2].clone()], &dir.join("m"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("shard 1/3") && err.contains("is incomplete: 1 of its 3"),
        "{err}"
    );
    assert!(err.contains("2 of 9 runs missing"), "{err}");
    // The three shards merge.
    ok(merge(&s, &dir.join("m")));
}

#[test]
fn plan_prints_the_runs_the_cost_and_a_layout_for_the_workers() {
    let dir = tempdir("plan");
    let file = write_campaign(&dir, &campaign_text(10, 1));
    for workers in [1u64, 3, 4] {
        let out = ok(host_sim()
            .args(["campaign", "plan"])
            .arg(&file)
            .args(["--workers", &workers.to_string()])
            .output()
            .unwrap());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("runs: 10\n"), "{text}");
        assert!(text.contains("runs/s per core"), "{text}");
        let shards: u64 = text
            .split("suggested shards: ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no layout in {text}"));
        // Tiny runs: one shard a worker, never more shards than runs.
        assert_eq!(shards, workers.min(10), "{text}");
        assert!(
            text.contains(&format!("--array=0-{}%{workers}", shards - 1)),
            "{text}"
        );
    }
}

#[test]
fn a_bad_campaign_file_is_refused_naming_the_key() {
    let dir = tempdir("bad");
    let cases: [(&str, String, &str); 7] = [
        (
            "unknown key",
            campaign_text(5, 1).replace("current = 0.2", "currnet = 0.2"),
            "currnet",
        ),
        ("no runs", campaign_text(0, 1), "`runs`"),
        (
            "current too fast",
            campaign_text(5, 1).replace("current = 0.2", "current = 7.0"),
            "`draw.current`",
        ),
        (
            "time scale below 1",
            campaign_text(5, 1).replace("[1.0, 1.5]", "[0.5, 1.5]"),
            "`draw.time_scale`",
        ),
        (
            "unknown metric",
            campaign_text(5, 1).replace("\"rms_path\"", "\"rms\""),
            "`metrics`",
        ),
        (
            "unknown thruster",
            campaign_text(5, 1).replace(
                "\"vert fore\", \"horz fore\"]",
                "\"vert fore\", \"rudder\"]",
            ),
            "`draw.mountings[1][1]`",
        ),
        (
            "bound fraction",
            campaign_text(5, 1).replace("saturated = 0.5", "saturated = 0.5\nfraction = 2"),
            "`bound.fraction`",
        ),
    ];
    for (what, text, key) in cases {
        let file = write_campaign(&dir, &text);
        let out = run_shard(&file, "0/1", &dir.join("out"));
        assert_eq!(out.status.code(), Some(2), "{what}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(key), "{what}: {err}");
    }
    // A base with its own [variation] when the campaign draws Δp.
    let file = write_campaign(&dir, &campaign_text(5, 1));
    std::fs::write(
        dir.join("base.toml"),
        BASE.replace("profile = \"none\"", "profile = \"abs-sin\""),
    )
    .unwrap();
    let out = run_shard(&file, "0/1", &dir.join("out"));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`draw.parameters`"));
    // A base that is not a scenario: its key named, through the campaign.
    std::fs::write(dir.join("base.toml"), BASE.replace("radius", "radios")).unwrap();
    let out = run_shard(&file, "0/1", &dir.join("out"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("base.toml") && err.contains("radios"), "{err}");
}

#[test]
fn every_worst_case_replays_bit_for_bit_from_its_printed_command() {
    let dir = tempdir("worst");
    let file = write_campaign(&dir, &campaign_text(10, 11));
    let merged = sharded(&dir, &file, 2);
    let all = records(&merged.join("records.csv"));
    let report = std::fs::read_to_string(merged.join("report.md")).unwrap();
    for (m, metric) in [(3, "max_path"), (4, "rms_path"), (9, "saturated_fraction")] {
        // The worst run, found here from the records: the largest value, the first run with
        // it (records are in index order).
        let top = all.iter().map(|r| r.metrics[m]).fold(f64::MIN, f64::max);
        let worst = all.iter().find(|r| r.metrics[m] == top).unwrap();
        let f = format!("worst-{metric}.toml");
        let cmd = format!("`host-sim run --scenario {f} --out runs/t-{}`", worst.index);
        assert!(report.contains(&cmd), "{cmd} not in the report");
        let pil = format!(
            "`host-sim pil --scenario {f} --out runs/t-{}-pil`",
            worst.index
        );
        assert!(report.contains(&pil), "{pil} not in the report");
        // The command as printed, from the report's folder.
        let out = ok(host_sim()
            .current_dir(&merged)
            .args(["run", "--scenario", &f, "--json", "--out"])
            .arg(dir.join(format!("replay-{metric}")))
            .output()
            .unwrap());
        let text = String::from_utf8_lossy(&out.stdout);
        for (k, name) in host_sim::studies::campaign::METRIC_NAMES.iter().enumerate() {
            let x = json_number(&text, name);
            assert_eq!(
                x.to_bits(),
                worst.metrics[k].to_bits(),
                "{metric}'s worst run {}: {name} replayed {x}, campaign {}",
                worst.index,
                worst.metrics[k]
            );
        }
    }
}

/// The first number at `"key":` in `json`, read with Rust's correctly rounded parser
/// (serde_json's default float parsing may be one ulp off).
fn json_number(json: &str, key: &str) -> f64 {
    let at = json.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
    let end = json[at..].find([',', '}']).unwrap() + at;
    json[at..end].trim().parse().unwrap()
}

#[test]
fn the_shard_comes_from_the_flag_or_the_engines_environment() {
    let env = |pairs: &'static [(&'static str, &'static str)]| {
        move |k: &str| pairs.iter().find(|p| p.0 == k).map(|p| p.1.to_string())
    };
    assert_eq!(resolve_shard(Some("2/5"), None, env(&[])).unwrap(), (2, 5));
    assert_eq!(resolve_shard(None, None, env(&[])).unwrap(), (0, 1));
    // Slurm: an array 1-4 is shards 0..4.
    let slurm: &'static [(&str, &str)] = &[
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    assert_eq!(resolve_shard(None, None, env(slurm)).unwrap(), (2, 4));
    // The flag wins over the environment.
    assert_eq!(
        resolve_shard(Some("0/2"), None, env(slurm)).unwrap(),
        (0, 2)
    );
    // Kubernetes: the index, and the count from the flag or HOST_SIM_SHARDS.
    let k8s: &'static [(&str, &str)] = &[("JOB_COMPLETION_INDEX", "4")];
    assert_eq!(resolve_shard(None, Some(6), env(k8s)).unwrap(), (4, 6));
    let k8s_env: &'static [(&str, &str)] =
        &[("JOB_COMPLETION_INDEX", "4"), ("HOST_SIM_SHARDS", "5")];
    assert_eq!(resolve_shard(None, None, env(k8s_env)).unwrap(), (4, 5));
    assert!(resolve_shard(None, None, env(k8s)).is_err());
    assert!(resolve_shard(None, Some(4), env(k8s)).is_err());
    assert!(resolve_shard(Some("3/3"), None, env(&[])).is_err());
    assert!(resolve_shard(Some("1-3"), None, env(&[])).is_err());
    // Through the binary: a Slurm array task.
    let dir = tempdir("env");
    let file = write_campaign(&dir, &campaign_text(4, 1));
    ok(host_sim()
        .args(["campaign", "run"])
        .arg(&file)
        .arg("--out")
        .arg(dir.join("shard-{shard}"))
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .env_remove("SLURM_ARRAY_TASK_MIN")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .unwrap());
    let r = records(&dir.join("shard-1/records.csv"));
    let mut idx: Vec<u64> = r.iter().map(|r| r.index).collect();
    idx.sort();
    assert_eq!(idx, [1, 3]);
}

/// The fields of the shipped Kubernetes manifest, typed (unknown fields refused: a misspelt key
/// fails here, as the API server would refuse it).
mod k8s {
    use std::collections::BTreeMap;

    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Object {
        pub api_version: String,
        pub kind: String,
        pub metadata: Metadata,
        pub spec: serde_yaml::Value,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Metadata {
        pub name: String,
        pub labels: BTreeMap<String, String>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct JobSpec {
        pub completion_mode: Option<String>,
        pub completions: u64,
        pub parallelism: Option<u64>,
        pub backoff_limit: Option<u64>,
        pub backoff_limit_per_index: Option<u64>,
        pub max_failed_indexes: Option<u64>,
        pub template: PodTemplate,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct PodTemplate {
        pub spec: PodSpec,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct PodSpec {
        pub restart_policy: String,
        pub containers: Vec<Container>,
        pub volumes: Vec<Volume>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Container {
        pub name: String,
        pub image: String,
        pub command: Vec<String>,
        pub args: Vec<String>,
        pub env: Vec<EnvVar>,
        pub resources: serde_yaml::Value,
        pub volume_mounts: Vec<VolumeMount>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct EnvVar {
        pub name: String,
        pub value: String,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct VolumeMount {
        pub name: String,
        pub mount_path: String,
        pub read_only: Option<bool>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Volume {
        pub name: String,
        pub config_map: Option<Named>,
        pub persistent_volume_claim: Option<Claim>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Named {
        pub name: String,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Claim {
        pub claim_name: String,
    }

    /// `$(NAME)` replaced by the container's env value, as the kubelet expands args.
    pub fn expand(s: &str, env: &[EnvVar]) -> String {
        env.iter().fold(s.to_string(), |s, e| {
            s.replace(&format!("$({})", e.name), &e.value)
        })
    }
}

#[test]
fn the_kubernetes_manifest_parses_and_its_command_lines_run_the_campaign() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("deploy/k8s/campaign-job.yaml")).unwrap();
    let objects: Vec<k8s::Object> = serde_yaml::Deserializer::from_str(&text)
        .map(|d| serde::Deserialize::deserialize(d).unwrap())
        .collect();
    let kinds: Vec<&str> = objects.iter().map(|o| o.kind.as_str()).collect();
    assert_eq!(kinds, ["PersistentVolumeClaim", "Job", "Job"]);
    let claim = &objects[0].metadata.name;
    let job = |o: &k8s::Object| -> k8s::JobSpec {
        assert_eq!(o.api_version, "batch/v1");
        serde_yaml::from_value(o.spec.clone()).unwrap()
    };
    let shards = job(&objects[1]);
    let merge_job = job(&objects[2]);
    assert_eq!(objects[1].metadata.labels["part"], "shards");
    assert_eq!(objects[2].metadata.labels["part"], "merge");
    assert_eq!(shards.completion_mode.as_deref(), Some("Indexed"));
    for j in [&shards, &merge_job] {
        assert_eq!(j.template.spec.restart_policy, "Never");
        // Every mount is a volume of the pod, and the data volume is the claim.
        let c = &j.template.spec.containers[0];
        for m in &c.volume_mounts {
            let v = j.template.spec.volumes.iter().find(|v| v.name == m.name);
            assert!(v.is_some(), "mount {} has no volume", m.name);
        }
        let data = j.template.spec.volumes.iter().find(|v| v.name == "data");
        let data_claim = data.and_then(|v| v.persistent_volume_claim.as_ref());
        assert_eq!(&data_claim.unwrap().claim_name, claim);
    }
    // Shards are retried per index, and one that keeps failing fails the Job (no merge).
    assert!(shards.parallelism.unwrap() <= shards.completions);
    assert!(shards.backoff_limit_per_index.is_some_and(|n| n > 0));
    assert_eq!(shards.max_failed_indexes, Some(0));
    assert_eq!(merge_job.backoff_limit, Some(0));
    let shard_c = &shards.template.spec.containers[0];
    assert_eq!(
        (shard_c.name.as_str(), shard_c.image.as_str()),
        ("shard", "host-sim:latest")
    );
    assert!(shard_c.resources.get("requests").is_some());
    let ro = shard_c.volume_mounts.iter().find(|m| m.name == "campaign");
    assert_eq!(ro.and_then(|m| m.read_only), Some(true));
    let count = shard_c.env.iter().find(|e| e.name == "HOST_SIM_SHARDS");
    assert_eq!(
        count.map(|e| e.value.parse::<u64>().unwrap()),
        Some(shards.completions),
        "HOST_SIM_SHARDS must equal the Job's completions"
    );
    let config_map = shards
        .template
        .spec
        .volumes
        .iter()
        .find_map(|v| v.config_map.as_ref());
    assert_eq!(config_map.unwrap().name, "host-sim-campaign");

    // Run the command lines here: the mounts are folders, the campaign is the CI's small one
    // (the env's CAMPAIGN is the documented knob; ci-small has as many runs as the Job has
    // completions, so every index has its run), one process per completion index.
    let dir = tempdir("k8s");
    let mounts = |c: &k8s::Container, s: &str| {
        c.volume_mounts.iter().fold(s.to_string(), |s, m| {
            let local = match m.name.as_str() {
                "campaign" => root.join("host-sim/campaigns"),
                _ => dir.join(&m.name),
            };
            s.replace(&m.mount_path, &local.display().to_string())
        })
    };
    let mut env = shard_c.env.clone_env();
    env.iter_mut()
        .filter(|e| e.name == "CAMPAIGN")
        .for_each(|e| e.value = "/campaign/ci-small.campaign.toml".into());
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_host-sim")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let run = |c: &k8s::Container, env: &[k8s::EnvVar], index: Option<u64>| {
        let args: Vec<String> = c
            .args
            .iter()
            .map(|a| mounts(c, &k8s::expand(a, env)))
            .collect();
        let mut cmd = Command::new(&c.command[0]);
        cmd.args(&c.command[1..]).args(&args).env("PATH", &path);
        cmd.env_remove("SLURM_ARRAY_TASK_ID");
        for e in env {
            cmd.env(&e.name, &e.value);
        }
        if let Some(i) = index {
            cmd.env("JOB_COMPLETION_INDEX", i.to_string());
        }
        ok(cmd.output().unwrap())
    };
    for i in 0..shards.completions {
        run(shard_c, &env, Some(i));
    }
    let merge_c = &merge_job.template.spec.containers[0];
    run(merge_c, &merge_c.env.clone_env(), None);
    // The report is the one-machine run's.
    let out_name = &env.iter().find(|e| e.name == "OUT").unwrap().value;
    let one = dir.join("one");
    let file = root.join("host-sim/campaigns/ci-small.campaign.toml");
    ok(run_shard(&file, "0/1", &one.join("shard")));
    ok(merge(&[one.join("shard")], &one.join("report")));
    let k8s_report = report_files(&dir.join("data").join(out_name).join("report"));
    assert!(k8s_report == report_files(&one.join("report")));
}

/// Owned copies of a container's env (the test changes one value).
trait CloneEnv {
    fn clone_env(&self) -> Vec<k8s::EnvVar>;
}

impl CloneEnv for Vec<k8s::EnvVar> {
    fn clone_env(&self) -> Vec<k8s::EnvVar> {
        self.iter()
            .map(|e| k8s::EnvVar {
                name: e.name.clone(),
                value: e.value.clone(),
            })
            .collect()
    }
}

/// Starts a shard of `file` into `out` and returns it once it has recorded more than 100 runs
/// (or ended).
fn shard_under_way(file: &Path, out: &Path) -> std::process::Child {
    let mut child = host_sim()
        .args(["campaign", "run"])
        .arg(file)
        .args(["--shard", "0/1", "--out"])
        .arg(out)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let records_file = out.join("records.csv");
    loop {
        let lines = std::fs::read(&records_file)
            .map(|b| b.iter().filter(|c| **c == b'\n').count())
            .unwrap_or(0);
        if lines > 100 || child.try_wait().unwrap().is_some() {
            return child;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// A campaign of 3000 short runs (0.3 s each) in `dir`: a shard of it takes long enough to be
/// stopped half-way.
fn many_short_runs(dir: &Path) -> PathBuf {
    let text = campaign_text(3000, 8).replace("mountings", "# mountings");
    let file = write_campaign(dir, &text);
    std::fs::write(
        dir.join("base.toml"),
        BASE.replace("duration = 2.0", "duration = 0.3"),
    )
    .unwrap();
    file
}

#[test]
fn an_interrupted_shard_says_partial_exits_130_and_finishes_on_a_rerun() {
    let dir = tempdir("sigint");
    let file = many_short_runs(&dir);
    let part = dir.join("part");
    let child = shard_under_way(&file, &part);
    // SAFETY: a signal to the child this test started.
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let out = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("interrupted shard: exit {:?}: {stdout}", out.status.code());
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(part.join("shard.json")).unwrap()).unwrap();
    if out.status.code() == Some(0) {
        // The shard ended before the signal came: nothing to check but completeness.
        assert_eq!(m["complete"], true);
    } else {
        assert_eq!(out.status.code(), Some(130), "{stdout}");
        assert!(stdout.contains("PARTIAL: rerun to finish"), "{stdout}");
        assert_eq!(m["complete"], false);
        let done = m["done"].as_u64().unwrap();
        assert_eq!(records(&part.join("records.csv")).len() as u64, done);
    }
    let rerun = ok(run_shard(&file, "0/1", &part));
    assert!(String::from_utf8_lossy(&rerun.stdout).contains("3000 of 3000 recorded"));
    let mut idx: Vec<u64> = records(&part.join("records.csv"))
        .iter()
        .map(|r| r.index)
        .collect();
    idx.sort();
    assert_eq!(idx, (0..3000).collect::<Vec<_>>());
}

#[test]
fn a_shard_killed_mid_run_resumes_to_the_same_records() {
    let dir = tempdir("kill");
    let file = many_short_runs(&dir);
    let whole = dir.join("whole");
    ok(run_shard(&file, "0/1", &whole));
    let part = dir.join("part");
    // SIGKILL once records are being appended: no code of the shard runs after it.
    let mut child = shard_under_way(&file, &part);
    let records_file = part.join("records.csv");
    let _ = child.kill();
    let _ = child.wait();
    let before = std::fs::read_to_string(&records_file)
        .unwrap()
        .lines()
        .count();
    eprintln!("killed with {before} lines of 3001 written");
    ok(run_shard(&file, "0/1", &part));
    let mut a = records(&whole.join("records.csv"));
    let mut b = records(&records_file);
    a.sort_by_key(|r| r.index);
    b.sort_by_key(|r| r.index);
    assert_eq!(a.len(), 3000);
    assert!(a == b, "resumed after {before} lines: the records differ");
}
