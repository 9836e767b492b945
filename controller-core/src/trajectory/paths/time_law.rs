//! The waypoint path's time law (docs/missions.md#the-time-law, Choice 156): a speed per part of the path
//! (each leg and each turn), flown as constant-speed runs joined by speed changes on the quintic
//! smoothstep, so that σ̈ is continuous and σ⃛ bounded.
//!
//! A change from v_a to v_b takes T = (15/8)·|v_b − v_a|/A (A = `speed_change`, the largest
//! |σ̈|): σ̇ = v_a + (v_b − v_a)·S(τ), S(τ) = τ³(10 − 15τ + 6τ²), τ = (t − t₀)/T, so
//! σ̈ = (v_b − v_a)/T·30τ²(1 − τ)² (peak (15/8)·|Δv|/T = A, zero with its slope at both ends) and
//! σ⃛ = (v_b − v_a)/T²·60τ(1 − τ)(1 − 2τ) (bounded, continuous). The change covers
//! (v_a + v_b)/2·T of path and happens inside the faster part: a slowdown ends where the slower
//! part begins, a speed-up starts where the slower part ends, so each part is flown at most at
//! its own speed. A part too short for the changes at its two ends is refused (the host's
//! preflight lowers its speed until they fit, docs/missions.md#the-speed-profile).
//!
//! The pieces (at most three per segment: speed-up, cruise, slowdown) are sorted by start time;
//! a fixed [`PIECE_SEARCH_STEPS`]-step binary search finds the piece. Each piece keeps its
//! segment and its offset in it, and the time since its start is formed to its own ulp
//! ([`MissionTime::linear_since`]), so the path position keeps the precision of the constant
//! speed path (Choice 153).

use super::waypoints::{segment_bounds, PathPoint, Route};
use crate::phase::{LinearRate, MissionTime};
use crate::trajectory::error::{positive, TrajectoryError};
use crate::trajectory::limits::{MAX_PARTS, MAX_SEGMENTS, MAX_SPEED, MAX_SPEED_CHANGE};
use crate::trajectory::phases::Planar;

/// Pieces of a time law: a speed-up, a cruise and a slowdown per segment.
pub const MAX_PIECES: usize = 3 * MAX_SEGMENTS;
/// Steps of the binary search over the pieces: 2^PIECE_SEARCH_STEPS ≥ [`MAX_PIECES`].
const PIECE_SEARCH_STEPS: u32 = 8;
const _: () = assert!(1 << PIECE_SEARCH_STEPS >= MAX_PIECES);
/// Peak of the smoothstep's derivative, S′(½) = 15/8: T = (15/8)·|Δv|/A.
const PEAK: f32 = 15.0 / 8.0;

/// The speed of each part of the path, in path order: leg 0, the turn at waypoint 1, leg 1, …
/// (2n − 3 values for n waypoints), m/s. With the `serde` feature the scenario's
/// `speeds = [v, …]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedList {
    len: u8,
    speeds: [f32; MAX_PARTS],
}

impl SpeedList {
    /// The speeds, or [`TrajectoryError::SpeedCount`] if there are more than [`MAX_PARTS`].
    pub fn new(speeds: &[f32]) -> Result<Self, TrajectoryError> {
        if speeds.len() > MAX_PARTS {
            return Err(TrajectoryError::SpeedCount {
                count: speeds.len(),
                expected: MAX_PARTS,
            });
        }
        let mut list = SpeedList {
            len: speeds.len() as u8,
            speeds: [0.0; MAX_PARTS],
        };
        list.speeds[..speeds.len()].copy_from_slice(speeds);
        Ok(list)
    }

    /// The speeds, in path order.
    pub fn as_slice(&self) -> &[f32] {
        &self.speeds[..self.len as usize]
    }
}

/// One piece of the time law: from `t0`, in segment `segment` at offset `local0`, σ̇ goes from
/// `v0` by `dv` over 1/`inv_dur` s (a cruise: `dv` = `inv_dur` = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    t0: f32,
    segment: u8,
    local0: f32,
    v0: f32,
    dv: f32,
    inv_dur: f32,
}

const NO_PIECE: Piece = Piece {
    t0: 0.0,
    segment: 0,
    local0: 0.0,
    v0: 0.0,
    dv: 0.0,
    inv_dur: 0.0,
};

/// The time law of a waypoint path (see the module docs), at time scale 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeLaw {
    count: u8,
    pieces: [Piece; MAX_PIECES],
    /// The time at which the path's end is reached (s).
    duration: f32,
}

