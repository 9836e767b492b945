//! One [`ControllerConfig`] with the paper's defaults, validated once into a
//! [`Controller`](crate::controller::Controller).
//!
//! Validation is where every configuration-time number is computed (P, ‖K‖, the bounds over the
//! Table-3 box, the allocation inverse) and every check of the paper and of AUV150.md §4 and §8
//! is made. A failed check is a [`ConfigError`] that names the check and its numbers; a
//! configuration is never run silently out of its assumptions.

use core::fmt;

use crate::allocation::AllocationError;
use crate::effectiveness::ThrusterGeometry;
use crate::law::{RobustLaw, CONTROLLED, ROLL};
use crate::model::VehicleParams;
use crate::uncertainty::{BoundsError, ParamBox};

/// Which bound on ‖b‖ = ‖M̄⁻¹‖ enters δ(e,t) (AUV150.md §4 **Choice**).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BBound {
    /// c_b · max(1, 1/|cos θ|) with c_b = sup‖S₀ M(p)⁻¹‖₂ over the controlled rows u, v, w, q, r.
    /// δ ≈ 4–7 on the paper's missions; the default.
    ControlledRows,
    /// The literal ‖M̄⁻¹‖ ≤ sup‖M(p)⁻¹‖₂ · max(1, 1/cos²θ): dominated by the unactuated roll
    /// inertia (17.1 kg m²), it gives δ ≈ 200, far more thrust demand and chattering, and needs a
    /// loop of ≈ 150 Hz or a δ clamp (§8). Offered for comparison with the paper's derivation.
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
    /// Clamp on δ (AUV150.md §8): δ grows with ‖e‖, so an off-path start would ask for tens of
    /// kN. The output reports when the clamp is active. Default 25.
    pub delta_max: f32,
    /// Control-loop rate (Hz). Time is `ticks / rate_hz`. Default 100.
    pub rate_hz: u32,
    /// |θ| beyond which the law faults instead of computing through the singularity of J
    /// (AUV150.md §8), radians. Default 80°.
    pub pitch_limit: f32,
    /// Thruster supply limit: voltages are clamped to ±`voltage_limit` (V). Default 24.
    pub voltage_limit: f32,
    /// Nominal model (the hats of Eq 7).
    pub params: VehicleParams<f32>,
    /// Parameter box the bounds are taken over (Table 3).
    pub uncertainty: ParamBox<f32>,
    /// Thruster positions and directions (AUV150.md §5 **Choice**).
    pub geometry: ThrusterGeometry,
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
            voltage_limit: 24.0,
            params: VehicleParams::auv150().cast(|x| x as f32),
            uncertainty: ParamBox::table3().cast(|x| x as f32),
            geometry: ThrusterGeometry::default(),
        }
    }
}

/// A failed configuration check, with its numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConfigError {
    /// A gain of a controlled axis is not finite and positive (K₁ and K₂ must make Ā Hurwitz).
    Gain {
        name: &'static str,
        axis: usize,
        value: f32,
    },
    /// Roll is not actuated: the paper's K₁₄ = K₂₄ = 0 is required.
    RollGain { k1: f32, k2: f32 },
    /// Q must be positive definite.
    LyapunovWeight { q1: f32, q2: f32 },
    /// A scalar out of its range (β ∈ (0,1), μ > 0, δ_max > 0, 0 < pitch limit < 90°, …).
    OutOfRange {
        name: &'static str,
        value: f32,
        min: f32,
        max: f32,
    },
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
    /// AUV150.md §8: inside the boundary layer Δu is a gain δ/μ; the sampled loop needs
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
                "gain {name}[{axis}] = {value}: controlled axes need a finite gain > 0"
            ),
            ConfigError::RollGain { k1, k2 } => write!(
                f,
                "roll gains K1[3] = {k1}, K2[3] = {k2}: roll is not actuated, both must be 0"
            ),
            ConfigError::LyapunovWeight { q1, q2 } => {
                write!(f, "Lyapunov weight Q = diag({q1}, {q2}) must be positive definite")
            }
            ConfigError::OutOfRange {
                name,
                value,
                min,
                max,
            } => write!(f, "{name} = {value} is outside ({min}, {max})"),
            ConfigError::ZeroRate => write!(f, "loop rate is 0 Hz"),
            ConfigError::NonFiniteParams => write!(f, "nominal vehicle parameters are not finite"),
            ConfigError::InvalidBox => {
                write!(f, "parameter box is not finite or has lower > upper")
            }
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
                "loop period {period} s is too long for axis {axis}: with δ_max = {delta_max} and μ = {mu} the boundary-layer gain needs T < {max_period} s (AUV150.md §8)"
            ),
            ConfigError::Allocation(e) => write!(f, "thruster allocation: {e:?}"),
        }
    }
}

fn range(name: &'static str, value: f32, min: f32, max: f32) -> Result<(), ConfigError> {
    // Open interval; NaN fails every comparison.
    if value > min && value < max {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            name,
            value,
            min,
            max,
        })
    }
}

impl ControllerConfig {
    /// Checks of the scalar settings that need no model (the model checks live in
    /// [`crate::controller::Controller::new`]).
    pub(crate) fn check_scalars(&self) -> Result<(), ConfigError> {
        for &axis in CONTROLLED.iter() {
            for (name, k) in [("K1", self.k1[axis]), ("K2", self.k2[axis])] {
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
        let [q1, q2] = self.q;
        if !(q1.is_finite() && q2.is_finite() && q1 > 0.0 && q2 > 0.0) {
            return Err(ConfigError::LyapunovWeight { q1, q2 });
        }
        range("beta", self.beta, 0.0, 1.0)?;
        range("mu", self.mu, 0.0, f32::MAX)?;
        range("delta_max", self.delta_max, 0.0, f32::MAX)?;
        range(
            "pitch_limit",
            self.pitch_limit,
            0.0,
            core::f32::consts::FRAC_PI_2,
        )?;
        range("voltage_limit", self.voltage_limit, 0.0, f32::MAX)?;
        if self.rate_hz == 0 {
            return Err(ConfigError::ZeroRate);
        }
        if !self.params.is_finite() {
            return Err(ConfigError::NonFiniteParams);
        }
        if !self.uncertainty.is_valid() {
            return Err(ConfigError::InvalidBox);
        }
        Ok(())
    }
}
