//! The campaign file's errors, named by key, and `campaign plan`.

use crate::support::*;

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

/// A bad `draw.initial_offset` used to be refused with f64::MAX written out (309 digits) as
/// the positions' limit, and the value as given (`-1e308`: 309 digits more): the message names
/// the entry, its range and the value, readable.
#[test]
fn a_bad_initial_offset_is_refused_in_a_readable_line() {
    let dir = tempdir("offset-digits");
    for (offset, key) in [
        (
            "[-1e308, 0.02, 0.02, 0.0, 0.0, 0.02]",
            "`draw.initial_offset[0]`",
        ),
        (
            "[0.02, 0.02, 0.02, 0.0, 4.0, 0.02]",
            "`draw.initial_offset[4]`",
        ),
    ] {
        let text = campaign_text(5, 1).replace("[0.02, 0.02, 0.02, 0.0, 0.0, 0.02]", offset);
        let file = write_campaign(&dir, &text);
        let (code, err) = refused(&run_shard(&file, "0/1", &dir.join("out")));
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(key), "{err}");
        assert!(err.lines().all(|l| l.len() < 200), "{err}");
    }
}

#[test]
fn a_metric_listed_twice_is_refused() {
    let dir = tempdir("metric-twice");
    let text = campaign_text(5, 1).replace(
        "metrics = [\"max_path\", \"rms_path\"",
        "metrics = [\"max_path\", \"rms_path\", \"max_path\"",
    );
    let file = write_campaign(&dir, &text);
    let (code, err) = refused(&run_shard(&file, "0/1", &dir.join("out")));
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("`metrics`") && err.contains("max_path"),
        "{err}"
    );
}

#[test]
fn a_base_that_is_not_a_scenario_is_named_without_echoing_its_content() {
    let dir = tempdir("base-echo");
    let file = write_campaign(&dir, &campaign_text(5, 1));
    // Not TOML at all, and TOML that is not a scenario: neither line is printed.
    for (what, text) in [
        ("not toml", "token: s3cr3t-f1rst-l1ne\n"),
        ("not a scenario", "password = \"s3cr3t-f1rst-l1ne\"\n"),
    ] {
        std::fs::write(dir.join("base.toml"), text).unwrap();
        let (code, err) = refused(&run_shard(&file, "0/1", &dir.join("out")));
        assert_eq!(code, Some(2), "{what}: {err}");
        assert!(
            err.contains("base.toml") && err.contains("line 1"),
            "{what}: {err}"
        );
        assert!(!err.contains("s3cr3t"), "{what}: {err}");
    }
}
