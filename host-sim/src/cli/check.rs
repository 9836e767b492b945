//! `host-sim check`: the preflight feasibility check of one scenario.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use controller_core::readable::Readable;
use serde::Serialize;

use controller_core::trajectory::SpeedList;
use controller_core::TrajectoryKind;

use super::common::load;
use super::json::print_json;
use super::Exit;
use crate::scenario::{KeyPath, ScenarioError, ScenarioFile};
use crate::studies::preflight::profile::{self, SpeedProfile};
use crate::studies::preflight::{self, CheckError, Preflight, DEFAULT_MARGIN};

/// `check`: the preflight feasibility check of one scenario (nothing is simulated).
#[derive(Args, Clone, Debug, PartialEq)]
pub struct CheckArgs {
    #[arg(long)]
    pub scenario: PathBuf,
    /// Print one JSON object (the check's [`Preflight`], and a waypoint mission's proposed
    /// speed profile under `speed_profile`) instead of the text.
    #[arg(long)]
    pub json: bool,
    /// Fraction of each thruster's envelope the reference may use, in (0, 1]; the rest is left
    /// to the feedback.
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
}

/// `check`: the preflight check of one scenario; exit 0 feasible, 1 infeasible, 2 bad input,
/// 130 interrupted. With `--json` exactly one JSON object is printed on every exit
/// (**Choice 304**): the verdict ([`CheckJson`]), with `"interrupted": true` and what was done
/// so far when interrupted, or `{"error": {"kind", "message", "key"?}}` ([`CheckErrorJson`])
/// before the error goes to the binary (stderr, exit 2).
pub fn check(args: &CheckArgs, stdout: &mut dyn Write) -> Result<Exit> {
    match (checked(args, stdout), args.json) {
        (Ok(c), true) => {
            print_json(stdout, &c.json())?;
            Ok(c.exit())
        }
        (Ok(c), false) => Ok(c.exit()),
        (Err(e), true) => {
            // Said on stdout for the program reading it, and on stderr by the binary.
            print_json(stdout, &CheckErrorJson::of(&e))?;
            Err(e)
        }
        (Err(e), false) => Err(e),
    }
}

/// How far a check got: the verdict (`None`: interrupted before it), a waypoint mission's
/// proposed profile (or why there is none), and whether it was interrupted.
struct Checked {
    preflight: Option<Preflight>,
    speed_profile: Option<SpeedProfile>,
    no_speed_profile: Option<String>,
    interrupted: bool,
}

impl Checked {
    fn exit(&self) -> Exit {
        match &self.preflight {
            _ if self.interrupted => Exit::Interrupted,
            Some(p) if p.feasible() => Exit::Success,
            _ => Exit::Infeasible,
        }
    }

    fn json(&self) -> CheckJson<'_> {
        CheckJson {
            preflight: self.preflight.as_ref(),
            speed_profile: self.speed_profile.clone(),
            no_speed_profile: self.no_speed_profile.clone(),
            interrupted: self.interrupted,
        }
    }
}

/// The check, its text printed as it goes unless `--json`.
fn checked(args: &CheckArgs, stdout: &mut dyn Write) -> Result<Checked> {
    if !(args.margin > 0.0 && args.margin <= 1.0) {
        return Err(anyhow!(FlagError(format!(
            "--margin must be a fraction of the envelope in (0, 1], got {}",
            Readable(args.margin)
        ))));
    }
    let scenario = load(&args.scenario, false)?;
    let mut out = Checked {
        preflight: None,
        speed_profile: None,
        no_speed_profile: None,
        interrupted: false,
    };
    let p = match preflight::check(&scenario, args.margin) {
        Ok(p) => p,
        Err(CheckError::Interrupted) => {
            eprintln!("host-sim: check: interrupted before the verdict");
            out.interrupted = true;
            return Ok(out);
        }
        Err(e) => return Err(anyhow!(e)),
    };
    let waypoints = matches!(
        scenario.config().trajectory,
        TrajectoryKind::Waypoints { .. }
    );
    if !args.json {
        // The verdict first: the profile's search takes a while.
        writeln!(stdout, "{p}")?;
        writeln!(stdout, "{}", preflight_table(&p))?;
    } else if waypoints {
        // Nothing is on stdout until the end: say why the wait.
        eprintln!("host-sim: check: verdict made; searching the speed profile (tens of seconds)");
    }
    out.preflight = Some(p);
    // A waypoint mission: the fastest speed profile (docs/missions.md#the-speed-profile).
    // None at all (Choice 175): said, and the verdict above stands (infeasible: a part that
    // cannot be flown even slowly over the box cannot be flown as written either).
    match profile::propose(&scenario, args.margin) {
        Ok(s) => out.speed_profile = s,
        Err(e @ (CheckError::NoProfile { .. } | CheckError::NoProfileTerm { .. })) => {
            out.no_speed_profile = Some(e.to_string())
        }
        Err(CheckError::Interrupted) => {
            eprintln!("host-sim: check: interrupted before the speed profile");
            out.interrupted = true;
            return Ok(out);
        }
        Err(e) => return Err(anyhow!(e)),
    };
    if !args.json {
        match (&out.speed_profile, &out.no_speed_profile) {
            (Some(s), _) => writeln!(
                stdout,
                "{}",
                profile_table(scenario.config().trajectory, s)?
            )?,
            (None, Some(why)) => writeln!(stdout, "{why}")?,
            (None, None) => {}
        }
    }
    Ok(out)
}

