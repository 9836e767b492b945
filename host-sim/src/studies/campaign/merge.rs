//! The merge of a campaign's shards (**Choice 133**): every shard of the same campaign (hash),
//! every index present exactly once (a missing or duplicate shard is named, and so are the
//! indices), every record the campaign's own (**Choice 240**: its draw is the campaign's draw of
//! its index, its run belongs to its shard, its outcome agrees with its metrics and bound), then
//! the statistics of the whole.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::record::{Outcome, Record};
use super::{Campaign, METRIC_NAMES};
use crate::sim::bound;

/// A shard's manifest (`shard.json` in its folder): which campaign, which shard, how far it got,
/// and the campaign's texts (so the merge needs nothing but the shard folders); every field
/// under [`Manifest::manifest_hash`] (**Choice 241**).
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
    /// sha256 (hex) of every other field ([`Manifest::fields_hash`]); absent in the manifests
    /// of host-sim before it, which are refused.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manifest_hash: Option<String>,
}

/// Why a manifest is not to be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ManifestError {
    /// No hash: written by a host-sim whose manifests were not hashed whole.
    Unhashed,
    /// A hash that its fields do not give.
    Edited,
}

impl std::fmt::Display for ManifestError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ManifestError::Unhashed => {
                "has no manifest_hash: it was written by an earlier host-sim, whose shard \
                 manifests are not hashed whole, and this one neither resumes nor merges it; run \
                 the shard again into a new folder"
            }
            ManifestError::Edited => {
                "was edited: its fields do not give its manifest_hash (only host-sim writes a \
                 shard's manifest); run the shard again into a new folder"
            }
        })
    }
}

impl std::error::Error for ManifestError {}

impl Manifest {
    /// The manifest of `shard`/`shards` of `c` with `done` runs recorded, hashed.
    pub fn of(c: &Campaign, shard: u64, shards: u64, done: u64) -> Self {
        let owned = c.shard(shard, shards).len();
        let mut m = Manifest {
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
            manifest_hash: None,
        };
        m.manifest_hash = Some(m.fields_hash());
        m
    }

    /// sha256 over a format tag and every field but the hash, as JSON (serde's field order).
    pub fn fields_hash(&self) -> String {
        let mut h = Sha256::new();
        h.update(b"auv150 shard manifest v1\n");
        let fields = Manifest {
            manifest_hash: None,
            ..self.clone()
        };
        // Plain data always serialises.
        h.update(
            serde_json::to_string(&fields)
                .unwrap_or_default()
                .as_bytes(),
        );
        super::hex(h)
    }

    /// The manifest as host-sim wrote it: hashed, and the hash its fields give.
    pub fn verify(&self) -> Result<(), ManifestError> {
        match &self.manifest_hash {
            None => Err(ManifestError::Unhashed),
            Some(h) if *h != self.fields_hash() => Err(ManifestError::Edited),
            Some(_) => Ok(()),
        }
    }
}

/// One shard as the merge reads it: where it is (for messages), its manifest, its records.
pub struct ShardInput {
    pub label: String,
    pub manifest: Manifest,
    pub records: Vec<Record>,
}

/// Every shard carries the first one's campaign hash; else each other one is named.
pub fn same_campaign(shards: &[ShardInput]) -> Result<(), String> {
    let Some(first) = shards.first() else {
        return Err("no shard folder given".into());
    };
    let short = |h: &str| h[..12.min(h.len())].to_string();
    let problems: Vec<String> = shards
        .iter()
        .filter(|s| s.manifest.campaign_hash != first.manifest.campaign_hash)
        .map(|s| {
            format!(
                "{} is a shard of another campaign (hash {}…, {} has {}…; a different campaign \
                 file, base scenario or host-sim version)",
                s.label,
                short(&s.manifest.campaign_hash),
                first.label,
                short(&first.manifest.campaign_hash)
            )
        })
        .collect();
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}

/// Most problems with records listed (each kind is counted whole).
const LISTED: usize = 10;

