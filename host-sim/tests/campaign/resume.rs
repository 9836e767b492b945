//! A shard resumes after a kill or an interrupt, and redoes a torn last line (Choices 135, 136).

use crate::support::*;

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
