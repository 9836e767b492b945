//! Chatter of a run's thruster voltages, counted from its samples (the estimator's comparison,
//! docs/law.md#the-state-estimator): per thruster, the sign reversals through a ±[`BAND`] dead
//! band and the voltage's total variation.

use controller_core::effectiveness::THRUSTERS;
use host_sim::sim::{Observer, Sample};

/// A thruster's voltage reverses when it goes from beyond +BAND (V) to beyond −BAND, or back.
pub const BAND: f64 = 0.5;

/// Sees every sample of a run.
#[derive(Default)]
pub struct Chatter {
    sign: [i8; THRUSTERS],
    reversals: [u64; THRUSTERS],
    variation: [f64; THRUSTERS],
    last: Option<[f64; THRUSTERS]>,
    first_t: Option<f64>,
    last_t: f64,
}

impl Chatter {
    fn duration(&self) -> f64 {
        (self.last_t - self.first_t.unwrap_or(0.0)).max(1e-9)
    }

    /// Sign reversals per second, per thruster.
    pub fn reversals_per_s(&self) -> [f64; THRUSTERS] {
        self.reversals.map(|n| n as f64 / self.duration())
    }

    /// Σ|ΔV| per second, per thruster (V/s).
    pub fn variation_per_s(&self) -> [f64; THRUSTERS] {
        self.variation.map(|v| v / self.duration())
    }
}

impl Observer for Chatter {
    fn sample(&mut self, s: &Sample) {
        for i in 0..THRUSTERS {
            let v = s.voltage[i];
            let now = if v > BAND {
                1
            } else if v < -BAND {
                -1
            } else {
                0
            };
            if now != 0 {
                if self.sign[i] != 0 && now != self.sign[i] {
                    self.reversals[i] += 1;
                }
                self.sign[i] = now;
            }
            if let Some(last) = self.last {
                self.variation[i] += (v - last[i]).abs();
            }
        }
        self.last = Some(s.voltage);
        self.first_t.get_or_insert(s.t);
        self.last_t = s.t;
    }
}
