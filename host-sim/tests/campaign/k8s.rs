//! The shipped Kubernetes manifest: typed, and its command lines run here (Choice 141).

use std::path::Path;
use std::process::Command;

use crate::support::*;

/// The fields of the shipped Kubernetes manifest, typed (unknown fields refused: a misspelt key
/// fails here, as the API server would refuse it).
mod schema {
    use std::collections::BTreeMap;

    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Object {
        pub api_version: String,
        pub kind: String,
        pub metadata: Metadata,
        pub spec: serde_yaml::Value,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Metadata {
        pub name: String,
        pub labels: BTreeMap<String, String>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct JobSpec {
        pub completion_mode: Option<String>,
        pub completions: u64,
        pub parallelism: Option<u64>,
        pub backoff_limit: Option<u64>,
        pub backoff_limit_per_index: Option<u64>,
        pub max_failed_indexes: Option<u64>,
        pub template: PodTemplate,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct PodTemplate {
        pub spec: PodSpec,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct PodSpec {
        pub restart_policy: String,
        pub containers: Vec<Container>,
        pub volumes: Vec<Volume>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Container {
        pub name: String,
        pub image: String,
        pub command: Vec<String>,
        pub args: Vec<String>,
        pub env: Vec<EnvVar>,
        pub resources: serde_yaml::Value,
        pub volume_mounts: Vec<VolumeMount>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct EnvVar {
        pub name: String,
        pub value: String,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct VolumeMount {
        pub name: String,
        pub mount_path: String,
        pub read_only: Option<bool>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Volume {
        pub name: String,
        pub config_map: Option<Named>,
        pub persistent_volume_claim: Option<Claim>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Named {
        pub name: String,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields, rename_all = "camelCase")]
    pub struct Claim {
        pub claim_name: String,
    }

    /// `$(NAME)` replaced by the container's env value, as the kubelet expands args.
    pub fn expand(s: &str, env: &[EnvVar]) -> String {
        env.iter().fold(s.to_string(), |s, e| {
            s.replace(&format!("$({})", e.name), &e.value)
        })
    }
}

#[test]
fn the_kubernetes_manifest_parses_and_its_command_lines_run_the_campaign() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("deploy/k8s/campaign-job.yaml")).unwrap();
    let objects: Vec<schema::Object> = serde_yaml::Deserializer::from_str(&text)
        .map(|d| serde::Deserialize::deserialize(d).unwrap())
        .collect();
    let kinds: Vec<&str> = objects.iter().map(|o| o.kind.as_str()).collect();
    assert_eq!(kinds, ["PersistentVolumeClaim", "Job", "Job"]);
    let claim = &objects[0].metadata.name;
    let job = |o: &schema::Object| -> schema::JobSpec {
        assert_eq!(o.api_version, "batch/v1");
        serde_yaml::from_value(o.spec.clone()).unwrap()
    };
    let shards = job(&objects[1]);
    let merge_job = job(&objects[2]);
    assert_eq!(objects[1].metadata.labels["part"], "shards");
    assert_eq!(objects[2].metadata.labels["part"], "merge");
    assert_eq!(shards.completion_mode.as_deref(), Some("Indexed"));
    for j in [&shards, &merge_job] {
        assert_eq!(j.template.spec.restart_policy, "Never");
        // Every mount is a volume of the pod, and the data volume is the claim.
        let c = &j.template.spec.containers[0];
        for m in &c.volume_mounts {
            let v = j.template.spec.volumes.iter().find(|v| v.name == m.name);
            assert!(v.is_some(), "mount {} has no volume", m.name);
        }
        let data = j.template.spec.volumes.iter().find(|v| v.name == "data");
        let data_claim = data.and_then(|v| v.persistent_volume_claim.as_ref());
        assert_eq!(&data_claim.unwrap().claim_name, claim);
    }
    // Shards are retried per index, and one that keeps failing fails the Job (no merge).
    assert!(shards.parallelism.unwrap() <= shards.completions);
    assert!(shards.backoff_limit_per_index.is_some_and(|n| n > 0));
    assert_eq!(shards.max_failed_indexes, Some(0));
    assert_eq!(merge_job.backoff_limit, Some(0));
    let shard_c = &shards.template.spec.containers[0];
    assert_eq!(
        (shard_c.name.as_str(), shard_c.image.as_str()),
        ("shard", "host-sim:latest")
    );
    assert!(shard_c.resources.get("requests").is_some());
    let ro = shard_c.volume_mounts.iter().find(|m| m.name == "campaign");
    assert_eq!(ro.and_then(|m| m.read_only), Some(true));
    let count = shard_c.env.iter().find(|e| e.name == "HOST_SIM_SHARDS");
    assert_eq!(
        count.map(|e| e.value.parse::<u64>().unwrap()),
        Some(shards.completions),
        "HOST_SIM_SHARDS must equal the Job's completions"
    );
    let config_map = shards
        .template
        .spec
        .volumes
        .iter()
        .find_map(|v| v.config_map.as_ref());
    assert_eq!(config_map.unwrap().name, "host-sim-campaign");

    // Run the command lines here: the mounts are folders, the campaign is the CI's small one
    // (the env's CAMPAIGN is the documented knob; ci-small has as many runs as the Job has
    // completions, so every index has its run), one process per completion index.
    let dir = tempdir("k8s");
    let mounts = |c: &schema::Container, s: &str| {
        c.volume_mounts.iter().fold(s.to_string(), |s, m| {
            let local = match m.name.as_str() {
                "campaign" => root.join("host-sim/campaigns"),
                _ => dir.join(&m.name),
            };
            s.replace(&m.mount_path, &local.display().to_string())
        })
    };
    let mut env = shard_c.env.clone_env();
    env.iter_mut()
        .filter(|e| e.name == "CAMPAIGN")
        .for_each(|e| e.value = "/campaign/ci-small.campaign.toml".into());
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_host-sim")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let run = |c: &schema::Container, env: &[schema::EnvVar], index: Option<u64>| {
        let args: Vec<String> = c
            .args
            .iter()
            .map(|a| mounts(c, &schema::expand(a, env)))
            .collect();
        let mut cmd = Command::new(&c.command[0]);
        cmd.args(&c.command[1..]).args(&args).env("PATH", &path);
        cmd.env_remove("SLURM_ARRAY_TASK_ID");
        for e in env {
            cmd.env(&e.name, &e.value);
        }
        if let Some(i) = index {
            cmd.env("JOB_COMPLETION_INDEX", i.to_string());
        }
        ok(cmd.output().unwrap())
    };
    for i in 0..shards.completions {
        run(shard_c, &env, Some(i));
    }
    let merge_c = &merge_job.template.spec.containers[0];
    run(merge_c, &merge_c.env.clone_env(), None);
    // The report is the one-machine run's.
    let out_name = &env.iter().find(|e| e.name == "OUT").unwrap().value;
    let one = dir.join("one");
    let file = root.join("host-sim/campaigns/ci-small.campaign.toml");
    ok(run_shard(&file, "0/1", &one.join("shard")));
    ok(merge(&[one.join("shard")], &one.join("report")));
    let k8s_report = report_files(&dir.join("data").join(out_name).join("report"));
    assert!(k8s_report == report_files(&one.join("report")));
}

/// Owned copies of a container's env (the test changes one value).
trait CloneEnv {
    fn clone_env(&self) -> Vec<schema::EnvVar>;
}

impl CloneEnv for Vec<schema::EnvVar> {
    fn clone_env(&self) -> Vec<schema::EnvVar> {
        self.iter()
            .map(|e| schema::EnvVar {
                name: e.name.clone(),
                value: e.value.clone(),
            })
            .collect()
    }
}
