//! The figure-eight (docs/missions.md#closed-form-paths): x_d = A sin ωt, y_d = A cos(ωt/2), z_d = depth,
//! ψ_d the triangle series of base ω (`series.rs`; paper: ω = 0.1, A = 15 or 20 for the
//! 30×30 and 40×40 cases).

#[cfg(feature = "serde")]
use super::kind::{paper_depth, paper_omega};
use super::kind::{ClosedForm, PathKind, DEPTH, OMEGA};
use crate::math;
use crate::phase::{Frequency, MissionTime};
use crate::trajectory::error::{Parameter, ParameterRange};
use crate::trajectory::phases::{Harmonics, Phases, Planar};
use crate::trajectory::series::Series;
use crate::trajectory::Trajectory;

/// x = A sin ωt, y = A cos(ωt/2), z = depth,
/// ψ = (8/π) Σ_{n odd ≤ N} (−1)^((n−1)/2) sin(nωt)/n² (a triangle wave of amplitude π;
/// paper: ω = 0.1, A = 15 or 20 for the 30×30 and 40×40 cases).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct FigureEight {
    /// A (m): x and y each span 2A.
    pub amplitude: f32,
    /// ω (rad/s).
    #[cfg_attr(feature = "serde", serde(default = "paper_omega"))]
    pub omega: f32,
    /// z_d (m, positive down).
    #[cfg_attr(feature = "serde", serde(default = "paper_depth"))]
    pub depth: f32,
}

/// A in (0, [`Trajectory::MAX_SIZE`]].
const AMPLITUDE: Parameter = Parameter {
    name: "amplitude",
    range: ParameterRange::Positive(Trajectory::MAX_SIZE),
};

impl ClosedForm for FigureEight {
    /// The paper's 30 m × 30 m figure-eight.
    const EXAMPLE: FigureEight = FigureEight {
        amplitude: 15.0,
        omega: Trajectory::PAPER_OMEGA,
        depth: Trajectory::PAPER_DEPTH,
    };
}

impl PathKind for FigureEight {
    fn parameters(&mut self, visit: &mut dyn FnMut(&Parameter, &mut f32)) {
        visit(&AMPLITUDE, &mut self.amplitude);
        visit(&OMEGA, &mut self.omega);
        visit(&DEPTH, &mut self.depth);
    }

    fn rates(&self) -> (f32, f32) {
        (self.omega, 0.0)
    }

    /// ω/2k: y_d runs on the half phase.
    fn half_frequency(&self, omega: f64) -> Frequency {
        Frequency::from_rad_per_s(0.5 * omega)
    }

    fn heading_series(&self) -> Option<Series> {
        Some(Series::Triangle)
    }

    /// Σ |amplitude|·frequency² of ẍ_d (Aω²) and of ÿ_d (A(ω/2)²).
    fn accel(&self, omega: f32) -> (f32, f32) {
        let a = self.amplitude;
        let half = 0.5 * omega;
        (a * omega * omega, a * half * half)
    }

    /// ẋ = Aω cos θ, ẏ = −(Aω/2) sin(θ/2), so with s = sin²(θ/2) the speed² is
    /// A²ω²[(1 − 2s)² + s/4], least at s = 15/32: Aω√31/16 ≈ 0.348 Aω.
    fn min_speed(&self, t: &Trajectory) -> f32 {
        self.amplitude * t.omega * math::exact_sqrt(31.0) / 16.0
    }

    /// y_d has the half phase: the course's period is 4π in θ.
    fn course_period_phases(&self, a: u32) -> Option<Phases> {
        Some(Phases {
            half: a,
            h: Harmonics::of(a.wrapping_mul(2)),
            time: MissionTime::new(0, 1),
        })
    }

    /// The path at a sample (ω/k; y_d runs on the half phase).
    #[inline]
    fn planar(&self, t: &Trajectory, ph: &Phases) -> Planar {
        let (amplitude, omega) = (self.amplitude, t.omega);
        let half = 0.5 * omega;
        let (s1, c1) = (ph.h.s1, ph.h.c1);
        let (sh, ch) = math::sin_cos_turns(ph.half);
        Planar {
            x: amplitude * s1,
            y: amplitude * ch,
            z: self.depth,
            z_dot: 0.0,
            z_ddot: 0.0,
            d: [
                [amplitude * omega * c1, -amplitude * half * sh],
                [
                    -amplitude * omega * omega * s1,
                    -amplitude * half * half * ch,
                ],
                [
                    -amplitude * omega * omega * omega * c1,
                    amplitude * half * half * half * sh,
                ],
            ],
        }
    }
}
