//! The waypoint path (docs/missions.md#waypoint-paths, Choices 150–156): straight legs between the
//! waypoints, each corner turned on a **septic Hermite blend**, flown at a constant path
//! speed (`speed` over the time scale k).
//!
//! **The blend** (Choice 150). At waypoint W between legs of unit directions u_in, u_out
//! (turn angle Δ), the path leaves the first leg a cut distance a before W and joins the
//! second a after it: P₀ = W − a·u_in, P₁ = W + a·u_out. The blend is the septic Hermite
//! interpolant of the two legs over a parameter length L = 2a (position, unit tangent and zero
//! second and third derivatives matched at both ends). With these end conditions its basis
//! collapses to one sextic: with u = σ/L ∈ [0, 1],
//!
//! B(σ) = P₀ + u_in·σ + e·q(u),  e = a·(u_out − u_in),  q(u) = u⁴(5 − 6u + 2u²),
//!
//! q(0) = q′(0) = q″(0) = q‴(0) = 0, q(1) = 1, q′(1) = 2, q″(1) = q‴(1) = 0 (so B(L) = P₁,
//! B′(L) = u_out), and q″(u) = 60u²(1 − u)²: the blend's acceleration p″ = e·q″/L² keeps one
//! direction and its size is a smooth bump that is zero, with its slope, at both ends. The path
//! is therefore C³ in its parameter σ at every knot, every derivative is a polynomial in closed
//! form, and one sample costs a fixed ~40 flops whatever the segment. A leg is the same form
//! with e = 0 (p = P₀ + u·σ exactly), so every segment is evaluated by the same code.
//!
//! **Closed forms of the blend** (at u = ½: q = 5/32, q′ = 1, q″ = 15/4; the tests check them
//! by dense sampling): the parameter speed |B′(σ)| is ≤ 1 everywhere and cos(Δ/2) at the middle (the path
//! is slower in a turn than on a leg at the same σ̇); the largest curvature is at the middle,
//! κ_max = (15/8)·sin(Δ/2) / (a·cos²(Δ/2)); and the blend passes the waypoint at the distance
//! (5/16)·a·sin(Δ/2) (at u = ½, on the inside of the turn): the path's stated tolerance.
//!
//! **The corner rule** (Choice 151): a = turn_radius · max((15/8)·sin(Δ/2)/cos²(Δ/2), ½), so that
//! κ ≤ 1/turn_radius on every blend (the ½ keeps a blend of a nearly straight corner from being
//! shorter than half a radius). Refused (Choice 152): fewer than 2 or more than
//! [`MAX_WAYPOINTS`] points, two consecutive points closer than [`MIN_LEG`] (repeated), a turn
//! over [`MAX_TURN_DEGREES`], a leg too short for the cuts of its two corners, a leg steeper
//! than [`MAX_SLOPE`] (the tangent heading needs horizontal motion).
//!
//! **Lookup** (Choice 153): the segments' start parameters are sorted; a fixed
//! [`SEARCH_STEPS`]-step binary search finds the segment (the same work for any point count).
//! After the last waypoint the path continues straight along the last leg (C³ there too).

use crate::math;
use crate::phase::{LinearRate, MissionTime};
use crate::trajectory::error::TrajectoryError;
use crate::trajectory::limits::{
    MAX_COORDINATE, MAX_SEGMENTS, MAX_SLOPE, MAX_TURN_DEGREES, MAX_WAYPOINTS, MIN_LEG,
    MIN_TURN_RADIUS, TURN_ACCEL,
};
use crate::trajectory::phases::Planar;

/// Steps of the binary search: 2^SEARCH_STEPS ≥ [`MAX_SEGMENTS`].
const SEARCH_STEPS: u32 = 6;
const _: () = assert!(1 << SEARCH_STEPS >= MAX_SEGMENTS);
/// The smallest cut, in turn radii (Choice 151).
const MIN_CUT: f32 = 0.5;
/// A straight remainder of a leg shorter than this (m) is not a segment of its own.
const MIN_SEGMENT: f32 = 1e-3;

