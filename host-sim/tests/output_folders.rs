//! Output folders on shared machines: a bad or symlinked folder refused before the run, a
//! reused one holding only the last run's files, a file-size limit as an incomplete output, the
//! temporary files of dead processes removed, a second run into a folder in use refused. Every
//! test runs the binary and reads its exit code, stderr and files.

mod common;

use std::process::Command;

use common::{entries, run, scenario, signal, spawn_run, stderr, tempdir, SHORT};

#[test]
fn a_bad_output_folder_is_refused_before_the_run() {
    let dir = tempdir("badout");
    // A day at 100 Hz: minutes of work, if it were started.
    let s = scenario(
        &dir,
        "day",
        "duration = 86400\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let file = dir.join("a-file");
    std::fs::write(&file, "mine").unwrap();
    let o = run(&[], &s, &file);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is not a folder"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");

    // A symlink as the folder: refused, nothing written where it points.
    let target = dir.join("elsewhere");
    std::fs::create_dir_all(&target).unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = run(&[], &s, &link);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("symlink"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&target).unwrap().count(), 0);

    // A folder of someone else's files: refused, untouched, and the error said once.
    let foreign = dir.join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.csv"), "mine").unwrap();
    let o = run(&[], &s, &foreign);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("notes.csv") && e.contains("manifest"), "{e}");
    assert_eq!(e.matches("error").count(), 1, "{e}");
    assert_eq!(
        std::fs::read_to_string(foreign.join("notes.csv")).unwrap(),
        "mine"
    );
}

#[test]
fn a_reused_folder_holds_only_the_last_runs_files_and_symlinks_are_not_followed() {
    let dir = tempdir("reuse");
    let out = dir.join("out");
    let a = scenario(&dir, "a", &format!("name = \"alpha\"\n{SHORT}"));
    let b = scenario(&dir, "b", &format!("name = \"beta\"\n{SHORT}"));
    assert!(run(&[], &a, &out).status.success());
    assert!(out.join("alpha-with.csv").exists());
    std::fs::write(out.join("my-notes.txt"), "mine").unwrap();

    // A symlink planted where the next run writes its report, and one in place of a listed
    // output: neither is followed.
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "precious").unwrap();
    std::fs::remove_file(out.join("report.md")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("report.md")).unwrap();
    std::fs::remove_file(out.join("alpha-xy.png")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("alpha-xy.png")).unwrap();

    let o = run(&[], &b, &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    let report = std::fs::symlink_metadata(out.join("report.md")).unwrap();
    assert!(report.is_file(), "report.md is a file again, not the link");
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert!(names.iter().all(|n| !n.starts_with("alpha")), "{names:?}");
    assert!(names.contains(&"beta-with.csv".to_string()), "{names:?}");
    assert!(names.contains(&"my-notes.txt".to_string()), "{names:?}");
    let manifest = std::fs::read_to_string(out.join("host-sim-manifest.txt")).unwrap();
    assert!(manifest.contains("beta-with.csv") && !manifest.contains("alpha"));
    assert!(!manifest.contains("my-notes.txt"));
}

/// Under `ulimit -f` the process used to die of SIGXFSZ (exit 153 in a shell), with
/// no report and no message. A write beyond the limit is now an incomplete output: named, in
/// the report, exit 2.
#[test]
fn a_file_size_limit_is_an_incomplete_output_not_death() {
    let dir = tempdir("fsize");
    // 20 s at 100 Hz: ≈ 2 MB of CSV per run, beyond a 200 kB limit.
    let s = scenario(
        &dir,
        "big",
        "name = \"big\"\nduration = 20\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let out = dir.join("out");
    let o = Command::new("bash")
        .arg("-c")
        .arg("ulimit -f 200 && exec \"$0\" run --scenario \"$1\" --out \"$2\"")
        .arg(env!("CARGO_BIN_EXE_host-sim"))
        .arg(&s)
        .arg(&out)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{:?}: {e}", o.status);
    assert!(
        e.contains("big-with.csv is incomplete") && e.contains("File too large"),
        "{e}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("incomplete") && report.contains("big-with.csv"));
    assert!(entries(&out, ".host-sim-tmp").is_empty());
}

/// The next run into a folder removes the temporary files of dead processes (their
/// pid is in the name) and only those.
#[test]
fn stale_temporary_files_of_dead_processes_are_removed_and_no_others() {
    let dir = tempdir("stale");
    let out = dir.join("out");
    let s = scenario(&dir, "short", &format!("name = \"short\"\n{SHORT}"));
    assert!(run(&[], &s, &out).status.success());
    let mut gone = Command::new("true").spawn().unwrap();
    let dead = gone.id();
    gone.wait().unwrap();
    let stale = out.join(format!(".host-sim-tmp.{dead}-0.short-with.csv"));
    // This test's own process is alive: its file might be being written.
    let live = out.join(format!(".host-sim-tmp.{}-0.x.csv", std::process::id()));
    std::fs::write(&stale, "half").unwrap();
    std::fs::write(&live, "writing").unwrap();
    assert!(run(&[], &s, &out).status.success());
    assert!(!stale.exists());
    assert_eq!(std::fs::read_to_string(&live).unwrap(), "writing");
}

/// Two runs into one folder used to race (the second removed the first's files and
/// failed with "not writable: No such file or directory"). The second is refused at once,
/// naming the first, and the first is untouched.
#[test]
fn a_second_run_into_a_folder_in_use_is_refused_at_once() {
    let dir = tempdir("lock");
    let out = dir.join("out");
    let s = scenario(
        &dir,
        "hour",
        "name = \"hour\"\nduration = 3600\n[trajectory]\nkind = \"circle\"\nradius = 10\n",
    );
    let first = spawn_run(&s, &out);
    // Wait (bounded) until the first run holds the folder.
    let lock = out.join("host-sim.lock");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while std::fs::read_to_string(&lock)
        .map_or(true, |t| !t.starts_with(&format!("{} ", first.id())))
        && std::time::Instant::now() < deadline
    {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let o = run(&[], &s, &out);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains(&format!("is in use by process {}", first.id())),
        "{e}"
    );
    signal(first.id(), libc::SIGINT);
    let o = first.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    // The first run's report (of whatever phase it was in) is there: the second removed
    // nothing. The lock went with the first run's end.
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("AUV-150 scenario hour (PARTIAL)"),
        "{report}"
    );
    let next = scenario(&dir, "next", &format!("name = \"next\"\n{SHORT}"));
    assert!(run(&[], &next, &out).status.success());
    // A symlink planted as the lock file is not followed.
    let victim = dir.join("victim");
    std::fs::remove_file(&lock).unwrap();
    std::os::unix::fs::symlink(&victim, &lock).unwrap();
    let o = run(&[], &next, &out);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("host-sim.lock is a symlink"),
        "{}",
        stderr(&o)
    );
    assert!(!victim.exists());
}
