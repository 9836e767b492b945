//! One run of a campaign as one CSV line (**Choice 132**): its index, its base, what it drew,
//! its metrics and its outcome. Numbers are written in Rust's shortest form that reads back to
//! the same f64 (`{}`), so a record read back is the run's exact numbers (NaN as `NaN`).

use std::fmt::Write as _;

use controller_core::model::{VARIED_PARAMETERS, VARIED_PARAMETER_NAMES};

use super::{Draw, METRIC_NAMES};
use crate::sim::RunResult;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Ran to its end within its bound.
    Completed,
    /// Ran to its end outside its bound.
    Missed,
    /// Stopped early (a runaway).
    Diverged,
    /// The draw made a scenario that does not validate (not flown; metrics NaN).
    Invalid,
}

impl Outcome {
    pub const ALL: [Outcome; 4] = [
        Outcome::Completed,
        Outcome::Missed,
        Outcome::Diverged,
        Outcome::Invalid,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Completed => "completed",
            Outcome::Missed => "missed",
            Outcome::Diverged => "diverged",
            Outcome::Invalid => "invalid",
        }
    }
}

/// One run's record.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub index: u64,
    pub base: usize,
    pub draw: Draw,
    /// In the order of [`METRIC_NAMES`].
    pub metrics: [f64; METRIC_NAMES.len()],
    /// The controller was in fail-safe in some period.
    pub faulted: bool,
    pub outcome: Outcome,
}

/// The names of the drawn values' columns, in order: the nine Δ, the current (north, east),
/// the noise seed, the six offsets, the time scale.
pub const DRAWN_COLUMNS: [&str; 18] = [
    "mass",
    "x_g",
    "y_g",
    "z_g",
    "ix",
    "iy",
    "iz",
    "x_udot",
    "y_vdot",
    "current_n",
    "current_e",
    "noise_seed",
    "offset_x",
    "offset_y",
    "offset_z",
    "offset_roll",
    "offset_pitch",
    "offset_yaw",
];

/// The time-scale column (after [`DRAWN_COLUMNS`]).
pub const TIME_SCALE_COLUMN: &str = "time_scale";
/// The mounting column (after the time scale): the reversed-thruster mask, 0–31
/// ([`super::NOT_AUV150_LAYOUT`]: another geometry).
pub const MOUNTING_COLUMN: &str = "mounting";

/// The CSV header line (no newline).
pub fn header() -> String {
    let mut cols = vec!["index", "base"];
    cols.extend(DRAWN_COLUMNS);
    cols.extend([TIME_SCALE_COLUMN, MOUNTING_COLUMN]);
    cols.extend(METRIC_NAMES);
    cols.extend(["faulted", "outcome"]);
    cols.join(",")
}

const _: () = assert!(VARIED_PARAMETERS == 9 && VARIED_PARAMETER_NAMES.len() == 9);

impl Record {
    /// The record of a run flown.
    pub fn of(index: u64, base: usize, draw: Draw, r: &RunResult) -> Self {
        let outcome = if r.diverged() {
            Outcome::Diverged
        } else if r.missed() {
            Outcome::Missed
        } else {
            Outcome::Completed
        };
        Record {
            index,
            base,
            draw,
            metrics: r.metrics.values(),
            faulted: !r.faults.is_empty(),
            outcome,
        }
    }

    /// The record of a draw whose scenario does not validate (`why`, reported on stderr).
    pub fn invalid(index: u64, base: usize, draw: Draw, why: String) -> Self {
        eprintln!("host-sim: campaign run {index}: not flown: {why}");
        Record {
            index,
            base,
            draw,
            metrics: [f64::NAN; METRIC_NAMES.len()],
            faulted: false,
            outcome: Outcome::Invalid,
        }
    }

    /// The drawn values as numbers, in the order of [`DRAWN_COLUMNS`], then the time scale
    /// and the mounting.
    pub fn drawn(&self) -> [f64; 20] {
        let d = &self.draw;
        let mut v = [0.0; 20];
        v[..9].copy_from_slice(&d.variation);
        v[9] = d.current[0];
        v[10] = d.current[1];
        v[11] = d.noise_seed as f64;
        v[12..18].copy_from_slice(&d.initial_offset);
        v[18] = f64::from(d.time_scale);
        v[19] = f64::from(d.mounting);
        v
    }

