//! One [`ControllerConfig`] with the paper's defaults, validated once into a
//! [`Controller`](crate::controller::Controller).
//!
//! Validation is where every configuration-time number is computed (P, ‖K‖, the bounds over the
//! Table-3 box, the allocation inverse) and every check of the paper and of docs/law.md#configuration-checks
//! is made. A failed check is a [`ConfigError`] that names the check and its numbers; a
//! configuration is never run silently out of its assumptions.

use core::fmt;

use crate::allocation::{AllocationError, AxisPriority};
use crate::axes::{ACTUATED, ROLL};
use crate::effectiveness::ThrusterGeometry;
use crate::estimator::{EstimatorConfig, EstimatorKind};
use crate::law::RobustLaw;
use crate::model::VehicleParams;
use crate::readable::Readable;
use crate::thruster::ThrustUnit;
use crate::uncertainty::{BoundsError, ParamBox};

/// Which bound on ‖b‖ = ‖M̄⁻¹‖ enters δ(e,t) (docs/law.md#the-uncertainty-bound-eq-29 **Choice**).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BBound {
    /// c_b · max(1, 1/|cos θ|) with c_b = sup‖S₀ M(p)⁻¹‖₂ over the controlled rows u, v, w, q, r.
    /// δ stays in single digits on the paper's missions (`cargo run -p controller-core
    /// --example track` prints it); the default.
    ControlledRows,
    /// The literal ‖M̄⁻¹‖ ≤ sup‖M(p)⁻¹‖₂ · max(1, 1/cos²θ): dominated by the unactuated roll
    /// inertia (17.1 kg m²), it gives δ ≈ 200, far more thrust demand and chattering, and needs a
    /// loop of ≈ 150 Hz or a δ clamp (docs/law.md#the-δ-clamp). Offered for comparison with the paper's derivation.
    Literal,
}

/// Everything the law needs, with the paper's values as [`Default`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControllerConfig {
    /// K₁ = diag(ω²ᵢ) of Eq (17). Paper: diag(4, 4, 4, 0, 4, 4). Roll must be 0.
    pub k1: [f32; 6],
    /// K₂ = diag(2ωᵢ) of Eq (17). Paper: diag(4, 4, 4, 0, 4, 4). Roll must be 0.
    pub k2: [f32; 6],
    /// Per-axis Q = diag(q₁, q₂) of the Lyapunov equation (Theorem 3). Default (1, 1).
    pub q: [f32; 2],
    /// β of Assumption 2 and Eq (29). Paper: 0.605.
    pub beta: f32,
    /// Boundary-layer width μ of Eq (30). Paper: 0.1.
    pub mu: f32,
    /// Theorem 3 or Theorem 4 (default).
    pub law: RobustLaw,
    /// Add Δu at all (false: u = ū only, the paper's "without Δu" column).
    pub robust: bool,
    /// Which ‖b‖ bound enters δ.
    pub b_bound: BBound,
    /// Clamp on δ (docs/law.md#the-δ-clamp): δ grows with ‖e‖, so an off-path start would ask for tens of
    /// kN. The output reports when the clamp is active. Default 25.
    pub delta_max: f32,
    /// Control-loop rate (Hz). Time is `ticks / rate_hz`. Default 100.
    pub rate_hz: u32,
    /// |θ| beyond which the law faults instead of computing through the singularity of J
    /// (docs/law.md#the-sampled-f32-loop), radians. Default 80°.
    pub pitch_limit: f32,
    /// Thruster supply limit: voltages are clamped to ±`voltage_limit` (V). Default
    /// [`DEFAULT_V_LIMIT`](crate::DEFAULT_V_LIMIT), the board's 24 V supply.
    pub voltage_limit: f32,
    /// Nominal model (the hats of Eq 7).
    pub params: VehicleParams<f32>,
    /// Parameter box the bounds are taken over (Table 3).
    pub uncertainty: ParamBox<f32>,
    /// Thruster positions and directions, the direction carrying each thruster's mounting
    /// sign (docs/thrusters.md#geometry-and-the-effectiveness-matrix, docs/real-vehicle.md#the-default-mounting **Choice 105**: the real AUV-150's, the vertical pair's
    /// strong sides pushing up fore and down aft, the horizontal pair's to port).
    pub geometry: ThrusterGeometry,
    /// The thrust unit of Eqs 31–32 (docs/thrusters.md#the-thrust-unit **Choice**: kgf by default).
    pub thrust_unit: ThrustUnit,
    /// Which forces the saturation-aware allocator gives up first (docs/thrusters.md#allocation-blocks-and-the-axis-priority
    /// **Choice**: pitch, depth, yaw, sway, surge, highest first).
    pub priority: AxisPriority,
    /// The state estimator the law flies on (docs/law.md#the-state-estimator **Choice 340**):
    /// off by default, so the law is given the navigation solution as it arrives.
    pub estimator: EstimatorConfig,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        ControllerConfig {
            k1: [4.0, 4.0, 4.0, 0.0, 4.0, 4.0],
            k2: [4.0, 4.0, 4.0, 0.0, 4.0, 4.0],
            q: [1.0, 1.0],
            beta: 0.605,
            mu: 0.1,
            law: RobustLaw::BoundaryLayer,
            robust: true,
            b_bound: BBound::ControlledRows,
            delta_max: 25.0,
            rate_hz: 100,
            pitch_limit: 80.0_f32.to_radians(),
            voltage_limit: crate::DEFAULT_V_LIMIT,
            params: VehicleParams::auv150().cast(|x| x as f32),
            uncertainty: ParamBox::table3().cast(|x| x as f32),
            geometry: ThrusterGeometry::default(),
            thrust_unit: ThrustUnit::Kgf,
            priority: AxisPriority::default(),
            estimator: EstimatorConfig::default(),
        }
    }
}