/// σ's derivatives with respect to time: σ̇, σ̈, σ⃛.
pub(crate) type Rates = [f32; 3];

impl TimeLaw {
    /// No pieces: the path is flown at its constant `speed`.
    pub const EMPTY: TimeLaw = TimeLaw {
        count: 0,
        pieces: [NO_PIECE; MAX_PIECES],
        duration: 0.0,
    };

    /// The time law of `route` at `speeds` (one per part) with speed changes at `accel`
    /// (m/s²), built into `self` in place (Choice 180: no `TimeLaw` on the stack; every piece
    /// past the new law's is reset, so the result is the same whatever `self` held; after an
    /// error `self` has no pieces). Refused, under `speeds`: a count other than the route's
    /// parts, a speed outside (0, [`MAX_SPEED`]], a part too short for its speed changes; under
    /// `speed_change`: an `accel` outside (0, [`MAX_SPEED_CHANGE`]].
    pub fn build_into(
        &mut self,
        route: &Route,
        speeds: &SpeedList,
        accel: f32,
    ) -> Result<(), TrajectoryError> {
        self.clear();
        positive("speed_change", accel, MAX_SPEED_CHANGE)?;
        let n = route.segment_count();
        let parts = if n == 0 {
            0
        } else {
            route.segment_part(n - 1) + 1
        };
        if speeds.as_slice().len() != parts {
            return Err(TrajectoryError::SpeedCount {
                count: speeds.as_slice().len(),
                expected: parts,
            });
        }
        for (part, &value) in speeds.as_slice().iter().enumerate() {
            // The error names the part (Choice 315).
            if !value.is_finite() {
                return Err(TrajectoryError::SpeedNotFinite { part });
            }
            if positive("speeds", value, MAX_SPEED).is_err() {
                return Err(TrajectoryError::BadSpeed { part, value });
            }
        }
        let v = |i: usize| speeds.as_slice()[route.segment_part(i)];
        let mut t = 0.0f32;
        for i in 0..n {
            let vi = v(i);
            let len = route.segment_length(i);
            let up = (i > 0 && v(i - 1) < vi).then(|| v(i - 1));
            let down = (i + 1 < n && v(i + 1) < vi).then(|| v(i + 1));
            let change = |other: f32| {
                let dur = PEAK * (vi - other) / accel;
                (dur, 0.5 * (vi + other) * dur)
            };
            let (d_up, d_down) = (
                up.map_or(0.0, |o| change(o).1),
                down.map_or(0.0, |o| change(o).1),
            );
            if d_up + d_down > len {
                self.clear();
                return Err(TrajectoryError::SpeedChangeTooLong {
                    part: route.segment_part(i),
                    needs: d_up + d_down,
                    has: len,
                });
            }
            let mut local = 0.0f32;
            if let Some(o) = up {
                let (dur, dist) = change(o);
                self.push(t, i, local, o, vi - o, 1.0 / dur);
                t += dur;
                local += dist;
            }
            let cruise = len - d_up - d_down;
            self.push(t, i, local, vi, 0.0, 0.0);
            t += cruise / vi;
            local += cruise;
            if let Some(o) = down {
                let (dur, _) = change(o);
                self.push(t, i, local, vi, o - vi, 1.0 / dur);
                t += dur;
            }
        }
        self.duration = t;
        Ok(())
    }

    /// Back to [`TimeLaw::EMPTY`], in place.
    pub(crate) fn clear(&mut self) {
        self.count = 0;
        self.pieces.fill(NO_PIECE);
        self.duration = 0.0;
    }

    fn push(&mut self, t0: f32, segment: usize, local0: f32, v0: f32, dv: f32, inv_dur: f32) {
        self.pieces[self.count as usize] = Piece {
            t0,
            segment: segment as u8,
            local0,
            v0,
            dv,
            inv_dur,
        };
        self.count += 1;
    }

    /// True when there are pieces (else the path is flown at constant speed).
    pub fn is_set(&self) -> bool {
        self.count > 0
    }

    /// The time (s, at time scale 1) at which the path's end is reached.
    pub fn duration(&self) -> f32 {
        self.duration
    }

    /// The time (s, at time scale 1) at which segment `i` of the route begins.
    pub fn segment_time(&self, i: usize) -> f32 {
        for p in &self.pieces[..self.count as usize] {
            if p.segment as usize == i {
                return p.t0;
            }
        }
        self.duration
    }

