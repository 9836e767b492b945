//! The one closed loop: the f32 `controller-core` as the firmware runs it (on the host, or on
//! a board through [`ControlSource`]), sampled at its own rate with zero-order hold, around the
//! f64 plant integrated with RK4 at the plant step. [`fly`] is the loop; everything it uses is
//! a module of its own:
//!
//! | module | owns |
//! |---|---|
//! | [`control`] | where the law runs: [`ControlSource`], [`LocalController`] (SIL), [`ControlOut`], why a source stops ([`Stop`]) |
//! | [`navigation`], [`nav_model`] | what the law is told: the navigation solution of `[navigation]` (or the exact state), heading as navigation reports it, `[noise]` |
//! | [`thrusters`] | what the thrusters deliver (ideal or the real chain), their lag, B·thrust |
//! | [`vehicle`] | the plant with its parameter profile and current, stepped by RK4 |
//! | [`record`] | a run's samples, outcome, metrics and JSON summary |
//! | [`recorder`] | what a run keeps as it goes (metrics, fault counts, plot series, observer) |
//! | [`metrics`], [`decimate`] | the Table-1 metrics; the bounded plot series of a long run |
//! | [`chatter`] | what the commands do between the limits: reversals, total variation, power above the thruster's corner |
//! | [`observer`], [`progress`] | who sees each sample as it is made; progress of long commands |
//! | [`bound`] | the bound a real-vehicle run must fly within |
//!
//! A non-finite state, a plant fault or a position error beyond `divergence_limit` stops the
//! run with a reason; every sample recorded until then is kept. A board in the loop that is
//! lost stops it too ([`Outcome::LostBoard`], not a divergence: [`Stop`]). An interrupt
//! ([`crate::interrupt`]) stops it at the period it is in.

pub mod bound;
pub mod chatter;
pub mod control;
pub mod decimate;
pub mod metrics;
pub mod nav_model;
pub mod navigation;
pub mod observer;
pub mod progress;
pub mod record;
pub mod recorder;
pub mod thrusters;
pub mod vehicle;

use controller_core::effectiveness::THRUSTERS;
use controller_core::Desired;

pub use control::{ControlOut, ControlSource, LocalController, Stop};
pub use observer::Observer;
use record::FaultCounts;
pub use record::{
    BoardLoss, BoardReport, ControlStatus, LinkCounters, LoopSignals, Metrics, Outcome, RunResult,
    Sample, UploadRound,
};
pub use recorder::Recording;

use crate::interrupt;
use crate::plant::PlantState;
use crate::scenario::{path_time, Scenario};
use metrics::Accumulator;
use navigation::{wrap_pi, Navigation};
use recorder::Recorder;
use thrusters::{Thrusters, Thrusts};
use vehicle::Vehicle;

/// Runs one simulation with the law on the host (software in the loop), keeping the plot
/// series.
pub fn run(scenario: &Scenario) -> RunResult {
    fly(
        scenario,
        &mut LocalController::new(scenario),
        &mut (),
        Recording::Plot,
    )
}

/// Flies `scenario` with the law wherever `source` runs it, showing every sample to
/// `observer` as it is made and keeping what `recording` says. Per control period k
/// (t = k/rate): measure, control, actuate, then hold the thrust for the period while the plant
/// is integrated (docs/simulator.md#table-1). Memory stays bounded whatever the duration.
///
/// **Choice 569:** a run that keeps only its metrics, that no observer watches and whose law
/// runs here ([`ControlSource::runs_here`]: a campaign's, a Monte Carlo's) samples its
/// trajectory once a period, not twice: it measures and controls first and takes the law's
/// η_d for its reference (the same trajectory at the same tick, so the same bits), sampling
/// it itself only where the law did not run. The stop check then follows the control it
/// would have preceded; a run that stops there drops that control, which nobody saw. What no
/// metric reads is then left out of the samples: η̇_d and η̈_d (zero), the payload, what the
/// law was told, the thrust demand, the navigation's arrivals and τ applied.
pub fn fly(
    scenario: &Scenario,
    source: &mut dyn ControlSource,
    observer: &mut dyn Observer,
    recording: Recording,
) -> RunResult {
    let cfg = scenario.config();
    let (steps, substeps, period) = (scenario.steps(), scenario.substeps(), scenario.period());
    let h = period / substeps as f64;
    let lean = recording == Recording::MetricsOnly && !observer.watches() && source.runs_here();
    let mut vehicle = Vehicle::new(scenario);
    let mut navigation = Navigation::of(cfg);
    let mut thrusters = Thrusters::new(cfg, scenario.controller(), h);
    let mut recorder = Recorder::new(observer, recording, steps + 1, Accumulator::of(cfg));
    let mut outcome = Outcome::Completed;
    for k in 0..=steps {
        let t = k as f64 * period;
        // 1. Measure and control (before the stop check when lean).
        let mut control = || {
            let (eta, nu) = navigation.measure(&vehicle.state);
            (eta, nu, source.control(k, &eta, &nu))
        };
        let early = lean.then(&mut control);
        let reference = reference(scenario, k, &early);
        let error = tracking_error(&vehicle.state, &reference);
        if let Some(stop) = stop(t, &vehicle.state, &error, cfg.divergence_limit) {
            outcome = stop;
            break;
        }
        let (eta, nu, controlled) = early.unwrap_or_else(control);
        let out = match controlled {
            Ok(out) => out,
            // A board's wait for its answer gives up on a stop request.
            Err(Stop::Interrupted) => {
                outcome = Outcome::Interrupted { t };
                break;
            }
            Err(Stop::LostBoard { cause, reason }) => {
                outcome = Outcome::LostBoard { t, cause, reason };
                break;
            }
        };
        // 2. Actuate: the thrust the thrusters are driven towards.
        let target = thrusters.target(&out);
        let mut sample = sample_of(t, &vehicle.state, &reference, error, &out);
        if !lean {
            sample.payload = cfg.variation.at(t).mass;
            sample.signals.eta_told = eta;
            sample.signals.nu_told = nu;
            sample.signals.thrust_demand = target;
            sample.signals.navigation =
                navigation.solution().map(|s| s.arrived).unwrap_or_default();
        }
        // 3. Hold it for the period: thruster lag, RK4 substeps (none after the last sample).
        let (thrust, held): (Thrusts, Result<(), (f64, String)>) = if k < steps {
            thrusters.hold(&target, substeps, |j, tau| {
                let ts = t + j as f64 * h;
                vehicle.step(ts, tau, h).map_err(|e| (ts, e.to_string()))
            })
        } else {
            (thrusters.applied_or(&target), Ok(()))
        };
        sample.thrust = thrust;
        if !lean {
            sample.tau_applied = thrusters.wrench(&thrust).into();
        }
        recorder.record(&sample);
        if let Err((t, reason)) = held {
            outcome = Outcome::Diverged { t, reason };
            break;
        }
    }
    let (metrics, faults, samples) = recorder.finish();
    let flown = (metrics, faults, samples, vehicle.factorisations());
    result(scenario, outcome, flown)
}