/// A failed configuration check, with its numbers.
///
/// A check of one setting names it: [`ConfigError::field`] gives the [`ControllerConfig`] field
/// (and element), e.g. `mu` or `k1[4]`, so a front end can point at its own key for it (a
/// scenario file's `controller.mu`) without repeating the check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConfigError {
    /// A gain of a controlled axis is not finite and positive (K₁ and K₂ must make Ā Hurwitz).
    /// `name` is the field, `"k1"` or `"k2"`.
    Gain {
        name: &'static str,
        axis: usize,
        value: f32,
    },
    /// Roll is not actuated: the paper's K₁₄ = K₂₄ = 0 is required.
    RollGain { k1: f32, k2: f32 },
    /// Q = diag(q₁, q₂) must be positive definite: `q[index]` is not finite and positive.
    LyapunovWeight { index: usize, value: f32 },
    /// A setting that must be finite and > 0 is not (`mu`, `delta_max`, `voltage_limit`).
    NotPositive { name: &'static str, value: f32 },
    /// A setting outside its open interval (`beta` ∈ (0, 1)).
    OutOfRange {
        name: &'static str,
        value: f32,
        min: f32,
        max: f32,
    },
    /// `pitch_limit` (rad) outside (0, π/2): the law must fault before J's singularity at 90°.
    PitchLimit { value: f32 },
    /// Loop rate of zero.
    ZeroRate,
    /// Nominal parameters contain a non-finite value.
    NonFiniteParams,
    /// The parameter box is not finite or has lower > upper somewhere.
    InvalidBox,
    /// The bounds over the box could not be computed.
    Bounds(BoundsError),
    /// Assumption 2 (Eq 20): β̂ = sup‖S₀(M(p)⁻¹M₀ − I)‖ must be < 1 and ≤ β.
    Assumption2 { beta_hat: f32, beta: f32 },
    /// Theorem 2 (Eq 25) as printed: λmaxλmin/(λmin − λmax) < λmin + λmin(ΔM).
    Theorem2 { lhs: f32, rhs: f32 },
    /// docs/law.md#the-loop-rate-rule: inside the boundary layer Δu is a gain δ/μ; the sampled loop needs
    /// T·(k₂ + p₂₂ δ_max/μ) < 2 on every controlled axis.
    LoopRate {
        axis: usize,
        period: f32,
        max_period: f32,
        delta_max: f32,
        mu: f32,
    },
    /// Thruster geometry rejected.
    Allocation(AllocationError),
    /// An estimator noise setting (`estimator_position_sigma`, `estimator_velocity_sigma`,
    /// `estimator_accel_sigma`) of `axis` is not finite and > 0.
    EstimatorSigma {
        name: &'static str,
        axis: usize,
        value: f32,
    },
    /// The estimator's Riccati equation has no steady state on `axis` at this rate.
    EstimatorGain { axis: usize },
    /// The bounds given to `Controller::with_bounds` are of other vehicle parameters or
    /// another box than the configuration's (Choice 363).
    BoundsOfAnotherBox,
}

