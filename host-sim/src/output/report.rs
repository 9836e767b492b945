//! The Table-1 style report: the table (Markdown and terminal text) of each case's runs with
//! and without Δu beside the paper's numbers, and `report.md` with the plots and notes.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use controller_core::Table1Case;

use super::atomic;
use crate::sim::bound;
use crate::sim::chatter::{ThrusterChatter, DEAD_BAND, NOMINAL_THRUSTER_LAG};
use crate::sim::{Metrics, RunResult};
use crate::studies::preflight::{Preflight, Verdict};
use crate::studies::table1 as paper_table1;
use controller_core::effectiveness::THRUSTER_NAMES;

/// One row of a report table: a case, its run with Δu, optionally its run without Δu, and
/// the paper's Table-1 case it reproduces, if any (its numbers are printed beside ours).
#[derive(Clone, Copy, Debug)]
pub struct ReportRow<'a> {
    pub with: &'a RunResult,
    pub without: Option<&'a RunResult>,
    pub case: Option<Table1Case>,
}

impl<'a> ReportRow<'a> {
    /// The row of a run and its companion without Δu, for the case the run names
    /// ([`RunResult::case`]).
    pub fn new(with: &'a RunResult, without: Option<&'a RunResult>) -> Self {
        ReportRow {
            with,
            without,
            case: with.case,
        }
    }
}

/// A length or angle: 3 decimals as in the paper, scientific when that would hide it.
fn fmt_err(v: f64) -> String {
    if !v.is_finite() {
        format!("{v}")
    } else if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e6) {
        format!("{v:.3}")
    } else {
        format!("{v:.2e}")
    }
}

fn fmt_fixed(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        format!("{v}")
    }
}

const TABLE_HEADER: [&str; 14] = [
    "case",
    "Δu",
    "max x (m)",
    "max y (m)",
    "max z (m)",
    "path (m)",
    "rms path (m)",
    "max roll (rad)",
    "max pitch (rad)",
    "max yaw (rad)",
    "peak |V| (V)",
    "saturated",
    "faults",
    "outcome",
];

/// The runs of a row as the table shows them: the run without Δu, then the run with Δu (each
/// labelled by its own [`RunResult::robust`]); where the paper has numbers and one of the two
/// was not run, `None` in its place.
fn row_runs<'a>(row: &ReportRow<'a>) -> Vec<(Option<&'a RunResult>, bool)> {
    let mut out = Vec::new();
    for robust in [false, true] {
        let runs: Vec<&RunResult> = std::iter::once(row.with)
            .chain(row.without)
            .filter(|r| r.robust == robust)
            .collect();
        if runs.is_empty() && row.case.is_some() {
            out.push((None, robust));
        }
        out.extend(runs.into_iter().map(|r| (Some(r), robust)));
    }
    out
}

/// The table's cells: per case the run without Δu (if run or if the paper has numbers), then
/// the run with Δu. Max errors read "ours (paper)".
fn table_cells(rows: &[ReportRow]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for row in rows {
        for (run, robust) in row_runs(row) {
            let col = usize::from(robust);
            let du = if robust { "with" } else { "without" }.to_string();
            let name = run.map_or(row.with.name.as_str(), |r| r.name.as_str());
            // A run that recorded no period has no metrics: every cell `—` (Choice 129).
            let m = run.map(|r| r.metrics).filter(Metrics::recorded);
            let ours_vs = |ours: Option<f64>, paper: Option<f64>| -> String {
                let ours = ours.map_or("—".to_string(), fmt_err);
                match paper {
                    Some(p) => format!("{ours} ({})", fmt_err(p)),
                    None => ours,
                }
            };
            let p = row.case.map(paper_table1::table1_row);
            let ours = |f: fn(&Metrics) -> f64| m.as_ref().map(f);
            let other = |f: fn(&Metrics) -> f64, fmt: &dyn Fn(f64) -> String| {
                m.as_ref().map_or("—".to_string(), |m| fmt(f(m)))
            };
            out.push(vec![
                name.to_string(),
                du,
                ours_vs(ours(|m| m.max_x), p.map(|p| p.x[col])),
                ours_vs(ours(|m| m.max_y), p.map(|p| p.y[col])),
                ours_vs(ours(|m| m.max_z), p.map(|p| p.z[col])),
                ours_vs(ours(|m| m.max_path), p.map(|p| p.path[col])),
                other(|m| m.rms_path, &fmt_err),
                other(|m| m.max_roll, &fmt_err),
                other(|m| m.max_pitch, &fmt_err),
                other(|m| m.max_yaw, &fmt_err),
                other(|m| m.peak_voltage, &|v| fmt_fixed(v, 1)),
                other(|m| m.saturated_fraction, &|v| {
                    format!("{} %", fmt_fixed(100.0 * v, 1))
                }),
                run.map_or("—".to_string(), |r| {
                    let expected = if r.faults_expected && !r.faults.is_empty() {
                        ", expected"
                    } else {
                        ""
                    };
                    format!("{}{expected}", r.faults)
                }),
                run.map_or("not run".to_string(), |r| {
                    let expected = if r.missed() && r.miss_expected {
                        " (expected)"
                    } else {
                        ""
                    };
                    match &r.path {
                        Some(path) => format!("{}{expected}; {path}", r.outcome),
                        None => format!("{}{expected}", r.outcome),
                    }
                }),
            ]);
        }
    }
    out
}

