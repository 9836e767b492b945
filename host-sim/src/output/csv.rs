//! The per-period CSV of a run: one row per control period, columns [`CSV_COLUMNS`].

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use super::atomic::Pending;
use crate::interrupt;
use crate::sim::{Observer, RunResult, Sample};

/// The columns of [`write_csv`], in order.
pub const CSV_COLUMNS: [&str; 47] = [
    "t",
    "x",
    "y",
    "z",
    "roll",
    "pitch",
    "yaw",
    "x_d",
    "y_d",
    "z_d",
    "roll_d",
    "pitch_d",
    "yaw_d",
    "e_x",
    "e_y",
    "e_z",
    "e_roll",
    "e_pitch",
    "e_yaw",
    "tau_X",
    "tau_Y",
    "tau_Z",
    "tau_K",
    "tau_M",
    "tau_N",
    "tau_applied_X",
    "tau_applied_Y",
    "tau_applied_Z",
    "tau_applied_K",
    "tau_applied_M",
    "tau_applied_N",
    "thrust_main",
    "thrust_vert_fore",
    "thrust_vert_aft",
    "thrust_horz_fore",
    "thrust_horz_aft",
    "volt_main",
    "volt_vert_fore",
    "volt_vert_aft",
    "volt_horz_fore",
    "volt_horz_aft",
    "saturated",
    "delta",
    "delta_clamped",
    "w_norm",
    "payload",
    "status",
];

/// One CSV record for a sample, in [`CSV_COLUMNS`] order. Floats use Rust's shortest
/// round-trip formatting, so a value read back with `str::parse::<f64>` is bit-identical
/// (NaN is written `NaN`, infinities `inf`/`-inf`).
fn csv_record(s: &Sample, rec: &mut Vec<String>) {
    rec.clear();
    rec.push(s.t.to_string());
    for block in [&s.eta, &s.eta_d, &s.error, &s.tau, &s.tau_applied] {
        rec.extend(block.iter().map(f64::to_string));
    }
    for block in [&s.thrust, &s.voltage] {
        rec.extend(block.iter().map(f64::to_string));
    }
    rec.push(s.saturated.to_string());
    rec.push(s.delta.to_string());
    rec.push(u8::from(s.delta_clamped).to_string());
    rec.push(s.w_norm.to_string());
    rec.push(s.payload.to_string());
    rec.push(s.status.to_string());
}

/// Writes the per-period time series of one run as CSV, header row first. Columns
/// ([`CSV_COLUMNS`]):
/// t, x, y, z, roll, pitch, yaw, x_d, y_d, z_d, roll_d, pitch_d, yaw_d, e_x, e_y, e_z, e_roll,
/// e_pitch, e_yaw, tau_X, tau_Y, tau_Z, tau_K, tau_M, tau_N, tau_applied_X … tau_applied_N,
/// thrust_main, thrust_vert_fore, thrust_vert_aft, thrust_horz_fore, thrust_horz_aft,
/// volt_main, … (same five), saturated (bitmask integer), delta, delta_clamped (0/1), w_norm,
/// payload, status.
///
/// Units as in [`Sample`] (s, m, rad, N, N m, V, kg). The parent directory is created if
/// needed. An empty run writes the header only. Written whole or not at all
/// ([`super::atomic`]). The commands stream the CSV as the run goes instead ([`CsvStream`]);
/// this writes the samples a [`RunResult`] holds.
pub fn write_csv(path: &Path, run: &RunResult) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).with_context(|| format!("writing {}", path.display()))?;
    }
    let mut csv = CsvStream::create(path)?;
    for s in &run.samples {
        csv.push(s);
    }
    csv.finish()?;
    Ok(())
}

/// The CSV of one run written as the run goes, one row per sample ([`Observer`]): memory
/// stays bounded whatever the duration. The rows go to a temporary file, which
/// [`CsvStream::finish`] flushes and renames onto the final name ([`super::atomic`]).
///
/// A write error (a full disk: ENOSPC; the file-size limit: EFBIG) stops the writing but not
/// the run: the error and the time of the first row lost are kept, [`CsvStream::finish`]
/// returns them as a [`CsvIncomplete`] naming the file, and the temporary file is removed
/// (which also gives the disk space back for the report).
///
/// What was streamed survives any other exit that can run code (**Choice 126**): a stream
/// dropped without [`finish`](CsvStream::finish) (a panic unwinding) and a second signal
/// ([`crate::interrupt::keep_on_exit`]) rename the temporary file to
/// [`partial_name`]`(name)`, e.g. `circle-with.partial.csv`: the rows written so far, under a
/// name that says they are not the whole run.
pub struct CsvStream {
    pending: Option<Pending>,
    rows: CsvRows<File>,
    _streaming: interrupt::Streaming,
}

