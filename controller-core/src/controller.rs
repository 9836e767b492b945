//! [`Controller`]: a validated configuration and its precomputed constants, and
//! [`Controller::update`], one step of the sampled robust law.
//!
//! `update` does a fixed amount of work (no loop whose length depends on data, no allocation)
//! and never panics. Any non-finite or implausible input, a pitch beyond the configured limit,
//! or a non-finite intermediate result gives the fail-safe output — all thrusters off — with a
//! [`Status`] that says why. Nothing non-finite ever leaves it.

use nalgebra::{Matrix6, Vector6};

use crate::allocation::{Allocated, Allocator, PseudoInverse};
use crate::axes::ACTUATED;
use crate::config::{BBound, ConfigError, ControllerConfig};
use crate::effectiveness::THRUSTERS;
use crate::estimator::{self, Estimate, EstimatorGains, EstimatorKind, Period, StateAt};
use crate::kinematics::{Attitude, Kinematics};
use crate::law::{self, AxisLyapunov, DeltaConstants, DeltaInputs, RobustLaw};
use crate::math::times_zero;
use crate::model::{self, VehicleParams};
use crate::thruster::{self, Actuation, ThrustEnvelope, ThrusterMap};
use crate::trajectory::{Desired, Trajectory};
use crate::uncertainty::UncertaintyBounds;

/// Largest |position| accepted (m). Positions are relative to a mission origin near the
/// vehicle (docs/numerics.md#positions): f32 keeps ≈ 1 mm at 10 km.
pub const MAX_POSITION: f32 = 10_000.0;
/// Largest |Euler angle| accepted (rad). Angles are wrapped internally; this only rejects
/// absurd values.
pub const MAX_ANGLE: f32 = 1_000.0;
/// Largest |linear velocity| accepted (m/s); the AUV-150 cruises at ≈ 2 m/s.
pub const MAX_LINEAR_SPEED: f32 = 50.0;
/// Largest |angular velocity| accepted (rad/s).
pub const MAX_ANGULAR_RATE: f32 = 50.0;
// Choice 310: a waypoint corner flown at any path speed turns the heading at most at
// MAX_SPEED/MIN_TURN_RADIUS (|ψ′| ≤ 1/R, `Route::peak_heading_rate`), inside the rate accepted
// above, so no corner can put the law in fail-safe.
const _: () =
    assert!(crate::trajectory::MAX_SPEED / crate::trajectory::MIN_TURN_RADIUS <= MAX_ANGULAR_RATE);

/// Why the output is the fail-safe one.
///
/// The discriminant is the fault's **code** ([`Fault::code`]), the byte the board reports in
/// its telemetry (`auv_link::Telemetry::controller_fault`; 0 means no fault). The codes are
/// part of the link protocol: never renumber them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Fault {
    /// η or ν contains NaN or ±∞.
    NonFiniteInput = 1,
    /// η or ν is finite but outside the plausible range (see the `MAX_*` constants).
    InputOutOfRange = 2,
    /// |θ| beyond the configured pitch limit (J is singular at ±90°, docs/law.md#the-sampled-f32-loop).
    PitchLimit = 3,
    /// An intermediate result was not finite (overflow on extreme but accepted inputs).
    NonFiniteResult = 4,
}

/// Outcome of one `update`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// The law ran; see the flags in [`Output`] for δ clamping and saturation.
    Ok,
    /// Fail-safe: every thruster off.
    Fault(Fault),
}

/// The names of the faults, once: [`Fault::as_str`] and, with the `fault:` prefix,
/// [`Status::as_str`] (the simulator's CSV `status` column) both come from this list.
macro_rules! fault_names {
    ($($variant:ident => $name:literal),+ $(,)?) => {
        impl Fault {
            /// Every fault, in code order.
            pub const ALL: [Fault; [$(Fault::$variant),+].len()] = [$(Fault::$variant),+];

            /// Stable kebab-case name, e.g. `"pitch-limit"`.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $(Fault::$variant => $name,)+
                }
            }

            /// The fault from its [`code`](Self::code); `None` for 0 (no fault) and unknown
            /// codes.
            pub const fn from_code(code: u8) -> Option<Fault> {
                $(if code == Fault::$variant as u8 {
                    return Some(Fault::$variant);
                })+
                None
            }
        }

        impl Status {
            /// `"ok"` or `"fault:"` and the fault's name, e.g. `"fault:pitch-limit"`.
            pub const fn as_str(self) -> &'static str {
                match self {
                    Status::Ok => "ok",
                    $(Status::Fault(Fault::$variant) => concat!("fault:", $name),)+
                }
            }
        }
    };
}

fault_names! {
    NonFiniteInput => "non-finite-input",
    InputOutOfRange => "input-out-of-range",
    PitchLimit => "pitch-limit",
    NonFiniteResult => "non-finite-result",
}