/// The waypoints of a mission in its frame (x north, y east, z down, m): 2 to
/// [`MAX_WAYPOINTS`] points in a fixed array (no heap). With the `serde` feature it is the
/// scenario's `points = [[x, y, z], …]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaypointList {
    len: u8,
    points: [[f32; 3]; MAX_WAYPOINTS],
}

impl WaypointList {
    /// The points, or [`TrajectoryError::WaypointCount`] if there are more than
    /// [`MAX_WAYPOINTS`] (fewer than 2 are refused by [`crate::Trajectory::new`]).
    pub fn new(points: &[[f32; 3]]) -> Result<Self, TrajectoryError> {
        if points.len() > MAX_WAYPOINTS {
            return Err(TrajectoryError::WaypointCount {
                count: points.len(),
            });
        }
        let mut list = WaypointList {
            len: points.len() as u8,
            points: [[0.0; 3]; MAX_WAYPOINTS],
        };
        list.points[..points.len()].copy_from_slice(points);
        Ok(list)
    }

    /// The points of a list known at compile time (at most [`MAX_WAYPOINTS`]: more is a
    /// compile error where it is evaluated as a constant).
    pub(crate) const fn from_array<const N: usize>(points: [[f32; 3]; N]) -> Self {
        assert!(N <= MAX_WAYPOINTS);
        let mut list = WaypointList {
            len: N as u8,
            points: [[0.0; 3]; MAX_WAYPOINTS],
        };
        let mut i = 0;
        while i < N {
            list.points[i] = points[i];
            i += 1;
        }
        list
    }

    /// The points, in order.
    pub fn as_slice(&self) -> &[[f32; 3]] {
        &self.points[..self.len as usize]
    }
}

/// The turn radius flown (m): as configured, else speed²/[`TURN_ACCEL`], at least
/// [`MIN_TURN_RADIUS`] (Choice 151).
pub fn turn_radius(speed: f32, configured: Option<f32>) -> f32 {
    configured.unwrap_or((speed * speed / TURN_ACCEL).max(MIN_TURN_RADIUS))
}

/// One segment: p(σ) = p0 + dir·(σ − s0) + e·q(u), u = (σ − s0)/len (e = 0 on a leg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    s0: f32,
    len: f32,
    inv_len: f32,
    /// Which part of the path it is: 2i for (the straight part of) leg i, 2i − 1 for the turn
    /// at waypoint i: the index of its speed in a [`SpeedList`](super::time_law::SpeedList).
    part: u8,
    p0: [f32; 3],
    dir: [f32; 3],
    e: [f32; 3],
}

/// Points of the scan in [`Route::heading_accel_peaks`].
const PEAK_SCAN: u32 = 256;

/// A blend's horizontal tangent h(s) = h_in + s·Δh (Choice 314): 1/L, |h_in|², h_in·Δh,
/// |Δh|² and C = h_in × Δh.
struct BlendGeometry {
    inv_len: f32,
    h2: f32,
    dot: f32,
    dh2: f32,
    c: f32,
}

impl BlendGeometry {
    /// D(s) = |h_in + s·Δh|².
    fn d(&self, s: f32) -> f32 {
        self.h2 + s * (2.0 * self.dot + s * self.dh2)
    }

    /// The smallest D on s ∈ [0, 1] (a quadratic: at s* = −h_in·Δh/|Δh|², clamped).
    fn d_min(&self) -> f32 {
        let s = match self.dh2 > 0.0 {
            true => (-self.dot / self.dh2).clamp(0.0, 1.0),
            false => 0.0,
        };
        self.d(s)
    }
}

/// An unused segment (all zeros).
const NO_SEGMENT: Segment = Segment {
    s0: 0.0,
    len: 0.0,
    inv_len: 0.0,
    part: 0,
    p0: [0.0; 3],
    dir: [0.0; 3],
    e: [0.0; 3],
};

