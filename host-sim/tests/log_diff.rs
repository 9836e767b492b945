//! `host-sim diff A B` (docs/logs.md#comparing-two-flights): a flight against itself is the
//! same (exit 0); a copy with one value changed at a known time differs (exit 4), and diff
//! names that time and that series first, for an MCAP log and for a CSV; a file that is not a
//! flight is bad input (exit 2).

mod common;

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use common::{host_sim, scenario, tempdir};
use serde_json::Value;

/// A 5 s circle run into `dir/out`; its log and CSV.
fn flown(dir: &Path) -> (PathBuf, PathBuf) {
    let s = scenario(
        dir,
        "c",
        "name = \"c\"\nduration = 5\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let out = dir.join("out");
    let o = common::run(&[], &s, &out);
    assert!(o.status.success(), "{}", common::stderr(&o));
    (out.join("c-with.mcap"), out.join("c-with.csv"))
}

fn diff(a: &Path, b: &Path, out: &Path) -> (i32, String) {
    let o = host_sim()
        .arg("diff")
        .arg(a)
        .arg(b)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr),
    )
}

/// A copy of the log at `from` with `change` applied to the message of `topic` at `t_ns`
/// (rewritten by the `mcap` crate, message by message).
fn log_changed(from: &Path, to: &Path, topic: &str, t_ns: u64, change: impl Fn(&mut Value)) {
    let bytes = std::fs::read(from).unwrap();
    let mut writer = mcap::Writer::new(std::io::Cursor::new(Vec::new())).unwrap();
    let mut changed = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let mut m = m.unwrap();
        if m.channel.topic == topic && m.log_time == t_ns {
            let mut v: Value = serde_json::from_slice(&m.data).unwrap();
            change(&mut v);
            m.data = Cow::Owned(serde_json::to_vec(&v).unwrap());
            changed += 1;
        }
        writer.write(&m).unwrap();
    }
    assert_eq!(changed, 1, "one message of {topic} at {t_ns} ns");
    writer.finish().unwrap();
    std::fs::write(to, writer.into_inner().into_inner()).unwrap();
}

#[test]
fn diff_names_the_first_time_and_the_series_of_an_injected_difference() {
    let dir = tempdir("diff");
    let (log, csv) = flown(&dir);

    let (code, text) = diff(&log, &log, &dir.join("same"));
    assert_eq!(code, 0, "{text}");
    assert!(text.starts_with("the same:"), "{text}");

    // MCAP: the main thruster's voltage 0.25 V off at t = 2.5 s, and nothing else.
    let changed = dir.join("changed.mcap");
    log_changed(&log, &changed, "/thrusters", 2_500_000_000, |v| {
        let x = v["voltage"]["main"].as_f64().unwrap();
        v["voltage"]["main"] = Value::from(x + 0.25);
    });
    let (code, text) = diff(&log, &changed, &dir.join("mcap"));
    assert_eq!(code, 4, "{text}");
    assert!(
        text.contains("first divergence: t = 2.500 s in /thrusters voltage.main (1 of "),
        "{text}"
    );
    assert!(dir.join("mcap/diff.png").is_file());
    // Within a tolerance above the change, the same.
    let o = host_sim()
        .arg("diff")
        .arg(&log)
        .arg(&changed)
        .args(["--abs", "0.3", "--out"])
        .arg(dir.join("tol"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));

    // CSV: e_x changed in the row of t = 1.2 s.
    let text_csv = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = text_csv.lines().map(str::to_string).collect();
    let row = lines
        .iter()
        .position(|l| l.starts_with("1.2,"))
        .expect("the row of t = 1.2 s");
    let mut fields: Vec<String> = lines[row].split(',').map(str::to_string).collect();
    let e_x = host_sim::output::CSV_COLUMNS
        .iter()
        .position(|c| *c == "e_x")
        .unwrap();
    fields[e_x] = "0.5".to_string();
    lines[row] = fields.join(",");
    let changed_csv = dir.join("changed.csv");
    std::fs::write(&changed_csv, lines.join("\n") + "\n").unwrap();
    let (code, text) = diff(&csv, &changed_csv, &dir.join("csv"));
    assert_eq!(code, 4, "{text}");
    assert!(
        text.contains("first divergence: t = 1.200 s in csv e_x (1 of "),
        "{text}"
    );

    // Not a flight: exit 2, the file named.
    let notes = dir.join("notes.txt");
    std::fs::write(&notes, "not a flight\n").unwrap();
    let (code, text) = diff(&log, &notes, &dir.join("bad"));
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("notes.txt"), "{text}");
}