impl Fault {
    /// The fault's code on the link (its discriminant, 1…): what the board puts in
    /// `Telemetry::controller_fault`.
    pub const fn code(self) -> u8 {
        self as u8
    }
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl core::fmt::Display for Status {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Everything one step produces. All fields are finite, always.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    pub status: Status,
    /// Commanded body force τ = [X Y Z K M N] (N, N m). K is not actuated.
    pub tau: [f32; 6],
    /// Body force the thrusters actually give (B · achieved thrusts).
    pub tau_achieved: [f32; 6],
    /// The part of τ the saturation-aware allocator could not give inside the thrusters'
    /// envelopes (τ − B·T over the axes of each block that was not met; zero when every block
    /// was met, and on the unactuated roll row). docs/thrusters.md#allocation-blocks-and-the-axis-priority, docs/thrusters.md#the-chain-end-to-end.
    pub tau_unallocated: [f32; 6],
    /// Achieved thrust per thruster (N), order [main, vert fore, vert aft, horz fore, horz aft].
    pub thrust: [f32; THRUSTERS],
    /// Voltage per thruster (V), within ±voltage_limit.
    pub voltage: [f32; THRUSTERS],
    /// Bit i set: thruster i saturated — it is on a bound of its envelope for a block the
    /// allocator could not meet, or the voltage chain clipped it ([`thruster::actuate`]).
    pub saturated: u8,
    /// δ(e,t) after the clamp, Eq (29). Computed (and reported) also when Δu is off.
    pub delta: f32,
    /// True when the δ clamp (docs/law.md#the-δ-clamp) limited Δu this step (never when Δu is off).
    pub delta_clamped: bool,
    /// ‖w‖ = ‖BᵀPe‖.
    pub w_norm: f32,
    /// η_d this step.
    pub eta_d: [f32; 6],
    /// e₁ = η − η_d (yaw wrapped).
    pub e1: [f32; 6],
    /// The commanded η̈ = ū + Δu (m/s², rad/s²): what the state estimator's model takes as
    /// applied (docs/law.md#the-state-estimator).
    pub u: [f32; 6],
}

impl Output {
    /// The fail-safe output: thrusters off, everything zero, `status` = the fault.
    pub const fn fail_safe(fault: Fault) -> Self {
        Output {
            status: Status::Fault(fault),
            tau: [0.0; 6],
            tau_achieved: [0.0; 6],
            tau_unallocated: [0.0; 6],
            thrust: Actuation::OFF.thrusts,
            voltage: Actuation::OFF.voltages,
            saturated: 0,
            delta: 0.0,
            delta_clamped: false,
            w_norm: 0.0,
            eta_d: [0.0; 6],
            e1: [0.0; 6],
            u: [0.0; 6],
        }
    }
}

/// A validated configuration with everything `update` needs precomputed.
#[derive(Clone, Debug)]
pub struct Controller {
    config: ControllerConfig,
    m_hat: Matrix6<f32>,
    k1: Vector6<f32>,
    k2: Vector6<f32>,
    lyapunov: [AxisLyapunov<f32>; 6],
    delta_constants: DeltaConstants,
    bounds: UncertaintyBounds<f32>,
    allocator: Allocator,
    maps: [ThrusterMap; THRUSTERS],
    cos_pitch_limit: f32,
    /// The estimator's gains and 1/M̂ᵢᵢ for its model (Choice 340); `None`: off, and nothing
    /// of it computed.
    estimator: Option<EstimatorParts>,
}

/// What the estimator flies on: its gains and 1/M̂ᵢᵢ for its model (Choice 340).
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorParts {
    pub gains: EstimatorGains,
    pub m_diag_inv: [f32; 6],
}

/// The suprema over a parameter box ([`UncertaintyBounds`]) with the vehicle parameters and
/// the box they are of: what [`Controller::with_bounds`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxBounds {
    pub params: VehicleParams<f32>,
    pub uncertainty: crate::uncertainty::ParamBox<f32>,
    pub bounds: UncertaintyBounds<f32>,
}

/// The state the law flies on with the estimator on, with J's kinematics there and η̇ = J ν,
/// formed once by the estimator's stages and passed down to the law (Choice 431).
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimated {
    pub eta: [f32; 6],
    pub nu: [f32; 6],
    pub eta_dot: Vector6<f32>,
    pub kin: Kinematics<f32>,
    pub cos_theta_abs: f32,
}

/// What the law's first stage is given: the solution as [`Controller::update`] is told it, or
/// the estimator's state with its kinematics already formed.
enum LawInput<'a> {
    Told { eta: &'a [f32; 6], nu: &'a [f32; 6] },
    Estimated(&'a Estimated),
}

/// What [`Controller::fly`] records its output into with the estimator on: the estimator's
/// parts, its memory and the estimate the law flew ([`Controller::estimator_record_stage`]).
struct Recording<'a> {
    parts: &'a EstimatorParts,
    memory: &'a mut Estimate,
    period: Period,
    est: &'a Estimated,
}

/// Records the stages' results (`applied`; `None`: the fail-safe, nothing applied) when
/// dropped, at the end of [`Controller::fly`].
struct Recorder<'a> {
    recording: Recording<'a>,
    applied: Option<&'a Stepped>,
}

impl Drop for Recorder<'_> {
    #[inline]
    fn drop(&mut self) {
        let r = &mut self.recording;
        let applied = self
            .applied
            .map(|p| (&p.law.u, &p.law.tau, &p.tau_achieved));
        Controller::record_applied(r.parts, r.memory, r.period, r.est, applied);
    }
}

/// The stages' results of one step, before they are assembled into the [`Output`].
#[derive(Clone, Copy)]
struct Stepped {
    eta_d: Vector6<f32>,
    law: StepLaw,
    alloc: Allocated,
    act: Actuation,
    tau_achieved: Vector6<f32>,
}

impl Stepped {
    /// Every field the output takes finite, as a sum of x·0 (Choice 524: zero exactly when
    /// every x is finite), but those the stages have already made finite (**Choice 582**):
    /// τ (the law stage's check); δ (δ_raw checked finite, δ_max finite by the
    /// configuration's checks); the thrusts and voltages ([`thruster::actuate_within`]: every
    /// output finite for a finite voltage limit > 0, which the configuration checks); u, since
    /// J⁻¹ and M̂ (invertible) take every uᵢ into some τⱼ, and ±∞ or NaN times or plus any
    /// value is not finite; and e₁, which enters u through ū = η̈_d − K₁e₁ − K₂e₂ (Eq 17;
    /// the yaw's wrap keeps a non-finite value non-finite). η_d reaches τ the same way through
    /// e₁ but stays in: without it the compiler lays `fly` out anew, 313 instructions dearer.
    #[inline]
    fn finite(&self) -> bool {
        let vectors = [&self.tau_achieved, &self.eta_d];
        let mut zero = (self.law.w_norm * 0.0) + times_zero(&self.alloc.unallocated);
        for v in vectors {
            zero += times_zero(&(*v).into());
        }
        zero == 0.0
    }

