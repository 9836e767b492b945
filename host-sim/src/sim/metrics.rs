//! The paper's Table-1 metrics (docs/simulator.md#table-1) and the commands' chatter
//! ([`super::chatter`]) from a run's samples, accumulated as the run goes ([`Accumulator`]:
//! constant memory whatever the duration) or from a slice ([`compute`]).

use super::chatter::{ChatterAccumulator, ThrusterChatter};
use super::record::{Metrics, Sample};
use crate::scenario::SimConfig;

/// The metrics of the samples pushed so far: maximum absolute errors per axis, the paper's
/// path error √(max|e_x|² + max|e_y|² + max|e_z|²), the RMS of the 3-D position error, and the
/// actuator figures: peak voltage, saturated fraction and chatter.
#[derive(Clone, Debug)]
pub struct Accumulator {
    m: Metrics,
    sq: f64,
    saturated: u64,
    n: u64,
    chatter: ChatterAccumulator,
}

impl Accumulator {
    /// For the commands of a run of `config`: at its control rate, to its thrusters.
    pub fn of(config: &SimConfig) -> Self {
        Accumulator::new(f64::from(config.controller.rate_hz), config.thruster_lag)
    }

    /// For commands at `rate_hz` to thrusters of time constant `lag` (s; `None`: ideal).
    pub fn new(rate_hz: f64, lag: Option<f64>) -> Self {
        Accumulator {
            m: Metrics::default(),
            sq: 0.0,
            saturated: 0,
            n: 0,
            chatter: ChatterAccumulator::new(rate_hz, lag),
        }
    }

    pub fn push(&mut self, s: &Sample) {
        let m = &mut self.m;
        let e = &s.error;
        m.max_x = m.max_x.max(e[0].abs());
        m.max_y = m.max_y.max(e[1].abs());
        m.max_z = m.max_z.max(e[2].abs());
        m.max_roll = m.max_roll.max(e[3].abs());
        m.max_pitch = m.max_pitch.max(e[4].abs());
        m.max_yaw = m.max_yaw.max(e[5].abs());
        self.sq += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        for v in s.voltage {
            m.peak_voltage = m.peak_voltage.max(v.abs());
        }
        if s.saturated != 0 {
            self.saturated += 1;
        }
        self.chatter.push(s.t, &s.voltage);
        self.n += 1;
    }

    /// The metrics ([`Metrics::NONE`] for no samples).
    pub fn metrics(&self) -> Metrics {
        let mut m = self.m;
        if self.n == 0 {
            return Metrics::NONE;
        }
        m.max_path = (m.max_x * m.max_x + m.max_y * m.max_y + m.max_z * m.max_z).sqrt();
        m.rms_path = (self.sq / self.n as f64).sqrt();
        m.saturated_fraction = self.saturated as f64 / self.n as f64;
        m.chatter = self.chatter.chatter();
        m.reversals_per_s = m.chatter.worst(|c: &ThrusterChatter| c.reversals_per_s).0;
        m.command_tv = m.chatter.worst(|c: &ThrusterChatter| c.command_tv).0;
        m.hf_share = m.chatter.worst(|c: &ThrusterChatter| c.hf_share).0;
        m
    }
}

/// The metrics of `samples` ([`Accumulator`] over them), commanded at the default control
/// rate to ideal thrusters.
pub fn compute(samples: &[Sample]) -> Metrics {
    let rate = f64::from(controller_core::ControllerConfig::default().rate_hz);
    let mut acc = Accumulator::new(rate, None);
    for s in samples {
        acc.push(s);
    }
    acc.metrics()
}