fn md_escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('|', "\\|")
}

/// Markdown table: per case one row without Δu and one with, each giving x, y, z and path max
/// errors as "ours (paper)" (the paper's value only where [`ReportRow::case`] is given), rms
/// path, max roll/pitch/yaw error, peak voltage, saturated fraction, the control periods in
/// fail-safe per status ("0", or e.g. "12 (fault:pitch-limit 12; first at t = 3.20 s)",
/// ", expected" added when the scenario expects faults), and the outcome (a diverged run says
/// "DIVERGED at t = … s: reason"). Each row is labelled with or without Δu by its own run's
/// `robust`. A run the paper has numbers for that was not run gets a row with "—" and
/// "not run".
pub fn table_markdown(rows: &[ReportRow]) -> String {
    let mut s = String::new();
    let line = |cells: &mut dyn Iterator<Item = String>| {
        let mut l = String::from("|");
        for c in cells {
            l.push(' ');
            l.push_str(&c);
            l.push_str(" |");
        }
        l.push('\n');
        l
    };
    s.push_str(&line(&mut TABLE_HEADER.iter().map(|h| md_escape(h))));
    s.push_str(&line(&mut TABLE_HEADER.iter().enumerate().map(|(i, _)| {
        if i < 2 || i == TABLE_HEADER.len() - 1 {
            "---".to_string()
        } else {
            "---:".to_string()
        }
    })));
    for row in table_cells(rows) {
        s.push_str(&line(&mut row.iter().map(|c| md_escape(c))));
    }
    s
}

/// The same table as [`table_markdown`] for the terminal: plain text, columns aligned (by
/// characters), numbers right-aligned, and a line saying what the parentheses hold when any
/// row has the paper's numbers.
pub fn table_text(rows: &[ReportRow]) -> String {
    let header: Vec<String> = TABLE_HEADER.iter().map(|h| h.to_string()).collect();
    let body = table_cells(rows);
    let n = header.len();
    let width = |i: usize| {
        std::iter::once(&header)
            .chain(&body)
            .map(|r| r[i].chars().count())
            .max()
            .unwrap_or(0)
    };
    let widths: Vec<usize> = (0..n).map(width).collect();
    let fmt_row = |r: &[String]| {
        let mut l = String::new();
        for (i, c) in r.iter().enumerate() {
            if i > 0 {
                l.push_str("  ");
            }
            let pad = widths[i].saturating_sub(c.chars().count());
            let numeric = (2..n - 1).contains(&i);
            if numeric {
                l.extend(std::iter::repeat_n(' ', pad));
                l.push_str(c);
            } else {
                l.push_str(c);
                l.extend(std::iter::repeat_n(' ', pad));
            }
        }
        l.truncate(l.trim_end().len());
        l.push('\n');
        l
    };
    let mut s = fmt_row(&header);
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
    s.push_str(&fmt_row(&rule));
    for r in &body {
        s.push_str(&fmt_row(r));
    }
    if rows.iter().any(|r| r.case.is_some()) {
        s.push_str("max errors as ours (paper's Table 1, docs/simulator.md#table-1)\n");
    }
    s
}