/// A command-line flag `check` refuses (its [`CheckErrorKind::Flag`]).
#[derive(Debug)]
struct FlagError(String);

impl std::fmt::Display for FlagError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for FlagError {}

/// What `check --json` prints: the check's [`Preflight`] (its keys at the top level) and, for a
/// waypoint mission, the proposed [`SpeedProfile`] under `speed_profile` (docs/missions.md#the-speed-profile,
/// Choice 172); interrupted, `"interrupted": true` with what was done (Choice 304).
#[derive(Serialize)]
struct CheckJson<'a> {
    #[serde(flatten)]
    preflight: Option<&'a Preflight>,
    #[serde(skip_serializing_if = "Option::is_none")]
    speed_profile: Option<SpeedProfile>,
    /// Why a waypoint mission has no profile (Choice 175).
    #[serde(skip_serializing_if = "Option::is_none")]
    no_speed_profile: Option<String>,
    /// Stopped by an interrupt (exit 130): only what was done is here.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    interrupted: bool,
}

/// Why `check` exited 2, as `check --json` says it (Choice 304): a closed set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
enum CheckErrorKind {
    /// A command line the parser refuses (an unknown flag, a value of the wrong type).
    Usage,
    /// A flag out of its range (`--margin`).
    Flag,
    /// The scenario file cannot be read.
    ScenarioUnreadable,
    /// Not TOML, an unknown key, a missing one, a value of the wrong type.
    ScenarioSyntax,
    /// A value out of its range (`key` names it).
    ScenarioValue,
    /// The check cannot be made on this scenario (its allocator or plants cannot be built).
    Check,
    /// Anything else (an output that cannot be written).
    Other,
}

/// `check --json`'s object on exit 2: `{"error": {"kind", "message", "key"?}}`.
#[derive(Serialize)]
struct CheckErrorJson {
    error: CheckErrorBody,
}

#[derive(Serialize)]
struct CheckErrorBody {
    kind: CheckErrorKind,
    /// The whole chain, as stderr says it.
    message: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    key: Option<String>,
}

/// The JSON line `check --json` prints when its command line is refused by the parser
/// (`args`: the process's, `message`: the parser's), or `None` when the command line is not
/// `check … --json …` (Choice 304: one object on every exit, exit 2 included).
pub fn usage_error_json(args: &[std::ffi::OsString], message: &str) -> Option<String> {
    let json = args.iter().skip(2).any(|a| a == "--json");
    (args.get(1).is_some_and(|c| c == "check") && json).then(|| {
        let body = CheckErrorJson {
            error: CheckErrorBody {
                kind: CheckErrorKind::Usage,
                message: message.trim_end().to_string(),
                key: None,
            },
        };
        serde_json::to_value(&body).map_or_else(|_| String::new(), |v| v.to_string())
    })
}

impl CheckErrorJson {
    fn of(e: &anyhow::Error) -> CheckErrorJson {
        let (kind, key) = if e.downcast_ref::<FlagError>().is_some() {
            (CheckErrorKind::Flag, None)
        } else if let Some(s) = e.downcast_ref::<ScenarioError>() {
            match s {
                ScenarioError::Io { .. } => (CheckErrorKind::ScenarioUnreadable, None),
                ScenarioError::Toml(_) => (CheckErrorKind::ScenarioSyntax, None),
                ScenarioError::Invalid { key, .. } => {
                    (CheckErrorKind::ScenarioValue, Some(key.clone()))
                }
                ScenarioError::Write(_) => (CheckErrorKind::Other, None),
            }
        } else if e.downcast_ref::<CheckError>().is_some() {
            (CheckErrorKind::Check, None)
        } else {
            (CheckErrorKind::Other, None)
        };
        CheckErrorJson {
            error: CheckErrorBody {
                kind,
                message: format!("{e:#}"),
                key,
            },
        }
    }
}

