//! The paper's Table-1 metrics (docs/design.md §7) from a run's samples.

use crate::record::{Metrics, Sample};

/// Maximum absolute errors per axis, the paper's path error √(max|e_x|² + max|e_y|² +
/// max|e_z|²), the RMS of the 3-D position error, and the actuator figures.
pub fn compute(samples: &[Sample]) -> Metrics {
    let mut m = Metrics::default();
    if samples.is_empty() {
        return m;
    }
    let mut sq = 0.0;
    let mut saturated = 0usize;
    for s in samples {
        let e = &s.error;
        m.max_x = m.max_x.max(e[0].abs());
        m.max_y = m.max_y.max(e[1].abs());
        m.max_z = m.max_z.max(e[2].abs());
        m.max_roll = m.max_roll.max(e[3].abs());
        m.max_pitch = m.max_pitch.max(e[4].abs());
        m.max_yaw = m.max_yaw.max(e[5].abs());
        sq += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        for v in s.voltage {
            m.peak_voltage = m.peak_voltage.max(v.abs());
        }
        if s.saturated != 0 {
            saturated += 1;
        }
    }
    m.max_path = (m.max_x * m.max_x + m.max_y * m.max_y + m.max_z * m.max_z).sqrt();
    m.rms_path = (sq / samples.len() as f64).sqrt();
    m.saturated_fraction = saturated as f64 / samples.len() as f64;
    m
}
