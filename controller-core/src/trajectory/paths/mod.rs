//! The path kinds ([`TrajectoryKind`]), one file each: its parameters and their ranges, the
//! path and its derivatives at a sample, its smallest horizontal speed and its acceleration
//! bound, in closed form (docs/missions.md#closed-form-paths), as an impl of [`PathKind`] (`kind.rs`).
//!
//! **One list.** [`path_kinds!`] below is the only place the kinds are listed: it declares
//! [`TrajectoryKind`] (one variant per kind, holding the kind's struct), its
//! [`EXAMPLES`](TrajectoryKind::EXAMPLES) and [`NAMES`](TrajectoryKind::NAMES), and the one
//! `match` that dispatches each question to the variant's impl. A new closed-form kind is its
//! file (the struct, its docs, its [`ClosedForm`] impl) and one line in the list; the link's
//! wire form (`auv_link::MissionSpec`) then fails to compile until it carries the kind.
//!
//! The waypoint path (docs/missions.md#the-time-law) is the one kind with a route and a time law: its
//! fields stay in the variant (a scenario file's `points`, `speeds`, …), borrowed as a
//! [`WaypointPath`] for the dispatch; it is listed once, in the macro.

mod circle;
mod figure_eight;
mod helix;
mod kind;
mod lawn_mower;
pub(super) mod time_law;
mod waypoint_path;
pub(super) mod waypoints;

pub(crate) use kind::PathKind;

use kind::ClosedForm;
use time_law::{SpeedList, TimeLaw};
use waypoint_path::WaypointPath;
use waypoints::{Route, WaypointList};

