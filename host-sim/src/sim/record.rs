//! What a run leaves behind: one [`Sample`] per control period, the outcome, and the metrics.

use std::collections::BTreeMap;
use std::fmt;

use auv_link::BoardStatus;
use controller_core::effectiveness::THRUSTERS;
use controller_core::{Status, Table1Case};
use serde::{Deserialize, Serialize};

use super::chatter::Chatter;

/// What produced a control period's output, and its state: the core's own [`Status`] when the
/// law runs on the host (SIL), the board's [`BoardStatus`] when it runs on the board (PIL).
///
/// `Display` is the CSV `status` column: `ok` when the law ran (the core's [`Status::Ok`], the
/// board's [`BoardStatus::Running`]); the core's name otherwise (`fault:pitch-limit`); for the
/// board `board:` and its name with `": "` → `":"` and spaces → `-`
/// (`board:fail-safe:stale-state`), so that the column holds one token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlStatus {
    /// The core on the host.
    Law(Status),
    /// The firmware on the board.
    Board(BoardStatus),
}

impl ControlStatus {
    /// True when the law ran this period (thrusters are driven); false: fail-safe, all off.
    pub fn is_ok(&self) -> bool {
        matches!(
            self,
            ControlStatus::Law(Status::Ok) | ControlStatus::Board(BoardStatus::Running)
        )
    }
}

impl fmt::Display for ControlStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            _ if self.is_ok() => f.write_str("ok"),
            ControlStatus::Law(s) => f.write_str(s.as_str()),
            ControlStatus::Board(s) => {
                let token = s.as_str().replace(": ", ":").replace(' ', "-");
                write!(f, "board:{token}")
            }
        }
    }
}

impl Serialize for ControlStatus {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// One control period, as the controller saw and commanded it and as the plant was.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// True pose η (m, rad).
    pub eta: [f64; 6],
    /// Desired pose η_d.
    pub eta_d: [f64; 6],
    /// e = η − η_d from the true pose (yaw wrapped to (−π, π]).
    pub error: [f64; 6],
    /// Commanded body force τ (N, N m).
    pub tau: [f64; 6],
    /// Body force actually applied to the plant by the thrusters.
    pub tau_applied: [f64; 6],
    /// Thrust per thruster applied to the plant (N): [main, vert fore, vert aft, horz fore,
    /// horz aft].
    pub thrust: [f64; THRUSTERS],
    /// Voltage per thruster from the controller (V), clamped to the supply limit.
    pub voltage: [f64; THRUSTERS],
    /// Saturation bits from the controller.
    pub saturated: u8,
    /// δ(e,t).
    pub delta: f64,
    /// True when the δ clamp was active.
    pub delta_clamped: bool,
    /// ‖w‖.
    pub w_norm: f64,
    /// Payload mass variation Δm (kg) at this time.
    pub payload: f64,
    /// Controller status: ok, or why the thrusters are off.
    pub status: ControlStatus,
    /// What the loop had besides the CSV's columns (the flight log has them:
    /// docs/logs.md#channels).
    pub signals: LoopSignals,
}

/// The rest of a control period's signals, which the flight log records and the CSV does not
/// ([`crate::output::log`]): the plant's body velocities, the state the law was told, the
/// reference's derivatives and the thrust each thruster was driven towards.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LoopSignals {
    /// True body velocities ν (m/s, rad/s).
    pub nu: [f64; 6],
    /// η as the navigation told the law, in f32 as it crossed ([`super::navigation`]).
    pub eta_told: [f32; 6],
    /// ν as the navigation told the law.
    pub nu_told: [f32; 6],
    /// η̇_d this period.
    pub eta_d_dot: [f32; 6],
    /// η̈_d this period.
    pub eta_d_ddot: [f32; 6],
    /// The thrust each thruster was driven towards this period (N; before the lag), order of
    /// [`Sample::thrust`].
    pub thrust_demand: [f64; THRUSTERS],
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Outcome {
    Completed,
    /// Stopped early; everything recorded up to `t` is kept.
    Diverged {
        t: f64,
        reason: String,
    },
    /// Stopped at `t` because the board in the loop (PIL, HIL) was lost or no longer flies
    /// what the plant reads: `cause` says how, `reason` is the runner's message (what to check).
    /// Everything recorded before `t` is kept. The vehicle did not diverge: the run has no
    /// verdict on the controller, and the command exits 1 as for a divergence
    /// ([`crate::cli::Exit::RunFailed`]; Choice 200).
    LostBoard {
        t: f64,
        cause: BoardLoss,
        reason: String,
    },
    /// Stopped at `t` on request (Ctrl-C, SIGTERM: [`crate::interrupt`]); everything recorded
    /// before `t` is kept and every output says it is partial.
    Interrupted {
        t: f64,
    },
    /// Ran to its end outside its bound ([`crate::scenario::SimConfig::bound`]): `reason` says
    /// which limit and by how much.
    Missed {
        reason: String,
    },
}