/// The precomputed path: its segments in order of σ, the total length, and the end point and
/// direction the path continues along.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Route {
    count: u8,
    segments: [Segment; MAX_SEGMENTS],
    length: f32,
    end: [f32; 3],
    end_dir: [f32; 3],
    /// The cut distance a at each inner waypoint (index 0 and the last are 0).
    cuts: [f32; MAX_WAYPOINTS],
    /// The turn angle at each inner waypoint (rad).
    turns: [f32; MAX_WAYPOINTS],
}

/// Position and its first three derivatives with respect to σ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// p(σ).
    pub p: [f32; 3],
    /// dp/dσ, d²p/dσ², d³p/dσ³.
    pub d: [[f32; 3]; 3],
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(v: [f32; 3], k: f32) -> [f32; 3] {
    [v[0] * k, v[1] * k, v[2] * k]
}
fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn length(v: [f32; 3]) -> f32 {
    math::exact_sqrt(dot(v, v))
}

/// Every coordinate finite and within ±[`MAX_COORDINATE`] (parameter `points`; the error
/// names the waypoint and the coordinate, Choice 315).
fn check_points(pts: &[[f32; 3]]) -> Result<(), TrajectoryError> {
    for (index, p) in pts.iter().enumerate() {
        for (axis, &value) in p.iter().enumerate() {
            if !value.is_finite() {
                return Err(TrajectoryError::PointNotFinite { index, axis });
            }
            if value.abs() > MAX_COORDINATE {
                return Err(TrajectoryError::BadPoint { index, axis, value });
            }
        }
    }
    Ok(())
}

/// The cut distance at a corner whose unit directions are `u_in`, `u_out` (Choice 151), and
/// the turn angle (rad). sin(Δ/2) = |u_out − u_in|/2, cos(Δ/2) = |u_in + u_out|/2.
pub(crate) fn corner(u_in: [f32; 3], u_out: [f32; 3], turn_radius: f32) -> (f32, f32) {
    let s = 0.5 * length(sub(u_out, u_in));
    let c = 0.5 * length(add(u_in, u_out));
    let f = 15.0 / 8.0 * s / (c * c);
    (turn_radius * f.max(MIN_CUT), 2.0 * libm::atan2f(s, c))
}

impl Route {
    /// No segments (the route of a path that is not a waypoint path).
    pub const EMPTY: Route = Route {
        count: 0,
        segments: [NO_SEGMENT; MAX_SEGMENTS],
        length: 0.0,
        end: [0.0; 3],
        end_dir: [0.0; 3],
        cuts: [0.0; MAX_WAYPOINTS],
        turns: [0.0; MAX_WAYPOINTS],
    };

    /// Checks the points (Choice 152; the error's parameter is `points`) and builds the legs
    /// and blends for corners of radius `turn_radius` (m, positive and finite: checked by the
    /// caller) into `self`, in place (Choice 180: no `Route` on the stack). Every entry past
    /// the new path's is reset, so the result is the same whatever `self` held; after an error
    /// `self` has no segments (it samples as [`Route::EMPTY`]). Fixed work: at most
    /// [`MAX_SEGMENTS`] segments.
    pub fn build_into(
        &mut self,
        list: &WaypointList,
        turn_radius: f32,
    ) -> Result<(), TrajectoryError> {
        self.clear();
        let pts = list.as_slice();
        let n = pts.len();
        if n < 2 {
            return Err(TrajectoryError::WaypointCount { count: n });
        }
        check_points(pts)?;
        // Legs: unit directions and lengths.
        let mut dirs = [[0.0f32; 3]; MAX_WAYPOINTS];
        let mut lens = [0.0f32; MAX_WAYPOINTS];
        for i in 0..n - 1 {
            let d = sub(pts[i + 1], pts[i]);
            let len = length(d);
            if len.is_nan() || len < MIN_LEG {
                return Err(TrajectoryError::RepeatedWaypoint { index: i + 1 });
            }
            let horizontal = math::exact_sqrt(d[0] * d[0] + d[1] * d[1]);
            if d[2].abs() > MAX_SLOPE * horizontal {
                return Err(TrajectoryError::TooSteep {
                    leg: i,
                    slope: d[2].abs() / horizontal,
                });
            }
            dirs[i] = scale(d, 1.0 / len);
            lens[i] = len;
        }
        let cos_max = libm::cosf(MAX_TURN_DEGREES.to_radians());
        for j in 1..n - 1 {
            if dot(dirs[j - 1], dirs[j]) < cos_max {
                let (_, turn) = corner(dirs[j - 1], dirs[j], turn_radius);
                return Err(TrajectoryError::TurnTooSharp {
                    index: j,
                    degrees: turn.to_degrees(),
                });
            }
            let (cut, turn) = corner(dirs[j - 1], dirs[j], turn_radius);
            self.cuts[j] = cut;
            self.turns[j] = turn;
        }
        for (i, &has) in lens.iter().enumerate().take(n - 1) {
            let needs = self.cuts[i] + self.cuts[i + 1];
            if needs > has {
                return Err(TrajectoryError::LegTooShort { leg: i, needs, has });
            }
        }
        self.assemble(pts, &dirs, &lens);
        Ok(())
    }