    /// The CSV line, with its newline.
    pub fn line(&self) -> String {
        let d = &self.draw;
        let mut s = format!("{},{}", self.index, self.base);
        for x in d.variation {
            let _ = write!(s, ",{x}");
        }
        let _ = write!(s, ",{},{},{}", d.current[0], d.current[1], d.noise_seed);
        for x in d.initial_offset {
            let _ = write!(s, ",{x}");
        }
        let _ = write!(s, ",{},{}", d.time_scale, d.mounting);
        for x in self.metrics {
            let _ = write!(s, ",{x}");
        }
        let _ = writeln!(s, ",{},{}", self.faulted, self.outcome.as_str());
        s
    }

    /// Reads a line written by [`Record::line`] (without its newline); `None` if it is not one
    /// (a torn line, another format).
    pub fn parse(line: &str) -> Option<Self> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 2 + DRAWN_COLUMNS.len() + 2 + METRIC_NAMES.len() + 2 {
            return None;
        }
        let num = |k: usize| f[k].parse::<f64>().ok();
        let variation: [f64; 9] = array(|j| num(2 + j))?;
        let current = [num(11)?, num(12)?, 0.0];
        let noise_seed = f[13].parse().ok()?;
        let initial_offset: [f64; 6] = array(|j| num(14 + j))?;
        let time_scale = f[20].parse::<f32>().ok()?;
        let mounting = f[21].parse().ok()?;
        let metrics: [f64; METRIC_NAMES.len()] = array(|j| num(22 + j))?;
        let after = 22 + METRIC_NAMES.len();
        let faulted = f[after].parse().ok()?;
        let outcome = *Outcome::ALL.iter().find(|o| o.as_str() == f[after + 1])?;
        Some(Record {
            index: f[0].parse().ok()?,
            base: f[1].parse().ok()?,
            draw: Draw {
                variation,
                current,
                noise_seed,
                initial_offset,
                time_scale,
                mounting,
            },
            metrics,
            faulted,
            outcome,
        })
    }

    /// Within its bound: completed (not missed, diverged or invalid).
    pub fn within(&self) -> bool {
        self.outcome == Outcome::Completed
    }
}

/// One drawn value as a record writes it.
#[derive(Clone, Copy, Debug)]
enum Drawn {
    F64(f64),
    F32(f32),
    Int(u64),
}

impl Drawn {
    /// The same bits (a NaN equals nothing but itself, -0 is not 0).
    fn same(self, other: Drawn) -> bool {
        match (self, other) {
            (Drawn::F64(a), Drawn::F64(b)) => a.to_bits() == b.to_bits(),
            (Drawn::F32(a), Drawn::F32(b)) => a.to_bits() == b.to_bits(),
            (Drawn::Int(a), Drawn::Int(b)) => a == b,
            _ => false,
        }
    }
}

impl std::fmt::Display for Drawn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Drawn::F64(x) => write!(f, "{x}"),
            Drawn::F32(x) => write!(f, "{x}"),
            Drawn::Int(x) => write!(f, "{x}"),
        }
    }
}

impl Draw {
    /// The values a record writes, in the order of its columns ([`DRAWN_COLUMNS`], the time
    /// scale, the mounting), each with its column's name.
    fn columns(&self) -> [(&'static str, Drawn); 20] {
        let mut v = [("", Drawn::Int(0)); 20];
        let floats = self.variation.iter().chain(&self.current[..2]);
        for (k, x) in floats.enumerate() {
            v[k] = (DRAWN_COLUMNS[k], Drawn::F64(*x));
        }
        v[11] = (DRAWN_COLUMNS[11], Drawn::Int(self.noise_seed));
        for (j, x) in self.initial_offset.iter().enumerate() {
            v[12 + j] = (DRAWN_COLUMNS[12 + j], Drawn::F64(*x));
        }
        v[18] = (TIME_SCALE_COLUMN, Drawn::F32(self.time_scale));
        v[19] = (MOUNTING_COLUMN, Drawn::Int(u64::from(self.mounting)));
        v
    }

    /// The first column in which `self` and `other` differ, bit for bit: its name and the two
    /// values as a record writes them (the vertical current, never drawn, is not compared).
    pub fn first_difference(&self, other: &Draw) -> Option<(&'static str, String, String)> {
        self.columns()
            .into_iter()
            .zip(other.columns())
            .find(|(a, b)| !a.1.same(b.1))
            .map(|(a, b)| (a.0, a.1.to_string(), b.1.to_string()))
    }
}

fn array<const N: usize>(mut f: impl FnMut(usize) -> Option<f64>) -> Option<[f64; N]> {
    let mut a = [0.0; N];
    for (j, x) in a.iter_mut().enumerate() {
        *x = f(j)?;
    }
    Some(a)
}