/// What the law was told and what it answered for one period.
type Controlled = ([f32; 6], [f32; 6], Result<ControlOut, Stop>);

/// The loop's reference of period `k`: the law's η_d if it answered this period already
/// (`early`, Choice 569; η̇_d and η̈_d zero), else the trajectory sampled here.
fn reference(scenario: &Scenario, k: u64, early: &Option<Controlled>) -> Desired {
    match early {
        Some((
            _,
            _,
            Ok(ControlOut {
                eta_d: Some(eta_d), ..
            }),
        )) => Desired {
            eta: (*eta_d).into(),
            eta_dot: nalgebra::Vector6::zeros(),
            eta_ddot: nalgebra::Vector6::zeros(),
        },
        _ => scenario
            .trajectory()
            .sample(k, scenario.config().controller.rate_hz),
    }
}

/// The run's result: its outcome held against the bound, with what the flight measured.
fn result(
    scenario: &Scenario,
    mut outcome: Outcome,
    (metrics, faults, samples, plant_factorisations): (Metrics, FaultCounts, Vec<Sample>, u64),
) -> RunResult {
    let cfg = scenario.config();
    if outcome == Outcome::Completed {
        if let Some(reason) = cfg.bound().and_then(|b| bound::miss(&b, &metrics)) {
            outcome = Outcome::Missed { reason };
        }
    }
    let path = path_note(scenario, &outcome);
    RunResult {
        name: cfg.name.clone(),
        case: cfg.case,
        robust: cfg.controller.robust,
        metrics,
        outcome,
        faults,
        faults_expected: cfg.expect_faults,
        miss_expected: cfg.expect_missed,
        path,
        samples,
        plant_factorisations,
    }
}

/// A run that flew to its end says when its waypoint path did not (Choice 312).
fn path_note(scenario: &Scenario, outcome: &Outcome) -> Option<String> {
    match outcome {
        Outcome::Completed | Outcome::Missed { .. } => path_time::run_note(
            scenario.trajectory(),
            scenario.steps() as f64 * scenario.period(),
        ),
        _ => None,
    }
}

/// e = η − η_d from the true pose, the yaw error wrapped to (−π, π].
fn tracking_error(state: &PlantState, reference: &Desired) -> [f64; 6] {
    let mut error = [0.0; 6];
    for (i, e) in error.iter_mut().enumerate() {
        *e = state.eta[i] - f64::from(reference.eta[i]);
    }
    error[5] = wrap_pi(error[5]);
    error
}

/// Why the run stops before period t, if it does: an interrupt, a non-finite state, or a
/// position error beyond the divergence limit.
fn stop(t: f64, state: &PlantState, error: &[f64; 6], limit: f64) -> Option<Outcome> {
    if interrupt::requested() {
        return Some(Outcome::Interrupted { t });
    }
    let diverged = |reason: String| Some(Outcome::Diverged { t, reason });
    if !state.is_finite() {
        return diverged("plant state is not finite".into());
    }
    let position = (error[0] * error[0] + error[1] * error[1] + error[2] * error[2]).sqrt();
    if position > limit {
        return diverged(format!(
            "position error {position:.1} m exceeds the divergence limit {limit} m"
        ));
    }
    None
}

/// The sample of period t before its thrust is known (thrust, τ applied and payload are filled
/// in by the loop).
fn sample_of(
    t: f64,
    state: &PlantState,
    reference: &Desired,
    error: [f64; 6],
    out: &ControlOut,
) -> Sample {
    Sample {
        t,
        eta: state.eta.into(),
        eta_d: reference.eta.cast::<f64>().into(),
        error,
        tau: out.tau.map(f64::from),
        tau_applied: [0.0; 6],
        thrust: [0.0; THRUSTERS],
        voltage: out.voltage.map(f64::from),
        saturated: out.saturated,
        delta: f64::from(out.delta),
        delta_clamped: out.delta_clamped,
        w_norm: f64::from(out.w_norm),
        payload: 0.0,
        status: out.status,
        signals: LoopSignals {
            nu: state.nu.into(),
            eta_d_dot: reference.eta_dot.into(),
            eta_d_ddot: reference.eta_ddot.into(),
            board: out.board,
            ..LoopSignals::default()
        },
    }
}