    /// Back to [`Route::EMPTY`], in place.
    pub(crate) fn clear(&mut self) {
        self.count = 0;
        self.segments.fill(NO_SEGMENT);
        self.length = 0.0;
        self.end = [0.0; 3];
        self.end_dir = [0.0; 3];
        self.cuts.fill(0.0);
        self.turns.fill(0.0);
    }

    /// The segments in order: leg 0, blend 1, leg 1, … (a leg's straight remainder shorter
    /// than [`MIN_SEGMENT`] is left out).
    fn assemble(&mut self, pts: &[[f32; 3]], dirs: &[[f32; 3]], lens: &[f32]) {
        let n = pts.len();
        let mut s = 0.0f32;
        let mut count = 0usize;
        for i in 0..n - 1 {
            if i > 0 {
                // The blend at waypoint i.
                let a = self.cuts[i];
                let len = 2.0 * a;
                self.segments[count] = Segment {
                    s0: s,
                    len,
                    part: (2 * i - 1) as u8,
                    inv_len: 1.0 / len,
                    p0: sub(pts[i], scale(dirs[i - 1], a)),
                    dir: dirs[i - 1],
                    e: scale(sub(dirs[i], dirs[i - 1]), a),
                };
                count += 1;
                s += len;
            }
            let straight = lens[i] - self.cuts[i] - self.cuts[i + 1];
            if straight >= MIN_SEGMENT {
                self.segments[count] = Segment {
                    s0: s,
                    len: straight,
                    part: (2 * i) as u8,
                    inv_len: 1.0 / straight,
                    p0: add(pts[i], scale(dirs[i], self.cuts[i])),
                    dir: dirs[i],
                    e: [0.0; 3],
                };
                count += 1;
                s += straight;
            }
        }
        self.count = count as u8;
        self.length = s;
        self.end_dir = dirs[n - 2];
        // The last segment's end (the last waypoint, to rounding): p0 + dir·len + e·q(1).
        let last = &self.segments[count - 1];
        self.end = add(add(last.p0, scale(last.dir, s - last.s0)), last.e);
    }

    /// The path's parameter length (m): the legs' straight parts plus the blends' 2a.
    pub fn length(&self) -> f32 {
        self.length
    }

    /// Number of segments (legs and blends).
    pub fn segment_count(&self) -> usize {
        self.count as usize
    }

    /// The parameter σ at which segment `i` starts (i < [`Route::segment_count`]).
    pub fn segment_start(&self, i: usize) -> f32 {
        self.segments[i].s0
    }

    /// Segment `i`'s parameter length (m).
    pub fn segment_length(&self, i: usize) -> f32 {
        self.segments[i].len
    }

    /// Which part of the path segment `i` is: 2j for leg j, 2j − 1 for the turn at waypoint j.
    pub fn segment_part(&self, i: usize) -> usize {
        self.segments[i].part as usize
    }