/// The name the rows of `name` (`circle-with.csv`) keep when the run ends without finishing
/// its CSV: `circle-with.partial.csv`.
pub fn partial_name(name: &str) -> String {
    match name.strip_suffix(".csv") {
        Some(stem) => format!("{stem}.partial.csv"),
        None => format!("{name}.partial"),
    }
}

/// [`partial_name`] of a path.
fn partial_path(dest: &Path) -> PathBuf {
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dest.with_file_name(partial_name(&name))
}

impl CsvStream {
    /// Starts `dest`'s temporary file and writes the header.
    pub fn create(dest: &Path) -> Result<Self> {
        let (pending, file) =
            Pending::create(dest).with_context(|| format!("writing {}", dest.display()))?;
        let streaming = interrupt::keep_on_exit(pending.tmp_path(), &partial_path(dest));
        Ok(CsvStream {
            pending: Some(pending),
            rows: CsvRows::new(file),
            _streaming: streaming,
        })
    }

    /// Writes one row (after an error: nothing).
    pub fn push(&mut self, s: &Sample) {
        self.rows.push(s);
    }

    /// The CSV in place under its final name, or why it is not.
    pub fn finish(mut self) -> Result<PathBuf, CsvIncomplete> {
        let Some(pending) = self.pending.take() else {
            unreachable!("a CsvStream is finished once (finish takes it)")
        };
        let dest = pending.dest().to_path_buf();
        let incomplete = |error: String| CsvIncomplete {
            path: dest.clone(),
            error,
        };
        let rows = std::mem::replace(&mut self.rows, CsvRows::closed());
        rows.finish().map_err(incomplete)?;
        pending
            .commit()
            .map_err(|e| incomplete(format!("putting it in place: {e}")))
    }
}

impl Drop for CsvStream {
    /// Not finished (a panic unwinding): the rows written so far are kept under the partial
    /// name (the writer flushes its buffer into the renamed file as it is dropped next).
    fn drop(&mut self) {
        if let Some(pending) = self.pending.take() {
            let partial = partial_path(pending.dest());
            let _ = pending.keep_as(&partial);
        }
    }
}

impl Observer for CsvStream {
    fn sample(&mut self, s: &Sample) {
        self.push(s);
    }
}

/// A CSV that could not be written completely: `path` does not exist (its temporary file was
/// removed); `error` says where the writing stopped and why.
#[derive(Debug)]
pub struct CsvIncomplete {
    pub path: PathBuf,
    pub error: String,
}

impl std::fmt::Display for CsvIncomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} is incomplete and was not written: {}",
            self.path.display(),
            self.error
        )
    }
}

impl std::error::Error for CsvIncomplete {}

/// The rows of a CSV into any writer: the header at once, then one row per sample; the first
/// write error stops the writing and is kept (with the time of the row it lost).
pub struct CsvRows<W: Write> {
    writer: Option<csv::Writer<W>>,
    rec: Vec<String>,
    error: Option<String>,
}

impl<W: Write> CsvRows<W> {
    /// The header row into `w`.
    pub fn new(w: W) -> Self {
        let mut writer = csv::Writer::from_writer(w);
        let error = writer
            .write_record(CSV_COLUMNS)
            .err()
            .map(|e| format!("writing the header: {e}"));
        CsvRows {
            writer: Some(writer),
            rec: Vec::with_capacity(CSV_COLUMNS.len()),
            error,
        }
    }

    /// A writer that writes nothing (what [`CsvStream::finish`] leaves behind).
    fn closed() -> Self {
        CsvRows {
            writer: None,
            rec: Vec::new(),
            error: None,
        }
    }

    pub fn push(&mut self, s: &Sample) {
        if self.error.is_some() {
            return;
        }
        let Some(w) = self.writer.as_mut() else {
            return;
        };
        csv_record(s, &mut self.rec);
        if let Err(e) = w.write_record(&self.rec) {
            self.error = Some(format!("writing stopped at t = {:.3} s: {e}", s.t));
        }
    }

    /// Flushes; the writer back, or the first error.
    pub fn finish(mut self) -> Result<W, String> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let w = self.writer.take().ok_or("no writer")?;
        w.into_inner()
            .map_err(|e| format!("writing the last rows: {}", e.error()))
    }
}
