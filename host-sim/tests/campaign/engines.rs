//! The shard from `--shard`, or from Slurm's or Kubernetes' environment (Choice 137).

use host_sim::cli::resolve_shard;

use crate::support::*;

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

#[test]
fn an_ambiguous_shard_is_refused_with_the_reason_and_a_stepped_array_is_honoured() {
    let env = |pairs: &'static [(&'static str, &'static str)]| {
        move |k: &str| pairs.iter().find(|p| p.0 == k).map(|p| p.1.to_string())
    };
    let err = |r: anyhow::Result<(u64, u64)>| format!("{:#}", r.unwrap_err());
    // A count without an index: not shard 0 of it.
    let e = err(resolve_shard(None, Some(4), env(&[])));
    assert!(e.contains("--shard I/4"), "{e}");
    // A count that the flag's contradicts.
    assert!(err(resolve_shard(Some("1/3"), Some(4), env(&[]))).contains("--shards 4"));
    // Slurm's count against an explicit --shards: refused, not overridden; the same count is
    // fine.
    let slurm: &'static [(&str, &str)] = &[
        ("SLURM_ARRAY_TASK_ID", "3"),
        ("SLURM_ARRAY_TASK_MIN", "1"),
        ("SLURM_ARRAY_TASK_MAX", "4"),
        ("SLURM_ARRAY_TASK_COUNT", "4"),
    ];
    let e = err(resolve_shard(None, Some(3), env(slurm)));
    assert!(
        e.contains("SLURM_ARRAY_TASK_COUNT") && e.contains("--shards 3"),
        "{e}"
    );
    assert_eq!(resolve_shard(None, Some(4), env(slurm)).unwrap(), (2, 4));
    // `--array=0-6:2`: tasks 0, 2, 4, 6 are shards 0..4.
    for (id, shard) in [("0", 0), ("2", 1), ("4", 2), ("6", 3)] {
        let vars = [
            ("SLURM_ARRAY_TASK_ID", id),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "6"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        let get = |k: &str| vars.iter().find(|p| p.0 == k).map(|p| p.1.to_string());
        assert_eq!(
            resolve_shard(None, None, get).unwrap(),
            (shard, 4),
            "task {id}"
        );
    }
    // `--array=0,2,3`: not evenly spaced, no shard numbering to read from it.
    let list: &'static [(&str, &str)] = &[
        ("SLURM_ARRAY_TASK_ID", "2"),
        ("SLURM_ARRAY_TASK_MIN", "0"),
        ("SLURM_ARRAY_TASK_MAX", "3"),
        ("SLURM_ARRAY_TASK_STEP", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    let e = err(resolve_shard(None, None, env(list)));
    assert!(e.contains("evenly spaced"), "{e}");
    // Both engines' variables: which one is meant is not known.
    let both: &'static [(&str, &str)] = &[
        ("SLURM_ARRAY_TASK_ID", "1"),
        ("SLURM_ARRAY_TASK_COUNT", "2"),
        ("JOB_COMPLETION_INDEX", "0"),
    ];
    let e = err(resolve_shard(None, Some(2), env(both)));
    assert!(e.contains("JOB_COMPLETION_INDEX"), "{e}");
    // Kubernetes: --shards and HOST_SIM_SHARDS that disagree.
    let k8s: &'static [(&str, &str)] = &[("JOB_COMPLETION_INDEX", "1"), ("HOST_SIM_SHARDS", "5")];
    assert!(err(resolve_shard(None, Some(4), env(k8s))).contains("HOST_SIM_SHARDS"));
    // Through the binary: exit 2 with the reason.
    let dir = tempdir("ambiguous");
    let file = write_campaign(&dir, &campaign_text(4, 1));
    let out = host_sim()
        .args(["campaign", "run"])
        .arg(&file)
        .args(["--shards", "4", "--out"])
        .arg(dir.join("s"))
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .output()
        .unwrap();
    let (code, e) = refused(&out);
    assert_eq!(code, Some(2), "{e}");
    assert!(e.contains("--shard I/4"), "{e}");
}
