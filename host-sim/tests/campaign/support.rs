//! What every campaign test uses: the binary, scratch folders, a short base scenario, a
//! campaign file that draws everything, running and merging shards, reading records.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use host_sim::studies::campaign::Record;

pub fn host_sim() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

pub fn tempdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("host-sim-campaign-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 s real-chain circle with sensor noise: short, and every drawn value acts.
pub const BASE: &str = r#"
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
pub fn campaign_text(runs: u64, seed: u64) -> String {
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
# As loose as the rest: these tests are about the merge, and the noisy base chatters (tens of
# reversals a second, hundreds of V/s: docs/real-vehicle.md#chatter).
max_reversals_per_s = 100.0
max_command_tv = 5000.0
saturated = 0.5
"#
    )
}

/// Writes the base and a campaign file into `dir`; returns the campaign's path.
pub fn write_campaign(dir: &Path, text: &str) -> PathBuf {
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let p = dir.join("c.campaign.toml");
    std::fs::write(&p, text).unwrap();
    p
}

pub fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "exit {:?}\nstdout: {}\nstderr: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

pub fn run_shard(file: &Path, shard: &str, out: &Path) -> Output {
    host_sim()
        .args(["campaign", "run"])
        .arg(file)
        .args(["--shard", shard, "--out"])
        .arg(out)
        .output()
        .unwrap()
}

pub fn merge(shards: &[PathBuf], out: &Path) -> Output {
    host_sim()
        .args(["campaign", "merge"])
        .args(shards)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// Runs the campaign in `n` shards (one process each) and merges them into `dir/merged-n`.
pub fn sharded(dir: &Path, file: &Path, n: u64) -> PathBuf {
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
pub fn report_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
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

pub fn records(path: &Path) -> Vec<Record> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| Record::parse(l).unwrap_or_else(|| panic!("bad record {l:?}")))
        .collect()
}

/// Starts a shard of `file` into `out` and returns it once it has recorded more than 100 runs
/// (or ended).
pub fn shard_under_way(file: &Path, out: &Path) -> std::process::Child {
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
pub fn many_short_runs(dir: &Path) -> PathBuf {
    let text = campaign_text(3000, 8).replace("mountings", "# mountings");
    let file = write_campaign(dir, &text);
    std::fs::write(
        dir.join("base.toml"),
        BASE.replace("duration = 2.0", "duration = 0.3"),
    )
    .unwrap();
    file
}

/// Copies the files of folder `from` (not its lock) into a new folder `to`.
pub fn copy_shard(from: &Path, to: &Path) {
    let _ = std::fs::remove_dir_all(to);
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_name() != "host-sim.lock" {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// Sets column `column` (by its header name) of run `index`'s record in `dir`'s records.csv.
pub fn edit_record(dir: &Path, index: u64, column: &str, value: &str) {
    let path = dir.join("records.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let header = text.lines().next().unwrap();
    let k = header.split(',').position(|c| c == column).unwrap();
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            if f[0] == index.to_string() {
                f[k] = value;
            }
            f.join(",")
        })
        .collect();
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
}

/// Changes `dir`'s shard.json through `f`.
pub fn edit_manifest(dir: &Path, f: impl FnOnce(&mut serde_json::Value)) {
    let path = dir.join("shard.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    f(&mut m);
    std::fs::write(&path, m.to_string()).unwrap();
}

/// The exit code and stderr of `out`.
pub fn refused(out: &Output) -> (Option<i32>, String) {
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