    /// The output of these results (`robust`: Δu on, so a δ clamp is reported).
    #[inline]
    fn output(&self, robust: bool) -> Output {
        Output {
            status: Status::Ok,
            tau: self.law.tau.into(),
            tau_achieved: self.tau_achieved.into(),
            tau_unallocated: self.alloc.unallocated,
            thrust: self.act.thrusts,
            voltage: self.act.voltages,
            saturated: self.alloc.saturated | self.act.saturated,
            delta: self.law.delta,
            delta_clamped: robust && self.law.delta_clamped,
            w_norm: self.law.w_norm,
            eta_d: self.eta_d.into(),
            e1: self.law.e1.into(),
            u: self.law.u.into(),
        }
    }
}

/// A navigation solution as the board is told it: η, ν and the tick (mission clock) the
/// solution holds at (`t_ticks` of the link's state frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution {
    pub stamp: u64,
    pub eta: [f32; 6],
    pub nu: [f32; 6],
}

impl Controller {
    /// Validates `config` and precomputes the law's constants. Every check of docs/law.md#configuration-checks
    /// is made here; see [`ConfigError`] for the list.
    pub fn new(config: ControllerConfig) -> Result<Self, ConfigError> {
        Self::build(config, None)
    }

    /// The controller [`Controller::new`] gives for `config`, the same in every bit, reusing
    /// this one's suprema over the parameter box ([`UncertaintyBounds`]) when `config` has the
    /// same vehicle parameters and box: they depend on nothing else, and they are nearly all
    /// of `new`'s cost (2⁹ corners, each with its eigen-decompositions: ≈ 26 M instructions on
    /// the board's Cortex-M4F, ≥ 156 ms at 168 MHz). Every other check is made again.
    ///
    /// **Choice 225:** what a board does when its configuration changes over the link, which
    /// can set the rate, Δu, δ_max, the voltage limit, the thrust unit, the mounting and the
    /// axis priority but never the vehicle or the box: the bounds are computed once, at boot,
    /// before the watchdog starts, and a change costs a fraction of a control period.
    pub fn reconfigure(&self, config: ControllerConfig) -> Result<Self, ConfigError> {
        let same_box =
            config.params == self.config.params && config.uncertainty == self.config.uncertainty;
        Self::build(config, same_box.then_some(self.bounds))
    }

    /// The controller [`Controller::new`] gives for `config`, the same in every bit, with the
    /// suprema over the parameter box given: `bounds` must be those of `config`'s vehicle
    /// parameters and box ([`ConfigError::BoundsOfAnotherBox`] otherwise). Never computes them.
    ///
    /// **Choice 363:** the flying images boot on bounds the firmware's build computed on the
    /// host with this same f32 code (firmware/build.rs), and rebuild with
    /// [`Controller::rebuild`], so no flying image carries the bounds' eigen-solver (≈ 12 kB
    /// of flash) nor spends its ≈ 26 M instructions at boot; the self-test computes them on
    /// the board and requires the very bits the build gave.
    pub fn with_bounds(config: ControllerConfig, bounds: &BoxBounds) -> Result<Self, ConfigError> {
        if config.params != bounds.params || config.uncertainty != bounds.uncertainty {
            return Err(ConfigError::BoundsOfAnotherBox);
        }
        Self::build_on(config, bounds.bounds)
    }

    /// [`Controller::reconfigure`] that never computes the bounds: `config` must have this
    /// controller's vehicle parameters and box ([`ConfigError::BoundsOfAnotherBox`]
    /// otherwise), which every configuration a board's link can set has (Choice 225).
    pub fn rebuild(&self, config: ControllerConfig) -> Result<Self, ConfigError> {
        Self::with_bounds(config, &self.box_bounds())
    }

    /// This controller's bounds with the parameters and box they are of.
    pub fn box_bounds(&self) -> BoxBounds {
        BoxBounds {
            params: self.config.params,
            uncertainty: self.config.uncertainty,
            bounds: self.bounds,
        }
    }

    /// `new`, with the bounds over the box given (`Some`: computed before for the same
    /// parameters and box) or computed here (after the scalar checks).
    fn build(
        config: ControllerConfig,
        bounds: Option<UncertaintyBounds<f32>>,
    ) -> Result<Self, ConfigError> {
        let bounds = match bounds {
            Some(b) => b,
            None => {
                config.check_scalars()?;
                UncertaintyBounds::compute(&config.params, &config.uncertainty)?
            }
        };
        Self::build_on(config, bounds)
    }

