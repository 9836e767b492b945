//! The merge of a campaign's shards (**Choice 133**): every shard of the same campaign (hash),
//! every index present exactly once (a missing or duplicate shard is named, and so are the
//! indices), then the statistics of the whole.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::record::Record;
use super::{Campaign, METRIC_NAMES};

/// A shard's manifest (`shard.json` in its folder): which campaign, which shard, how far it got,
/// and the campaign's texts (so the merge needs nothing but the shard folders).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The campaign's hash ([`Campaign::hash`]).
    pub campaign_hash: String,
    pub program_version: String,
    /// The campaign's name.
    pub name: String,
    pub runs: u64,
    pub shard: u64,
    pub shards: u64,
    /// Runs of this shard recorded.
    pub done: u64,
    /// Runs this shard owns.
    pub owned: u64,
    /// Every owned run is recorded.
    pub complete: bool,
    /// The campaign file's text.
    pub campaign_text: String,
    /// Each base: (the file name the campaign gives, its text).
    pub bases: Vec<(String, String)>,
}

impl Manifest {
    /// The manifest of `shard`/`shards` of `c` with `done` runs recorded.
    pub fn of(c: &Campaign, shard: u64, shards: u64, done: u64) -> Self {
        let owned = c.shard(shard, shards).len();
        Manifest {
            campaign_hash: c.hash.clone(),
            program_version: super::PROGRAM_VERSION.to_string(),
            name: c.spec.name().to_string(),
            runs: c.runs(),
            shard,
            shards,
            done,
            owned,
            complete: done == owned,
            campaign_text: c.text.clone(),
            bases: c
                .bases
                .iter()
                .map(|b| (b.path.clone(), b.text.clone()))
                .collect(),
        }
    }
}

/// One shard as the merge reads it: where it is (for messages), its manifest, its records.
pub struct ShardInput {
    pub label: String,
    pub manifest: Manifest,
    pub records: Vec<Record>,
}

/// Checks the shards (see the module doc) and returns every record sorted by index (taken out
/// of `shards`); an error lists every problem found, each naming the shard folders concerned.
pub fn check(shards: &mut [ShardInput]) -> Result<Vec<Record>, String> {
    let Some(first) = shards.first() else {
        return Err("no shard folder given".into());
    };
    let mut problems = Vec::new();
    for s in shards.iter() {
        if s.manifest.campaign_hash != first.manifest.campaign_hash {
            problems.push(format!(
                "{} is a shard of another campaign (hash {}…, {} has {}…; a different campaign \
                 file, base scenario or host-sim version)",
                s.label,
                &s.manifest.campaign_hash[..12.min(s.manifest.campaign_hash.len())],
                first.label,
                &first.manifest.campaign_hash[..12.min(first.manifest.campaign_hash.len())]
            ));
        }
    }
    if !problems.is_empty() {
        return Err(problems.join("\n"));
    }
    let runs = first.manifest.runs;
    shard_problems(shards, &mut problems);
    // Every record with its shard, sorted by index: duplicates are neighbours, gaps are missing
    // runs. The records are moved, not copied (a merge of 10⁶ runs holds them once).
    let mut order: Vec<(u64, usize, Record)> = shards
        .iter_mut()
        .enumerate()
        .flat_map(|(k, s)| {
            std::mem::take(&mut s.records)
                .into_iter()
                .map(move |r| (r.index, k, r))
        })
        .collect();
    order.sort_unstable_by_key(|o| (o.0, o.1));
    let mut dup: Vec<String> = Vec::new();
    let mut dup_count = 0usize;
    let labels: Vec<&str> = shards.iter().map(|s| s.label.as_str()).collect();
    for w in order.windows(2).filter(|w| w[0].0 == w[1].0) {
        dup_count += 1;
        if dup.len() < 5 {
            let (a, b) = (labels[w[0].1], labels[w[1].1]);
            dup.push(format!(" run {} in {a} and {b};", w[0].0));
        }
    }
    if dup_count > 0 {
        problems.push(format!(
            "{dup_count} run(s) recorded more than once:{}",
            dup.concat()
        ));
    }
    let outside: Vec<u64> = order.iter().map(|o| o.0).filter(|i| *i >= runs).collect();
    if !outside.is_empty() {
        problems.push(format!("runs {outside:?} are beyond the campaign's {runs}"));
    }
    let mut present = order.iter().map(|o| o.0).peekable();
    let missing: Vec<u64> = (0..runs)
        .filter(|i| {
            while present.next_if(|p| p < i).is_some() {}
            present.peek() != Some(i)
        })
        .collect();
    if !missing.is_empty() {
        problems.push(format!(
            "{} of {runs} runs missing (indices {}{})",
            missing.len(),
            missing
                .iter()
                .take(10)
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            if missing.len() > 10 { ", …" } else { "" }
        ));
    }
    if !problems.is_empty() {
        return Err(problems.join("\n"));
    }
    Ok(order.into_iter().map(|o| o.2).collect())
}

/// Missing, duplicate and incomplete shards, by their manifests.
fn shard_problems(shards: &[ShardInput], problems: &mut Vec<String>) {
    let mut seen: BTreeMap<(u64, u64), Vec<&str>> = BTreeMap::new();
    for s in shards {
        let m = &s.manifest;
        seen.entry((m.shards, m.shard)).or_default().push(&s.label);
        if !m.complete {
            problems.push(format!(
                "shard {}/{} ({}) is incomplete: {} of its {} runs recorded (rerun it with the \
                 same --out: it skips the runs done)",
                m.shard, m.shards, s.label, m.done, m.owned
            ));
        }
    }
    for ((n, i), dirs) in &seen {
        if dirs.len() > 1 {
            problems.push(format!("shard {i}/{n} given twice: {}", dirs.join(", ")));
        }
    }
    let counts: Vec<u64> = seen.keys().map(|k| k.0).collect();
    for n in counts
        .iter()
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
    {
        let missing: Vec<String> = (0..n)
            .filter(|i| !seen.contains_key(&(n, *i)))
            .map(|i| format!("{i}/{n}"))
            .collect();
        if !missing.is_empty() {
            problems.push(format!("shard(s) missing: {}", missing.join(", ")));
        }
    }
}

/// Percentiles of one metric over the runs that have it (NaN: not flown, left out), and its
/// worst run (the largest value; the lowest index among equals).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MetricStats {
    pub name: &'static str,
    pub p50: f64,
    pub p90: f64,
    pub p99: f64,
    pub max: f64,
    pub worst: Option<u64>,
}

/// Nearest-rank percentile of sorted values (the one definition, `monte-carlo`'s).
fn percentile(sorted: &[f64], p: f64) -> f64 {
    crate::studies::montecarlo::percentile(sorted, p)
}

/// The stats of metric `m` (its index in [`METRIC_NAMES`]) over `records` (sorted by index).
pub fn stats(records: &[Record], m: usize) -> MetricStats {
    let mut v: Vec<(f64, u64)> = records
        .iter()
        .map(|r| (r.metrics[m], r.index))
        .filter(|x| !x.0.is_nan())
        .collect();
    // Ascending value, and for equal values descending index: the last is the largest value
    // with the lowest index.
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
    let sorted: Vec<f64> = v.iter().map(|x| x.0).collect();
    MetricStats {
        name: METRIC_NAMES[m],
        p50: percentile(&sorted, 50.0),
        p90: percentile(&sorted, 90.0),
        p99: percentile(&sorted, 99.0),
        max: sorted.last().copied().unwrap_or(f64::NAN),
        worst: v.last().map(|x| x.1),
    }
}
