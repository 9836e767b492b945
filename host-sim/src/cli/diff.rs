//! `host-sim diff A B`: two flights (MCAP logs, or runs' CSVs) compared series by series
//! (docs/logs.md#comparing-two-flights): the first time they diverge beyond the tolerance and
//! in which series, the largest difference of every series that differs, and a plot of those
//! that differ most. Exit 0 the same, 4 they differ, 2 a file that is not a flight.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::Exit;
use crate::output::log::diff::{self, Tolerance};
use crate::output::log::read::read_flight;
use crate::output::OutputDir;

/// `diff`: two flights compared.
#[derive(Args, Clone, Debug, PartialEq)]
pub struct DiffArgs {
    /// The first flight: an MCAP log (`{name}-with.mcap`) or a run's CSV.
    pub a: PathBuf,
    /// The second flight, of the same kind.
    pub b: PathBuf,
    /// Absolute tolerance: values closer than abs + rel·max(|a|, |b|) are the same.
    #[arg(long, default_value_t = 0.0)]
    pub abs: f64,
    /// Relative tolerance.
    #[arg(long, default_value_t = 0.0)]
    pub rel: f64,
    /// Folder of the plot of the series that differ most (`diff.png`); default `runs/diff`.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// How many of the series that differ are listed (most different first).
    #[arg(long, default_value_t = 20)]
    pub top: usize,
}

/// `diff`.
pub fn diff(args: &DiffArgs, stdout: &mut dyn Write) -> Result<Exit> {
    for (flag, x) in [("--abs", args.abs), ("--rel", args.rel)] {
        anyhow::ensure!(x.is_finite() && x >= 0.0, "{flag} {x}: a tolerance is ≥ 0");
    }
    let a = read_flight(&args.a)?;
    let b = read_flight(&args.b)?;
    let tol = Tolerance {
        abs: args.abs,
        rel: args.rel,
    };
    let diffs = diff::compare(&a, &b, tol);
    for (name, flight) in [("A", &a), ("B", &b)] {
        if let Some(cut) = &flight.cut {
            writeln!(stdout, "{name} ends early (its writer stopped): {cut}")?;
        }
    }
    let Some(first) = diff::first_divergence(&diffs) else {
        writeln!(
            stdout,
            "the same: {} series, no difference beyond abs {} + rel {}",
            diffs.len(),
            args.abs,
            args.rel
        )?;
        return Ok(Exit::Success);
    };
    let ranked = diff::ranked(&diffs);
    writeln!(
        stdout,
        "first divergence: t = {:.3} s in {} ({} of {} series differ)",
        first.first.unwrap_or(f64::NAN),
        first.name,
        ranked.len(),
        diffs.len()
    )?;
    writeln!(
        stdout,
        "series | max |A − B| | at t (s) | first beyond tolerance (s) | unmatched times"
    )?;
    for d in ranked.iter().take(args.top) {
        let at = d.max_at.map_or("—".to_string(), |t| format!("{t:.3}"));
        let only = d
            .only_in
            .map_or(String::new(), |w| format!(" (only in {w})"));
        writeln!(
            stdout,
            "{}{only} | {:.6e} | {at} | {:.3} | {}",
            d.name,
            d.max,
            d.first.unwrap_or(f64::NAN),
            d.unmatched
        )?;
    }
    let dir = OutputDir::prepare(
        &args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("runs/diff")),
    )?;
    let png = dir.claim("diff.png")?;
    match diff::plot_most_different(&png, &a, &b, &diffs) {
        Ok(()) => writeln!(stdout, "plot: {}", png.display())?,
        Err(e) => eprintln!("host-sim: error: {} was not written: {e:#}", png.display()),
    }
    Ok(Exit::Differ)
}
