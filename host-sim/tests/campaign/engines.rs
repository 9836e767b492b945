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
