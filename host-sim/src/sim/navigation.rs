//! The simulated navigation computer: what the law is told of the vehicle's state each period
//! (the plant's η, ν, or the solution of a `[navigation]` model ([`super::nav_model`]), with
//! the heading as a navigation solution reports it, plus `[noise]`'s seeded white noise),
//! rounded to f32 as it crosses to the controller. The same values go to the law wherever it
//! runs (SIL, PIL, HIL: [`super::ControlSource`]), so PIL = SIL holds with navigation on.

use super::nav_model::{NavComputer, NoiseDraws, Normals, Solution};
use crate::plant::PlantState;
use crate::scenario::{SensorNoise, SimConfig};

/// x reduced into (−π, π].
pub fn wrap_pi(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let r = (x + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// The heading the simulated navigation reports: the plant's ψ while |ψ| ≤
/// [`HEADING_REPORT_BOUND`], else ψ reduced by whole turns into (−π, π].
///
/// **Choice 33:** a navigation solution reports a heading, not a count of turns: the plant's ψ
/// grows without bound on a circle (ω t), and the controller refuses |angle| beyond
/// `controller_core::controller::MAX_ANGLE` (1000 rad), which a 24 h circle reaches after
/// 10 000 s (the run then went to fail-safe and diverged). The reduction is applied only
/// beyond 4π, which the paper's 70 s missions never reach (their ψ stays below 7.1 rad), so
/// the Table-1 runs are bit for bit as before; the controller wraps the yaw error anyway
/// (docs/law.md#structure), so the jump by whole turns is invisible to the law.
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

/// The navigation computer of one run: its model's computer (none: the exact state), its
/// white noise and the noise's generator.
///
/// **Choice 330:** `[noise]` stays what it was, white noise added to what the law is told, now
/// on top of the `[navigation]` solution; with the `ideal` preset (the default, no sources)
/// the run is today's bit for bit: the exact state, then the same draws in the same order from
/// the same seed (docs/navigation.md#noise-and-navigation).
pub struct Navigation {
    computer: Option<NavComputer>,
    noise: Option<SensorNoise>,
    rng: Normals,
}

impl Navigation {
    /// A navigation with `noise` (seeded from it) over the exact state.
    pub fn new(noise: Option<&SensorNoise>) -> Self {
        Self::with_draws(noise, NoiseDraws::EveryPeriod)
    }

    /// [`Navigation::new`] with the noise's generator of `draws` (Choice 536).
    fn with_draws(noise: Option<&SensorNoise>, draws: NoiseDraws) -> Self {
        Navigation {
            computer: None,
            noise: noise.cloned(),
            rng: Normals::new(draws, noise.map_or(0, |n| n.seed)),
        }
    }

    /// The navigation of a run of `cfg`: its `[navigation]` model and its `[noise]`, drawn as
    /// its `noise_draws` says.
    pub fn of(cfg: &SimConfig) -> Self {
        let mut n = Navigation::with_draws(cfg.noise.as_ref(), cfg.noise_draws);
        n.computer = cfg.navigation.as_ref().map(|m| {
            NavComputer::with_draws(m, f64::from(cfg.controller.rate_hz), cfg.noise_draws)
        });
        n
    }

    /// The model's solution of the last period measured (`None` without a model).
    pub fn solution(&self) -> Option<&Solution> {
        self.computer.as_ref().and_then(NavComputer::solution)
    }

    /// The measured η, ν the controller is given, in f32 (one call per control period, in
    /// order).
    pub fn measure(&mut self, state: &PlantState) -> ([f32; 6], [f32; 6]) {
        let (mut eta, mut nu) = (state.eta, state.nu);
        if let Some(c) = &mut self.computer {
            let s = c.measure(&eta.into(), &nu.into());
            eta = s.eta.into();
            nu = s.nu.into();
        }
        eta[5] = reported_heading(eta[5]);
        if let Some(n) = &self.noise {
            for i in 0..6 {
                let a = self.rng.normal();
                let b = self.rng.normal();
                eta[i] += n.eta_sigma[i] * a;
                nu[i] += n.nu_sigma[i] * b;
            }
        }
        (eta.cast::<f32>().into(), nu.cast::<f32>().into())
    }
}