/// Checks the shards of campaign `c` (see the module doc; [`same_campaign`] first) and returns
/// every record sorted by index (taken out of `shards`); an error lists every problem found,
/// each naming the shard folders concerned.
pub fn check(c: &Campaign, shards: &mut [ShardInput]) -> Result<Vec<Record>, String> {
    let runs = c.runs();
    let mut problems = Vec::new();
    shard_problems(c, shards, &mut problems);
    problems.extend(records_problem(c, shards));
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

/// The records of `shards` that campaign `c` did not make ([`record_problem`]): how many, and
/// the first [`LISTED`]. In parallel (rayon): an `invalid` record's scenario is built again,
/// about a millisecond each.
fn records_problem(c: &Campaign, shards: &[ShardInput]) -> Option<String> {
    use rayon::prelude::*;
    let found: Vec<String> = shards
        .iter()
        .flat_map(|s| s.records.iter().map(move |r| (s, r)))
        .collect::<Vec<_>>()
        .par_iter()
        .filter_map(|(s, r)| record_problem(c, s, r))
        .collect();
    (!found.is_empty()).then(|| {
        format!(
            "{} record(s) that the campaign did not make (edited, moved, or written by another \
             program){}:\n  {}",
            found.len(),
            if found.len() > LISTED {
                ", the first"
            } else {
                ""
            },
            found[..found.len().min(LISTED)].join("\n  ")
        )
    })
}

/// Why record `r` of shard `s` is not one campaign `c` made, if it is not: an index outside
/// the campaign or the shard, a base or a draw other than the campaign's for its index, or an
/// outcome its metrics and bound contradict (**Choice 240**). Only an `invalid` record's
/// scenario is built again (to see that its draw does not validate): flown runs are checked
/// from their metrics, without flying them.
pub fn record_problem(c: &Campaign, s: &ShardInput, r: &Record) -> Option<String> {
    let (i, m, at) = (r.index, &s.manifest, &s.label);
    if i >= c.runs() {
        return Some(format!(
            "run {i} in {at} is beyond the campaign's {} runs",
            c.runs()
        ));
    }
    if i % m.shards.max(1) != m.shard {
        return Some(format!(
            "run {i} is in {at}, shard {}/{}, but belongs to shard {}/{}",
            m.shard,
            m.shards,
            i % m.shards.max(1),
            m.shards
        ));
    }
    if r.base != c.base_of(i) {
        return Some(format!(
            "run {i} in {at}: base {}, but the campaign flies base {} in it",
            r.base,
            c.base_of(i)
        ));
    }
    let d = c.draw(i);
    if let Some((column, got, want)) = r.draw.first_difference(&d) {
        return Some(format!(
            "run {i} in {at}: {column} = {got}, but the campaign draws {want} for it"
        ));
    }
    outcome_problem(c, r, &d).map(|why| format!("run {i} in {at}: {why}"))
}

/// Why the outcome of `r` (drawn `d`) contradicts its metrics or its bound, if it does.
fn outcome_problem(c: &Campaign, r: &Record, d: &super::Draw) -> Option<String> {
    let i = r.index;
    let metrics = || {
        METRIC_NAMES
            .iter()
            .zip(r.metrics)
            .map(|(n, x)| format!("{n} = {x}"))
    };
    match r.outcome {
        Outcome::Completed => {
            if let Some(bad) = metrics().zip(r.metrics).find(|(_, x)| !x.is_finite()) {
                return Some(format!(
                    "`completed` with {}: a run flown to its end has every metric finite",
                    bad.0
                ));
            }
            let miss = c.bound_of(i).and_then(|b| bound::miss(&b, &metrics_of(r)));
            miss.map(|why| format!("`completed`, but its metrics miss its bound: {why}"))
        }
        Outcome::Missed => match c.bound_of(i) {
            None => Some("`missed`, but its scenario sets no bound".into()),
            Some(b) => bound::miss(&b, &metrics_of(r))
                .is_none()
                .then(|| "`missed`, but its metrics are within its bound".into()),
        },
        Outcome::Invalid => {
            if r.faulted || r.metrics.iter().any(|x| !x.is_nan()) {
                Some("`invalid` (not flown), but it has metrics or a fault".into())
            } else if c.scenario(i, d).is_ok() {
                Some("`invalid`, but its draw makes a scenario that validates (it flies)".into())
            } else {
                None
            }
        }
        Outcome::Diverged => None,
    }
}

/// A record's metrics as the bound reads them (the four it holds a run to, by name).
fn metrics_of(r: &Record) -> crate::sim::Metrics {
    let at = |name: &str| {
        METRIC_NAMES
            .iter()
            .position(|n| *n == name)
            .map_or(f64::NAN, |k| r.metrics[k])
    };
    crate::sim::Metrics {
        max_path: at("max_path"),
        saturated_fraction: at("saturated_fraction"),
        reversals_per_s: at("reversals_per_s"),
        command_tv: at("command_tv"),
        ..crate::sim::Metrics::default()
    }
}

/// Missing, duplicate and incomplete shards, by their manifests; a manifest whose numbers are
/// not the campaign's.
fn shard_problems(c: &Campaign, shards: &[ShardInput], problems: &mut Vec<String>) {
    let mut seen: BTreeMap<(u64, u64), Vec<&str>> = BTreeMap::new();
    for s in shards {
        let m = &s.manifest;
        if let Some(why) = manifest_problem(c, m) {
            problems.push(format!("{}: {why}", s.label));
            continue;
        }
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

/// Why the numbers of manifest `m` are not those campaign `c` gives its shard, if they are not.
fn manifest_problem(c: &Campaign, m: &Manifest) -> Option<String> {
    let shard = c.shard(m.shard, m.shards);
    if m.name != c.spec.name() || m.runs != c.runs() {
        return Some(format!(
            "its manifest says campaign {} of {} runs; the campaign it keeps is {} of {}",
            m.name,
            m.runs,
            c.spec.name(),
            c.runs()
        ));
    }
    if m.shards == 0 || m.shard >= m.shards || m.shards > c.runs() {
        return Some(format!(
            "shard {}/{} is not a shard of {} runs",
            m.shard,
            m.shards,
            c.runs()
        ));
    }
    if m.owned != shard.len() || m.done > m.owned || m.complete != (m.done == m.owned) {
        return Some(format!(
            "its manifest's counts ({} done of {} owned, complete {}) are not those of shard \
             {}/{} ({} runs)",
            m.done,
            m.owned,
            m.complete,
            m.shard,
            m.shards,
            shard.len()
        ));
    }
    None
}
