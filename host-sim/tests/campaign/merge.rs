//! The merge's checks (Choice 133) and its verdict.

use std::path::PathBuf;

use host_sim::studies::campaign::merge::Manifest;
use host_sim::studies::campaign::Campaign;

use crate::support::*;

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
    // A shard cut short (its last two runs lost, its manifest saying so, as a shard interrupted
    // after one run writes it) is named incomplete, and its runs missing.
    let cut = dir.join("cut1");
    ok(run_shard(&file, "1/3", &cut));
    let text = std::fs::read_to_string(cut.join("records.csv")).unwrap();
    let kept: Vec<&str> = text.lines().take(2).collect();
    std::fs::write(cut.join("records.csv"), kept.join("\n") + "\n").unwrap();
    let c = Campaign::load(&file).unwrap();
    let m = serde_json::to_string_pretty(&Manifest::of(&c, 1, 3, 1)).unwrap();
    std::fs::write(cut.join("shard.json"), m).unwrap();
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
fn the_merge_refuses_an_output_folder_that_is_contains_or_is_inside_a_shard() {
    let dir = tempdir("merge-out");
    let file = write_campaign(&dir, &campaign_text(4, 2));
    let shards = dir.join("shards");
    let s: Vec<PathBuf> = (0..2)
        .map(|i| {
            let out = shards.join(format!("s{i}"));
            ok(run_shard(&file, &format!("{i}/2"), &out));
            out
        })
        .collect();
    let before: Vec<Vec<u8>> = s
        .iter()
        .map(|d| std::fs::read(d.join("records.csv")).unwrap())
        .collect();
    // The shard itself (also spelt another way), the folder holding it, a folder inside it.
    for out in [
        s[1].clone(),
        shards.join("s0/../s1"),
        shards.clone(),
        s[0].join("report"),
    ] {
        let (code, err) = refused(&merge(&s, &out));
        assert_eq!(code, Some(2), "{}: {err}", out.display());
        assert!(err.contains("--out"), "{}: {err}", out.display());
    }
    for (d, b) in s.iter().zip(&before) {
        assert!(std::fs::read(d.join("records.csv")).unwrap() == *b);
        assert!(d.join("shard.json").exists());
    }
    assert!(!s[0].join("report").exists());
    ok(merge(&s, &dir.join("report")));
}

#[test]
fn a_campaign_in_which_no_run_flew_fails_and_says_so() {
    let dir = tempdir("none-flew");
    // Start offsets of up to ±1000 km: beyond the divergence limit, every draw is invalid.
    let text = campaign_text(3, 2).replace(
        "initial_offset = [0.02, 0.02, 0.02, 0.0, 0.0, 0.02]",
        "initial_offset = [1e6, 1e6, 1e6, 0.0, 0.0, 0.0]",
    );
    let file = write_campaign(&dir, &text);
    ok(run_shard(&file, "0/1", &dir.join("s")));
    let r = records(&dir.join("s/records.csv"));
    assert!(r.iter().all(|r| r.outcome.as_str() == "invalid"));
    let out = merge(&[dir.join("s")], &dir.join("m"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("invalid 3"), "{stdout}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("no run flew"));
    // The report is written all the same.
    assert!(dir.join("m/report.md").exists());
}