/// The [`ControllerConfig`] field a [`ConfigError`] is about: `name` is the field's name,
/// `index` the element of an array field (`k1[4]`: name `"k1"`, index `Some(4)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConfigField {
    pub name: &'static str,
    pub index: Option<usize>,
}

impl ConfigError {
    /// The one field the failed check is about; `None` for checks of the configuration as a
    /// whole (Assumption 2, Theorem 2, the loop rate against δ_max/μ).
    pub fn field(&self) -> Option<ConfigField> {
        let (name, index) = match *self {
            ConfigError::Gain { name, axis, .. } => (name, Some(axis)),
            ConfigError::RollGain { k1, .. } => (if k1 != 0.0 { "k1" } else { "k2" }, Some(ROLL)),
            ConfigError::LyapunovWeight { index, .. } => ("q", Some(index)),
            ConfigError::NotPositive { name, .. } | ConfigError::OutOfRange { name, .. } => {
                (name, None)
            }
            ConfigError::PitchLimit { .. } => ("pitch_limit", None),
            ConfigError::ZeroRate => ("rate_hz", None),
            ConfigError::NonFiniteParams => ("params", None),
            ConfigError::InvalidBox | ConfigError::Bounds(_) | ConfigError::BoundsOfAnotherBox => {
                ("uncertainty", None)
            }
            ConfigError::Allocation(AllocationError::Weight { axis, .. }) => {
                ("priority", Some(axis))
            }
            ConfigError::Allocation(AllocationError::ThrustEnvelope { .. }) => {
                ("voltage_limit", None)
            }
            ConfigError::Allocation(_) => ("geometry", None),
            ConfigError::EstimatorSigma { name, axis, .. } => (name, Some(axis)),
            ConfigError::EstimatorGain { axis } => ("estimator_accel_sigma", Some(axis)),
            ConfigError::Assumption2 { .. }
            | ConfigError::Theorem2 { .. }
            | ConfigError::LoopRate { .. } => return None,
        };
        Some(ConfigField { name, index })
    }
}

impl From<BoundsError> for ConfigError {
    fn from(e: BoundsError) -> Self {
        ConfigError::Bounds(e)
    }
}

impl From<AllocationError> for ConfigError {
    fn from(e: AllocationError) -> Self {
        ConfigError::Allocation(e)
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ConfigError::Gain { name, axis, value } => write!(
                f,
                "gain {name}[{axis}] must be a finite number > 0 on a controlled axis, got {}", Readable(value)
            ),
            ConfigError::RollGain { k1, k2 } => write!(
                f,
                "roll is not actuated: gains k1[{ROLL}] and k2[{ROLL}] must both be 0, got {} and {}", Readable(k1), Readable(k2)
            ),
            ConfigError::LyapunovWeight { index, value } => write!(
                f,
                "Lyapunov weight q[{index}] must be a finite number > 0 (Q positive definite), got {}", Readable(value)
            ),
            ConfigError::NotPositive { name, value } => {
                write!(f, "{name} must be a finite number > 0, got {}", Readable(value))
            }
            ConfigError::OutOfRange {
                name,
                value,
                min,
                max,
            } => write!(
                f,
                "{name} must be in ({}, {}), got {}",
                Readable(min),
                Readable(max),
                Readable(value)
            ),
            ConfigError::PitchLimit { value } => write!(
                f,
                "pitch_limit must be in (0°, 90°), got {}° ({} rad)",
                Readable(value.to_degrees()),
                Readable(value)
            ),
            ConfigError::ZeroRate => write!(f, "rate_hz must be ≥ 1 Hz, got 0"),
            ConfigError::NonFiniteParams => write!(f, "nominal vehicle parameters are not finite"),
            ConfigError::InvalidBox => {
                write!(f, "parameter box is not finite or has lower > upper")
            }
            ConfigError::BoundsOfAnotherBox => f.write_str(BOUNDS_OF_ANOTHER_BOX),
            ConfigError::Bounds(BoundsError::MassNotPositiveDefinite {
                corner,
                min_eigenvalue,
            }) => write!(
                f,
                "M(p) is not positive definite at box corner {corner} (λmin = {min_eigenvalue})"
            ),
            ConfigError::Bounds(BoundsError::EigenSolver) => {
                write!(f, "eigen-solver failed on the parameter box")
            }
            ConfigError::Assumption2 { beta_hat, beta } => write!(
                f,
                "Assumption 2 (Eq 20) fails: β̂ = sup‖M(p)⁻¹M₀ − I‖ = {beta_hat} must be < 1 and ≤ β = {beta}"
            ),
            ConfigError::Theorem2 { lhs, rhs } => write!(
                f,
                "Theorem 2 (Eq 25) fails: λmaxλmin/(λmin − λmax) = {lhs} is not < λmin + λmin(ΔM) = {rhs}"
            ),
            ConfigError::LoopRate {
                axis,
                period,
                max_period,
                delta_max,
                mu,
            } => write!(
                f,
                "loop period {} s is too long for axis {axis}: with δ_max = {} and μ = {} the boundary-layer gain needs T < {} s (docs/law.md#the-loop-rate-rule)",
                Readable(period),
                Readable(delta_max),
                Readable(mu),
                Readable(max_period)
            ),
            ConfigError::Allocation(e) => write!(f, "thruster allocation: {e}"),
            ConfigError::EstimatorSigma { .. }
            | ConfigError::EstimatorGain { .. } => self.fmt_estimator(f),
        }
    }
}

