//! A flight read back as series: every field of every message of an MCAP log (a group's
//! members one by one: `/law e.x`), or every column of a run's CSV (channel `csv`), each a
//! series of (time, value). What `diff` compares.

use std::collections::BTreeMap;
use std::path::Path;

use mcap::read::Options;
use serde_json::Value;

/// One value of a series: a number (a boolean as 0 or 1; `null` as NaN) or a text.
#[derive(Clone, Debug, PartialEq)]
pub enum Point {
    Num(f64),
    Text(String),
}

/// One field's values in time order, times in ns of flight.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    pub times: Vec<u64>,
    pub values: Vec<Point>,
}

/// Every series of a flight, by `"{channel} {field}"` (`/thrusters voltage.main`,
/// `csv volt_main`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Flight {
    pub series: BTreeMap<String, Series>,
    /// Where the reading stopped early and why (a log whose writer was killed), if it did.
    pub cut: Option<String>,
}

/// Why a file cannot be read as a flight.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("cannot read {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path} is neither an MCAP log nor a run's CSV: {why}")]
    Format { path: String, why: String },
}

/// The MCAP file's first bytes.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Reads `path`: an MCAP log (by its magic), else a run's CSV (a header with `t`).
pub fn read_flight(path: &Path) -> Result<Flight, ReadError> {
    let shown = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: shown.clone(),
        source,
    })?;
    let format = |why: String| ReadError::Format {
        path: shown.clone(),
        why,
    };
    if bytes.starts_with(MAGIC) {
        read_mcap(&bytes).map_err(format)
    } else {
        read_csv(&bytes).map_err(format)
    }
}

fn read_mcap(bytes: &[u8]) -> Result<Flight, String> {
    let mut flight = Flight::default();
    let stream = mcap::MessageStream::new_with_options(bytes, Options::IgnoreEndMagic.into())
        .map_err(|e| e.to_string())?;
    for message in stream {
        let message = match message {
            Ok(m) => m,
            // A log cut short (its writer killed): what came before the cut is the flight.
            Err(e) => {
                flight.cut = Some(e.to_string());
                break;
            }
        };
        let value: Value = serde_json::from_slice(&message.data)
            .map_err(|e| format!("a message on {} is not JSON: {e}", message.channel.topic))?;
        flatten(
            &mut flight,
            &message.channel.topic,
            "",
            &value,
            message.log_time,
        );
    }
    if flight.series.is_empty() {
        return Err(flight
            .cut
            .unwrap_or_else(|| "it has no message".to_string()));
    }
    Ok(flight)
}

fn flatten(flight: &mut Flight, topic: &str, prefix: &str, value: &Value, t: u64) {
    let point = match value {
        Value::Object(members) => {
            for (name, v) in members {
                let path = if prefix.is_empty() {
                    name.clone()
                } else {
                    format!("{prefix}.{name}")
                };
                flatten(flight, topic, &path, v, t);
            }
            return;
        }
        Value::Number(n) => Point::Num(n.as_f64().unwrap_or(f64::NAN)),
        Value::Bool(b) => Point::Num(f64::from(u8::from(*b))),
        Value::Null => Point::Num(f64::NAN),
        Value::String(s) => Point::Text(s.clone()),
        Value::Array(_) => Point::Text(value.to_string()),
    };
    let series = flight
        .series
        .entry(format!("{topic} {prefix}"))
        .or_default();
    series.times.push(t);
    series.values.push(point);
}

fn read_csv(bytes: &[u8]) -> Result<Flight, String> {
    let mut reader = csv::Reader::from_reader(bytes);
    let header = reader.headers().map_err(|e| e.to_string())?.clone();
    let t_col = header
        .iter()
        .position(|h| h == "t")
        .ok_or("no column `t` (the time of each row)")?;
    let mut flight = Flight::default();
    for (row, record) in reader.records().enumerate() {
        let record = record.map_err(|e| format!("row {}: {e}", row + 2))?;
        let t: f64 = record
            .get(t_col)
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| format!("row {}: `t` is not a number", row + 2))?;
        let t = (t.max(0.0) * 1e9).round() as u64;
        for (name, field) in header.iter().zip(record.iter()) {
            if name == "t" {
                continue;
            }
            let point = field
                .parse::<f64>()
                .map_or_else(|_| Point::Text(field.to_string()), Point::Num);
            let series = flight.series.entry(format!("csv {name}")).or_default();
            series.times.push(t);
            series.values.push(point);
        }
    }
    if flight.series.is_empty() {
        return Err("it has no row".to_string());
    }
    Ok(flight)
}
