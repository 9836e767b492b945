//! How ψ_d is formed ([`HeadingMode`]): the paper's headings (ωt on the circle and the helix,
//! the series of `series.rs` on the figure-eight and the lawn-mower; `paths/`), or the path's
//! course (the tangent heading, docs/missions.md#heading) with its sampled bound on |ψ̈_d|
//! (docs/missions.md#heading **Choice**).

use core::fmt;

use crate::trajectory::paths::PathKind;
use crate::trajectory::phases::tangent;
use crate::trajectory::Trajectory;

/// How a mission's desired heading ψ_d is formed (docs/missions.md#closed-form-paths, docs/missions.md#heading).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum HeadingMode {
    /// The paper's headings: ψ_d = ωt on the circle and the helix, the triangle and trapezoid
    /// series on the figure-eight and the lawn-mower. They make a torpedo vehicle crab.
    #[default]
    Paper,
    /// ψ_d follows the path's course χ_d = atan2(ẏ_d, ẋ_d), with ψ̇_d and ψ̈_d from the
    /// path's curvature (docs/missions.md#heading): ψ̇_d = N/D, ψ̈_d = (Ṅ − ψ̇_d Ḋ)/D with
    /// N = ẋ_d ÿ_d − ẏ_d ẍ_d, D = ẋ_d² + ẏ_d², Ṅ = ẋ_d y⃛_d − ẏ_d x⃛_d,
    /// Ḋ = 2(ẋ_d ẍ_d + ẏ_d ÿ_d). Defined where the horizontal speed √D is not zero:
    /// [`Trajectory::new`] refuses a tangent mission whose minimum speed is below
    /// [`Trajectory::MIN_TANGENT_SPEED`].
    Tangent,
}

impl HeadingMode {
    /// Both modes, the paper's first.
    pub const ALL: [HeadingMode; 2] = [HeadingMode::Paper, HeadingMode::Tangent];

    /// `"paper"` or `"tangent"`: the scenario files' `trajectory.heading`.
    pub const fn as_str(self) -> &'static str {
        match self {
            HeadingMode::Paper => "paper",
            HeadingMode::Tangent => "tangent",
        }
    }

    /// The mode whose [`as_str`](Self::as_str) is `name`.
    pub fn from_name(name: &str) -> Option<HeadingMode> {
        Self::ALL.into_iter().find(|m| m.as_str() == name)
    }
}

impl fmt::Display for HeadingMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Samples per period of the path in the sampled bound on the tangent heading's |ψ̈_d|.
const TANGENT_BOUND_SAMPLES: u32 = 1024;
/// Margin on the sampled maximum of the tangent heading's |ψ̈_d| (docs/missions.md#heading **Choice**).
pub(super) const TANGENT_BOUND_MARGIN: f32 = 1.1;

impl Trajectory {
    /// An upper bound on the tangent heading's |ψ̈_d| (docs/missions.md#heading **Choice**). On the
    /// circle and the helix ψ̈_d = 0 exactly (the course turns at the constant −ω/k). On the
    /// figure-eight and the lawn-mower ψ̈_d is periodic in the path's phase: its maximum over
    /// [`TANGENT_BOUND_SAMPLES`] phases of one period, times [`TANGENT_BOUND_MARGIN`] for
    /// the peak between samples. Fixed work, at configuration time only; the tests check the
    /// bound against whole missions sampled at the control rate.
    pub(super) fn tangent_accel_bound(&self) -> f32 {
        let mut max = 0.0f32;
        for j in 0..TANGENT_BOUND_SAMPLES {
            // One period of the path's course, in TANGENT_BOUND_SAMPLES steps of the phase.
            let a = j.wrapping_mul(u32::MAX / TANGENT_BOUND_SAMPLES + 1);
            let Some(ph) = self.mission.path.course_period_phases(a) else {
                // The course turns at a constant rate: ψ̈_d = 0.
                return 0.0;
            };
            let (_, _, accel) = tangent(&self.mission.path.planar(self, &ph));
            let accel = libm::fabsf(accel);
            if accel > max {
                max = accel;
            }
        }
        max * TANGENT_BOUND_MARGIN
    }
}