    /// The cut distance a at waypoint `i` (m; 0 at the first and last).
    pub fn cut(&self, i: usize) -> f32 {
        self.cuts[i]
    }

    /// The turn angle Δ at waypoint `i` (rad; 0 at the first and last).
    pub fn turn(&self, i: usize) -> f32 {
        self.turns[i]
    }

    /// The number of waypoints the route was built from (0 for an empty route): the last
    /// segment is the last leg, n − 2, whose part is 2(n − 2).
    pub fn waypoint_count(&self) -> usize {
        match self.count {
            0 => 0,
            n => self.segments[n as usize - 1].part as usize / 2 + 2,
        }
    }

    /// The path parameter σ (m) at which the path passes waypoint `i` nearest (Choice 311): 0
    /// at the first, the path's length at the last, the middle of the blend (its start plus
    /// the cut a, where the waypoint is passed at [`Route::miss`]) at an inner one.
    pub fn passing(&self, i: usize) -> f32 {
        if i == 0 {
            return 0.0;
        }
        let turn = (2 * i - 1) as u8;
        self.segments[..self.count as usize]
            .iter()
            .find(|s| s.part == turn)
            .map_or(self.length, |s| s.s0 + self.cuts[i])
    }

    /// The distance at which the path passes waypoint `i` (m): (5/16)·a·sin(Δ/2), 0 at the
    /// first and the last.
    pub fn miss(&self, i: usize) -> f32 {
        5.0 / 16.0 * self.cuts[i] * libm::sinf(0.5 * self.turns[i])
    }

    /// The largest curvature of the blend at waypoint `i` (1/m), in closed form:
    /// (15/8)·sin(Δ/2)/(a·cos²(Δ/2)); 0 where there is no blend.
    pub fn peak_curvature(&self, i: usize) -> f32 {
        let a = self.cuts[i];
        if a <= 0.0 {
            return 0.0;
        }
        let (s, c) = (
            libm::sinf(0.5 * self.turns[i]),
            libm::cosf(0.5 * self.turns[i]),
        );
        15.0 / 8.0 * s / (a * c * c)
    }

    /// The tangent heading on segment `i` in closed form (Choice 314): its first two
    /// derivatives with respect to σ, (ψ′, ψ″), at `local` = σ − the segment's start (0 on a
    /// leg; at σ̇ = v, σ̈ = 0 the heading's rate is ψ′v and its acceleration ψ″v²). On a blend
    /// the horizontal tangent is h(s) = h_in + s·Δh with s = q′(u)/2 ∈ [0, 1] (u = local/L,
    /// Δh = h_out − h_in), so with C = h_in × Δh, D(s) = |h(s)|², s′ = q″(u)/(2L) and
    /// s″ = q‴(u)/(2L²):
    ///
    /// ψ′ = C·s′/D,  ψ″ = C·s″/D − C·D′(s)·s′²/D²,  D′(s) = 2 h_in·Δh + 2s|Δh|².
    pub fn heading_derivatives(&self, i: usize, local: f32) -> (f32, f32) {
        let Some(b) = self.blend(i) else {
            return (0.0, 0.0);
        };
        let u = local * b.inv_len;
        let w = u * (1.0 - u);
        let s = 0.5 * u * u * u * (20.0 + u * (-30.0 + 12.0 * u));
        let s1 = 30.0 * w * w * b.inv_len;
        let s2 = 60.0 * w * (1.0 - 2.0 * u) * b.inv_len * b.inv_len;
        let d = b.d(s);
        let dd = 2.0 * (b.dot + s * b.dh2);
        (b.c * s1 / d, b.c * s2 / d - b.c * dd * s1 * s1 / (d * d))
    }