impl ConfigError {
    /// The estimator's errors, in words.
    fn fmt_estimator(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ConfigError::EstimatorSigma { name, axis, value } => write!(
                f,
                "{name}[{axis}] must be a finite number > 0, got {}",
                Readable(value)
            ),
            ConfigError::EstimatorGain { axis } => write!(
                f,
                "the estimator's Riccati equation has no steady state on axis {axis} with these noise settings"
            ),
            _ => Ok(()),
        }
    }
}

/// [`ConfigError::BoundsOfAnotherBox`] in words.
const BOUNDS_OF_ANOTHER_BOX: &str =
    "the bounds given are of other vehicle parameters or another box than the configuration's";

/// A finite value > 0.
fn positive(name: &'static str, value: f32) -> Result<(), ConfigError> {
    // NaN fails the comparison; +∞ is not finite.
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::NotPositive { name, value })
    }
}

impl ControllerConfig {
    /// Checks of the scalar settings that need no model (the model checks live in
    /// [`crate::controller::Controller::new`]).
    pub(crate) fn check_scalars(&self) -> Result<(), ConfigError> {
        for &axis in ACTUATED.iter() {
            for (name, k) in [("k1", self.k1[axis]), ("k2", self.k2[axis])] {
                if !(k.is_finite() && k > 0.0) {
                    return Err(ConfigError::Gain {
                        name,
                        axis,
                        value: k,
                    });
                }
            }
        }
        if self.k1[ROLL] != 0.0 || self.k2[ROLL] != 0.0 {
            return Err(ConfigError::RollGain {
                k1: self.k1[ROLL],
                k2: self.k2[ROLL],
            });
        }
        for (index, &value) in self.q.iter().enumerate() {
            if !(value.is_finite() && value > 0.0) {
                return Err(ConfigError::LyapunovWeight { index, value });
            }
        }
        // Open intervals; NaN fails every comparison.
        if !(self.beta > 0.0 && self.beta < 1.0) {
            return Err(ConfigError::OutOfRange {
                name: "beta",
                value: self.beta,
                min: 0.0,
                max: 1.0,
            });
        }
        positive("mu", self.mu)?;
        positive("delta_max", self.delta_max)?;
        if !(self.pitch_limit > 0.0 && self.pitch_limit < core::f32::consts::FRAC_PI_2) {
            return Err(ConfigError::PitchLimit {
                value: self.pitch_limit,
            });
        }
        positive("voltage_limit", self.voltage_limit)?;
        if self.rate_hz == 0 {
            return Err(ConfigError::ZeroRate);
        }
        if !self.params.is_finite() {
            return Err(ConfigError::NonFiniteParams);
        }
        if !self.uncertainty.is_valid() {
            return Err(ConfigError::InvalidBox);
        }
        if self.estimator.kind != EstimatorKind::Off {
            let e = &self.estimator;
            for (name, sigma) in [
                ("estimator_position_sigma", &e.position_sigma),
                ("estimator_velocity_sigma", &e.velocity_sigma),
                ("estimator_accel_sigma", &e.accel_sigma),
            ] {
                for (axis, &value) in sigma.iter().enumerate() {
                    if !(value.is_finite() && value > 0.0) {
                        return Err(ConfigError::EstimatorSigma { name, axis, value });
                    }
                }
            }
        }
        Ok(())
    }
}