/// How a run lost its board ([`Outcome::LostBoard`]), as the JSON's `lost_board.cause` names
/// it (kebab-case): what to look at first. The runner's message says the rest
/// (`crate::board::Error`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BoardLoss {
    /// Nothing at all came for the reply timeout: the board stopped, lost power, or is not
    /// wired to this port.
    Silent,
    /// Bytes came but no valid telemetry: a wrong baud rate or link key, another device.
    Noise,
    /// The link closed or its port went away (unplugged, powered off, the emulator ended).
    LinkGone,
    /// The board does not fly the configuration the run needs: another thrust unit or
    /// mounting, a refused set-up, a mission it did not take.
    Misconfigured,
    /// Anything else on the way to the board: an I/O error, the emulator or port not starting.
    Failed,
}

/// A reason on one line (the outcome's line in tables and on stderr).
fn one_line(reason: &str) -> String {
    reason.split_whitespace().collect::<Vec<_>>().join(" ")
}

impl fmt::Display for Outcome {
    /// "completed", "DIVERGED at t = … s: reason" (the reason on one line), "LOST THE BOARD at
    /// t = … s: reason" (the same), "INTERRUPTED at t = … s (partial)" or "MISSED its bound:
    /// reason".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Outcome::Completed => f.write_str("completed"),
            Outcome::Diverged { t, reason } => {
                write!(f, "DIVERGED at t = {t:.2} s: {}", one_line(reason))
            }
            Outcome::LostBoard { t, reason, .. } => {
                write!(f, "LOST THE BOARD at t = {t:.2} s: {}", one_line(reason))
            }
            Outcome::Interrupted { t } => write!(f, "INTERRUPTED at t = {t:.2} s (partial)"),
            Outcome::Missed { reason } => write!(f, "MISSED its bound: {reason}"),
        }
    }
}

/// The control periods of a run in which the law did not run (thrusters off: the core's
/// fail-safe, or the board's), counted per status.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultCounts {
    /// Periods per status, by the CSV `status` token ([`ControlStatus`]'s `Display`, e.g.
    /// `fault:pitch-limit`, `board:fail-safe:stale-state`); statuses that did not occur are
    /// absent.
    pub periods: BTreeMap<String, u64>,
    /// Time of the first such period (s); `None` when there was none.
    pub first_t: Option<f64>,
}

impl FaultCounts {
    /// Counts `sample` if its status is not ok.
    pub fn record(&mut self, sample: &Sample) {
        if sample.status.is_ok() {
            return;
        }
        *self.periods.entry(sample.status.to_string()).or_default() += 1;
        self.first_t.get_or_insert(sample.t);
    }

    /// Every period in which the law did not run.
    pub fn total(&self) -> u64 {
        self.periods.values().sum()
    }

    pub fn is_empty(&self) -> bool {
        self.periods.is_empty()
    }
}

impl fmt::Display for FaultCounts {
    /// "0", or the total and the periods per status:
    /// "12 (fault:pitch-limit 10, fault:non-finite-result 2; first at t = 3.20 s)".
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.total())?;
        if self.is_empty() {
            return Ok(());
        }
        let parts: Vec<String> = self
            .periods
            .iter()
            .map(|(status, n)| format!("{status} {n}"))
            .collect();
        write!(f, " ({}", parts.join(", "))?;
        if let Some(t) = self.first_t {
            write!(f, "; first at t = {t:.2} s")?;
        }
        f.write_str(")")
    }
}