/// A Markdown link target for `plot`: relative to `dir` when it lies inside it (compared as
/// given, then canonicalised), else the path as given.
fn link_target(dir: &Path, plot: &Path) -> String {
    let canonical = || {
        let (d, p) = (dir.canonicalize().ok()?, plot.canonicalize().ok()?);
        p.strip_prefix(d).ok().map(Path::to_path_buf)
    };
    let rel = match plot.strip_prefix(dir) {
        Ok(r) => r.to_path_buf(),
        Err(_) => canonical().unwrap_or_else(|| plot.to_path_buf()),
    };
    let s = rel.to_string_lossy().replace('\\', "/");
    if s.contains([' ', '(', ')', '<', '>']) {
        format!("<{s}>")
    } else {
        s
    }
}

/// Writes `dir/report.md` (creating `dir`, whole or not at all: [`super::atomic`]): the
/// [`report_markdown`] of the rows with nothing incomplete. Returns the report's path.
pub fn write_report(
    dir: &Path,
    title: &str,
    rows: &[ReportRow],
    plots: &[PathBuf],
    notes: &str,
) -> Result<PathBuf> {
    let path = dir.join("report.md");
    let s = report_markdown(dir, title, rows, "", plots, notes, &[]);
    fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    atomic::write(&path, s.as_bytes()).with_context(|| format!("writing {}", path.display()))
}

/// The text of `report.md` in `dir`: `# title`, a line on how to read the table, then the
/// warnings — outputs that are `incomplete` (each line says which file and why), runs that
/// were interrupted (the report is then **partial**), diverged, lost their board, or had the
/// controller in fail-safe (unexpectedly, or as the scenario expected) —, [`table_markdown`], `sections`
/// verbatim (Markdown with its own headings: the preflight verdicts, the real-vehicle table),
/// each plot embedded as `![file](path)` (relative to `dir` when inside it) under its file
/// name, and `notes` verbatim under "## Notes" (omitted if empty).
pub fn report_markdown(
    dir: &Path,
    title: &str,
    rows: &[ReportRow],
    sections: &str,
    plots: &[PathBuf],
    notes: &str,
    incomplete: &[String],
) -> String {
    let mut s = String::new();
    let runs: Vec<&RunResult> = rows
        .iter()
        .flat_map(|r| std::iter::once(r.with).chain(r.without))
        .collect();
    let partial = runs.iter().any(|r| r.interrupted()) || !incomplete.is_empty();
    let _ = writeln!(
        s,
        "# {title}{}
",
        if partial { " (PARTIAL)" } else { "" }
    );
    s.push_str(
        "Maximum errors over each run in metres as **ours (paper)**, the paper's numbers from \
         its Table 1 (docs/simulator.md#table-1) where the case is one of its six; path = \
         √(max|e_x|² + max|e_y|² + max|e_z|²), rms path = √mean(e_x² + e_y² + e_z²). Angles in \
         rad. Peak |V| is the largest thruster voltage commanded; saturated is the fraction of \
         control periods with at least one thruster at the supply limit; faults counts the \
         control periods in which the controller was in fail-safe (every thruster off), per \
         status.\n\n",
    );
    s.push_str(&warnings(&runs, incomplete));
    s.push_str(&table_markdown(rows));
    if !sections.is_empty() {
        s.push('\n');
        s.push_str(sections);
        if !sections.ends_with('\n') {
            s.push('\n');
        }
    }
    s.push_str(&plots_section(dir, plots));
    if !notes.is_empty() {
        let _ = write!(s, "\n## Notes\n\n{notes}");
        if !notes.ends_with('\n') {
            s.push('\n');
        }
    }
    s
}

/// A warning about some runs: its heading (from how many) and, per run it applies to, what to
/// say of it.
struct RunWarning {
    heading: fn(usize) -> String,
    detail: fn(&RunResult) -> Option<String>,
}