    /// A bound on |ψ′| over blend `i` in closed form (Choice 314; 0 on a leg):
    /// |C|/D_min · 15/(8L), the largest s′ (q″(½)/(2L)) over the smallest |h|². Exact for a
    /// level corner, where both are at the middle: (15/8)·tan(Δ/2)/a, ≤ cos(Δ/2)/R by the
    /// corner rule (Choice 151), so a blend flown at speed v turns the heading at most at v/R.
    pub fn peak_heading_rate(&self, i: usize) -> f32 {
        match self.blend(i) {
            Some(b) => libm::fabsf(b.c) / b.d_min() * (15.0 / 8.0) * b.inv_len,
            None => 0.0,
        }
    }

    /// The largest |ψ″| over blend `i` (Choice 314; 0 on a leg): the closed form
    /// ([`Route::heading_derivatives`]) at the peaks [`Route::heading_accel_peaks`] finds.
    /// (Each factor at its own largest would bound it too, but 3× high at 90°: at a level
    /// 90° corner the peak is 0.451/R², the bound 1.41/R².)
    pub fn peak_heading_accel(&self, i: usize) -> f32 {
        let [up, down] = self.heading_accel_peaks(i);
        libm::fabsf(self.heading_derivatives(i, up).1)
            .max(libm::fabsf(self.heading_derivatives(i, down).1))
    }

