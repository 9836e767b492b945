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

#[test]
fn a_complete_last_line_that_does_not_parse_is_an_error_not_a_torn_line() {
    let dir = tempdir("bad-last");
    let file = write_campaign(&dir, &campaign_text(6, 4));
    let shard = dir.join("shard");
    ok(run_shard(&file, "0/1", &shard));
    let path = shard.join("records.csv");
    let good = std::fs::read_to_string(&path).unwrap();
    // The last record's line with its newline, but not a record: an edit, not a kill.
    let mut lines: Vec<&str> = good.lines().collect();
    let last = lines
        .pop()
        .unwrap()
        .replace(",completed", ",complete")
        .replace(",missed", ",miss");
    let bad = format!("{}\n{last}\n", lines.join("\n"));
    std::fs::write(&path, &bad).unwrap();
    for out in [
        run_shard(&file, "0/1", &shard),
        merge(std::slice::from_ref(&shard), &dir.join("m")),
    ] {
        let (code, err) = refused(&out);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains("line 7") && err.contains("not a campaign record"),
            "{err}"
        );
    }
    // Left as it was: nothing cut.
    assert_eq!(std::fs::read_to_string(&path).unwrap(), bad);
}

/// A campaign at the documented maximum, 10⁹ runs in one shard, under a 1 GiB address-space
/// limit (a list of its 10⁹ indices is 8 GB): it starts, records runs, is interrupted, and
/// resumes (its bookkeeping of what is done is a bit a run, 125 MB) without a run twice
/// (Choice 244).
#[test]
fn a_shard_of_a_billion_runs_starts_and_resumes_in_bounded_memory() {
    use std::os::unix::process::CommandExt;
    let dir = tempdir("billion");
    let text = campaign_text(1_000_000_000, 8).replace("mountings", "# mountings");
    let file = write_campaign(&dir, &text);
    std::fs::write(
        dir.join("base.toml"),
        BASE.replace("duration = 2.0", "duration = 0.3"),
    )
    .unwrap();
    let out = dir.join("shard");
    let records_file = out.join("records.csv");
    let mut seen = 0;
    for round in 0..2 {
        let mut cmd = host_sim();
        cmd.args(["campaign", "run"])
            .arg(&file)
            .arg("--out")
            .arg(&out)
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("JOB_COMPLETION_INDEX")
            // Two threads and two malloc arenas whatever the machine: the limit is on address
            // space, which each thread's arena reserves.
            .env("RAYON_NUM_THREADS", "2")
            .env("MALLOC_ARENA_MAX", "2")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        // SAFETY: setrlimit between fork and exec touches no memory of the parent.
        unsafe {
            cmd.pre_exec(|| {
                let gib = libc::rlimit {
                    rlim_cur: 1 << 30,
                    rlim_max: 1 << 30,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &gib) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let mut child = cmd.spawn().unwrap();
        let lines = || {
            std::fs::read(&records_file)
                .map(|b| b.iter().filter(|c| **c == b'\n').count())
                .unwrap_or(0)
        };
        while lines() < seen + 20 && child.try_wait().unwrap().is_none() {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        // SAFETY: a signal to the child this test started.
        unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "round {round}: {stderr}");
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("shard.json")).unwrap())
                .unwrap();
        assert_eq!(m["owned"], 1_000_000_000u64, "{m}");
        let r = records(&records_file);
        assert_eq!(m["done"].as_u64(), Some(r.len() as u64));
        assert!(r.len() > seen, "round {round}: no new run");
        let mut idx: Vec<u64> = r.iter().map(|r| r.index).collect();
        idx.sort();
        idx.dedup();
        assert_eq!(idx.len(), r.len(), "a run recorded twice");
        seen = r.len();
    }
}