/// The paper's Table-1 metrics (docs/simulator.md#table-1) and the actuator figures.
///
/// A run that recorded no period has none (**Choice 129**): every field is NaN
/// ([`Metrics::NONE`]; the maximum and the mean of nothing), which the JSON writes as `null`
/// (and reads back as NaN), the tables as `—`; never 0, which read as a perfect run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    #[serde(deserialize_with = "nan_if_null")]
    pub max_x: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max_y: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max_z: f64,
    /// √(max|e_x|² + max|e_y|² + max|e_z|²), the paper's "path" error.
    #[serde(deserialize_with = "nan_if_null")]
    pub max_path: f64,
    /// √(mean(e_x² + e_y² + e_z²)).
    #[serde(deserialize_with = "nan_if_null")]
    pub rms_path: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max_roll: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max_pitch: f64,
    #[serde(deserialize_with = "nan_if_null")]
    pub max_yaw: f64,
    /// Largest |V| any thruster was commanded (V).
    #[serde(deserialize_with = "nan_if_null")]
    pub peak_voltage: f64,
    /// Fraction of control periods with at least one thruster saturated.
    #[serde(deserialize_with = "nan_if_null")]
    pub saturated_fraction: f64,
    /// Sign reversals per second through ±0.5 V of the thruster that reverses most (1/s;
    /// [`super::chatter`], Choice 320).
    #[serde(deserialize_with = "nan_if_null")]
    pub reversals_per_s: f64,
    /// Total variation per second of the command that varies most (V/s).
    #[serde(deserialize_with = "nan_if_null")]
    pub command_tv: f64,
    /// The largest share of a thruster's command power above its corner frequency (Choice 321).
    #[serde(deserialize_with = "nan_if_null")]
    pub hf_share: f64,
    /// The three chatter figures of each thruster (the three above are their worst).
    pub chatter: Chatter,
}

impl Metrics {
    /// The metrics of a run that recorded no period: every one NaN.
    pub const NONE: Metrics = Metrics {
        max_x: f64::NAN,
        max_y: f64::NAN,
        max_z: f64::NAN,
        max_path: f64::NAN,
        rms_path: f64::NAN,
        max_roll: f64::NAN,
        max_pitch: f64::NAN,
        max_yaw: f64::NAN,
        peak_voltage: f64::NAN,
        saturated_fraction: f64::NAN,
        reversals_per_s: f64::NAN,
        command_tv: f64::NAN,
        hf_share: f64::NAN,
        chatter: Chatter::NONE,
    };

    /// The metrics' names, as the JSON, the CSVs and the campaign files write them, in the
    /// order of [`Metrics::values`] (the field order; a test ties the two to serde's names).
    /// The per-thruster [`Metrics::chatter`] is not among them (it is not one number).
    pub const NAMES: [&'static str; 13] = [
        "max_x",
        "max_y",
        "max_z",
        "max_path",
        "rms_path",
        "max_roll",
        "max_pitch",
        "max_yaw",
        "peak_voltage",
        "saturated_fraction",
        "reversals_per_s",
        "command_tv",
        "hf_share",
    ];

    /// The metrics in the order of [`Metrics::NAMES`].
    pub fn values(&self) -> [f64; 13] {
        [
            self.max_x,
            self.max_y,
            self.max_z,
            self.max_path,
            self.rms_path,
            self.max_roll,
            self.max_pitch,
            self.max_yaw,
            self.peak_voltage,
            self.saturated_fraction,
            self.reversals_per_s,
            self.command_tv,
            self.hf_share,
        ]
    }

    /// False for [`Metrics::NONE`]: the run recorded no period.
    pub fn recorded(&self) -> bool {
        !self.max_path.is_nan()
    }
}

