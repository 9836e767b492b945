//! What a run leaves on disk: the per-period CSV ([`csv`], streamed as the run goes), PNG plots
//! in the manner of the paper's Figs 2–5 ([`figures`], drawn with the plotting layer [`plot`]),
//! and the Table-1 report, Markdown file and terminal text ([`report`]), a campaign's shards and
//! merged report ([`campaign`]); all of it in an
//! output folder checked before the computation and holding only its last run's files
//! ([`dir`]), each file written whole or not at all ([`atomic`]).
//!
//! Nothing here panics on data: NaN and ±∞ values (and magnitudes beyond 1e100) are skipped in
//! plots (a line is broken at them), written as `NaN`/`inf` in the CSV and in tables, and an
//! empty run gives plots that say "no data". A diverged run is always named as such, with its
//! time and reason, in plot subtitles and in the tables.

use std::path::PathBuf;

use anyhow::{Context, Result};

pub mod atomic;
pub mod campaign;
pub mod csv;
pub mod dir;
pub mod falsify;
pub mod figures;
pub mod log;
mod plot;
pub mod report;
pub mod sections;
pub mod speed_plot;
pub mod tune;
pub mod waypoint_plot;

pub use self::csv::{partial_name, write_csv, CsvStream, CSV_COLUMNS};
pub use self::dir::OutputDir;
pub use self::figures::{plot_case, plot_case_with_limit, plot_names};
pub use self::report::{
    chatter_section, chatter_table_markdown, chatter_table_text, real_table_markdown,
    real_table_text, report_markdown, table_markdown, table_text, write_report, RealRow, ReportRow,
};

/// The CSV file name of a run called `name`, with (`robust`) or without Δu:
/// `{name}-with.csv` / `{name}-without.csv`.
pub fn csv_name(name: &str, robust: bool) -> String {
    format!("{name}-{}.csv", crate::sim::record::du_suffix(robust))
}

/// Writes the plots of the report rows' runs and of `extra_plots` (five per run, voltages
/// against ±`voltage_limit`) and then `report.md` with the table, `sections`, the plots, the
/// `incomplete` outputs and `notes` into `dir` (the CSVs were streamed while the runs went). A
/// plot that cannot be written is added to `incomplete` and the rest go on; the report's own
/// failure is the error. Returns the report's path.
#[allow(clippy::too_many_arguments)]
pub fn write_plots_and_report(
    dir: &OutputDir,
    title: &str,
    rows: &[ReportRow],
    sections: &str,
    extra_plots: &[ReportRow],
    notes: &str,
    voltage_limit: f64,
    incomplete: &mut Vec<String>,
) -> Result<PathBuf> {
    write_plots_and_report_with(
        dir,
        title,
        rows,
        sections,
        extra_plots,
        &[],
        notes,
        voltage_limit,
        incomplete,
    )
}

/// [`write_plots_and_report`] with plots already written for some runs (`mission_plots`: the
/// run's name and the file, e.g. a waypoint mission's path and speed plots,
/// [`waypoint_plot::mission_plots`]), each linked in the report after its run's five plots.
#[allow(clippy::too_many_arguments)]
pub fn write_plots_and_report_with(
    dir: &OutputDir,
    title: &str,
    rows: &[ReportRow],
    sections: &str,
    extra_plots: &[ReportRow],
    mission_plots: &[(String, PathBuf)],
    notes: &str,
    voltage_limit: f64,
    incomplete: &mut Vec<String>,
) -> Result<PathBuf> {
    let mut plots = Vec::new();
    for row in rows.iter().chain(extra_plots) {
        let written = plot_names(&row.with.name)
            .iter()
            .try_for_each(|name| dir.claim(name).map(|_| ()))
            .and_then(|()| plot_case_with_limit(dir.path(), row.with, row.without, voltage_limit));
        match written {
            Ok(files) => plots.extend(files),
            Err(e) => incomplete.push(format!("plots of {}: {e:#}", row.with.name)),
        }
        plots.extend(
            mission_plots
                .iter()
                .filter(|(run, _)| *run == row.with.name)
                .map(|(_, file)| file.clone()),
        );
    }
    let path = dir.claim("report.md")?;
    let text = report_markdown(dir.path(), title, rows, sections, &plots, notes, incomplete);
    atomic::write(&path, text.as_bytes()).with_context(|| format!("writing {}", path.display()))
}