/// The report's warnings about runs, in the order they are given.
const RUN_WARNINGS: [RunWarning; 7] = [
    RunWarning {
        heading: |n| {
            format!(
                "**Partial: {n} run(s) were interrupted** — their metrics and files cover only \
                 the time before they stopped:"
            )
        },
        detail: |r| r.interrupted().then(|| r.outcome.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "**Warning: {n} run(s) diverged** — their metrics cover only the time before \
                 they stopped:"
            )
        },
        detail: |r| r.diverged().then(|| r.outcome.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "**Warning: {n} run(s) lost their board** (PIL, HIL: the board went silent, \
                 its link went away, or it flew another configuration) — their metrics cover \
                 only the time before they stopped:"
            )
        },
        detail: |r| r.lost_board().then(|| r.outcome.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "**Warning: {n} run(s) had the controller in fail-safe** (every thruster off) \
                 for some periods, which the scenario does not expect (`expect_faults`):"
            )
        },
        detail: |r| r.faulted_unexpectedly().then(|| r.faults.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "**Warning: {n} run(s) missed their bound** (`[bound]`; the real chain's \
                 default 0.05 m and 1 % saturated periods):"
            )
        },
        detail: |r| r.missed_unexpectedly().then(|| r.outcome.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "{n} run(s) missed their bound, as their scenario expects \
                 (`expect_missed = true`):"
            )
        },
        detail: |r| (r.missed() && r.miss_expected).then(|| r.outcome.to_string()),
    },
    RunWarning {
        heading: |n| {
            format!(
                "{n} run(s) had the controller in fail-safe for some periods, as their \
                 scenario expects (`expect_faults = true`):"
            )
        },
        detail: |r| (r.faults_expected && !r.faults.is_empty()).then(|| r.faults.to_string()),
    },
];

/// The report's warnings, each a heading and a list, for what the reader must not miss: outputs
/// not written, runs interrupted, diverged, that lost their board, missed or in fail-safe
/// (expected or not).
fn warnings(runs: &[&RunResult], incomplete: &[String]) -> String {
    let mut s = String::new();
    let mut warn = |head: String, items: Vec<String>| {
        if items.is_empty() {
            return;
        }
        let _ = writeln!(s, "{head}\n");
        for d in &items {
            let _ = writeln!(s, "- {}", md_escape(d));
        }
        s.push('\n');
    };
    warn(
        format!(
            "**Warning: {} output(s) are incomplete** and were not written:",
            incomplete.len()
        ),
        incomplete.to_vec(),
    );
    for w in &RUN_WARNINGS {
        let items: Vec<String> = runs
            .iter()
            .filter_map(|r| Some(format!("{} ({}): {}", r.name, r.du_label(), (w.detail)(r)?)))
            .collect();
        warn((w.heading)(items.len()), items);
    }
    s
}

/// The report's plots, each under its file name.
fn plots_section(dir: &Path, plots: &[PathBuf]) -> String {
    let mut s = String::new();
    if !plots.is_empty() {
        s.push_str("\n## Plots\n");
        for p in plots {
            let name = p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let _ = write!(s, "\n### {name}\n\n![{name}]({})\n", link_target(dir, p));
        }
    }
    s
}

/// The chatter table's header: per run, each figure for the five thrusters in
/// [`THRUSTER_NAMES`] order.
fn chatter_header() -> [String; 5] {
    let order = THRUSTER_NAMES.join(" / ");
    [
        "case".to_string(),
        "Δu".to_string(),
        format!("sign reversals/s through ±{DEAD_BAND} V ({order})"),
        format!("command total variation V/s ({order})"),
        format!("power above the thruster's corner ({order})"),
    ]
}

fn chatter_cells(runs: &[&RunResult]) -> Vec<[String; 5]> {
    runs.iter()
        .map(|r| {
            let m = Some(r.metrics).filter(Metrics::recorded);
            let per = |f: fn(&ThrusterChatter) -> String| {
                m.as_ref().map_or("—".to_string(), |m| {
                    m.chatter.0.iter().map(f).collect::<Vec<_>>().join(" / ")
                })
            };
            [
                r.name.clone(),
                if r.robust { "with" } else { "without" }.to_string(),
                per(|c| fmt_fixed(c.reversals_per_s, 1)),
                per(|c| fmt_fixed(c.command_tv, 0)),
                per(|c| format!("{} %", fmt_fixed(100.0 * c.hf_share, 0))),
            ]
        })
        .collect()
}