/// A metric as JSON has it: a number, or `null` for none (NaN).
pub(crate) fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// One finished (or stopped) run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunResult {
    pub name: String,
    /// The paper's Table-1 case the run reproduces ([`crate::scenario::SimConfig::case`]).
    #[serde(skip)]
    pub case: Option<Table1Case>,
    /// Whether Δu was on.
    pub robust: bool,
    pub outcome: Outcome,
    pub metrics: Metrics,
    /// The periods in fail-safe, per status.
    pub faults: FaultCounts,
    /// The scenario expects faults ([`crate::scenario::SimConfig::expect_faults`]): they are
    /// reported but do not fail the command.
    pub faults_expected: bool,
    /// The scenario expects to miss its bound ([`crate::scenario::SimConfig::expect_missed`]):
    /// the miss is reported but does not fail the command.
    pub miss_expected: bool,
    /// A waypoint run whose end is not its path's: the waypoints it never reached, or how long
    /// before it the path ended ([`crate::scenario::path_time::run_note`], Choice 312).
    pub path: Option<String>,
    /// The samples the plots draw: every sample of a run of at most
    /// [`super::decimate::PLOT_SAMPLES`] periods, else a decimated series (see
    /// [`super::decimate`]). The CSV has every period (it is written as the run goes).
    #[serde(skip)]
    pub samples: Vec<Sample>,
    /// How many times the plant formed and factorised M(p) ([`crate::plant::Plant::set_params`]):
    /// once per distinct parameter set the run met, not once per step.
    #[serde(skip)]
    pub plant_factorisations: u64,
}

/// A run as the commands report it in JSON (`--json`): `{"case": name, "robust", the
/// [`Metrics`] fields, "diverged": {"t", "reason"} if it diverged, "lost_board": {"t", "cause",
/// "reason"} if it lost its board}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// The run's name ([`RunResult::name`]).
    #[serde(rename = "case")]
    pub name: String,
    pub robust: bool,
    #[serde(flatten)]
    pub metrics: Metrics,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diverged: Option<Divergence>,
    /// When, how and why the run lost its board, if it did (PIL, HIL).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lost_board: Option<LostBoard>,
    /// The time the run was interrupted at (Ctrl-C), if it was: its metrics cover [0, t).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<f64>,
    /// Why the run missed its bound, if it did (which limit, by how much).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub missed: Option<String>,
    /// Whether the scenario expected the miss.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub miss_expected: bool,
    /// The periods in fail-safe, per status (`{"periods": {}, "first_t": null}` for none).
    #[serde(default)]
    pub faults: FaultCounts,
    /// Whether the scenario expected faults.
    #[serde(default)]
    pub faults_expected: bool,
    /// A waypoint run whose end is not its path's ([`RunResult::path`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
}

/// When and why a run stopped early ([`Outcome::Diverged`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Divergence {
    pub t: f64,
    pub reason: String,
}

/// When, how and why a run lost its board ([`Outcome::LostBoard`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LostBoard {
    pub t: f64,
    pub cause: BoardLoss,
    pub reason: String,
}

impl RunResult {
    /// The run's [`RunSummary`].
    pub fn summary(&self) -> RunSummary {
        RunSummary {
            name: self.name.clone(),
            robust: self.robust,
            metrics: self.metrics,
            diverged: match &self.outcome {
                Outcome::Diverged { t, reason } => Some(Divergence {
                    t: *t,
                    reason: reason.clone(),
                }),
                _ => None,
            },
            lost_board: match &self.outcome {
                Outcome::LostBoard { t, cause, reason } => Some(LostBoard {
                    t: *t,
                    cause: *cause,
                    reason: reason.clone(),
                }),
                _ => None,
            },
            interrupted: match self.outcome {
                Outcome::Interrupted { t } => Some(t),
                _ => None,
            },
            missed: match &self.outcome {
                Outcome::Missed { reason } => Some(reason.clone()),
                _ => None,
            },
            miss_expected: self.miss_expected,
            faults: self.faults.clone(),
            faults_expected: self.faults_expected,
            path: self.path.clone(),
        }
    }

    /// True if the run stopped early because it diverged.
    pub fn diverged(&self) -> bool {
        matches!(self.outcome, Outcome::Diverged { .. })
    }

    /// True if the run stopped early because it lost its board.
    pub fn lost_board(&self) -> bool {
        matches!(self.outcome, Outcome::LostBoard { .. })
    }

    /// True if the run was interrupted (its outputs are partial).
    pub fn interrupted(&self) -> bool {
        matches!(self.outcome, Outcome::Interrupted { .. })
    }

