//! A campaign on disk: a shard's folder (its manifest `shard.json`, its records
//! `records.csv`, appended run by run and resumed after a kill) and the merged report (the
//! Markdown, every record, histograms and scatter plots, a scenario file per worst case).

use std::fs::{self, File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{bail, Context, Result};

use super::plot::{self, Line, Panel, Stroke, C_WITH};
use super::{atomic, OutputDir};
use crate::studies::campaign::merge::{self, Manifest, MetricStats, ShardInput};
use crate::studies::campaign::record::{
    self, Record, DRAWN_COLUMNS, MOUNTING_COLUMN, TIME_SCALE_COLUMN,
};
use crate::studies::campaign::{Campaign, Outcome, METRIC_NAMES};

/// A shard's manifest file.
pub const SHARD_MANIFEST: &str = "shard.json";
/// A shard's (and the merge's) records.
pub const RECORDS: &str = "records.csv";

/// Writes `m` to `dir`'s [`SHARD_MANIFEST`], whole or not at all.
pub fn write_manifest(dir: &OutputDir, m: &Manifest) -> Result<()> {
    let path = dir.claim(SHARD_MANIFEST)?;
    let text = serde_json::to_string_pretty(m).context("serialising the shard manifest")?;
    atomic::write(&path, text.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Reads a manifest (`dir`/[`SHARD_MANIFEST`]); `None` if there is none. A manifest whose
/// fields do not give its hash, or without one (an earlier host-sim's), is an error naming it
/// (**Choice 241**).
pub fn read_manifest(dir: &Path) -> Result<Option<Manifest>> {
    let path = dir.join(SHARD_MANIFEST);
    let m: Manifest = match fs::read_to_string(&path) {
        Ok(text) => serde_json::from_str(&text)
            .with_context(|| format!("{} is not a shard manifest", path.display()))?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    m.verify()
        .map_err(|e| anyhow::anyhow!("{} {e}", path.display()))?;
    Ok(Some(m))
}

/// Reads the records of `path` ([`for_each_record`]), all of them.
pub fn read_records(path: &Path, repair: bool) -> Result<Vec<Record>> {
    let mut records = Vec::new();
    for_each_record(path, repair, |r| {
        records.push(r);
        Ok(())
    })?;
    Ok(records)
}

/// Hands each record of `path` to `f`, line by line (**Choice 136**, **Choice 242**): a shard
/// of 10⁹ runs resumes without holding its records. A last line without its newline is what a
/// killed writer left half-written: with `repair` the file is cut back to the line before it
/// (the run is done again), else it is left out. A complete line that is not a record, last or
/// not, is an error naming it (the file was edited, or is not a records file): a writer writes
/// the newline last, so only a line without it can be torn.
pub fn for_each_record(
    path: &Path,
    repair: bool,
    mut f: impl FnMut(Record) -> Result<()>,
) -> Result<()> {
    use std::io::BufRead;
    let shown = path.display();
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {shown}")),
    };
    let mut reader = std::io::BufReader::new(file);
    let header = record::header();
    let (mut good, mut line_no, mut line) = (0u64, 0usize, String::new());
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .with_context(|| format!("cannot read {shown}"))?;
        if n == 0 {
            break;
        }
        line_no += 1;
        let Some(text) = line.strip_suffix('\n') else {
            // Without its newline: the last line (read_line stops only at one or at the end),
            // torn (see the doc).
            if repair {
                cut(path, good)?;
            }
            break;
        };
        match line_no {
            1 if text == header => {}
            1 => bail!(
                "{shown} line 1 is not the records' header (the file was edited, or is not \
                 host-sim's); move it away to rerun the shard"
            ),
            _ => match Record::parse(text) {
                Some(r) => f(r)?,
                None => bail!(
                    "{shown} line {line_no} is not a campaign record (the file was edited, or is \
                     not host-sim's); move it away to rerun the shard"
                ),
            },
        }
        good += n as u64;
    }
    Ok(())
}

/// Cuts the records file `path` back to its first `len` bytes (a torn last line removed).
fn cut(path: &Path, len: u64) -> Result<()> {
    eprintln!(
        "host-sim: {}: the last line was cut short (a killed run): removed, its run is done \
         again",
        path.display()
    );
    OpenOptions::new()
        .write(true)
        .open(path)
        .and_then(|f| f.set_len(len))
        .with_context(|| format!("cannot repair {}", path.display()))
}

/// The records file of a shard, open for appending: one whole line per `write`, flushed, so a
/// kill leaves at most the last line torn.
pub struct RecordLog {
    file: Mutex<File>,
    path: PathBuf,
    errors: Mutex<Vec<String>>,
}

impl RecordLog {
    /// Opens (creates, with the header) `dir`'s [`RECORDS`] for appending.
    pub fn open(dir: &OutputDir) -> Result<Self> {
        let path = dir.claim(RECORDS)?;
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        if file.seek(SeekFrom::End(0))? == 0 {
            file.write_all(format!("{}\n", record::header()).as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok(RecordLog {
            file: Mutex::new(file),
            path,
            errors: Mutex::new(Vec::new()),
        })
    }

    /// Appends one record (an error is kept for [`RecordLog::finish`]).
    pub fn push(&self, r: &Record) {
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        if let Err(e) = f.write_all(r.line().as_bytes()) {
            let mut errs = self.errors.lock().unwrap_or_else(|e| e.into_inner());
            errs.push(format!("{}: {e}", self.path.display()));
        }
    }

    /// Syncs the file; the first write error, if any.
    pub fn finish(self) -> Result<()> {
        let f = self.file.into_inner().unwrap_or_else(|e| e.into_inner());
        let errs = self.errors.into_inner().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = errs.first() {
            bail!("writing records: {e}");
        }
        f.sync_all()
            .with_context(|| format!("syncing {}", self.path.display()))
    }
}

/// Reads a shard folder for the merge.
pub fn read_shard(dir: &Path) -> Result<ShardInput> {
    let manifest = read_manifest(dir)?.with_context(|| {
        format!(
            "{} has no {SHARD_MANIFEST}: not a campaign shard folder",
            dir.display()
        )
    })?;
    let records = read_records(&dir.join(RECORDS), false)?;
    Ok(ShardInput {
        label: dir.display().to_string(),
        manifest,
        records,
    })
}

/// The name of the scenario file of metric `name`'s worst case.
pub fn worst_file(name: &str) -> String {
    format!("worst-{name}.toml")
}

/// What the merge wrote.
pub struct Merged {
    pub report: PathBuf,
    pub stats: Vec<MetricStats>,
    /// Runs within their bound, of all.
    pub within: usize,
    pub runs: usize,
    pub diverged: usize,
    /// Runs not flown: their draw made a scenario that does not validate.
    pub invalid: usize,
    /// The campaign's required fraction within bound, when it sets one.
    pub required: Option<f64>,
    /// Outputs that could not be written (plots).
    pub incomplete: Vec<String>,
}

/// Writes the merged report of `records` (every index once, sorted) into `dir`.
pub fn write_report(dir: &OutputDir, c: &Campaign, records: &[Record]) -> Result<Merged> {
    let metrics = selected_metrics(c);
    let stats: Vec<MetricStats> = metrics.iter().map(|m| merge::stats(records, *m)).collect();
    write_records(&dir.claim(RECORDS)?, records)?;
    for s in &stats {
        let Some(i) = s.worst else { continue };
        let body = c
            .scenario_text(i, &c.draw(i))
            .map_err(|e| anyhow::anyhow!("worst case {i}: {e}"))?;
        let p = dir.claim(&worst_file(s.name))?;
        atomic::write(&p, body.as_bytes()).with_context(|| format!("writing {}", p.display()))?;
    }
    let mut incomplete = Vec::new();
    let mut plots = Vec::new();
    for (name, draw) in [
        ("histograms.png", histograms as PlotFn),
        ("scatter.png", scatter),
    ] {
        let p = dir.claim(name)?;
        let mut drawn = false;
        let written = super::figures::write_plot(&p, |tmp| {
            drawn = draw(tmp, c, records, &metrics)?;
            Ok(())
        });
        match written {
            Ok(_) if drawn => plots.push(name),
            Ok(_) => {
                let _ = fs::remove_file(&p);
            }
            Err(e) => incomplete.push(format!("{name}: {e:#}")),
        }
    }
    let within = records.iter().filter(|r| r.within()).count();
    let merged = Merged {
        report: dir.claim("report.md")?,
        stats,
        within,
        runs: records.len(),
        diverged: count(records, Outcome::Diverged),
        invalid: count(records, Outcome::Invalid),
        required: c.spec.required_fraction(),
        incomplete,
    };
    let md = markdown(c, records, &merged, &plots);
    atomic::write(&merged.report, md.as_bytes())
        .with_context(|| format!("writing {}", merged.report.display()))?;
    let json = serde_json::to_string_pretty(&summary(c, records, &merged))
        .context("serialising the summary")?;
    let path = dir.claim(SUMMARY)?;
    atomic::write(&path, json.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
    Ok(merged)
}

/// The merged report's summary for programs (`summary.json`, and `campaign merge --json`).
pub const SUMMARY: &str = "summary.json";

/// What `summary.json` holds: the campaign, the outcomes, the statistics, the worst cases'
/// files. NaN statistics (no run has the metric) are `null`.
#[derive(serde::Serialize)]
pub struct Summary<'a> {
    pub campaign: &'a str,
    pub hash: &'a str,
    pub runs: usize,
    /// Runs of each outcome, by name.
    pub outcomes: std::collections::BTreeMap<&'static str, usize>,
    pub faulted: usize,
    pub within_bound: usize,
    pub fraction_within_bound: f64,
    /// The campaign's `bound.fraction`, and whether it is met.
    pub required_fraction: Option<f64>,
    pub required_met: Option<bool>,
    pub metrics: &'a [MetricStats],
    /// Each metric's worst case: its scenario file beside the report.
    pub worst_files: std::collections::BTreeMap<&'static str, String>,
}

fn summary<'a>(c: &'a Campaign, records: &[Record], m: &'a Merged) -> Summary<'a> {
    let fraction = m.within as f64 / records.len().max(1) as f64;
    Summary {
        campaign: c.spec.name(),
        hash: &c.hash,
        runs: records.len(),
        outcomes: Outcome::ALL
            .iter()
            .map(|o| (o.as_str(), count(records, *o)))
            .collect(),
        faulted: records.iter().filter(|r| r.faulted).count(),
        within_bound: m.within,
        fraction_within_bound: fraction,
        required_fraction: m.required,
        required_met: m
            .required
            .map(|f| m.within as f64 >= f * records.len() as f64),
        metrics: &m.stats,
        worst_files: m
            .stats
            .iter()
            .filter(|s| s.worst.is_some())
            .map(|s| (s.name, worst_file(s.name)))
            .collect(),
    }
}

/// Writes every record (header first) to `path`, whole or not at all, streamed: a merge of
/// 10⁶ runs does not hold the 490 MB of text in memory.
fn write_records(path: &Path, records: &[Record]) -> Result<()> {
    let ctx = || format!("writing {}", path.display());
    let (pending, file) = atomic::Pending::create(path).with_context(ctx)?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(w, "{}", record::header()).with_context(ctx)?;
    for r in records {
        w.write_all(r.line().as_bytes()).with_context(ctx)?;
    }
    w.into_inner()
        .map_err(|e| e.into_error())
        .and_then(|mut f| f.flush())
        .with_context(ctx)?;
    pending.commit().with_context(ctx)?;
    Ok(())
}

/// Most runs drawn in a scatter plot: every k-th run by index beyond it (a plot of 10⁶ dots in
/// 20 panels takes minutes and shows no more than 20 000).
pub const SCATTER_RUNS: usize = 20_000;

type PlotFn = fn(&Path, &Campaign, &[Record], &[usize]) -> Result<bool>;

/// The indices (in [`METRIC_NAMES`]) of the campaign's metrics.
fn selected_metrics(c: &Campaign) -> Vec<usize> {
    match &c.spec.metrics {
        Some(names) => names
            .iter()
            .filter_map(|n| METRIC_NAMES.iter().position(|m| m == n))
            .collect(),
        None => (0..METRIC_NAMES.len()).collect(),
    }
}

fn count(records: &[Record], o: Outcome) -> usize {
    records.iter().filter(|r| r.outcome == o).count()
}

/// The report's Markdown: what was drawn, the outcomes, the statistics, the worst cases with
/// the commands that replay them, the plots.
fn markdown(c: &Campaign, records: &[Record], m: &Merged, plots: &[&str]) -> String {
    let spec = &c.spec;
    let n = records.len().max(1) as f64;
    let mut s = format!(
        "# Campaign {}\n\n{} runs, seed {}, campaign hash `{}` ({}).\n\nBases: {}.\n\n",
        spec.name(),
        spec.runs,
        spec.seed,
        c.hash,
        crate::studies::campaign::PROGRAM_VERSION,
        c.bases
            .iter()
            .map(|b| format!("`{}`", b.path))
            .collect::<Vec<_>>()
            .join(", ")
    );
    s += &format!(
        "Drawn per run: {}.\n\n",
        toml::to_string(&spec.draw)
            .unwrap_or_default()
            .trim()
            .replace('\n', "; ")
    );
    s += "| outcome | runs | fraction |\n|---|---|---|\n";
    for o in Outcome::ALL {
        let k = count(records, o);
        s += &format!("| {} | {k} | {:.4} |\n", o.as_str(), k as f64 / n);
    }
    let faulted = records.iter().filter(|r| r.faulted).count();
    s += &format!(
        "\nWithin bound: **{} of {} ({:.4} %)**; controller in fail-safe in some period: {faulted}.\n",
        m.within,
        records.len(),
        100.0 * m.within as f64 / n
    );
    if let Some(f) = m.required {
        let ok = m.within as f64 >= f * records.len() as f64;
        s += &format!(
            "Required: {:.4} % within bound: **{}**.\n",
            100.0 * f,
            if ok { "met" } else { "NOT MET (exit 4)" }
        );
    }
    s += "\n| metric | p50 | p90 | p99 | max | worst run |\n|---|---|---|---|---|---|\n";
    let cell = |v: f64| {
        if v.is_nan() {
            "—".to_string()
        } else {
            format!("{v:.6}")
        }
    };
    for st in &m.stats {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            st.name,
            cell(st.p50),
            cell(st.p90),
            cell(st.p99),
            cell(st.max),
            st.worst.map_or("—".into(), |i| i.to_string())
        );
    }
    s += &worst_cases(c, m);
    for p in plots {
        s += &format!("\n![{p}]({p})\n");
    }
    s
}

/// The worst case of each metric: its value and the commands that replay it.
fn worst_cases(c: &Campaign, m: &Merged) -> String {
    let mut s = String::from(
        "\n## Worst cases\n\nEach is a scenario file beside this report. From this folder, \
         `host-sim run` flies it bit for bit as the campaign did (the same metrics to the last \
         bit), and `host-sim pil` flies the same case with the law on the board (QEMU; \
         `host-sim hil --port …` for a real one).\n",
    );
    for st in &m.stats {
        let Some(i) = st.worst else { continue };
        let f = worst_file(st.name);
        let run = c.run_name(i);
        s += &format!(
            "\n- **{}** = {} in run {i} (base `{}`):\n  \
             `host-sim run --scenario {f} --out runs/{run}`\n  \
             `host-sim pil --scenario {f} --out runs/{run}-pil`\n",
            st.name,
            st.max,
            c.bases[c.base_of(i)].path
        );
    }
    s
}

/// A histogram of each metric (30 bins between its least and largest value).
fn histograms(path: &Path, c: &Campaign, records: &[Record], metrics: &[usize]) -> Result<bool> {
    let panels: Vec<Panel> = metrics
        .iter()
        .map(|&m| {
            let v: Vec<f64> = records
                .iter()
                .map(|r| r.metrics[m])
                .filter(|x| x.is_finite())
                .collect();
            let mut p = Panel::new(METRIC_NAMES[m], METRIC_NAMES[m], "runs");
            p.lines.push(Line {
                label: None,
                color: C_WITH,
                stroke: Stroke::Solid,
                pts: histogram_outline(&v, 30),
            });
            p
        })
        .collect();
    let title = format!("Campaign {}: {} runs", c.spec.name(), records.len());
    plot::panel_grid(path, &title, grid(panels.len()), &panels)?;
    Ok(true)
}

/// The outline of a histogram of `v` in `bins` equal bins: (edge, count) steps.
fn histogram_outline(v: &[f64], bins: usize) -> Vec<(f64, f64)> {
    let Some((lo, hi)) = plot::min_max(v.iter().copied()) else {
        return Vec::new();
    };
    let width = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        1.0
    };
    let mut counts = vec![0usize; bins];
    for x in v {
        let k = (((x - lo) / width) as usize).min(bins - 1);
        counts[k] += 1;
    }
    let mut pts = vec![(lo, 0.0)];
    for (k, n) in counts.iter().enumerate() {
        let (a, b) = (lo + k as f64 * width, lo + (k + 1) as f64 * width);
        pts.extend([(a, *n as f64), (b, *n as f64)]);
    }
    pts.push((lo + bins as f64 * width, 0.0));
    pts
}

/// The first metric (the campaign's "error") against each drawn value that varies.
fn scatter(path: &Path, c: &Campaign, records: &[Record], metrics: &[usize]) -> Result<bool> {
    let Some(&m) = metrics.first() else {
        return Ok(false);
    };
    let names: Vec<&str> = DRAWN_COLUMNS
        .iter()
        .copied()
        .chain([TIME_SCALE_COLUMN, MOUNTING_COLUMN])
        .collect();
    let step = records.len().div_ceil(SCATTER_RUNS).max(1);
    let shown: Vec<&Record> = records.iter().step_by(step).collect();
    let panels: Vec<Panel> = (0..names.len())
        .filter(|&k| {
            records
                .first()
                .is_some_and(|r0| records.iter().any(|r| r.drawn()[k] != r0.drawn()[k]))
        })
        .map(|k| {
            let mut p = Panel::new("", names[k], METRIC_NAMES[m]);
            p.lines.push(Line {
                label: None,
                color: C_WITH,
                stroke: Stroke::Dots,
                pts: shown.iter().map(|r| (r.drawn()[k], r.metrics[m])).collect(),
            });
            p
        })
        .collect();
    if panels.is_empty() {
        return Ok(false);
    }
    let every = match step {
        1 => String::new(),
        k => format!(", every {k}th"),
    };
    let title = format!(
        "Campaign {}: {} against each drawn value ({} runs{every})",
        c.spec.name(),
        METRIC_NAMES[m],
        shown.len()
    );
    plot::panel_grid(path, &title, grid(panels.len()), &panels)?;
    Ok(true)
}

/// Rows and columns for `n` panels: as square as it gets.
fn grid(n: usize) -> (usize, usize) {
    let cols = (n as f64).sqrt().ceil().max(1.0) as usize;
    (n.div_ceil(cols).max(1), cols)
}
