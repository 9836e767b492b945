//! The merge trusts no record and no manifest: every record's draw is the campaign's draw of its
//! index, its run belongs to its shard, its outcome agrees with its metrics and bound, and every
//! field of a shard's manifest is under its hash (Choices 240, 241).

use std::path::{Path, PathBuf};

use crate::support::*;

/// A 12-run campaign in 3 shards, run once; each case merges edited copies of them.
struct Shards {
    dir: PathBuf,
    s: Vec<PathBuf>,
}

impl Shards {
    fn new(tag: &str) -> Self {
        let dir = tempdir(tag);
        let file = write_campaign(&dir, &campaign_text(12, 13));
        let s = (0..3)
            .map(|i| {
                let out = dir.join(format!("s{i}"));
                ok(run_shard(&file, &format!("{i}/3"), &out));
                out
            })
            .collect();
        Shards { dir, s }
    }

    /// Copies of the three shards for case `case`, edited by `edit`, merged: (exit, stderr).
    fn merge_edited(&self, case: &str, edit: impl FnOnce(&[PathBuf])) -> (Option<i32>, String) {
        let copies: Vec<PathBuf> = (0..3)
            .map(|i| {
                let to = self.dir.join(format!("{case}-s{i}"));
                copy_shard(&self.s[i], &to);
                to
            })
            .collect();
        edit(&copies);
        refused(&merge(&copies, &self.dir.join(format!("{case}-merged"))))
    }
}

/// The records of `dir` (index, the whole line).
fn lines(dir: &Path) -> Vec<(u64, String)> {
    std::fs::read_to_string(dir.join("records.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| (l.split(',').next().unwrap().parse().unwrap(), l.to_string()))
        .collect()
}

fn write_lines(dir: &Path, lines: &[(u64, String)]) {
    let header = std::fs::read_to_string(dir.join("records.csv"))
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    let body: String = lines.iter().map(|l| format!("{}\n", l.1)).collect();
    std::fs::write(dir.join("records.csv"), format!("{header}\n{body}")).unwrap();
}

#[test]
fn a_record_whose_draw_is_not_the_campaigns_is_refused() {
    let shards = Shards::new("forged-draw");
    // Shard k holds the runs i ≡ k (mod 3).
    for (case, shard, run, column, value) in [
        ("mass", 0, 3, "mass", "999"),
        ("base", 0, 0, "base", "99"),
        ("mounting", 1, 4, "mounting", "255"),
        ("time-scale", 2, 5, "time_scale", "NaN"),
        ("seed", 1, 1, "noise_seed", "1"),
    ] {
        let (code, err) = shards.merge_edited(case, |s| edit_record(&s[shard], run, column, value));
        assert_eq!(code, Some(2), "{case}: {err}");
        assert!(
            err.contains(&format!("run {run} ")) && err.contains(column),
            "{case}: {err}"
        );
    }
    // The copies unedited merge.
    let (code, err) = shards.merge_edited("clean", |_| {});
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn an_outcome_that_its_metrics_contradict_is_refused() {
    let shards = Shards::new("forged-outcome");
    let completed: Vec<(u64, usize)> = (0..3)
        .flat_map(|k| {
            lines(&shards.s[k])
                .into_iter()
                .filter(|l| l.1.ends_with(",completed"))
                .map(move |l| (l.0, k))
        })
        .collect();
    assert!(completed.len() >= 2, "the campaign should complete runs");
    let (run, k) = completed[0];
    // A completed run with a NaN metric: it would count within bound and hide the worst run.
    let (code, err) = shards.merge_edited("nan", |s| edit_record(&s[k], run, "max_path", "NaN"));
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(&format!("run {run} ")) && err.contains("max_path"),
        "{err}"
    );
    // A completed run whose metrics miss its bound (0.2 m), and one called missed within it.
    let (code, err) = shards.merge_edited("beyond", |s| edit_record(&s[k], run, "max_path", "0.5"));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("run {run} ")), "{err}");
    // … or beyond its chatter limit (100 reversals/s), by the worst thruster's figure.
    let (code, err) = shards.merge_edited("chatter", |s| {
        edit_record(&s[k], run, "reversals_per_s", "150")
    });
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains(&format!("run {run} ")) && err.contains("reverses 150.0 times/s"),
        "{err}"
    );
    let (code, err) =
        shards.merge_edited("missed", |s| edit_record(&s[k], run, "outcome", "missed"));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("run {run} ")), "{err}");
    // A flown run said not flown (invalid) to leave it out of the statistics.
    let (code, err) =
        shards.merge_edited("invalid", |s| edit_record(&s[k], run, "outcome", "invalid"));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("run {run} ")), "{err}");
}

#[test]
fn a_record_moved_into_another_shards_file_is_refused() {
    let shards = Shards::new("forged-moved");
    let (code, err) = shards.merge_edited("moved", |s| {
        let mut from = lines(&s[1]);
        let mut to = lines(&s[0]);
        let k = from.iter().position(|l| l.0 == 4).unwrap();
        to.push(from.remove(k));
        write_lines(&s[1], &from);
        write_lines(&s[0], &to);
    });
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("run 4 ") && err.contains("1/3"), "{err}");
}

#[test]
fn every_field_of_a_shard_manifest_is_under_its_hash() {
    let shards = Shards::new("forged-manifest");
    // 8 runs of 12 said, the last 4 records dropped: every index of the 8 is there once.
    let (code, err) = shards.merge_edited("runs", |s| {
        for d in s {
            edit_manifest(d, |m| {
                m["runs"] = 8.into();
                m["owned"] = m["owned"].as_u64().map(|o| o - 1).unwrap().into();
                m["done"] = m["owned"].clone();
            });
            let kept: Vec<(u64, String)> = lines(d).into_iter().filter(|l| l.0 < 8).collect();
            write_lines(d, &kept);
        }
    });
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("shard.json") && err.contains("edited"),
        "{err}"
    );
    // The campaign a manifest keeps, edited (another seed): the manifest is named, not the
    // program's version.
    let (code, err) = shards.merge_edited("text", |s| {
        for d in s {
            edit_manifest(d, |m| {
                let t = m["campaign_text"]
                    .as_str()
                    .unwrap()
                    .replace("seed = 13", "seed = 14");
                m["campaign_text"] = t.into();
            });
        }
    });
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("edited") && !err.contains("made by"), "{err}");
    // A manifest of an earlier host-sim, without the hash: refused, saying so.
    let (code, err) = shards.merge_edited("old", |s| {
        edit_manifest(&s[0], |m| {
            m.as_object_mut().unwrap().remove("manifest_hash");
        })
    });
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("earlier host-sim"), "{err}");
}