    /// True if the run ended outside its bound.
    pub fn missed(&self) -> bool {
        matches!(self.outcome, Outcome::Missed { .. })
    }

    /// True if the run missed its bound and the scenario did not expect it.
    pub fn missed_unexpectedly(&self) -> bool {
        self.missed() && !self.miss_expected
    }

    /// True if the controller was in fail-safe in some period and the scenario did not expect
    /// it.
    pub fn faulted_unexpectedly(&self) -> bool {
        !self.faults.is_empty() && !self.faults_expected
    }

    /// "with Δu" or "without Δu", from [`RunResult::robust`]: the label of the run in tables,
    /// plots and file names.
    pub fn du_label(&self) -> &'static str {
        du_label(self.robust)
    }

    /// `with` or `without` ([`RunResult::robust`]): the suffix of the run's CSV,
    /// `{name}-with.csv`.
    pub fn du_suffix(&self) -> &'static str {
        du_suffix(self.robust)
    }
}

/// `with` (robust) or `without`: how file names say whether Δu was on.
pub fn du_suffix(robust: bool) -> &'static str {
    if robust {
        "with"
    } else {
        "without"
    }
}

/// "with Δu" (robust) or "without Δu".
pub fn du_label(robust: bool) -> &'static str {
    if robust {
        "with Δu"
    } else {
        "without Δu"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that lost its board is its own outcome, not a divergence: its summary (and JSON)
    /// has `lost_board` with the cause in kebab-case and no `diverged`, and its outcome prints
    /// on one line.
    #[test]
    fn a_lost_board_is_not_a_divergence_in_the_summary_and_json() {
        let reason = "the board's link went away (Broken pipe):\n  the port was unplugged";
        let run = RunResult {
            name: "lost".to_string(),
            case: None,
            robust: true,
            outcome: Outcome::LostBoard {
                t: 3.0,
                cause: BoardLoss::LinkGone,
                reason: reason.to_string(),
            },
            metrics: Metrics::NONE,
            faults: FaultCounts::default(),
            faults_expected: false,
            miss_expected: false,
            path: None,
            samples: Vec::new(),
            plant_factorisations: 0,
        };
        assert!(run.lost_board() && !run.diverged() && !run.interrupted());
        let json = serde_json::to_value(run.summary()).expect("a summary serialises");
        assert_eq!(json.get("diverged"), None);
        assert_eq!(json["lost_board"]["cause"], "link-gone");
        assert_eq!(json["lost_board"]["t"], 3.0);
        assert_eq!(json["lost_board"]["reason"], reason);
        let back: RunSummary = serde_json::from_value(json).expect("and reads back");
        assert_eq!(back.lost_board.map(|l| l.cause), Some(BoardLoss::LinkGone));
        let shown = run.outcome.to_string();
        assert!(!shown.contains('\n'), "{shown}");
        assert!(
            shown.starts_with("LOST THE BOARD at t = 3.00 s: "),
            "{shown}"
        );
    }

    /// The name table is the struct's: each name is the key serde writes for the value at the
    /// same index (distinct values, so a swapped or misspelt name cannot pass); the only other
    /// key is the per-thruster `chatter`.
    #[test]
    fn metric_names_are_the_json_keys_in_the_order_of_values() {
        let m = Metrics {
            max_x: 1.0,
            max_y: 2.0,
            max_z: 3.0,
            max_path: 4.0,
            rms_path: 5.0,
            max_roll: 6.0,
            max_pitch: 7.0,
            max_yaw: 8.0,
            peak_voltage: 9.0,
            saturated_fraction: 10.0,
            reversals_per_s: 11.0,
            command_tv: 12.0,
            hf_share: 13.0,
            chatter: Chatter::NONE,
        };
        let json = serde_json::to_value(m).expect("metrics serialise");
        let object = json.as_object().expect("an object");
        assert_eq!(object.len(), Metrics::NAMES.len() + 1);
        assert!(object["chatter"].is_object());
        for (name, value) in Metrics::NAMES.iter().zip(m.values()) {
            assert_eq!(object[*name].as_f64(), Some(value), "{name}");
        }
    }
}