    /// `new` on the bounds over the box given: never computes them (so that a flying image
    /// that only calls this carries no eigen-solver, Choice 363).
    fn build_on(
        config: ControllerConfig,
        bounds: UncertaintyBounds<f32>,
    ) -> Result<Self, ConfigError> {
        config.check_scalars()?;
        let allocation = PseudoInverse::new(&config.geometry)?;
        let maps = thruster::default_maps();
        let envelope = ThrustEnvelope::new(&maps, config.thrust_unit, config.voltage_limit);
        let allocator = Allocator::new(&allocation, &envelope, &config.priority)?;

        check_feasible(&bounds, config.beta)?;

        let mut lyapunov = [AxisLyapunov::default(); 6];
        let mut k_norm = 0.0f32;
        for &i in ACTUATED.iter() {
            let (k1, k2) = (config.k1[i], config.k2[i]);
            lyapunov[i] = AxisLyapunov::solve(k1, k2, config.q[0], config.q[1]);
            // ‖[K₁ K₂]‖₂ of diagonal blocks: max over axes of √(k₁² + k₂²).
            k_norm = k_norm.max(libm::sqrtf(k1 * k1 + k2 * k2));
        }

        // docs/law.md#the-loop-rate-rule: Δu inside the boundary layer is the gain δ/μ on w, a closed-loop pole
        // near −(k₂ + p₂₂ δ/μ); forward-Euler sampling of it is stable for T·(…) < 2. The
        // discontinuous law has no such pole (it chatters, bounded by δ), so only the
        // nominal gain is checked for it.
        let period = 1.0 / config.rate_hz as f32;
        for &i in ACTUATED.iter() {
            let layer_gain = match (config.robust, config.law) {
                (true, RobustLaw::BoundaryLayer) => lyapunov[i].p22 * config.delta_max / config.mu,
                _ => 0.0,
            };
            let max_period = 2.0 / (config.k2[i] + layer_gain);
            if period >= max_period {
                return Err(ConfigError::LoopRate {
                    axis: i,
                    period,
                    max_period,
                    delta_max: config.delta_max,
                    mu: config.mu,
                });
            }
        }

        let (b_level, b_sec_power) = match config.b_bound {
            BBound::ControlledRows => (bounds.b_controlled, 1),
            BBound::Literal => (bounds.b_full, 2),
        };
        let delta_constants = DeltaConstants {
            beta: config.beta,
            k_norm,
            delta_m: bounds.delta_m,
            delta_g: bounds.delta_g,
            b_level,
            b_sec_power,
        };

        let m_hat = model::mass_matrix(&config.params);
        let estimator = estimator_parts(&config, &m_hat)?;

        Ok(Controller {
            estimator,
            m_hat,
            k1: Vector6::from(config.k1),
            k2: Vector6::from(config.k2),
            lyapunov,
            delta_constants,
            bounds,
            allocator,
            maps,
            // Choice 360: the core's cosine kernel in every backend (libm's cosf, the one call of
            // it on the board, was 5.4 kB of flash with its f64 reduction).
            cos_pitch_limit: crate::math::kernels::cos(config.pitch_limit),
            config,
        })
    }

    /// The configuration this controller was built from.
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// The bounds over the parameter box (for reports).
    pub fn bounds(&self) -> &UncertaintyBounds<f32> {
        &self.bounds
    }

    /// The constants of δ(e,t).
    pub fn delta_constants(&self) -> &DeltaConstants {
        &self.delta_constants
    }

    /// Per-axis Lyapunov solutions (roll entries zero).
    pub fn lyapunov(&self) -> &[AxisLyapunov<f32>; 6] {
        &self.lyapunov
    }

    /// The exact (unconstrained) thrust allocation B₅⁻¹.
    pub fn allocation(&self) -> &PseudoInverse {
        self.allocator.pseudo_inverse()
    }

    /// The saturation-aware allocator `update` flies (docs/thrusters.md#allocation-blocks-and-the-axis-priority).
    pub fn allocator(&self) -> &Allocator {
        &self.allocator
    }

    /// Each thruster's envelope [T_min, T_max] (N) at the supply limit, in the configured
    /// thrust unit's reading of Eqs 31–32.
    pub fn envelope(&self) -> &ThrustEnvelope {
        self.allocator.envelope()
    }

    /// Nominal M̂.
    pub fn mass_matrix(&self) -> &Matrix6<f32> {
        &self.m_hat
    }

    /// Nominal parameters.
    pub fn params(&self) -> &VehicleParams<f32> {
        &self.config.params
    }

    /// One control step at t = `ticks` / rate_hz seconds since mission start, with the vehicle
    /// at pose `eta` (relative to the mission origin) and body velocity `nu`, tracking
    /// `trajectory`.
    ///
    /// Never inlined, so that the linked firmware has an `update` symbol: the firmware CI
    /// builds the call graph of the flying image from it (no soft-float f64 routine may be
    /// reachable, docs/numerics.md#no-f64-on-the-control-step-from-the-elf).
    #[inline(never)]
    pub fn update(
        &self,
        ticks: u64,
        eta: &[f32; 6],
        nu: &[f32; 6],
        trajectory: &Trajectory,
    ) -> Output {
        self.fly(ticks, &LawInput::Told { eta, nu }, trajectory, None)
    }

    /// The law's stages on `input`, checked: the one body of [`Controller::update`] and of
    /// [`Controller::update_from_solution`] (Choice 364: one caller of the stages, so they
    /// stay inlined). With `record` (the estimator's parts, memory and the estimate flown),
    /// the output is recorded by [`Controller::estimator_record_stage`] here, before it is
    /// returned (**Choice 572**: recorded by the caller after the return, the 196-byte
    /// output was first written to the caller's stack and then copied to its own return
    /// value, about 180 instructions on the target).
    #[inline(never)]
    fn fly(
        &self,
        ticks: u64,
        input: &LawInput,
        trajectory: &Trajectory,
        record: Option<Recording>,
    ) -> Output {
        let stepped = match self.step(ticks, input, trajectory) {
            Ok(parts) if parts.finite() => Ok(parts),
            Ok(_) => Err(Fault::NonFiniteResult),
            Err(fault) => Err(fault),
        };
        // Recorded when `_recorder` is dropped: after the output below is written to the
        // return value, which then holds it (not the stack across the record's call).
        let _recorder = record.map(|recording| Recorder {
            recording,
            applied: stepped.as_ref().ok(),
        });
        match &stepped {
            Ok(parts) => parts.output(self.config.robust),
            Err(fault) => Output::fail_safe(*fault),
        }
    }

