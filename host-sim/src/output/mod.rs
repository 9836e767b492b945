//! What a run leaves on disk: the per-period CSV ([`csv`]), PNG plots in the manner of the
//! paper's Figs 2–5 ([`figures`], drawn with the plotting layer [`plot`]), and the Table-1
//! report, Markdown file and terminal text ([`report`]).
//!
//! Nothing here panics on data: NaN and ±∞ values (and magnitudes beyond 1e100) are skipped in
//! plots (a line is broken at them), written as `NaN`/`inf` in the CSV and in tables, and an
//! empty run gives plots that say "no data". A diverged run is always named as such, with its
//! time and reason, in plot subtitles and in the tables.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

pub mod csv;
pub mod figures;
mod plot;
pub mod report;

pub use self::csv::{write_csv, CSV_COLUMNS};
pub use self::figures::{plot_case, plot_case_with_limit};
pub use self::report::{table_markdown, table_text, write_report, ReportRow};

/// Writes everything for the report rows' runs into `out` (created if needed): per row the CSV
/// of the run with Δu (`{name}-with.csv`) and of its companion without (`-without.csv`), the
/// five plots (voltages against ±`voltage_limit`), then `report.md` with the table, the plots
/// and `notes`. Returns the report's path.
pub fn write_all(
    out: &Path,
    title: &str,
    rows: &[ReportRow],
    notes: &str,
    voltage_limit: f64,
) -> Result<PathBuf> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut plots = Vec::new();
    for row in rows {
        write_csv(&out.join(format!("{}-with.csv", row.with.name)), row.with)?;
        if let Some(w) = row.without {
            write_csv(&out.join(format!("{}-without.csv", w.name)), w)?;
        }
        plots.extend(plot_case_with_limit(
            out,
            row.with,
            row.without,
            voltage_limit,
        )?);
    }
    write_report(out, title, rows, &plots, notes)
}
