//! The flight log of a run: an MCAP file (docs/logs.md) beside its CSV, from the same
//! [`Sample`]s, with the channels of [`schema`] at their own rates, the law's inside
//! ([`inside`]), the scenario as an attachment and the run's metadata (version, gains, bound,
//! outcome). [`read`] reads a log (or a run's CSV) back as series, [`diff`] compares two.
//!
//! **Choice 354** (docs/logs.md#a-killed-run): the log is written under its final name as
//! the run goes, zstd-compressed, one chunk per second of flight: each chunk is closed and
//! flushed to the file when a second of flight ends. A run killed mid-way (even `kill -9`)
//! leaves a file a linear reader reads up to the last whole second before the kill; the
//! summary (indexes, statistics) and the footer are written when the run ends however it ends
//! (completed, diverged, interrupted, a write error): a log without them is one whose process
//! died. This is the one output not written whole-or-nothing ([`super::atomic`]): the MCAP
//! format says itself whether a file is complete, and a log is most wanted from the run that
//! was killed.

pub mod diff;
pub mod inside;
pub mod read;
pub mod schema;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, WriteOptions, Writer};

use self::inside::InsideOf;
use self::schema::{Rate, Record, Topic};
use crate::scenario::Scenario;
use crate::sim::{Observer, RunResult, Sample};
use crate::studies::campaign::PROGRAM_VERSION;

/// Where a log's law ran, the channels' `source` metadata: `sil` (the core on the host), `pil`
/// (the board in QEMU), `hil` (the board on its wire).
pub type Source = &'static str;

/// The log file name of a run called `name`, with (`robust`) or without Δu:
/// `{name}-with.mcap` / `{name}-without.mcap` (beside the CSV of the same stem).
pub fn log_name(name: &str, robust: bool) -> String {
    format!("{name}-{}.mcap", crate::sim::record::du_suffix(robust))
}

/// The log of the SIL run `pil` and `hil` fly beside the board's (`{name}-sil.mcap`; the
/// board's is [`log_name`]'s, source `pil` or `hil`).
pub fn sil_log_name(name: &str) -> String {
    format!("{name}-sil.mcap")
}

/// The log of one run being written ([`Observer`]); [`McapLog::finish`] ends it.
///
/// A write error stops the writing but not the run, as for the CSV: the error and the time are
/// kept and [`McapLog::finish`] returns them.
pub struct McapLog<'c> {
    path: PathBuf,
    writer: Option<Writer<BufWriter<File>>>,
    channels: [u16; Topic::ALL.len()],
    /// Write a channel's message every this many periods ([`Rate`]); 0: events only.
    every: [u64; Topic::ALL.len()],
    sequence: u32,
    rate_hz: u64,
    inside: InsideOf<'c>,
    periods: u64,
    last_t: f64,
    status: Option<String>,
    buf: String,
    error: Option<String>,
}

/// A log that could not be written completely: `error` says where the writing stopped and why.
#[derive(Debug, thiserror::Error)]
#[error("{} is incomplete: {error}", path.display())]
pub struct LogIncomplete {
    pub path: PathBuf,
    pub error: String,
}

fn ns(t: f64) -> u64 {
    (t.max(0.0) * 1e9).round() as u64
}