    /// One control step on a navigation `solution` at period `ticks`, with the estimator's
    /// memory `memory` (docs/law.md#the-state-estimator, Choice 340): with the estimator off,
    /// exactly [`Controller::update`] on the solution's η, ν (the memory untouched); with it
    /// on, the solution is checked as `update` checks it (a fault gives the same fail-safe and
    /// the memory does not take the solution), converted to η̇ = J(η)ν, filtered at its stamp
    /// and predicted to `ticks`, and the law runs on the estimate (η̂, ν̂ = J(η̂)⁻¹η̂̇); the
    /// acceleration the applied thrust gives under the nominal model is then recorded for the
    /// next predictions. Its stages are [`EstimatorStage::ALL`], around the law's.
    ///
    /// **Choice 364:** the law on the estimate is `update`'s own body (`fly`), called, not a
    /// second copy of its stages: on the board each stage's code then has one caller and is
    /// inlined as before the estimator (two callers made the compiler outline them, and
    /// `update` alone went from 3 920 to 6 160 instructions in the self-test).
    ///
    /// **Choice 431:** J(η̂)'s sines, cosines and matrices are formed once, by the estimate
    /// stage, and passed down: the law takes them with η̂̇ itself (not J(η̂)J(η̂)⁻¹η̂̇ again), and
    /// the recorded acceleration uses them too. Before, the attitude's maths ran three times
    /// a period (the solution's, the estimate's, and the law's own on the estimate).
    #[inline(never)]
    pub fn update_from_solution(
        &self,
        memory: &mut Estimate,
        ticks: u64,
        solution: &Solution,
        trajectory: &Trajectory,
    ) -> Output {
        let Some(parts) = &self.estimator else {
            return self.update(ticks, &solution.eta, &solution.nu, trajectory);
        };
        let eta_dot = match self.estimator_solution_stage(solution) {
            Ok(eta_dot) => eta_dot,
            Err(fault) => {
                memory.applied(&parts.gains, ticks, &[0.0; 6]);
                return Output::fail_safe(fault);
            }
        };
        let (period, state) =
            Self::estimator_filter_stage(parts, memory, ticks, solution, &eta_dot);
        // By reference: the estimate stays where its stage left it (a move copied it).
        match &self.estimator_estimate_stage(state, solution, &eta_dot) {
            Err(fault) => {
                memory.applied_in(&parts.gains, period, &[0.0; 6]);
                Output::fail_safe(*fault)
            }
            Ok(est) => {
                let record = Recording {
                    parts,
                    memory,
                    period,
                    est,
                };
                self.fly(ticks, &LawInput::Estimated(est), trajectory, Some(record))
            }
        }
    }

    /// The estimator's parts (`None`: off).
    #[doc(hidden)]
    pub fn estimator_parts(&self) -> Option<&EstimatorParts> {
        self.estimator.as_ref()
    }

    /// Stage [`EstimatorStage::Solution`]: the solution checked as [`Controller::update`]
    /// checks it and its η̇ = J(η)ν, what the filter takes. **Choice 561:** only η̇: J at the
    /// solution's attitude is formed again by the estimate stage on the one path that flies
    /// the solution as told (before any is taken), rather than kept alive through the filter.
    #[doc(hidden)]
    #[inline]
    pub fn estimator_solution_stage(&self, solution: &Solution) -> Result<[f32; 6], Fault> {
        check_inputs(&solution.eta, &solution.nu)?;
        let (kin, _) = self.checked_kinematics(&solution.eta)?;
        Ok(kin.eta_dot(&Vector6::from(solution.nu)).into())
    }

    /// Stage [`EstimatorStage::Filter`]: the solution (its η, and `eta_dot` its η̇) taken into
    /// `memory` at its stamp and the state predicted to `ticks` ([`Estimate::step`]), with the
    /// period as the memory counts it, for the record stage (Choice 568).
    #[doc(hidden)]
    #[inline]
    pub fn estimator_filter_stage(
        parts: &EstimatorParts,
        memory: &mut Estimate,
        ticks: u64,
        solution: &Solution,
        eta_dot: &[f32; 6],
    ) -> (Period, Option<StateAt>) {
        let period = memory.period(ticks);
        let state = memory.step_in(&parts.gains, period, solution.stamp, &solution.eta, eta_dot);
        (period, state)
    }

    /// Stage [`EstimatorStage::Estimate`]: the state the law flies on: the filter's (η̂, η̂̇)
    /// with J(η̂) (pitch limit checked) and ν̂ = J(η̂)⁻¹η̂̇, or, before any solution could be
    /// taken, the solution as told (with `told_eta_dot` its η̇, J at its attitude: no more work
    /// than the estimate's).
    #[doc(hidden)]
    #[inline]
    pub fn estimator_estimate_stage(
        &self,
        state: Option<([f32; 6], [f32; 6])>,
        solution: &Solution,
        told_eta_dot: &[f32; 6],
    ) -> Result<Estimated, Fault> {
        let Some((eta, eta_dot)) = state else {
            let (kin, cos_theta_abs) = self.checked_kinematics(&solution.eta)?;
            return Ok(Estimated {
                eta: solution.eta,
                nu: solution.nu,
                eta_dot: Vector6::from(*told_eta_dot),
                kin,
                cos_theta_abs,
            });
        };
        if times_zero(&eta) + times_zero(&eta_dot) != 0.0 {
            return Err(Fault::NonFiniteResult);
        }
        let (kin, cos_theta_abs) = self.checked_kinematics(&eta)?;
        let eta_dot = Vector6::from(eta_dot);
        Ok(Estimated {
            eta,
            nu: kin.jinv_mul(&eta_dot).into(),
            eta_dot,
            kin,
            cos_theta_abs,
        })
    }

    /// Stage [`EstimatorStage::Record`]: the acceleration the applied thrust gives under the
    /// nominal model at the estimate ([`estimator::applied_acceleration`], zero after a
    /// fault) recorded into `memory` for `period` (the filter stage's).
    #[doc(hidden)]
    #[inline]
    pub fn estimator_record_stage(
        parts: &EstimatorParts,
        memory: &mut Estimate,
        period: Period,
        est: &Estimated,
        out: &Output,
    ) {
        let applied = match out.status {
            Status::Ok => Some((
                Vector6::from(out.u),
                Vector6::from(out.tau),
                Vector6::from(out.tau_achieved),
            )),
            Status::Fault(_) => None,
        };
        let applied = applied
            .as_ref()
            .map(|(u, tau, achieved)| (u, tau, achieved));
        Self::record_applied(parts, memory, period, est, applied);
    }