/// Declares [`TrajectoryKind`] from the list of closed-form kinds (`"name" => Variant(module::
/// Struct)`, declaration order = the serde and wire order), with the waypoint path last, and
/// `dispatch!(path, k => expr)`: `expr` with `k` bound to the variant's [`PathKind`] (a
/// `match`, so each arm is inlined: no vtable on the tick path). `$d` is a literal `$`, for
/// the inner macro's own variables.
macro_rules! path_kinds {
    ($d:tt $($(#[$doc:meta])* $name:literal => $variant:ident($module:ident::$kind:ident),)+) => {
        $(pub use $module::$kind;)+

        /// Shape and parameters of a mission (the paper's "Simulation Results";
        /// docs/missions.md#closed-form-paths): one variant per path kind, each holding its parameters.
        ///
        /// All frequencies ω are in rad/s and must be positive; sizes in metres; z is positive
        /// down (NED).
        ///
        /// With the `serde` feature it is a table tagged by `kind` (one of
        /// [`NAMES`](Self::NAMES)) with the fields by name; unknown fields are refused, and
        /// `omega` and `depth` default to the paper's values ([`Trajectory::PAPER_OMEGA`],
        /// for the lawn-mower [`Trajectory::PAPER_LAWN_MOWER_OMEGA`];
        /// [`Trajectory::PAPER_DEPTH`]). This is the `[trajectory]` table of host-sim's
        /// scenario files. Values are not validated there: build the mission with
        /// [`Trajectory::new`].
        ///
        /// [`Trajectory::PAPER_OMEGA`]: crate::Trajectory::PAPER_OMEGA
        /// [`Trajectory::PAPER_LAWN_MOWER_OMEGA`]: crate::Trajectory::PAPER_LAWN_MOWER_OMEGA
        /// [`Trajectory::PAPER_DEPTH`]: crate::Trajectory::PAPER_DEPTH
        /// [`Trajectory::new`]: crate::Trajectory::new
        // The waypoint list is ~390 bytes beside the closed forms' 16: no heap on the board
        // (no `Box`), and a mission is copied at configuration only (`Trajectory::set`), never
        // per sample.
        #[allow(clippy::large_enum_variant)]
        // The tag in declaration order (Circle = 0), so that `Trajectory::EMPTY`, a circle of
        // zeros, is all zero bits (a board zeroes it instead of copying it from flash).
        #[repr(u8)]
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(tag = "kind", deny_unknown_fields))]
        pub enum TrajectoryKind {
            $(
                $(#[$doc])*
                #[cfg_attr(feature = "serde", serde(rename = $name))]
                $variant($kind),
            )+
            /// Straight legs through the waypoints, each corner turned on a septic blend, flown
            /// at `speed` along the path (not in the paper; docs/missions.md#waypoint-paths).
            #[cfg_attr(feature = "serde", serde(rename = "waypoints"))]
            Waypoints {
                /// The points in the mission frame (m, z positive down):
                /// `points = [[x, y, z], …]`.
                points: WaypointList,
                /// σ̇, the path speed on the legs (m/s; slower in the turns).
                #[cfg_attr(
                    feature = "serde",
                    serde(deserialize_with = "waypoint_path::narrow_speed")
                )]
                speed: f32,
                /// The smallest radius of a turn (m); `None`: speed²/[`TURN_ACCEL`]
                /// (Choice 151).
                ///
                /// [`TURN_ACCEL`]: crate::trajectory::TURN_ACCEL
                #[cfg_attr(
                    feature = "serde",
                    serde(default, deserialize_with = "waypoint_path::narrow_turn_radius")
                )]
                turn_radius: Option<f32>,
                /// The time law: a speed per leg and turn in path order (m/s; Choice 156), the
                /// profile `host-sim check` proposes; `None`: `speed` everywhere.
                #[cfg_attr(feature = "serde", serde(default))]
                speeds: Option<SpeedList>,
                /// The largest |σ̈| of a change of speed (m/s²); `None`:
                /// [`DEFAULT_SPEED_CHANGE`].
                ///
                /// [`DEFAULT_SPEED_CHANGE`]: crate::trajectory::DEFAULT_SPEED_CHANGE
                #[cfg_attr(
                    feature = "serde",
                    serde(default, deserialize_with = "waypoint_path::narrow_speed_change")
                )]
                speed_change: Option<f32>,
            },
        }

        impl TrajectoryKind {
            /// One valid mission of each kind, in declaration order (each closed form's
            /// example, then a three-point waypoint path): what the tests, the fuzzers, the
            /// golden vectors and the docs iterate.
            pub const EXAMPLES: [TrajectoryKind; [$($name,)+ "waypoints"].len()] =
                [$(TrajectoryKind::$variant(<$kind as ClosedForm>::EXAMPLE),)+ waypoint_path::EXAMPLE];

            /// Each kind's name, in declaration order: the scenario files' `kind`.
            pub const NAMES: [&'static str; [$($name,)+ "waypoints"].len()] = [$($name,)+ "waypoints"];

            /// The kind's name (one of [`NAMES`](Self::NAMES)), e.g. `"figure-eight"`.
            pub const fn name(&self) -> &'static str {
                match self {
                    $(TrajectoryKind::$variant(_) => $name,)+
                    TrajectoryKind::Waypoints { .. } => "waypoints",
                }
            }
        }

        /// `$body` with `$k` bound to `$path`'s kind as a [`PathKind`] (`&` or `&mut`, as
        /// `$path` is).
        macro_rules! dispatch {
            ($d path:expr, $d k:ident => $d body:expr) => {
                match $d path {
                    $(TrajectoryKind::$variant($d k) => $d body,)+
                    TrajectoryKind::Waypoints {
                        points,
                        speed,
                        turn_radius,
                        speeds,
                        speed_change,
                    } => {
                        #[allow(unused_mut)]
                        let mut $d k = WaypointPath {
                            points,
                            speed: *speed,
                            turn_radius: *turn_radius,
                            speeds: speeds.as_ref(),
                            speed_change: *speed_change,
                        };
                        $d body
                    }
                }
            };
        }
    };
}