    /// Where on blend `i` the heading's acceleration is largest (Choice 314): the local σ of
    /// the largest and of the smallest ψ″ ([`Route::heading_derivatives`]), found on the closed
    /// form by a scan of [`PEAK_SCAN`] points and a golden-section refinement around each;
    /// `[0, 0]` on a leg. Configuration-time work, for the host's preflight.
    pub fn heading_accel_peaks(&self, i: usize) -> [f32; 2] {
        let Some(b) = self.blend(i) else {
            return [0.0; 2];
        };
        let len = 1.0 / b.inv_len;
        let at = |u: f32| self.heading_derivatives(i, u * len).1;
        let mut best = [(0.0f32, f32::NEG_INFINITY), (0.0f32, f32::NEG_INFINITY)];
        for j in 0..=PEAK_SCAN {
            let u = j as f32 / PEAK_SCAN as f32;
            let v = at(u);
            if v > best[0].1 {
                best[0] = (u, v);
            }
            if -v > best[1].1 {
                best[1] = (u, -v);
            }
        }
        let step = 1.0 / PEAK_SCAN as f32;
        let refine = |u0: f32, sign: f32| {
            let (mut lo, mut hi) = ((u0 - step).max(0.0), (u0 + step).min(1.0));
            const G: f32 = 0.618_034;
            for _ in 0..30 {
                let (m1, m2) = (hi - G * (hi - lo), lo + G * (hi - lo));
                if sign * at(m1) >= sign * at(m2) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            0.5 * (lo + hi) * len
        };
        [refine(best[0].0, 1.0), refine(best[1].0, -1.0)]
    }

    /// The horizontal geometry of blend `i`, `None` for a leg or an index past the end.
    fn blend(&self, i: usize) -> Option<BlendGeometry> {
        let seg = self.segments[..self.count as usize].get(i)?;
        if seg.part % 2 == 0 {
            return None;
        }
        // u_out − u_in = e/a = 2e/L.
        let k = 2.0 * seg.inv_len;
        let (hx, hy) = (seg.dir[0], seg.dir[1]);
        let (dx, dy) = (seg.e[0] * k, seg.e[1] * k);
        Some(BlendGeometry {
            inv_len: seg.inv_len,
            h2: hx * hx + hy * hy,
            dot: hx * dx + hy * dy,
            dh2: dx * dx + dy * dy,
            c: hx * dy - hy * dx,
        })
    }

    /// The index of the segment holding σ: the last whose start is ≤ σ, by a binary search of
    /// a fixed [`SEARCH_STEPS`] steps.
    #[inline]
    fn find(&self, sigma: f32) -> usize {
        let mut lo = 0usize;
        let mut step = 1usize << (SEARCH_STEPS - 1);
        let count = self.count as usize;
        for _ in 0..SEARCH_STEPS {
            let probe = lo + step;
            if probe < count && self.segments[probe].s0 <= sigma {
                lo = probe;
            }
            step >>= 1;
        }
        lo
    }

    /// p(σ) and its first three derivatives; before 0 the first segment's polynomial, after
    /// the end the straight continuation of the last leg. Fixed work, never panics (an empty
    /// route gives zeros).
    #[inline]
    pub fn at(&self, sigma: f32) -> PathPoint {
        let (segment, start) = self.locate(sigma);
        self.at_local(segment, sigma - start)
    }

    /// Where σ lies: the segment's index (`None` beyond the end, where the path continues
    /// straight) and the σ its local parameter is counted from.
    #[inline]
    pub fn locate(&self, sigma: f32) -> (Option<usize>, f32) {
        if sigma >= self.length || self.count == 0 {
            (None, self.length)
        } else {
            let i = self.find(sigma);
            (Some(i), self.segments[i].s0)
        }
    }

    /// p and its derivatives at `local` = σ − the start [`Route::locate`] gave: a caller that
    /// forms `local` with one rounding (from the mission time) keeps the position exact to its
    /// ulp however long the path (σ itself, as an f32, is only good to 1.2e-4 m at 1.3 km).
    #[inline]
    pub fn at_local(&self, segment: Option<usize>, local: f32) -> PathPoint {
        let Some(i) = segment else {
            return PathPoint {
                p: add(self.end, scale(self.end_dir, local)),
                d: [self.end_dir, [0.0; 3], [0.0; 3]],
            };
        };
        let seg = &self.segments[i];
        // Not clamped: `local` may stray past the segment by σ's rounding, and the polynomial
        // continues into the next segment to O(δ⁴) (its derivatives match there up to the third).
        let u = local * seg.inv_len;
        let w = u * (1.0 - u);
        let u2 = u * u;
        let k = seg.inv_len;
        // q and its derivatives with respect to σ (q′/L, q″/L², q‴/L³).
        let q = [
            u2 * u2 * (5.0 + u * (-6.0 + 2.0 * u)),
            u2 * u * (20.0 + u * (-30.0 + 12.0 * u)) * k,
            60.0 * w * w * k * k,
            120.0 * w * (1.0 - 2.0 * u) * k * k * k,
        ];
        let mut p = [0.0f32; 3];
        let mut d = [[0.0f32; 3]; 3];
        for axis in 0..3 {
            let e = seg.e[axis];
            p[axis] = seg.p0[axis] + seg.dir[axis] * local + e * q[0];
            d[0][axis] = seg.dir[axis] + e * q[1];
            d[1][axis] = e * q[2];
            d[2][axis] = e * q[3];
        }
        PathPoint { p, d }
    }
}

/// The path flown at σ̇ = `rate` (σ̈ = 0) at the mission time `time` (σ = rate·t): x_d, y_d and
/// three time derivatives, z_d, ż_d, z̈_d. σ locates the segment; the local parameter
/// rate·t − start is then formed to a few ulps of itself ([`MissionTime::linear_since`]).
#[inline]
pub(super) fn planar(
    route: &Route,
    time: &MissionTime,
    position_rate: &LinearRate,
    rate: f32,
) -> Planar {
    let (segment, start) = route.locate(time.linear(position_rate, 0.0));
    let pp = route.at_local(segment, time.linear_since(position_rate, start));
    from_path(&pp, rate)
}

/// A path point flown at σ̇ = `rate`, σ̈ = 0.
#[inline]
pub(super) fn from_path(pp: &PathPoint, rate: f32) -> Planar {
    let r2 = rate * rate;
    let r3 = r2 * rate;
    Planar {
        x: pp.p[0],
        y: pp.p[1],
        z: pp.p[2],
        z_dot: pp.d[0][2] * rate,
        z_ddot: pp.d[1][2] * r2,
        d: [
            [pp.d[0][0] * rate, pp.d[0][1] * rate],
            [pp.d[1][0] * r2, pp.d[1][1] * r2],
            [pp.d[2][0] * r3, pp.d[2][1] * r3],
        ],
    }
}

/// Samples per segment for the configuration-time bounds ([`bounds`]).
const BOUND_SAMPLES: u32 = 64;

/// What one segment asks at σ̇ = 1, σ̈ = 0 (sampled at [`BOUND_SAMPLES`] points and both ends;
/// the caller scales by the speeds and adds a margin): the smallest horizontal parameter speed
/// |p′_h|, the largest ‖p″‖, and the tangent heading's largest |ψ′| and |ψ″|.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SegmentBounds {
    pub(crate) min_speed: f32,
    pub(crate) accel: f32,
    pub(crate) heading_rate: f32,
    pub(crate) heading_accel: f32,
}