    /// The record stage on the law's u, τ and the achieved τ (`None`: a fault, nothing
    /// applied): what [`Controller::fly`] records from the stages' parts, before the output
    /// is assembled.
    #[inline]
    fn record_applied(
        parts: &EstimatorParts,
        memory: &mut Estimate,
        period: Period,
        est: &Estimated,
        applied: Option<(&Vector6<f32>, &Vector6<f32>, &Vector6<f32>)>,
    ) {
        let accel = match applied {
            Some((u, tau, achieved)) => {
                estimator::applied_acceleration(u, &est.kin, &parts.m_diag_inv, tau, achieved)
                    .into()
            }
            None => [0.0; 6],
        };
        memory.applied_in(&parts.gains, period, &accel);
    }

    /// J(η)'s kinematics and |cos θ|, with the pitch limit (η finite).
    fn checked_kinematics(&self, eta: &[f32; 6]) -> Result<(Kinematics<f32>, f32), Fault> {
        let att = Attitude::from_eta_f32(&Vector6::from(*eta));
        let cos_theta_abs = att.ctheta.abs();
        if cos_theta_abs < self.cos_pitch_limit {
            return Err(Fault::PitchLimit);
        }
        let kin = Kinematics::new(att).map_err(|_| Fault::PitchLimit)?;
        Ok((kin, cos_theta_abs))
    }

    /// The stages of [`Stage::ALL`] in order, then the output.
    fn step(
        &self,
        ticks: u64,
        input: &LawInput,
        trajectory: &Trajectory,
    ) -> Result<Stepped, Fault> {
        let kin = match input {
            LawInput::Told { eta, nu } => self.kinematics_stage(eta, nu)?,
            LawInput::Estimated(est) => self.estimated_kinematics(est)?,
        };
        let desired = self.trajectory_stage(ticks, trajectory);
        let law = self.law_stage(&kin, &desired, trajectory)?;
        let alloc = self.allocation_stage(&law.tau);
        let (act, tau_achieved) = self.maps_stage(&alloc.thrusts);
        Ok(Stepped {
            eta_d: desired.eta,
            law,
            alloc,
            act,
            tau_achieved,
        })
    }

    /// Stage [`Stage::Kinematics`]: the input checks, the attitude's sines and cosines, the
    /// pitch limit, η̇ = J(η)ν (Eq 2) and J⁻¹J̇ν (Eq 3).
    #[doc(hidden)]
    #[inline]
    pub fn kinematics_stage(&self, eta: &[f32; 6], nu: &[f32; 6]) -> Result<StepKinematics, Fault> {
        check_inputs(eta, nu)?;
        let eta = Vector6::from(*eta);
        let nu = Vector6::from(*nu);
        let att = Attitude::from_eta_f32(&eta);
        // |cos θ| below cos(limit) ⇔ |θ| (mod 2π, folded) beyond the limit. θ is finite here,
        // so cos θ is not NaN.
        let cos_theta_abs = att.ctheta.abs();
        if cos_theta_abs < self.cos_pitch_limit {
            return Err(Fault::PitchLimit);
        }
        let kin = Kinematics::new(att).map_err(|_| Fault::PitchLimit)?;
        let eta_dot = kin.eta_dot(&nu);
        let jinv_jdot_nu = kin.jinv_jdot_nu(&nu);
        Ok(StepKinematics {
            eta,
            nu,
            kin,
            cos_theta_abs,
            eta_dot,
            jinv_jdot_nu,
        })
    }

    /// Stage [`Stage::Kinematics`] on the estimator's state, whose J, η̇ and pitch check its
    /// stages made (Choice 431): the input checks and J⁻¹J̇ν only.
    #[inline]
    fn estimated_kinematics(&self, est: &Estimated) -> Result<StepKinematics, Fault> {
        check_inputs(&est.eta, &est.nu)?;
        let nu = Vector6::from(est.nu);
        Ok(StepKinematics {
            eta: Vector6::from(est.eta),
            nu,
            kin: est.kin,
            cos_theta_abs: est.cos_theta_abs,
            eta_dot: est.eta_dot,
            jinv_jdot_nu: est.kin.jinv_jdot_nu(&nu),
        })
    }

    /// Stage [`Stage::Trajectory`]: η_d, η̇_d, η̈_d at t = `ticks` / rate_hz.
    #[doc(hidden)]
    #[inline]
    pub fn trajectory_stage(&self, ticks: u64, trajectory: &Trajectory) -> Desired {
        trajectory.sample(ticks, self.config.rate_hz)
    }

