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
pub mod views;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, WriteOptions, Writer};

use self::inside::InsideOf;
use self::schema::{Rate, Record, Topic};
use crate::scenario::Scenario;
use crate::sim::{BoardReport, Observer, RunResult, Sample, UploadRound};
use crate::studies::campaign::PROGRAM_VERSION;

/// The git revision this host-sim was built from (`git describe --always --dirty`, or
/// `unknown` outside a checkout; host-sim/build.rs, **Choice 380**): the log's `version`
/// metadata names it beside [`PROGRAM_VERSION`].
pub const REVISION: &str = env!("HOST_SIM_GIT");

/// The `version` metadata of a log: the program and the revision it was built from
/// (`host-sim 0.1.0 (git 72eb61f0a1b2-dirty)`).
pub fn version() -> String {
    format!("{PROGRAM_VERSION} (git {REVISION})")
}

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
    /// The board's last answer's supervisor state and count of refused commands.
    board: Option<(auv_link::BoardStatus, u32)>,
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
        // The metadata and attachments before the channels (Choice 481): a metadata record
        // closes the open chunk, and the chunk of the channels alone would hold no message,
        // which the TypeScript MCAP reader (Foxglove) refuses ("Chunks without message
        // indexes"). Declared after them, the channels share the first second's chunk.
        writer
            .write_metadata(&run_metadata(scenario, source))
            .and_then(|()| {
                attachments(scenario, text)
                    .iter()
                    .try_for_each(|a| writer.attach(a))
            })
            .map_err(|e| incomplete(format!("writing its metadata: {e}")))?;
        let (channels, every) = declare(&mut writer, rate_hz, source).map_err(incomplete)?;
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
            board: None,
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

impl McapLog<'_> {
    /// The rounds of the mission's upload before the flight, at time 0 (`/board/upload`).
    pub fn upload(&mut self, rounds: &[UploadRound]) {
        for round in rounds {
            schema::upload_round(round, &mut self.buf);
            self.write(Topic::Upload, 0.0);
        }
    }

    /// The board's supervisor state at its first answer and when it changes, and the
    /// commands it refused when its count grows (Choice 382).
    fn board_events(&mut self, b: &BoardReport, t: f64) {
        let refused = b.counters.refused_commands;
        let (previous, before) = match self.board {
            Some((status, count)) => (Some(status), count),
            None => (None, 0),
        };
        if previous != Some(b.status) {
            let previous = previous.map_or(String::new(), |p| p.as_str().to_string());
            schema::supervisor(b.status.as_str(), &previous, b.board_tick, &mut self.buf);
            self.write(Topic::Supervisor, t);
        }
        if refused > before {
            let reason = b.last_refusal.map_or("", |r| r.as_str());
            schema::refusals(refused - before, refused, reason, &mut self.buf);
            self.write(Topic::Refusals, t);
        }
        self.board = Some((b.status, refused.max(before)));
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
        if let Some(b) = &s.signals.board {
            self.board_events(b, s.t);
        }
        let inside = self.inside.at(s);
        let record = Record {
            sample: s,
            inside: &inside,
            period: 1.0 / self.rate_hz as f64,
        };
        for topic in Topic::ALL {
            let every = self.every[topic as usize];
            if every == 0 || !k.is_multiple_of(every) {
                continue;
            }
            if schema::encode(topic, &record, &mut self.buf) {
                self.write(topic, s.t);
            }
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
            Rate::Control | Rate::Arrival => 1,
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
            ("version".to_string(), version()),
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