/// [`SegmentBounds`] of segment `i`. Fixed work.
pub(crate) fn segment_bounds(route: &Route, i: usize) -> SegmentBounds {
    let seg = route.segments[i];
    let mut b = SegmentBounds {
        min_speed: f32::INFINITY,
        accel: 0.0,
        heading_rate: 0.0,
        heading_accel: 0.0,
    };
    for j in 0..=BOUND_SAMPLES {
        let local = seg.len * (j as f32 / BOUND_SAMPLES as f32);
        let p = from_path(&route.at_local(Some(i), local), 1.0);
        let speed = math::exact_sqrt(p.d[0][0] * p.d[0][0] + p.d[0][1] * p.d[0][1]);
        b.min_speed = b.min_speed.min(speed);
        let [ax, ay] = p.d[1];
        b.accel = b
            .accel
            .max(math::exact_sqrt(ax * ax + ay * ay + p.z_ddot * p.z_ddot));
        let (_, rate, accel) = crate::trajectory::phases::tangent(&p);
        b.heading_rate = b.heading_rate.max(rate.abs());
        b.heading_accel = b.heading_accel.max(accel.abs());
    }
    b
}

/// At σ̇ = 1 over the whole path: the smallest |p′_h|, the largest ‖p″‖ and |ψ″|.
pub(crate) fn bounds(route: &Route) -> (f32, f32, f32) {
    let mut out = (f32::INFINITY, 0.0f32, 0.0f32);
    for i in 0..route.count as usize {
        let b = segment_bounds(route, i);
        out = (
            out.0.min(b.min_speed),
            out.1.max(b.accel),
            out.2.max(b.heading_accel),
        );
    }
    out
}

/// `points = [[x, y, z], …]`: a sequence of at most [`MAX_WAYPOINTS`] triples (the error of a
/// longer one says the limit).
#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for WaypointList {
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        struct Points;
        impl<'de> serde::de::Visitor<'de> for Points {
            type Value = WaypointList;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                write!(f, "a list of at most {MAX_WAYPOINTS} points [x, y, z]")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                let mut list = WaypointList {
                    len: 0,
                    points: [[0.0; 3]; MAX_WAYPOINTS],
                };
                while let Some(p) = seq.next_element::<[f64; 3]>()? {
                    let index = list.len as usize;
                    if index == MAX_WAYPOINTS {
                        return Err(serde::de::Error::custom(format_args!(
                            "more than {MAX_WAYPOINTS} waypoints"
                        )));
                    }
                    for (axis, &v) in p.iter().enumerate() {
                        // A number beyond an f32 is refused as itself, naming the point
                        // (Choice 315), not as the infinity it would become.
                        if v.is_finite() && !(v as f32).is_finite() {
                            return Err(serde::de::Error::custom(
                                TrajectoryError::BadPoint {
                                    index,
                                    axis,
                                    value: v as f32,
                                }
                                .narrowed(v),
                            ));
                        }
                        list.points[index][axis] = v as f32;
                    }
                    list.len += 1;
                }
                Ok(list)
            }
        }
        de.deserialize_seq(Points)
    }
}

/// The points as a sequence of triples.
#[cfg(feature = "serde")]
impl serde::Serialize for WaypointList {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.as_slice())
    }
}
