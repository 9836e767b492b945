//! What a run leaves behind: one [`Sample`] per control period, the outcome, and the metrics.

use serde::Serialize;

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
    pub thrust: [f64; 5],
    /// Voltage per thruster from the controller (V), clamped to the supply limit.
    pub voltage: [f64; 5],
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
    /// Controller status ("ok" or the fault).
    pub status: &'static str,
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
}

/// The paper's Table-1 metrics (AUV150.md §7) and the actuator figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Metrics {
    pub max_x: f64,
    pub max_y: f64,
    pub max_z: f64,
    /// √(max|e_x|² + max|e_y|² + max|e_z|²), the paper's "path" error.
    pub max_path: f64,
    /// √(mean(e_x² + e_y² + e_z²)).
    pub rms_path: f64,
    pub max_roll: f64,
    pub max_pitch: f64,
    pub max_yaw: f64,
    /// Largest |V| any thruster was commanded (V).
    pub peak_voltage: f64,
    /// Fraction of control periods with at least one thruster saturated.
    pub saturated_fraction: f64,
}

/// One finished (or stopped) run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunResult {
    pub name: String,
    /// Whether Δu was on.
    pub robust: bool,
    pub outcome: Outcome,
    pub metrics: Metrics,
    #[serde(skip)]
    pub samples: Vec<Sample>,
}
