//! The waypoint path's limits (docs/missions.md#waypoint-paths, Choices 151–152, 156): how many points,
//! legs and parts it may have, and the sanity limits on its geometry and speeds. A leaf: the
//! path's code (`paths/waypoints.rs`, `paths/time_law.rs`) and the refusals that name them
//! (`error.rs`) both read them here.

/// Most waypoints in one mission (Choice 152), on every target: the board builds a
/// trajectory in place ([`crate::Trajectory::set`], Choice 180), so the capacity costs it the
/// `Trajectory`'s static size but no stack copies of it.
pub const MAX_WAYPOINTS: usize = 32;
/// Segments of a path of [`MAX_WAYPOINTS`] points: its legs and the blends between them.
pub const MAX_SEGMENTS: usize = 2 * MAX_WAYPOINTS - 3;
/// Parts of a path of [`MAX_WAYPOINTS`] points: its legs and its turns, alternating.
pub const MAX_PARTS: usize = 2 * MAX_WAYPOINTS - 3;
/// Shortest leg (m): two consecutive waypoints closer than this are one point repeated.
pub const MIN_LEG: f32 = 0.1;
/// Sharpest turn at a waypoint (degrees): the blend's cut grows as sin(Δ/2)/cos²(Δ/2), 6.5 turn
/// radii at 120°, 27 at 150°.
pub const MAX_TURN_DEGREES: f32 = 120.0;
/// Steepest leg, |Δz| / horizontal length (1: 45°).
pub const MAX_SLOPE: f32 = 1.0;
/// Largest coordinate magnitude (m), a sanity limit.
pub const MAX_COORDINATE: f32 = 100_000.0;
/// Fastest path speed (m/s), a sanity limit.
pub const MAX_SPEED: f32 = 10.0;
/// The centripetal acceleration (m/s²) of the default turn radius, turn_radius = speed²/
/// TURN_ACCEL (Choice 151): the paper's circle of 10 m at ω = 0.1 rad/s (Rω² = 0.1 m/s²), which
/// the real vehicle flies within its bound.
pub const TURN_ACCEL: f32 = 0.1;
/// The smallest turn radius (m), default or configured (Choice 310, docs/missions.md#the-corner-radius):
/// a blend is then at least 1 m long (its cut a ≥ R/2), so it lasts at least 0.1 s at the
/// fastest path speed [`MAX_SPEED`] (10 control periods at 100 Hz), and it turns the tangent
/// heading at most at speed/R ≤ 10 rad/s, inside the controller's input limit.
pub const MIN_TURN_RADIUS: f32 = 1.0;
/// `speed_change` when not given (m/s²): the largest |σ̈| of a change of speed.
pub const DEFAULT_SPEED_CHANGE: f32 = 0.05;
/// Largest `speed_change` (m/s²), a sanity limit.
pub const MAX_SPEED_CHANGE: f32 = 10.0;