/// The per-thruster part of `check`'s text.
fn preflight_table(p: &Preflight) -> String {
    let mut s = format!(
        "thrust unit {}, heading {}, trimmed {}, start {}, time scale {}, margin {:.0} %\n\
         mounting (strong side): {}\n",
        p.thrust_unit,
        p.heading,
        p.trimmed,
        p.initial_attitude,
        p.time_scale,
        100.0 * p.margin,
        p.mounting
    );
    s.push_str(&format!(
        "{:<10} {:>18} {:>22} {:>22} {:>8}\n",
        "thruster", "envelope (N)", "min demand (N) at t", "max demand (N) at t", "usage"
    ));
    for t in &p.thrusters {
        s.push_str(&format!(
            "{:<10} {:>18} {:>22} {:>22} {:>6.0} %\n",
            t.thruster,
            format!("[{:.1}, {:.1}]", t.envelope[0], t.envelope[1]),
            format!("{:.1} at {:.2} s", t.min, t.t_min),
            format!("{:.1} at {:.2} s", t.max, t.t_max),
            100.0 * t.usage
        ));
    }
    s.push_str(&p.navigation.describe());
    s.push('\n');
    if let Some(b) = &p.path_budget {
        s.push_str(&b.describe());
        s.push('\n');
    }
    if let Some(c) = &p.chatter {
        s.push_str(&c.describe());
        s.push('\n');
    }
    if let Some(k) = p.smallest_time_scale {
        s.push_str(&format!(
            "smallest feasible time scale: {k} (the same path then takes {:.1} s)\n",
            p.duration * k / p.time_scale
        ));
    }
    s
}

/// The speed profile's part of `check`'s text: time per part, the limiting thruster (or `cap`,
/// `trajectory.speed_limits`, or `changes`: too short for the speed changes), the totals
/// against the uniform time scale, and the keys that pin it.
fn profile_table(path: TrajectoryKind, p: &SpeedProfile) -> Result<String> {
    let mut s = format!(
        "speed profile over the whole box (margin envelope, speed changes at {} m/s²):\n\
         {:<12} {:>10} {:>12} {:>10}  limited by (thruster, cap, changes, path budget or chatter)\n",
        Readable(p.speed_change),
        "part",
        "length (m)",
        "speed (m/s)",
        "time (s)"
    );
    for part in &p.parts {
        s.push_str(&format!(
            "{:<12} {:>10.1} {:>12.2} {:>10.1}  {}\n",
            part.name, part.length, part.speed, part.time, part.limiting
        ));
    }
    let saved = 1.0 - p.total_time / p.uniform_time;
    let compared = if saved > 0.0 {
        format!("{:.1} % less with the profile", 100.0 * saved)
    } else {
        // Every part held at one cap (Choice 543): the profile's own speed changes and its
        // rounding down make it no faster than the uniform speed.
        "no faster with the profile: its parts are held at one cap".to_string()
    };
    s.push_str(&format!(
        "total {:.1} s with the profile; {:.1} s at the fastest uniform speed {:.3} m/s \
         ({compared}); {:.1} s at the file's speed\n",
        p.total_time, p.uniform_time, p.uniform_speed, p.nominal_time
    ));
    if p.shrink_rounds > 0 {
        s.push_str(&format!(
            "(every speed lowered {} time(s) by {} to pass the check as flown)\n",
            p.shrink_rounds,
            profile::VERIFY_SHRINK
        ));
    }
    s.push_str(&pin(path, p)?);
    Ok(s)
}

/// The lines that pin the profile `p` on the waypoint path `path`: a [`ScenarioFile`] of the
/// path with the profile's `speeds` and `speed_change` and its `duration`, serialized, each
/// number at the precision the table shows (speeds to the cm/s, the time to the tenth).
fn pin(path: TrajectoryKind, p: &SpeedProfile) -> Result<String> {
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        ..
    } = path
    else {
        bail!("a speed profile of a path without waypoints");
    };
    let speeds: Vec<f32> = p.speeds.iter().map(|&v| v as f32).collect();
    let mut file = ScenarioFile::new(TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        speeds: Some(SpeedList::new(&speeds).map_err(|e| anyhow!("the speed profile: {e}"))?),
        speed_change: Some(p.speed_change as f32),
    });
    file.duration = Some(p.total_time);
    let mut doc = file.to_document()?;
    doc.set_numbers(KeyPath::SPEEDS, &p.speeds, |v| format!("{v:.2}"))?;
    doc.set_numbers(KeyPath::SPEED_CHANGE, &[p.speed_change], |a| {
        Readable(a).to_string()
    })?;
    doc.set_numbers(KeyPath::DURATION, &[p.total_time], |t| format!("{t:.1}"))?;
    Ok(format!(
        "to pin it, in [{}]: {}\n{}  # and {}\n",
        KeyPath::SPEEDS.table.unwrap_or_default(),
        doc.entry(KeyPath::SPEEDS)?,
        doc.entry(KeyPath::SPEED_CHANGE)?,
        doc.entry(KeyPath::DURATION)?
    ))
}