/// The chatter of `runs`' thruster commands (docs/real-vehicle.md#chatter) as Markdown: per
/// run, for each thruster, its sign reversals per second through the dead band, its command's
/// total variation per second and its share of command power above the thruster's corner.
pub fn chatter_table_markdown(runs: &[&RunResult]) -> String {
    let header = chatter_header();
    let mut s = format!(
        "| {} |\n|---|---|---:|---:|---:|\n",
        header.map(|h| md_escape(&h)).join(" | ")
    );
    for r in chatter_cells(runs) {
        s.push_str(&format!("| {} |\n", r.map(|c| md_escape(&c)).join(" | ")));
    }
    s
}

/// Each column's width in characters: its widest cell, header included.
fn column_widths<R: AsRef<[String]>>(header: &[String], body: &[R]) -> Vec<usize> {
    (0..header.len())
        .map(|i| {
            std::iter::once(header)
                .chain(body.iter().map(AsRef::as_ref))
                .map(|r| r[i].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect()
}

/// The same table as [`chatter_table_markdown`] for the terminal, columns aligned.
pub fn chatter_table_text(runs: &[&RunResult]) -> String {
    let header = chatter_header();
    let body = chatter_cells(runs);
    let widths = column_widths(&header, &body);
    let line = |r: &[String]| {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(c, w)| format!("{c}{}", " ".repeat(w - c.chars().count())))
            .collect();
        format!("{}\n", cells.join("  ").trim_end())
    };
    let mut s = line(&header);
    s.push_str(&line(
        &widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>(),
    ));
    for r in &body {
        s.push_str(&line(r));
    }
    s
}

/// The report section of the chatter table, with what its columns mean.
pub fn chatter_section(runs: &[&RunResult]) -> String {
    format!(
        "## Thruster commands (docs/real-vehicle.md#chatter)\n\nWhat the commands do between the \
         limits: a reversal counts when a command crosses from above +{DEAD_BAND} V to below \
         −{DEAD_BAND} V or back; the power share is above f_c = 1/(2π T) of the thruster's lag T \
         (the nominal {NOMINAL_THRUSTER_LAG} s when the scenario sets none). A run's bound allows \
         at most {} reversals/s and {} V/s per thruster (the real vehicle's; a scenario's \
         `[bound]` may set others).\n\n{}\n",
        bound::MAX_REVERSALS_PER_S,
        bound::MAX_COMMAND_TV,
        chatter_table_markdown(runs)
    )
}

/// One row of the real-vehicle table (docs/real-vehicle.md#the-real-missions): a run through the real actuator
/// chain and the preflight check of its scenario.
#[derive(Clone, Copy, Debug)]
pub struct RealRow<'a> {
    pub run: &'a RunResult,
    pub preflight: &'a Preflight,
}

const REAL_HEADER: [&str; 12] = [
    "mission",
    "heading",
    "time scale",
    "max path (m)",
    "rms path (m)",
    "peak |V| (V)",
    "saturated",
    "reversals/s",
    "TV (V/s)",
    "within bound",
    "preflight",
    "outcome",
];

/// The preflight verdict in a table cell: `feasible`, `needs k ≥ 2.35`, `statically
/// infeasible`, `infeasible`.
pub fn verdict_cell(p: &Preflight) -> String {
    match (p.verdict, p.smallest_time_scale) {
        (Verdict::Feasible, _) => "feasible".to_string(),
        (Verdict::NeedsTimeScale, Some(k)) => format!("needs k ≥ {k}"),
        (Verdict::StaticallyInfeasible, _) => "statically infeasible".to_string(),
        _ => "infeasible".to_string(),
    }
}

fn real_cells(rows: &[RealRow]) -> Vec<Vec<String>> {
    rows.iter()
        .map(|r| {
            let m = Some(r.run.metrics).filter(Metrics::recorded);
            let cell = |f: &dyn Fn(&Metrics) -> String| m.as_ref().map_or("—".to_string(), f);
            vec![
                r.run.name.clone(),
                r.preflight.heading.clone(),
                format!("{}", r.preflight.time_scale),
                cell(&|m| fmt_err(m.max_path)),
                cell(&|m| fmt_err(m.rms_path)),
                cell(&|m| fmt_fixed(m.peak_voltage, 1)),
                cell(&|m| format!("{} %", fmt_fixed(100.0 * m.saturated_fraction, 1))),
                cell(&|m| fmt_fixed(m.reversals_per_s, 1)),
                cell(&|m| fmt_fixed(m.command_tv, 0)),
                if bound::within_bound(r.run) {
                    "yes"
                } else {
                    "NO"
                }
                .to_string(),
                verdict_cell(r.preflight),
                r.run.outcome.to_string(),
            ]
        })
        .collect()
}

/// What the real-vehicle table's "within bound" column means.
pub fn real_table_legend() -> String {
    format!(
        "within bound: completed with max path error ≤ {} m, a thruster saturated in ≤ {} % \
         of the control periods (docs/real-vehicle.md#the-bound-and-the-start-in-trim), and no \
         thruster's command reversing more than {} times/s through ±{DEAD_BAND} V or varying by \
         more than {} V/s (reversals/s, TV: the worst thruster's; docs/real-vehicle.md#chatter)",
        bound::MAX_PATH_ERROR,
        100.0 * bound::MAX_SATURATED_FRACTION,
        bound::MAX_REVERSALS_PER_S,
        bound::MAX_COMMAND_TV
    )
}

/// The real-vehicle table as Markdown: per run its mission, heading, time scale, max and rms
/// path error, peak |V|, saturated fraction, the worst thruster's reversals/s and command TV,
/// whether it is within the bound, the preflight verdict and the outcome.
pub fn real_table_markdown(rows: &[RealRow]) -> String {
    let mut s = format!("| {} |\n|", REAL_HEADER.map(md_escape).join(" | "));
    for i in 0..REAL_HEADER.len() {
        s.push_str(if (2..10).contains(&i) {
            " ---: |"
        } else {
            " --- |"
        });
    }
    s.push('\n');
    for r in real_cells(rows) {
        let cells: Vec<String> = r.iter().map(|c| md_escape(c)).collect();
        s.push_str(&format!("| {} |\n", cells.join(" | ")));
    }
    s
}

/// The same table as [`real_table_markdown`] for the terminal, columns aligned.
pub fn real_table_text(rows: &[RealRow]) -> String {
    let header: Vec<String> = REAL_HEADER.iter().map(|h| h.to_string()).collect();
    let body = real_cells(rows);
    let widths = column_widths(&header, &body);
    let line = |r: &[String]| {
        let mut l = String::new();
        for (i, c) in r.iter().enumerate() {
            if i > 0 {
                l.push_str("  ");
            }
            let pad = " ".repeat(widths[i].saturating_sub(c.chars().count()));
            if (2..10).contains(&i) {
                l.push_str(&pad);
                l.push_str(c);
            } else {
                l.push_str(c);
                l.push_str(&pad);
            }
        }
        format!("{}\n", l.trim_end())
    };
    let mut s = line(&header);
    s.push_str(&line(
        &widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>(),
    ));
    for r in &body {
        s.push_str(&line(r));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::record::{FaultCounts, Metrics, Outcome};
    use crate::sim::BoardLoss;

    fn run(outcome: Outcome) -> RunResult {
        RunResult {
            name: "r".to_string(),
            case: None,
            robust: true,
            outcome,
            metrics: Metrics::NONE,
            faults: FaultCounts::default(),
            faults_expected: false,
            miss_expected: false,
            path: None,
            samples: Vec::new(),
            plant_factorisations: 0,
        }
    }

    /// A run that lost its board is warned of as such, and one that diverged as such: each
    /// under its own heading, never the other's.
    #[test]
    fn a_lost_board_and_a_divergence_are_warned_of_apart() {
        let lost = run(Outcome::LostBoard {
            t: 1.0,
            cause: BoardLoss::Silent,
            reason: "no telemetry".to_string(),
        });
        let diverged = run(Outcome::Diverged {
            t: 2.0,
            reason: "plant state is not finite".to_string(),
        });
        let w = warnings(&[&lost], &[]);
        assert!(w.contains("1 run(s) lost their board"), "{w}");
        assert!(w.contains(&lost.outcome.to_string()), "{w}");
        assert!(!w.contains("diverged**"), "{w}");
        let w = warnings(&[&diverged], &[]);
        assert!(w.contains("1 run(s) diverged**"), "{w}");
        assert!(!w.contains("lost their board"), "{w}");
    }
}
