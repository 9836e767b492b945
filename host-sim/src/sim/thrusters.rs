//! The simulated thrusters: what they deliver for a period's control output, their optional
//! first-order lag, and the body force they put on the plant (docs/simulator.md#table-1, docs/real-vehicle.md#the-real-chain-in-the-simulator, docs/thrusters.md#the-chain-end-to-end).
//!
//! - ideal actuators (**Choice 32**): the allocated thrusts B₅⁻¹τ, whatever the voltage;
//! - the real chain (**Choice 56**): the controller's (clamped) voltages through the inverse of
//!   Eqs 31–32, read in the controller's thrust unit (the simulated thrusters are the ones the
//!   board is configured for);
//! - a control period in fail-safe: every thruster off (0 N).

use controller_core::effectiveness::THRUSTERS;
use controller_core::thruster::{self, tunnel_thrusts, ThrusterMap};
use controller_core::{Controller, ThrustUnit};
use nalgebra::{Matrix6x5, SVector, Vector6};

use super::control::ControlOut;
use crate::scenario::SimConfig;

/// Thrust per thruster (N).
pub type Thrusts = [f64; THRUSTERS];

/// The thrusters of one run.
pub struct Thrusters<'a> {
    controller: &'a Controller,
    /// The allocation's B, in f64: τ_applied = B·thrust.
    b: Matrix6x5<f64>,
    maps: [ThrusterMap; THRUSTERS],
    unit: ThrustUnit,
    ideal: bool,
    /// 1 − e^(−h/T) of the lag over one plant step h, if there is a lag.
    lag_alpha: Option<f64>,
    /// (T/h)(1 − e^(−h/T)): the lag's mean over a step, for a plant step that is the whole
    /// control period (Choice 400).
    lag_mean: Option<f64>,
    /// The thrust at the end of the last period (the lag's state), once a period has run.
    applied: Option<Thrusts>,
}

impl<'a> Thrusters<'a> {
    /// The thrusters of `config`, for the allocation of `controller`, stepped every `h` s.
    pub fn new(config: &SimConfig, controller: &'a Controller, h: f64) -> Self {
        Thrusters {
            controller,
            b: controller.allocation().matrix().cast::<f64>(),
            maps: thruster::default_maps(),
            unit: config.controller.thrust_unit,
            ideal: config.ideal_actuators,
            lag_alpha: config.thruster_lag.map(|tl| 1.0 - (-h / tl).exp()),
            lag_mean: config.thruster_lag.map(|tl| -(-h / tl).exp_m1() * tl / h),
            applied: None,
        }
    }

    /// The thrust the thrusters are driven towards for this period's control output.
    pub fn target(&self, out: &ControlOut) -> Thrusts {
        if !out.status.is_ok() {
            return [0.0; THRUSTERS];
        }
        if self.ideal {
            let thrusts = self
                .controller
                .allocation()
                .thrusts(&Vector6::from(out.tau));
            return thrusts.map(f64::from);
        }
        // The four tunnels' inverse maps side by side (Choice 570), used where the map is
        // evaluated here.
        let tunnels = tunnel_thrusts(std::array::from_fn(|j| out.voltage[TUNNELS + j]));
        let mut t = [0.0; THRUSTERS];
        for (i, t) in t.iter_mut().enumerate() {
            let v = out.voltage[i];
            let clamped = out.saturated & (1 << i) != 0;
            *t = match out.thrust {
                // Choice 402: the law's maps are these maps in this unit; where the law reports
                // the inverse map of the voltage (Choice 525: not at 0 V, the law's power-off
                // 0 N, nor a tunnel's report, Choice 498) its thrust is
                // newtons_of_voltage(v), the same f32 operations. Elsewhere, and from a board
                // (read by its voltages alone), the map is evaluated here: PIL = SIL.
                Some(law) if thruster::reports_inverse_map(self.maps[i], clamped, v) => law[i],
                // newtons_of_voltage: thrust(v) · the unit's newtons.
                _ if i >= TUNNELS => tunnels[i - TUNNELS] * self.unit.newtons(),
                _ => self.maps[i].newtons_of_voltage(self.unit, v),
            } as f64;
        }
        t
    }

    /// The body force of `thrust`: B·thrust.
    pub fn wrench(&self, thrust: &Thrusts) -> Vector6<f64> {
        self.b * SVector::<f64, THRUSTERS>::from(*thrust)
    }

    /// The thrust at the end of the last period, or `target` before the first.
    pub fn applied_or(&self, target: &Thrusts) -> Thrusts {
        self.applied.unwrap_or(*target)
    }

    /// Drives the thrusters towards `target` over `substeps` plant steps, calling `step` with
    /// each step's index and body force; returns the thrust of the first step (what the
    /// period's sample reports). Stops at the first error of `step`.
    pub fn hold<E>(
        &mut self,
        target: &Thrusts,
        substeps: usize,
        mut step: impl FnMut(usize, &Vector6<f64>) -> Result<(), E>,
    ) -> (Thrusts, Result<(), E>) {
        let mut applied = self.applied_or(target);
        let mut first = None;
        // Without lag the thrust, so the wrench, is the target's all period.
        let mut tau = self.wrench(target);
        let mut result = Ok(());
        for j in 0..substeps {
            if let Some(alpha) = self.lag_alpha {
                let start = applied;
                for i in 0..THRUSTERS {
                    applied[i] += alpha * (target[i] - applied[i]);
                }
                tau = match self.lag_mean {
                    // Choice 400: one step for the whole period (study-grade flight) takes the
                    // lagged thrust's exact mean over it, T(t) = target + (start − target)e^(−t/T):
                    // its impulse, not its end value held for 10 ms.
                    Some(mean) if substeps == 1 => {
                        let m: Thrusts =
                            std::array::from_fn(|i| target[i] + mean * (start[i] - target[i]));
                        self.wrench(&m)
                    }
                    // Several substeps resolve the lag: each holds its end value.
                    _ => self.wrench(&applied),
                };
            } else {
                applied = *target;
            }
            first.get_or_insert(applied);
            result = step(j, &tau);
            if result.is_err() {
                break;
            }
        }
        self.applied = Some(applied);
        (first.unwrap_or(*target), result)
    }
}

/// The index of the first of the four tunnel thrusters ([`thruster::default_maps`]: the main
/// thruster, then four tunnels).
const TUNNELS: usize = 1;
const _: () = {
    let maps = thruster::default_maps();
    assert!(THRUSTERS == TUNNELS + 4);
    assert!(matches!(maps[0], ThrusterMap::Main));
    let mut i = TUNNELS;
    while i < THRUSTERS {
        assert!(matches!(maps[i], ThrusterMap::Tunnel));
        i += 1;
    }
};
