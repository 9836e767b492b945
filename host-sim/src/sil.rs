//! Software in the loop: the f32 `controller-core` as the firmware runs it, sampled at its own
//! rate with zero-order hold, around the f64 plant integrated with RK4 at the plant step.
//!
//! Per control period k (t = k/rate):
//! 1. measure η, ν (plus seeded sensor noise), round to f32, call `Controller::update(k, …)`;
//! 2. actuation: ideal — the allocated thrusts B₅⁻¹τ are delivered whatever the voltage;
//!    real — the controller's (clamped) voltages go through the inverse of Eqs 31–32, read in
//!    the controller's thrust unit (the simulated thrusters are the ones the board is
//!    configured for), to thrust; a controller fault means every thruster off (0 N);
//! 3. optional first-order thruster lag, then τ_applied = B·thrust;
//! 4. RK4 substeps with τ held, the plant's parameters (trimmed if the scenario says so,
//!    [`crate::plant::trimmed`]) and the current evaluated per substep; one plant for the
//!    run, whose M is formed again only when the parameters change (Choice 80,
//!    [`Plant::set_params`]).
//!
//! A non-finite state, a plant fault or a position error beyond `divergence_limit` stops the
//! run with a reason; every sample recorded until then is kept.

use controller_core::effectiveness::THRUSTERS;
use controller_core::kinematics::{self, Attitude};
use controller_core::model::VehicleParams;
use controller_core::thruster;
use controller_core::{Controller, Trajectory};
use nalgebra::{Vector3, Vector6};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

use crate::config::{CurrentModel, VariationProfile};
use crate::decimate::Decimator;
use crate::interrupt;
use crate::metrics;
use crate::plant::{Plant, PlantState, PlantTerms};
use crate::record::{ControlStatus, FaultCounts, Outcome, RunResult, Sample};
use crate::scenario::Scenario;

/// Ocean current state (Gauss–Markov is a random process, stepped with the plant).
struct Current {
    model: CurrentModel,
    v: Vector3<f64>,
    rng: rand::rngs::StdRng,
}

impl Current {
    fn new(model: &CurrentModel) -> Self {
        let (v, seed) = match model {
            CurrentModel::None => (Vector3::zeros(), 0),
            CurrentModel::Constant(v) => (Vector3::from(*v), 0),
            CurrentModel::GaussMarkov { mean, seed, .. } => (Vector3::from(*mean), *seed),
        };
        Current {
            model: model.clone(),
            v,
            rng: rand::rngs::StdRng::seed_from_u64(seed),
        }
    }

    /// Euler–Maruyama step of v̇ = −(v − mean)/τ + σ√(2/τ)·w: stationary std σ.
    fn step(&mut self, h: f64) {
        if let CurrentModel::GaussMarkov {
            mean, sigma, tau, ..
        } = &self.model
        {
            for i in 0..3 {
                let w: f64 = StandardNormal.sample(&mut self.rng);
                self.v[i] +=
                    -(self.v[i] - mean[i]) / tau * h + sigma[i] * (2.0 * h / tau).sqrt() * w;
            }
        }
    }
}

fn wrap_pi(x: f64) -> f64 {
    let r = (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if r <= -std::f64::consts::PI {
        r + std::f64::consts::TAU
    } else {
        r
    }
}

fn to_f64<const N: usize>(a: &[f32; N]) -> [f64; N] {
    a.map(|x| x as f64)
}

/// What one control period returns, whether the law ran here (SIL) or on the board (PIL).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOut {
    /// Whether the law ran ([`ControlStatus::is_ok`]); if not, the thrusters are off.
    pub status: ControlStatus,
    /// Commanded body force (used by ideal actuators).
    pub tau: [f32; 6],
    /// Voltages (used by the real actuator chain).
    pub voltage: [f32; 5],
    pub saturated: u8,
    pub delta: f32,
    pub delta_clamped: bool,
    pub w_norm: f32,
}

/// Where the control law runs.
pub trait ControlSource {
    /// The control for period `k` from the measured state. An `Err` ends the run (e.g. the
    /// board's link is gone) with the message as the reason; what was recorded is kept.
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, String>;
}