    /// Stage [`Stage::Law`]: e₁, e₂ (Eqs 12–13), ū (Eq 17), δ(e,t) (Eq 29) and its clamp,
    /// w = BᵀPe, Δu (Eq 26 or 30) and the body force τ (Eq 7, inversion-free route).
    #[doc(hidden)]
    #[inline]
    pub fn law_stage(
        &self,
        kin: &StepKinematics,
        desired: &Desired,
        trajectory: &Trajectory,
    ) -> Result<StepLaw, Fault> {
        let (e1, e2) = law::tracking_errors(&kin.eta, &kin.eta_dot, &desired.eta, &desired.eta_dot);
        let u_bar = law::nominal_input(&desired.eta_ddot, &self.k1, &self.k2, &e1, &e2);

        let mut e_sq = 0.0f32;
        for &i in ACTUATED.iter() {
            e_sq += e1[i] * e1[i] + e2[i] * e2[i];
        }
        let delta_raw = law::uncertainty_bound(
            &self.delta_constants,
            &DeltaInputs {
                accel_bound: trajectory.accel_bound(),
                error_norm: crate::math::sqrt(e_sq),
                nu_norm: crate::math::norm(&kin.nu.into()),
                jinv_jdot_nu_norm: crate::math::norm(&kin.jinv_jdot_nu.into()),
                cos_theta_abs: kin.cos_theta_abs,
            },
        );
        if !delta_raw.is_finite() {
            return Err(Fault::NonFiniteResult);
        }
        let delta_clamped = delta_raw > self.config.delta_max;
        let delta = if delta_clamped {
            self.config.delta_max
        } else {
            delta_raw
        };

        let w = law::switching_signal(&self.lyapunov, &e1, &e2);
        let w_norm = crate::math::norm(&w.into());
        let u = if self.config.robust {
            u_bar + law::robust_term(self.config.law, &w, w_norm, delta, self.config.mu)
        } else {
            u_bar
        };

        let tau = law::body_force(
            &self.m_hat,
            &self.config.params,
            &kin.kin,
            &kin.nu,
            &u,
            &kin.jinv_jdot_nu,
        );
        // Σ τᵢ·0 is NaN exactly when some τᵢ is not finite (Choice 524).
        if times_zero(&tau.into()) != 0.0 {
            return Err(Fault::NonFiniteResult);
        }
        Ok(StepLaw {
            u,
            tau,
            delta,
            delta_clamped,
            w_norm,
            e1,
        })
    }

    /// Stage [`Stage::Allocation`]: the thrust each thruster is asked for, by the
    /// saturation-aware allocator (B₅⁻¹τ when it fits the envelopes; docs/thrusters.md#allocation-blocks-and-the-axis-priority).
    #[doc(hidden)]
    #[inline]
    pub fn allocation_stage(&self, tau: &Vector6<f32>) -> Allocated {
        self.allocator.allocate(tau)
    }

    /// Stage [`Stage::Maps`]: the voltages (Eqs 31–32 in the configured thrust unit, clamped
    /// to the supply), the thrusts they give, and the wrench B·T those give.
    #[doc(hidden)]
    #[inline]
    pub fn maps_stage(&self, demand: &[f32; THRUSTERS]) -> (Actuation, Vector6<f32>) {
        let act = thruster::actuate_within(
            &self.maps,
            self.config.thrust_unit,
            demand,
            self.config.voltage_limit,
            self.allocator.envelope(),
        );
        let tau_achieved = self.allocator.wrench(&act.thrusts);
        (act, tau_achieved)
    }
}

/// The stages of one [`Controller::update`], in the order it runs them; each is a method of
/// [`Controller`] (`kinematics_stage`, `trajectory_stage`, …) that `update` is built from, so
/// the firmware self-test can count the instructions of each on the same inputs as `update`.
/// Around them `update` only assembles the [`Output`] and checks that it is finite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Input checks, attitude sines and cosines, pitch limit, η̇ = Jν and J⁻¹J̇ν.
    Kinematics,
    /// η_d, η̇_d, η̈_d from the mission ([`Trajectory::sample`]).
    Trajectory,
    /// e₁, e₂, ū, δ, w, Δu and τ.
    Law,
    /// Thrust demand: the saturation-aware allocator ([`Allocator`]).
    Allocation,
    /// Voltages (Eqs 31–32), achieved thrusts and achieved wrench.
    Maps,
}

impl Stage {
    /// Every stage, in `update`'s order.
    pub const ALL: [Stage; 5] = [
        Stage::Kinematics,
        Stage::Trajectory,
        Stage::Law,
        Stage::Allocation,
        Stage::Maps,
    ];

    /// Stable name for logs and budgets, e.g. `"voltage-maps"`.
    pub const fn name(self) -> &'static str {
        match self {
            Stage::Kinematics => "kinematics",
            Stage::Trajectory => "trajectory",
            Stage::Law => "law",
            Stage::Allocation => "allocation",
            Stage::Maps => "voltage-maps",
        }
    }
}

/// The stages [`Controller::update_from_solution`] adds around the law's ([`Stage`]) when
/// the estimator is on, in its order; each is a method of [`Controller`] the firmware
/// self-test counts on the estimator's golden vectors (Choice 432).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EstimatorStage {
    /// The solution's input checks, J at its attitude (pitch limit) and η̇ = J(η)ν.
    Solution,
    /// The filter: the correction at the solution's stamp and the prediction to the period.
    Filter,
    /// J at the estimate's attitude (pitch limit) and ν̂ = J(η̂)⁻¹η̂̇.
    Estimate,
    /// The acceleration the applied thrust gives, recorded for the next predictions.
    Record,
}

impl EstimatorStage {
    /// Every estimator stage, in `update_from_solution`'s order.
    pub const ALL: [EstimatorStage; 4] = [
        EstimatorStage::Solution,
        EstimatorStage::Filter,
        EstimatorStage::Estimate,
        EstimatorStage::Record,
    ];

    /// Stable name for logs and budgets, e.g. `"estimator-filter"`.
    pub const fn name(self) -> &'static str {
        match self {
            EstimatorStage::Solution => "estimator-solution",
            EstimatorStage::Filter => "estimator-filter",
            EstimatorStage::Estimate => "estimator-estimate",
            EstimatorStage::Record => "estimator-record",
        }
    }
}

/// What [`Stage::Kinematics`] gives the later stages.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepKinematics {
    pub eta: Vector6<f32>,
    pub nu: Vector6<f32>,
    /// R, sec θ, tan θ: formed once, used by every stage.
    pub kin: Kinematics<f32>,
    pub cos_theta_abs: f32,
    pub eta_dot: Vector6<f32>,
    pub jinv_jdot_nu: Vector6<f32>,
}