    /// The time (s, at time scale 1) at which the path parameter reaches `sigma` (m): the
    /// inverse of σ(t), at configuration time (Choice 311). On a cruise it is exact,
    /// t₀ + (σ − σ₀)/v; in a speed change σ(τ) is monotone (σ̇ > 0) and τ is found by a fixed
    /// 40-step bisection; beyond the end the path goes on at the last piece's final speed.
    /// 0 for an empty law.
    pub fn time_at(&self, route: &Route, sigma: f32) -> f32 {
        let count = self.count as usize;
        if count == 0 {
            return 0.0;
        }
        let (segment, start) = route.locate(sigma);
        let Some(segment) = segment else {
            let last = &self.pieces[count - 1];
            return self.duration + (sigma - route.length()) / (last.v0 + last.dv);
        };
        let local = sigma - start;
        let mut piece = &self.pieces[0];
        for p in &self.pieces[..count] {
            if p.segment as usize == segment && p.local0 <= local {
                piece = p;
            }
        }
        let along = local - piece.local0;
        if piece.inv_dur == 0.0 {
            return piece.t0 + along / piece.v0;
        }
        let (v0, dv, w) = (piece.v0, piece.dv, piece.inv_dur);
        let covered = |tau: f32| {
            let t2 = tau * tau;
            (v0 * tau + dv * t2 * t2 * (2.5 + tau * (-3.0 + tau))) / w
        };
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if covered(mid) < along {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        piece.t0 + 0.5 * (lo + hi) / w
    }

    /// The largest σ̇ on segment `i` (its own speed: changes happen in the faster part).
    pub(crate) fn segment_speed(&self, i: usize) -> f32 {
        let mut v = 0.0f32;
        for p in &self.pieces[..self.count as usize] {
            if p.segment as usize == i {
                v = v.max(p.v0).max(p.v0 + p.dv);
            }
        }
        v
    }

    /// The largest |σ̈| of a change of speed (m/s², at time scale 1).
    pub(crate) fn max_accel(&self) -> f32 {
        let mut a = 0.0f32;
        for p in &self.pieces[..self.count as usize] {
            a = a.max(PEAK * p.dv.abs() * p.inv_dur);
        }
        a
    }

    /// The smallest σ̇ anywhere.
    pub(crate) fn min_speed(&self) -> f32 {
        let mut v = f32::INFINITY;
        for p in &self.pieces[..self.count as usize] {
            v = v.min(p.v0).min(p.v0 + p.dv);
        }
        v
    }

    /// The index of the piece holding time `t`: the last whose start is ≤ t, by a binary
    /// search of a fixed [`PIECE_SEARCH_STEPS`] steps.
    #[inline]
    fn find(&self, t: f32) -> usize {
        let mut lo = 0usize;
        let mut step = 1usize << (PIECE_SEARCH_STEPS - 1);
        let count = self.count as usize;
        for _ in 0..PIECE_SEARCH_STEPS {
            let probe = lo + step;
            if probe < count && self.pieces[probe].t0 <= t {
                lo = probe;
            }
            step >>= 1;
        }
        lo
    }

    /// The path point and σ̇, σ̈, σ⃛ at the mission time `time`, the time law flown at
    /// `time_rate` = 1/k (the law's time is t/k; its rates are divided by k, k², k³). Fixed
    /// work, never panics.
    #[inline]
    pub(crate) fn at(
        &self,
        route: &Route,
        time: &MissionTime,
        time_rate: &LinearRate,
        inv_k: f32,
    ) -> (PathPoint, Rates) {
        let piece = &self.pieces[self.find(time.linear(time_rate, 0.0))];
        let dt = time.linear_since(time_rate, piece.t0);
        let tau = dt * piece.inv_dur;
        let (dv, w) = (piece.dv, piece.inv_dur);
        let t2 = tau * tau;
        let m = tau * (1.0 - tau);
        // σ − σ₀ = v₀·dt + Δv·T·τ⁴(5/2 − 3τ + τ²) (the smoothstep's integral); 0 on a cruise.
        let ramp = if w > 0.0 {
            dv / w * t2 * t2 * (2.5 + tau * (-3.0 + tau))
        } else {
            0.0
        };
        let local = piece.local0 + piece.v0 * dt + ramp;
        let rates = [
            (piece.v0 + dv * t2 * tau * (10.0 + tau * (-15.0 + 6.0 * tau))) * inv_k,
            dv * w * 30.0 * m * m * inv_k * inv_k,
            dv * w * w * 60.0 * m * (1.0 - 2.0 * tau) * inv_k * inv_k * inv_k,
        ];
        let segment = piece.segment as usize;
        let len = route.segment_length(segment);
        let pp = if segment + 1 == route.segment_count() && local > len {
            route.at_local(None, local - len)
        } else {
            route.at_local(Some(segment), local)
        };
        (pp, rates)
    }
}

/// The smallest horizontal speed and the square of K_d (Assumption 1) of the path flown at
/// the constant `rate` or by `law` (at 1/k = `rate`): per segment, its sampled bounds
/// ([`segment_bounds`]) times `margin`, with the segment's largest σ̇ and the law's largest
/// |σ̈| = A/k²: ‖η̈‖ ≤ ‖p″‖σ̇² + A, |ψ̈| ≤ |ψ″|σ̇² + |ψ′|·A.
pub(crate) fn speed_and_accel_bound(
    route: &Route,
    law: &TimeLaw,
    rate: f32,
    margin: f32,
) -> (f32, f32) {
    let mut min_speed = f32::INFINITY;
    let mut kd2 = 0.0f32;
    let law_accel = law.max_accel() * rate * rate;
    for i in 0..route.segment_count() {
        let b = segment_bounds(route, i);
        let (v, a, v_min) = match law.is_set() {
            true => (
                law.segment_speed(i) * rate,
                law_accel,
                law.min_speed() * rate,
            ),
            false => (rate, 0.0, rate),
        };
        min_speed = min_speed.min(b.min_speed * v_min);
        let path = margin * b.accel * v * v + a;
        let heading = margin * (b.heading_accel * v * v + b.heading_rate * a);
        kd2 = kd2.max(path * path + heading * heading);
    }
    (min_speed, kd2)
}

/// The path flown by `law` at the mission time `time` (its time over k: `time_rate` = 1/k,
/// `inv_k`): x_d, y_d and three time derivatives, z_d, ż_d, z̈_d, by the chain rule
/// η̇ = p′σ̇, η̈ = p″σ̇² + p′σ̈, η⃛ = p‴σ̇³ + 3p″σ̇σ̈ + p′σ⃛.
#[inline]
pub(super) fn timed(
    route: &Route,
    law: &TimeLaw,
    time: &MissionTime,
    time_rate: &LinearRate,
    inv_k: f32,
) -> Planar {
    let (pp, [v, a, j]) = law.at(route, time, time_rate, inv_k);
    let [d1, d2, d3] = pp.d;
    let v2 = v * v;
    let vel = |c: usize| d1[c] * v;
    let acc = |c: usize| d2[c] * v2 + d1[c] * a;
    let jerk = |c: usize| d3[c] * v2 * v + 3.0 * d2[c] * v * a + d1[c] * j;
    Planar {
        x: pp.p[0],
        y: pp.p[1],
        z: pp.p[2],
        z_dot: vel(2),
        z_ddot: acc(2),
        d: [[vel(0), vel(1)], [acc(0), acc(1)], [jerk(0), jerk(1)]],
    }
}

/// `speeds = [v, …]`: at most [`MAX_PARTS`] speeds.
#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for SpeedList {
    fn deserialize<D: serde::Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        struct Speeds;
        impl<'de> serde::de::Visitor<'de> for Speeds {
            type Value = SpeedList;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                write!(f, "a list of at most {MAX_PARTS} speeds (m/s)")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                let mut list = SpeedList {
                    len: 0,
                    speeds: [0.0; MAX_PARTS],
                };
                while let Some(v) = seq.next_element::<f64>()? {
                    let part = list.len as usize;
                    if part == MAX_PARTS {
                        return Err(serde::de::Error::custom(format_args!(
                            "more than {MAX_PARTS} speeds"
                        )));
                    }
                    // A number an f32 cannot hold is refused as itself, naming the part
                    // (Choice 315), not as the infinity or the 0 it would become.
                    let narrow = v as f32;
                    if (v.is_finite() && !narrow.is_finite()) || (v != 0.0 && narrow == 0.0) {
                        return Err(serde::de::Error::custom(
                            TrajectoryError::BadSpeed {
                                part,
                                value: narrow,
                            }
                            .narrowed(v),
                        ));
                    }
                    list.speeds[part] = narrow;
                    list.len += 1;
                }
                Ok(list)
            }
        }
        de.deserialize_seq(Speeds)
    }
}

/// The speeds as a sequence.
#[cfg(feature = "serde")]
impl serde::Serialize for SpeedList {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.as_slice())
    }
}