path_kinds! {$
    /// x = R sin ωt, y = R cos ωt, z = depth, ψ = ωt.
    "circle" => Circle(circle::Circle),
    /// x = A sin ωt, y = A cos(ωt/2), z = depth, ψ the triangle series.
    "figure-eight" => FigureEight(figure_eight::FigureEight),
    /// x = s(0.25 t + 2.5 sin 2ωt), y = 15 s cos ωt, z = depth, ψ the trapezoid series.
    "lawn-mower" => LawnMower(lawn_mower::LawnMower),
    /// A circle whose depth changes linearly: z = depth + depth_rate·t (not in the paper).
    "helix" => Helix(helix::Helix),
}

impl TrajectoryKind {
    /// Visits each `f32` parameter of a closed form, in field order, with its name and the
    /// range [`Trajectory::new`](crate::Trajectory::new) accepts (the waypoint path's points
    /// and options are not visited): a fuzzer fills them from its bytes, the docs list them.
    pub fn parameters(&mut self, visit: &mut dyn FnMut(&crate::trajectory::Parameter, &mut f32)) {
        dispatch!(self, k => k.parameters(visit))
    }
}

/// The path at a sample of `t` ([`PathKind::planar`] of its kind): the tick path's dispatch,
/// one `match` on the kind `t` holds, each arm inlined.
#[inline]
pub(super) fn planar(
    t: &crate::Trajectory,
    ph: &crate::trajectory::phases::Phases,
) -> crate::trajectory::phases::Planar {
    dispatch!(&t.mission.path, k => k.planar(t, ph))
}

/// The paper's heading at a sample of `t` ([`PathKind::paper_heading`] of its kind).
#[inline]
pub(super) fn paper_heading(
    t: &crate::Trajectory,
    theta: u32,
    h: &crate::trajectory::phases::Harmonics,
    p: &crate::trajectory::phases::Planar,
) -> (f32, f32, f32) {
    dispatch!(&t.mission.path, k => k.paper_heading(t, theta, h, p))
}

impl PathKind for TrajectoryKind {
    fn parameters(&mut self, visit: &mut dyn FnMut(&crate::trajectory::Parameter, &mut f32)) {
        TrajectoryKind::parameters(self, visit)
    }

    fn build_into(
        &self,
        route: &mut Route,
        law: &mut TimeLaw,
    ) -> Result<(), crate::trajectory::TrajectoryError> {
        dispatch!(self, k => k.build_into(route, law))
    }

    fn rates(&self) -> (f32, f32) {
        dispatch!(self, k => k.rates())
    }

    fn position_rate(&self, rate: f64) -> crate::phase::LinearRate {
        dispatch!(self, k => k.position_rate(rate))
    }

    fn half_frequency(&self, omega: f64) -> crate::phase::Frequency {
        dispatch!(self, k => k.half_frequency(omega))
    }

    fn heading_series(&self) -> Option<crate::trajectory::series::Series> {
        dispatch!(self, k => k.heading_series())
    }

    fn accel(&self, omega: f32) -> (f32, f32) {
        dispatch!(self, k => k.accel(omega))
    }

    fn min_speed(&self, t: &crate::Trajectory) -> f32 {
        dispatch!(self, k => k.min_speed(t))
    }

    fn course_period_phases(&self, a: u32) -> Option<crate::trajectory::phases::Phases> {
        dispatch!(self, k => k.course_period_phases(a))
    }

    #[inline]
    fn planar(
        &self,
        t: &crate::Trajectory,
        ph: &crate::trajectory::phases::Phases,
    ) -> crate::trajectory::phases::Planar {
        dispatch!(self, k => k.planar(t, ph))
    }

    #[inline]
    fn paper_heading(
        &self,
        t: &crate::Trajectory,
        theta: u32,
        h: &crate::trajectory::phases::Harmonics,
        p: &crate::trajectory::phases::Planar,
    ) -> (f32, f32, f32) {
        dispatch!(self, k => k.paper_heading(t, theta, h, p))
    }
}