impl<'c> McapLog<'c> {
    /// Starts the log of `scenario` at `path` (claimed in the output folder): the schemas,
    /// the channels (their `source`), the run's metadata and the attachments (`text`: the
    /// scenario file as written, if the run has one; the configuration as resolved, always).
    pub fn create(
        path: &Path,
        scenario: &'c Scenario,
        source: Source,
        text: Option<&str>,
    ) -> Result<Self, LogIncomplete> {
        let incomplete = |error: String| LogIncomplete {
            path: path.to_path_buf(),
            error,
        };
        let file = File::create(path).map_err(|e| incomplete(format!("creating it: {e}")))?;
        let options = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            // One thread: the runs of a command already fill the cores (rayon).
            .compression_threads(0)
            // Chunks are closed by the second of flight, not by size (Choice 354).
            .chunk_size(None)
            .profile("");
        let mut writer = options
            .create(BufWriter::new(file))
            .map_err(|e| incomplete(format!("starting it: {e}")))?;
        let cfg = scenario.config();
        let rate_hz = u64::from(cfg.controller.rate_hz.max(1));
        let (channels, every) = declare(&mut writer, rate_hz, source).map_err(incomplete)?;
        writer
            .write_metadata(&run_metadata(scenario, source))
            .and_then(|()| {
                attachments(scenario, text)
                    .iter()
                    .try_for_each(|a| writer.attach(a))
            })
            .map_err(|e| incomplete(format!("writing its metadata: {e}")))?;
        Ok(McapLog {
            path: path.to_path_buf(),
            writer: Some(writer),
            channels,
            every,
            sequence: 0,
            rate_hz,
            inside: InsideOf::new(scenario.controller()),
            periods: 0,
            last_t: 0.0,
            status: None,
            buf: String::new(),
            error: None,
        })
    }

    fn write(&mut self, topic: Topic, t: f64) {
        let Some(w) = self.writer.as_mut() else {
            return;
        };
        self.sequence = self.sequence.wrapping_add(1);
        let header = MessageHeader {
            channel_id: self.channels[topic as usize],
            sequence: self.sequence,
            log_time: ns(t),
            publish_time: ns(t),
        };
        if let Err(e) = w.write_to_known_channel(&header, self.buf.as_bytes()) {
            self.stop(t, &e);
        }
    }

    fn stop(&mut self, t: f64, e: &dyn std::fmt::Display) {
        self.error = Some(format!("writing stopped at t = {t:.3} s: {e}"));
        // Dropped: the writer tries its summary once more, and the file ends at the last
        // whole record written if it cannot.
        self.writer = None;
    }

    /// Ends the log: the outcome (an event and the `outcome` metadata), then the summary and
    /// the footer. The file's path, or why it is incomplete.
    pub fn finish(mut self, run: &RunResult) -> Result<PathBuf, LogIncomplete> {
        let t = match &run.outcome {
            crate::sim::Outcome::Diverged { t, .. }
            | crate::sim::Outcome::LostBoard { t, .. }
            | crate::sim::Outcome::Interrupted { t } => *t,
            _ => self.last_t,
        };
        schema::event("outcome", "", &run.outcome.to_string(), &mut self.buf);
        self.write(Topic::Events, t);
        let outcome = outcome_metadata(run);
        let path = self.path.clone();
        let error = self.error.take();
        let finished = match self.writer.take() {
            Some(mut w) => w
                .write_metadata(&outcome)
                .and_then(|()| w.finish().map(|_| ()))
                .map_err(|e| e.to_string()),
            None => Ok(()),
        };
        match error.or(finished.err()) {
            Some(error) => Err(LogIncomplete { path, error }),
            None => Ok(path),
        }
    }
}

impl Observer for McapLog<'_> {
    fn sample(&mut self, s: &Sample) {
        if self.writer.is_none() {
            return;
        }
        let k = self.periods;
        self.periods += 1;
        self.last_t = s.t;
        let status = s.status.to_string();
        if self.status.as_deref() != Some(status.as_str()) {
            let text = if s.status.is_ok() {
                "the law runs".to_string()
            } else {
                format!("the thrusters are off: {status}")
            };
            schema::event("status", &status, &text, &mut self.buf);
            self.write(Topic::Events, s.t);
            self.status = Some(status);
        }
        let inside = self.inside.at(s);
        let record = Record {
            sample: s,
            inside: &inside,
        };
        for topic in Topic::ALL {
            let every = self.every[topic as usize];
            if every == 0 || !k.is_multiple_of(every) {
                continue;
            }
            schema::encode(topic, &record, &mut self.buf);
            self.write(topic, s.t);
        }
        // A chunk per second of flight, flushed to the file (Choice 354).
        if (k + 1).is_multiple_of(self.rate_hz) {
            if let Some(Err(e)) = self.writer.as_mut().map(Writer::flush) {
                self.stop(s.t, &e);
            }
        }
    }
}