/// The f32 core on the host, as the firmware runs it (software in the loop): the scenario's
/// controller and trajectory.
pub struct LocalController<'a> {
    controller: &'a Controller,
    trajectory: &'a Trajectory,
}

impl<'a> LocalController<'a> {
    pub fn new(scenario: &'a Scenario) -> Self {
        LocalController {
            controller: scenario.controller(),
            trajectory: scenario.trajectory(),
        }
    }
}

impl ControlSource for LocalController<'_> {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, String> {
        let out = self.controller.update(k, eta, nu, self.trajectory);
        Ok(ControlOut {
            status: ControlStatus::Law(out.status),
            tau: out.tau,
            voltage: out.voltage,
            saturated: out.saturated,
            delta: out.delta,
            delta_clamped: out.delta_clamped,
            w_norm: out.w_norm,
        })
    }
}

/// The vehicle on the reference at t = 0: η = η_d(0), ν = J⁻¹ η̇_d(0).
pub fn reference_state(trajectory: &Trajectory, rate_hz: u32) -> PlantState {
    start_state(trajectory, rate_hz, &[0.0; 6])
}

/// Where a run starts (docs/design.md §6): on the reference, η = η_d(0) + `offset`, with the
/// reference's velocity ν = J⁻¹(η) η̇_d(0).
fn start_state(trajectory: &Trajectory, rate_hz: u32, offset: &[f64; 6]) -> PlantState {
    let d0 = trajectory.sample(0, rate_hz);
    let eta = d0.eta.cast::<f64>() + Vector6::from(*offset);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta(&eta)) * d0.eta_dot.cast::<f64>();
    PlantState { eta, nu }
}

/// Runs one simulation with the law on the host (software in the loop).
pub fn run(scenario: &Scenario) -> RunResult {
    run_with(scenario, &mut LocalController::new(scenario))
}

/// What sees every sample of a run as it is made: the streaming CSV
/// ([`crate::output::csv::CsvStream`]), the progress counter ([`crate::progress`]). `()` sees
/// nothing.
pub trait Observer {
    fn sample(&mut self, sample: &Sample);
}

impl Observer for () {
    fn sample(&mut self, _: &Sample) {}
}

impl<T: Observer + ?Sized> Observer for &mut T {
    fn sample(&mut self, s: &Sample) {
        (**self).sample(s);
    }
}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn sample(&mut self, s: &Sample) {
        self.0.sample(s);
        self.1.sample(s);
    }
}

/// The heading the simulated navigation reports: the plant's ψ while |ψ| ≤
/// [`HEADING_REPORT_BOUND`], else ψ reduced by whole turns into (−π, π].
///
/// **Choice:** a navigation solution reports a heading, not a count of turns: the plant's ψ
/// grows without bound on a circle (ω t), and the controller refuses |angle| beyond
/// `controller_core::controller::MAX_ANGLE` (1000 rad), which a 24 h circle reaches after
/// 10 000 s (the run then went to fail-safe and diverged). The reduction is applied only
/// beyond 4π, which the paper's 70 s missions never reach (their ψ stays below 7.1 rad), so
/// the Table-1 runs are bit for bit as before; the controller wraps the yaw error anyway
/// (docs/design.md §4), so the jump by whole turns is invisible to the law.
pub fn reported_heading(psi: f64) -> f64 {
    if psi.abs() <= HEADING_REPORT_BOUND {
        psi
    } else {
        wrap_pi(psi)
    }
}

/// |ψ| (rad) up to which the simulated navigation reports the plant's heading unchanged
/// ([`reported_heading`]).
pub const HEADING_REPORT_BOUND: f64 = 4.0 * std::f64::consts::PI;

/// Runs one simulation with the law wherever `source` runs it. The scenario's controller gives
/// the allocation the plant's thrusters use.
pub fn run_with(scenario: &Scenario, source: &mut dyn ControlSource) -> RunResult {
    run_observed(scenario, source, &mut ())
}