/// What [`Stage::Law`] gives the later stages and the output.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepLaw {
    /// The commanded η̈: ū + Δu.
    pub u: Vector6<f32>,
    pub tau: Vector6<f32>,
    pub delta: f32,
    /// δ was clamped (reported only when Δu is on).
    pub delta_clamped: bool,
    pub w_norm: f32,
    pub e1: Vector6<f32>,
}

/// The estimator's gains and 1/M̂ᵢᵢ for its model (Choice 340); `None` when it is off.
fn estimator_parts(
    config: &ControllerConfig,
    m_hat: &Matrix6<f32>,
) -> Result<Option<EstimatorParts>, ConfigError> {
    match config.estimator.kind {
        EstimatorKind::Off => Ok(None),
        EstimatorKind::Kalman => {
            let gains = EstimatorGains::new(&config.estimator, config.rate_hz)
                .map_err(|axis| ConfigError::EstimatorGain { axis })?;
            // M̂ is positive definite (checked over the box): its diagonal is > 0.
            let m_diag_inv = core::array::from_fn(|i| 1.0 / m_hat[(i, i)]);
            Ok(Some(EstimatorParts { gains, m_diag_inv }))
        }
    }
}

/// Assumption 2 (Eq 20: β̂ < 1 and β̂ ≤ the configured β) and Theorem 2 (Eq 25) over the box.
fn check_feasible(bounds: &UncertaintyBounds<f32>, beta: f32) -> Result<(), ConfigError> {
    let beta_hat = bounds.beta_hat;
    if !(beta_hat < 1.0 && beta_hat <= beta) {
        return Err(ConfigError::Assumption2 { beta_hat, beta });
    }
    if !bounds.theorem2.holds() {
        return Err(ConfigError::Theorem2 {
            lhs: bounds.theorem2.lhs,
            rhs: bounds.theorem2.rhs,
        });
    }
    Ok(())
}

/// η and ν finite ([`Fault::NonFiniteInput`] otherwise) and plausible
/// ([`Fault::InputOutOfRange`]). A plausible value is finite (|x| ≤ a limit is false for NaN
/// and ±∞), so the plausibility test alone passes every good input and the finiteness test
/// runs only to name the fault (Choice 524).
fn check_inputs(eta: &[f32; 6], nu: &[f32; 6]) -> Result<(), Fault> {
    let plausible = eta[..3].iter().all(|x| x.abs() <= MAX_POSITION)
        && eta[3..].iter().all(|x| x.abs() <= MAX_ANGLE)
        && nu[..3].iter().all(|x| x.abs() <= MAX_LINEAR_SPEED)
        && nu[3..].iter().all(|x| x.abs() <= MAX_ANGULAR_RATE);
    if plausible {
        Ok(())
    } else if eta.iter().chain(nu.iter()).all(|x| x.is_finite()) {
        Err(Fault::InputOutOfRange)
    } else {
        Err(Fault::NonFiniteInput)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Choice 524: the sum-times-zero check finds a non-finite value in every field and at
    /// every position, ±∞ and NaN alike, and passes finite values of any size and sign.
    #[test]
    fn the_finite_check_finds_every_non_finite_value_it_checks() {
        let zero = Vector6::zeros();
        let finite = Stepped {
            eta_d: Vector6::from([f32::MAX, -f32::MAX, 0.0, -0.0, f32::MIN_POSITIVE, 1.0]),
            law: StepLaw {
                u: zero,
                tau: zero,
                delta: 0.0,
                delta_clamped: false,
                w_norm: 0.0,
                e1: zero,
            },
            alloc: Allocated {
                thrusts: [0.0; THRUSTERS],
                saturated: 0,
                unallocated: [0.0; 6],
            },
            act: Actuation::OFF,
            tau_achieved: zero,
        };
        assert!(finite.finite());
        for k in 0..3 * 6 + 1 {
            for bad in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
                let mut p = finite;
                let slot = match k {
                    0..=5 => &mut p.tau_achieved[k],
                    6..=11 => &mut p.alloc.unallocated[k - 6],
                    12..=17 => &mut p.eta_d[k - 12],
                    _ => &mut p.law.w_norm,
                };
                *slot = bad;
                assert!(!p.finite(), "field slot {k}: {bad}");
            }
        }
    }

    /// Choice 582's grounds for leaving u and e₁ out of the finite check: a non-finite uᵢ
    /// gives a non-finite τ (which the law stage checks) at any attitude within the pitch
    /// limit, and a non-finite e₁ᵢ a non-finite ūᵢ (the yaw's through its wrap).
    #[test]
    fn a_non_finite_u_or_e1_makes_tau_non_finite() {
        let c = Controller::new(ControllerConfig::default()).expect("paper defaults");
        let zero = Vector6::zeros();
        let nu = Vector6::from([0.5, -0.2, 0.1, 0.05, -0.03, 0.2]);
        for eta in [
            [0.0; 6],
            [1.0, -2.0, 3.0, 0.4, -0.5, 3.0],
            [0.0, 0.0, 0.0, 0.0, 1.2, -2.0],
        ] {
            let kin = Kinematics::new(Attitude::from_eta_f32(&Vector6::from(eta))).unwrap();
            let jinv_jdot_nu = kin.jinv_jdot_nu(&nu);
            for i in 0..6 {
                for bad in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
                    let mut u = zero;
                    u[i] = bad;
                    let tau =
                        law::body_force(&c.m_hat, &c.config.params, &kin, &nu, &u, &jinv_jdot_nu);
                    assert!(times_zero(&tau.into()) != 0.0, "u[{i}] = {bad} at {eta:?}");
                    let mut e1 = zero;
                    e1[i] = bad;
                    if i == crate::axes::YAW {
                        e1[i] = crate::math::wrap_pi(bad);
                    }
                    let u_bar = law::nominal_input(&zero, &c.k1, &c.k2, &e1, &zero);
                    assert!(!u_bar[i].is_finite(), "e1[{i}] = {bad}");
                }
            }
        }
    }
}