/// The channels of [`Topic::ALL`] in `writer` (their ids), and how many periods apart each
/// has a message ([`Rate`]; 0: events only).
#[allow(clippy::type_complexity)]
fn declare(
    writer: &mut Writer<BufWriter<File>>,
    rate_hz: u64,
    source: Source,
) -> Result<([u16; Topic::ALL.len()], [u64; Topic::ALL.len()]), String> {
    let mut channels = [0; Topic::ALL.len()];
    let mut every = [0; Topic::ALL.len()];
    for topic in Topic::ALL {
        let spec = topic.spec();
        let schema = schema::json_schema(spec).to_string();
        let metadata = BTreeMap::from([
            ("source".to_string(), source.to_string()),
            ("about".to_string(), spec.about.to_string()),
        ]);
        channels[topic as usize] = writer
            .add_schema(spec.schema, "jsonschema", schema.as_bytes())
            .and_then(|id| writer.add_channel(id, spec.topic, "json", &metadata))
            .map_err(|e| format!("declaring {}: {e}", spec.topic))?;
        every[topic as usize] = match spec.rate {
            Rate::Control => 1,
            Rate::AtMost(hz) => rate_hz.div_ceil(u64::from(hz.max(1))),
            Rate::Events => 0,
        };
    }
    Ok((channels, every))
}

/// The attachments: the scenario file as written (`text`, if the run has one) and the
/// configuration as resolved (always).
fn attachments(scenario: &Scenario, text: Option<&str>) -> Vec<Attachment<'static>> {
    let attachment = |name: &str, media_type: &str, data: Vec<u8>| Attachment {
        log_time: 0,
        create_time: 0,
        name: name.to_string(),
        media_type: media_type.to_string(),
        data: data.into(),
    };
    let mut all = Vec::new();
    if let Some(text) = text {
        all.push(attachment(
            "scenario.toml",
            "application/toml",
            text.as_bytes().to_vec(),
        ));
    }
    let config = format!("{:#?}\n", scenario.config());
    all.push(attachment("config.txt", "text/plain", config.into_bytes()));
    all
}

/// The run's metadata record `run`: what flew, where, with which gains and bound.
fn run_metadata(scenario: &Scenario, source: Source) -> Metadata {
    let cfg = scenario.config();
    let c = &cfg.controller;
    let bound = cfg.bound().map_or_else(
        || "none".to_string(),
        |b| format!("max_path {} m, saturated {}", b.max_path, b.saturated),
    );
    Metadata {
        name: "run".to_string(),
        metadata: BTreeMap::from([
            ("name".to_string(), cfg.name.clone()),
            ("source".to_string(), source.to_string()),
            ("version".to_string(), PROGRAM_VERSION.to_string()),
            ("rate_hz".to_string(), c.rate_hz.to_string()),
            ("robust".to_string(), c.robust.to_string()),
            ("law".to_string(), format!("{:?}", c.law)),
            ("k1".to_string(), format!("{:?}", c.k1)),
            ("k2".to_string(), format!("{:?}", c.k2)),
            ("q".to_string(), format!("{:?}", c.q)),
            ("mu".to_string(), c.mu.to_string()),
            ("beta".to_string(), c.beta.to_string()),
            ("delta_max".to_string(), c.delta_max.to_string()),
            ("voltage_limit".to_string(), c.voltage_limit.to_string()),
            ("bound".to_string(), bound),
        ]),
    }
}

/// The metadata record `outcome`: how the run ended and its metrics.
fn outcome_metadata(run: &RunResult) -> Metadata {
    let mut metadata = BTreeMap::from([
        ("outcome".to_string(), run.outcome.to_string()),
        ("faults".to_string(), run.faults.to_string()),
    ]);
    for (name, value) in crate::sim::Metrics::NAMES.iter().zip(run.metrics.values()) {
        metadata.insert((*name).to_string(), value.to_string());
    }
    Metadata {
        name: "outcome".to_string(),
        metadata,
    }
}
