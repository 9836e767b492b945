//! Worst cases replay bit for bit from the commands the report prints (Choice 134).

use crate::support::*;

#[test]
fn every_worst_case_replays_bit_for_bit_from_its_printed_command() {
    let dir = tempdir("worst");
    let file = write_campaign(&dir, &campaign_text(10, 11));
    let merged = sharded(&dir, &file, 2);
    let all = records(&merged.join("records.csv"));
    let report = std::fs::read_to_string(merged.join("report.md")).unwrap();
    for (m, metric) in [(3, "max_path"), (4, "rms_path"), (9, "saturated_fraction")] {
        // The worst run, found here from the records: the largest value, the first run with
        // it (records are in index order).
        let top = all.iter().map(|r| r.metrics[m]).fold(f64::MIN, f64::max);
        let worst = all.iter().find(|r| r.metrics[m] == top).unwrap();
        let f = format!("worst-{metric}.toml");
        let cmd = format!("`host-sim run --scenario {f} --out runs/t-{}`", worst.index);
        assert!(report.contains(&cmd), "{cmd} not in the report");
        let pil = format!(
            "`host-sim pil --scenario {f} --out runs/t-{}-pil`",
            worst.index
        );
        assert!(report.contains(&pil), "{pil} not in the report");
        // The command as printed, from the report's folder.
        let out = ok(host_sim()
            .current_dir(&merged)
            .args(["run", "--scenario", &f, "--json", "--out"])
            .arg(dir.join(format!("replay-{metric}")))
            .output()
            .unwrap());
        let text = String::from_utf8_lossy(&out.stdout);
        for (k, name) in host_sim::studies::campaign::METRIC_NAMES.iter().enumerate() {
            let x = json_number(&text, name);
            assert_eq!(
                x.to_bits(),
                worst.metrics[k].to_bits(),
                "{metric}'s worst run {}: {name} replayed {x}, campaign {}",
                worst.index,
                worst.metrics[k]
            );
        }
    }
}

/// The first number at `"key":` in `json` outside a run's per-thruster `"chatter"` object
/// (which repeats the chatter figures' names), read with Rust's correctly rounded parser
/// (serde_json's default float parsing may be one ulp off).
fn json_number(json: &str, key: &str) -> f64 {
    let json = match json.find("\"chatter\":{") {
        Some(start) => {
            let end = json[start..].find("}}").unwrap() + start + 2;
            format!("{}{}", &json[..start], &json[end..])
        }
        None => json.to_string(),
    };
    let at = json.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
    let end = json[at..].find([',', '}']).unwrap() + at;
    json[at..end].trim().parse().unwrap()
}