/// [`run_with`], with every sample shown to `observer` as it is made. Memory stays bounded
/// whatever the duration: the metrics and the fault counts are accumulated, and the run keeps
/// only the plot series ([`crate::decimate`]). Stops early, with [`Outcome::Interrupted`],
/// when an interrupt is requested ([`crate::interrupt`]).
pub fn run_observed(
    scenario: &Scenario,
    source: &mut dyn ControlSource,
    observer: &mut dyn Observer,
) -> RunResult {
    run_recorded(scenario, source, observer, Recording::Plot)
}

/// What a run keeps of its samples besides the metrics and the fault counts (which are
/// accumulated from every sample either way, as is what the observer sees).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recording {
    /// The plot series ([`crate::decimate`]) in [`RunResult::samples`].
    Plot,
    /// No samples: [`RunResult::samples`] is empty. For runs nobody plots: **Choice 82**
    /// (docs/design.md §2), Monte Carlo records this way. The [`RunResult::summary`] is the
    /// same as with [`Recording::Plot`].
    MetricsOnly,
}

/// [`run_observed`], keeping what `recording` says.
pub fn run_recorded(
    scenario: &Scenario,
    source: &mut dyn ControlSource,
    observer: &mut dyn Observer,
    recording: Recording,
) -> RunResult {
    let cfg = scenario.config();
    let controller = scenario.controller();
    let trajectory = scenario.trajectory();
    let rate = cfg.controller.rate_hz;
    let period = scenario.period();
    let substeps = scenario.substeps();
    let h = period / substeps as f64;
    let steps = scenario.steps();

    let nominal = VehicleParams::auv150();
    let alloc_b = controller.allocation().matrix().cast::<f64>();
    let maps = thruster::default_maps();

    // Start on the reference (docs/design.md §6), plus the configured offset.
    let mut state = start_state(trajectory, rate, &cfg.initial_offset);

    let mut current = Current::new(&cfg.current);
    let mut noise_rng = rand::rngs::StdRng::seed_from_u64(cfg.noise.as_ref().map_or(0, |n| n.seed));
    let lag_alpha = cfg.thruster_lag.map(|tl| 1.0 - (-h / tl).exp());
    let mut thrust_applied: Option<[f64; THRUSTERS]> = None;
    // One plant for the run: M is refactorised only when the parameters change, and a
    // profile that does not vary in time is not evaluated again.
    let mut plant: Option<Plant> = None;
    let params_at = |ts: f64| {
        let params = nominal.with_variation(&cfg.variation.at(ts));
        match cfg.trimmed {
            true => crate::plant::trimmed(&params),
            false => params,
        }
    };
    let params_fixed = matches!(
        cfg.variation,
        VariationProfile::None | VariationProfile::Constant(_)
    );

    let mut plot = (recording == Recording::Plot).then(|| Decimator::new(steps + 1));
    let mut metrics = metrics::Accumulator::default();
    let mut faults = FaultCounts::default();
    let mut record = |s: Sample| {
        metrics.push(&s);
        faults.record(&s);
        observer.sample(&s);
        if let Some(plot) = &mut plot {
            plot.push(&s);
        }
    };
    let mut outcome = Outcome::Completed;

    for k in 0..=steps {
        let t = k as f64 * period;
        if interrupt::requested() {
            outcome = Outcome::Interrupted { t };
            break;
        }
        let d = trajectory.sample(k, rate);
        let eta_d = to_f64(&d.eta.into());
        let mut error = [0.0; 6];
        for i in 0..6 {
            error[i] = state.eta[i] - eta_d[i];
        }
        error[5] = wrap_pi(error[5]);
        let pos_err = (error[0] * error[0] + error[1] * error[1] + error[2] * error[2]).sqrt();
        if !state.is_finite() {
            outcome = Outcome::Diverged {
                t,
                reason: "plant state is not finite".into(),
            };
            break;
        }
        if pos_err > cfg.divergence_limit {
            outcome = Outcome::Diverged {
                t,
                reason: format!(
                    "position error {pos_err:.1} m exceeds the divergence limit {} m",
                    cfg.divergence_limit
                ),
            };
            break;
        }

        // 1. Measure and control.
        let (mut eta_m, mut nu_m) = (state.eta, state.nu);
        eta_m[5] = reported_heading(eta_m[5]);
        if let Some(n) = &cfg.noise {
            for i in 0..6 {
                let a: f64 = StandardNormal.sample(&mut noise_rng);
                let b: f64 = StandardNormal.sample(&mut noise_rng);
                eta_m[i] += n.eta_sigma[i] * a;
                nu_m[i] += n.nu_sigma[i] * b;
            }
        }
        let out = match source.control(k, &eta_m.cast::<f32>().into(), &nu_m.cast::<f32>().into()) {
            Ok(o) => o,
            Err(reason) => {
                outcome = Outcome::Diverged { t, reason };
                break;
            }
        };

        // 2. Actuation.
        let target: [f64; THRUSTERS] = match out.status.is_ok() {
            false => [0.0; THRUSTERS],
            true if cfg.ideal_actuators => {
                to_f64(&controller.allocation().thrusts(&Vector6::from(out.tau)))
            }
            true => {
                // The thrusters read Eqs 31–32 in the controller's unit (docs/design.md §9).
                let unit = cfg.controller.thrust_unit;
                let mut t = [0.0; THRUSTERS];
                for i in 0..THRUSTERS {
                    t[i] = maps[i].newtons_of_voltage(unit, out.voltage[i]) as f64;
                }
                t
            }
        };
        let mut rec = Sample {
            t,
            eta: state.eta.into(),
            eta_d,
            error,
            tau: to_f64(&out.tau),
            tau_applied: [0.0; 6],
            thrust: [0.0; THRUSTERS],
            voltage: to_f64(&out.voltage),
            saturated: out.saturated,
            delta: out.delta as f64,
            delta_clamped: out.delta_clamped,
            w_norm: out.w_norm as f64,
            payload: cfg.variation.at(t).mass,
            status: out.status,
        };
        if k == steps {
            rec.thrust = thrust_applied.unwrap_or(target);
            rec.tau_applied =
                (alloc_b * nalgebra::SVector::<f64, THRUSTERS>::from(rec.thrust)).into();
            record(rec);
            break;
        }

        // 3.–4. Lag, wrench, integrate.
        let wrench = |thrust: &[f64; THRUSTERS]| {
            alloc_b * nalgebra::SVector::<f64, THRUSTERS>::from(*thrust)
        };
        let mut applied = thrust_applied.unwrap_or(target);
        let mut first_applied = None;
        // Without lag the thrust, so the wrench, is the target's all period.
        let mut tau = wrench(&target);
        for j in 0..substeps {
            if let Some(alpha) = lag_alpha {
                for i in 0..THRUSTERS {
                    applied[i] += alpha * (target[i] - applied[i]);
                }
                tau = wrench(&applied);
            } else {
                applied = target;
            }
            if first_applied.is_none() {
                first_applied = Some(applied);
            }
            let ts = t + j as f64 * h;
            let stepped = match &mut plant {
                Some(p) if params_fixed => Ok(&*p),
                Some(p) => p.set_params(params_at(ts)).map(|()| &*p),
                None => Plant::new(params_at(ts), PlantTerms::default()).map(|p| &*plant.insert(p)),
            }
            .and_then(|p| p.rk4_step(&state, &tau, &current.v, h));
            match stepped {
                Ok(s) => state = s,
                Err(e) => {
                    outcome = Outcome::Diverged {
                        t: ts,
                        reason: e.to_string(),
                    };
                    break;
                }
            }
            current.step(h);
        }
        rec.thrust = first_applied.unwrap_or(target);
        rec.tau_applied = (alloc_b * nalgebra::SVector::<f64, THRUSTERS>::from(rec.thrust)).into();
        record(rec);
        thrust_applied = Some(applied);
        if matches!(outcome, Outcome::Diverged { .. }) {
            break;
        }
    }

    RunResult {
        name: cfg.name.clone(),
        case: cfg.case,
        robust: cfg.controller.robust,
        metrics: metrics.metrics(),
        outcome,
        faults,
        faults_expected: cfg.expect_faults,
        samples: plot.map_or_else(Vec::new, Decimator::finish),
        plant_factorisations: plant.map_or(0, |p| p.factorisations()),
    }
}
