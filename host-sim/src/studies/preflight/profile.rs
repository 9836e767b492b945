//! The speed profile of a waypoint mission (docs/missions.md#the-speed-profile, Choices 156–158): the fastest
//! speed per leg and turn at which the reference stays inside every thruster's margin envelope
//! over the whole parameter box (and the configured current), joined by the core's speed
//! changes, checked again as flown.
//!
//! 1. **Per part** (each leg and each turn, a segment of the route): the path is sampled once at
//!    its constant `speed`; a speed v on a part is the time scale speed/v on that part's
//!    samples, so the preflight's own sweep ([`Checker::sweep_samples`], scope
//!    [`Scope::WholeBox`]) at 1/k = v/speed judges it. The largest feasible v is found by
//!    geometric bisection to [`SPEED_TOLERANCE`] over every [`PROFILE_STRIDE`]-th sample; the
//!    thruster of the first violation just above it is the part's limiting thruster.
//! 2. **Room for the changes** (the core refuses a part too short for the changes at its two
//!    ends): in the manner of TOPP's backward and forward passes, a part whose changes do not
//!    fit is slowed towards its slower neighbour until they do, repeated until nothing changes.
//!    Speeds are rounded down to [`SPEED_STEP`].
//! 3. **Checked as flown:** the mission with the profile is sampled again (every sample, the
//!    speed changes' tangential acceleration included) and swept as written (its own payload
//!    profile at its own times, with the roll swings its payload jumps leave: the verdict
//!    `check` and the real-vehicle table give) and, if that passes, over the whole box
//!    (Choice 533: one case before 2⁹); if any sample fails,
//!    every speed is lowered by [`VERIFY_SHRINK`] and the whole is redone, at most
//!    [`MAX_VERIFY_ROUNDS`] times.
//!
//! **Caps** (`trajectory.speed_limits`, **Choice 161**): a leg's cap is the first speed its
//! search tries; if the sweep passes there the leg is proposed at the cap (limited by `cap`),
//! else the search runs as without it (so a cap above the free speed changes nothing). The
//! turns keep their own search; steps 2 and 3 only lower speeds, so no cap is exceeded.
//!
//! **The limit reported** per part is what bounded its search in step 1 (a thruster, or
//! [`CAP`]) unless step 2 slowed it below that speed: then [`CHANGES`] (**Choice 171**), since
//! neither a thruster nor the cap keeps it there but its length, too short for the speed
//! changes to and from its own speed at `speed_change`. Step 3's rounds lower every speed
//! alike and keep the labels.
//!
//! Compared with the uniform time scale: the fastest constant speed is the slowest part's
//! (every part must hold it), so the survey at one speed takes length/min(v).

use controller_core::{Mission, Trajectory, TrajectoryKind};
use serde::{Deserialize, Serialize};

use controller_core::trajectory::{Route, SpeedList, DEFAULT_SPEED_CHANGE, MAX_SPEED};

use super::sweep::Checker;
use super::{CheckError, Engine, Scope};
use crate::scenario::{path_time, Scenario, SimConfig, MAX_DURATION};

/// Every this many samples of the path (0.5 s of path time at 20 Hz) in the per-part search.
pub const PROFILE_STRIDE: usize = 10;
/// The per-part bisection stops when the feasible and the infeasible speed differ by less than
/// this fraction.
pub const SPEED_TOLERANCE: f64 = 0.01;
/// Proposed speeds are rounded down to a multiple of this (m/s).
pub const SPEED_STEP: f64 = 0.01;
/// Factor on every speed when the profile fails its check as flown.
pub const VERIFY_SHRINK: f64 = 0.97;
/// Rounds of [`VERIFY_SHRINK`] at most.
pub const MAX_VERIFY_ROUNDS: usize = 8;
/// The slowest speed the search considers (m/s): a part infeasible there is infeasible.
pub const MIN_PROFILE_SPEED: f64 = 0.02;
/// The slowest common speed step 4 caps the parts at (m/s): the navigation's terms hardly
/// change below it, and a vehicle this slow has little steerage (Choice 543).
pub const MIN_TERM_SPEED: f64 = 0.1;
/// The factor step 4 lowers its cap by before its bisection (Choice 543).
pub const TERM_STEP: f64 = 0.8;
/// What the report names as the limit of a leg its cap bound (`trajectory.speed_limits`).
pub const CAP: &str = "cap";
/// What the report names as the limit of a part that step 2 slowed below its own speed (and
/// below its cap): too short to reach it and come back with the speed changes at
/// `speed_change` (**Choice 171**).
pub const CHANGES: &str = "changes";
/// What the report names as the limit of a part the path-error budget capped (Choice 543).
pub const BUDGET: &str = "path budget";
/// What the report names as the limit of a part the chatter term capped (Choice 543).
pub const CHATTER: &str = "chatter";

/// One part of the path as the profile flies it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartTime {
    /// `leg j` or `turn at j`.
    pub name: String,
    /// Its length along the path (m).
    pub length: f64,
    /// Its speed (m/s).
    pub speed: f64,
    /// The time spent on it (s), speed changes included.
    pub time: f64,
    /// The thruster that stops it going faster (the first violation just above its speed),
    /// [`CAP`] for a leg its cap bound, or [`CHANGES`] for a part too short for the speed
    /// changes to and from a faster speed.
    pub limiting: String,
}

/// The proposed profile and what it saves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpeedProfile {
    pub parts: Vec<PartTime>,
    /// The speeds to pin (`speeds = […]`), m/s.
    pub speeds: Vec<f64>,
    /// The speed changes' largest |σ̈| (m/s²).
    pub speed_change: f64,
    /// The whole path with the profile (s).
    pub total_time: f64,
    /// The fastest constant speed over the whole path (m/s) and its time (s).
    pub uniform_speed: f64,
    pub uniform_time: f64,
    /// The path's length (m) and its time at the file's own constant `speed` (s).
    pub length: f64,
    pub nominal_time: f64,
    /// Rounds of [`VERIFY_SHRINK`] the check as flown needed.
    pub shrink_rounds: usize,
}

/// The waypoint mission's parts: the route, its constant `speed`, and the speed change.
struct Parts {
    route: Route,
    speed: f64,
    accel: f64,
    /// Per part: the leg's cap (`trajectory.speed_limits`), `None` for a turn or no cap.
    caps: Vec<Option<f64>>,
}

impl Parts {
    /// The parts of `constant` (the mission of `cfg` at its constant `speed`), with the legs'
    /// caps and the speed change.
    fn of(cfg: &SimConfig, constant: &Scenario, speed: f32, speed_change: Option<f32>) -> Self {
        let route = *constant.trajectory().route();
        let n_parts = route.segment_part(route.segment_count() - 1) + 1;
        // Part 2j is leg j (the turns between).
        let caps = (0..n_parts)
            .map(|p| match (p % 2, &cfg.speed_limits) {
                (0, Some(c)) => c.get(p / 2).copied(),
                _ => None,
            })
            .collect();
        Parts {
            route,
            caps,
            speed: f64::from(speed),
            // The f32 as the decimal it was written as (0.05, not 0.0500000007).
            accel: super::time_scale(speed_change.unwrap_or(DEFAULT_SPEED_CHANGE)),
        }
    }
}

/// The speed profile of `scenario` at `margin`, if it is a waypoint mission (`None` otherwise).
///
/// # Errors
/// [`CheckError::Invalid`] if the mission cannot be built at some step;
/// [`CheckError::NoProfile`] if a part cannot be flown over the whole box even at the slowest
/// speed; [`CheckError::Interrupted`].
pub fn propose(scenario: &Scenario, margin: f64) -> Result<Option<SpeedProfile>, CheckError> {
    propose_with(scenario, margin, Engine::Fast)
}

/// [`propose`] by `engine` (the reference engine is what the fast one is tested against).
///
/// # Errors
/// As [`propose`].
pub fn propose_with(
    scenario: &Scenario,
    margin: f64,
    engine: Engine,
) -> Result<Option<SpeedProfile>, CheckError> {
    let cfg = scenario.config();
    let TrajectoryKind::Waypoints {
        speed,
        speed_change,
        ..
    } = cfg.trajectory
    else {
        return Ok(None);
    };
    let constant = with_law(cfg, None, None, 1.0)?;
    let parts = Parts::of(cfg, &constant, speed, speed_change);
    let checker = Checker::new(&constant, margin, engine)?;
    let (fastest, mut limiting) = per_part_speeds(&checker, &parts)?;
    let mut uniform_speed = fastest.iter().copied().fold(f64::INFINITY, f64::min);
    let flown = |speeds: &[f64]| -> Result<(Vec<f64>, Vec<f64>, Scenario), CheckError> {
        let (rounded, fitted, accel) = pinned(&parts, speeds);
        let scenario = with_law(cfg, Some(&fitted), Some(accel), 1.0)?;
        Ok((rounded, fitted, scenario))
    };
    // The terms' verdict per profile as flown, kept by its pinned speeds (Choice 519).
    let mut memo = TermsMemo::default();
    let mut miss = |speeds: &[f64]| -> Result<Option<&'static str>, CheckError> {
        let (_, fitted, _) = pinned(&parts, speeds);
        memo.get_or(&fitted, || terms_miss(&flown(speeds)?.2))
    };
    // Step 4 (Choice 543): the path-error budget and the chatter term as flown.
    let mut speeds = fastest.clone();
    if let Some((cap, term)) = terms_cap(&fastest, &mut miss)? {
        for (l, &v) in limiting.iter_mut().zip(&fastest) {
            if v > cap {
                *l = term.to_string();
            }
        }
        speeds = fastest.iter().map(|&v| v.min(cap)).collect();
        // The fastest uniform speed is capped alike: the terms refuse any faster.
        uniform_speed = uniform_speed.min(cap);
    }
    for round in 0..=MAX_VERIFY_ROUNDS {
        let (rounded, fitted, flown) = flown(&speeds)?;
        let checker = Checker::new(&flown, margin, engine)?;
        // The mission as written first: one case against the box's 2⁹, and a round it
        // refuses needs no sweep of the box (Choice 533); then the terms (Choice 543).
        let ok = checker.feasible(Scope::AsWritten, 1.0)?
            && checker.feasible(Scope::WholeBox, 1.0)?
            && miss(&speeds)?.is_none();
        if ok {
            // A part step 2 slowed is limited by the changes, not by what bounded its search.
            let limiting = limiting
                .iter()
                .zip(fitted.iter().zip(&rounded))
                .map(|(l, (f, r))| match f < r {
                    true => String::from(CHANGES),
                    false => l.clone(),
                })
                .collect();
            return Ok(Some(report(
                &parts,
                &flown,
                fitted,
                limiting,
                uniform_speed,
                round,
            )));
        }
        speeds.iter_mut().for_each(|v| *v *= VERIFY_SHRINK);
    }
    // Choice 543: no profile is proposed that its own check refuses.
    Err(CheckError::NoProfileTerm {
        why: format!(
            "the check as flown still refuses it with every speed lowered {MAX_VERIFY_ROUNDS} times by {VERIFY_SHRINK}"
        ),
    })
}

/// Step 4 (Choice 543): when the path-error budget or the chatter term refuses the profile
/// `fastest` as flown (`flown` pins a profile and returns the scenario as its third part), the
/// common cap on every part's speed at which both pass, and the term that bounds it; `None`
/// when the profile passes as it is. A profile the force allows may still be one the
/// mission's navigation cannot fly within its bound (the boundary layer's gain grows with the
/// reference's speed, and with it the navigation noise the vehicle follows).
///
/// # Errors
/// [`CheckError::NoProfileTerm`] when no cap down to [`MIN_TERM_SPEED`] passes; as
/// [`propose`] otherwise.
fn terms_cap<F>(fastest: &[f64], miss: &mut F) -> Result<Option<(f64, &'static str)>, CheckError>
where
    F: FnMut(&[f64]) -> Result<Option<&'static str>, CheckError>,
{
    let capped = |c: f64| -> Vec<f64> { fastest.iter().map(|&v| v.min(c)).collect() };
    let Some(term) = miss(fastest)? else {
        return Ok(None);
    };
    // Down from the fastest part in steps of TERM_STEP to the first cap that fits, then
    // bisection between it and the step above: the terms are not monotone at the slow end (a
    // longer flight meets more fixes, and drifts longer without them), so the search keeps to
    // the fastest cap that fits.
    let top = fastest.iter().copied().fold(0.0, f64::max);
    let mut hi = top;
    let mut lo = hi * TERM_STEP;
    while miss(&capped(lo))?.is_some() {
        if lo <= MIN_TERM_SPEED {
            return Err(CheckError::NoProfileTerm {
                why: format!(
                    "the {term} refuses the route at every common speed from {top:.2} down to {MIN_TERM_SPEED} m/s"
                ),
            });
        }
        hi = lo;
        lo = (lo * TERM_STEP).max(MIN_TERM_SPEED);
    }
    let mut limit = term;
    while hi / lo > 1.0 + SPEED_TOLERANCE {
        let mid = (lo * hi).sqrt();
        match miss(&capped(mid))? {
            None => lo = mid,
            Some(t) => {
                hi = mid;
                limit = t;
            }
        }
    }
    Ok(Some((lo, limit)))
}

/// The speeds a profile pins for `speeds` (per part): rounded down to [`SPEED_STEP`], then
/// fitted to the speed changes (steps 2–3), and the changes' |σ̈|. The mission flown is a
/// function of these alone ([`with_law`] of the file's configuration).
fn pinned(parts: &Parts, speeds: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
    let rounded = round_down(speeds);
    let fitted = fit_changes(parts, &rounded);
    (rounded, fitted, parts.accel)
}

/// The terms' verdict ([`terms_miss`]) per profile as flown, by the bits of its pinned speeds
/// (**Choice 519**): the mission flown is a function of them alone, so a profile pinned the
/// same as one already judged has the same verdict. Step 4's bisection asks caps 1 % apart
/// that round to the same 0.01 m/s, and step 3's first round asks the profile step 4 ended
/// on; each was a new budget and a new chatter pass over the whole flight.
#[derive(Default)]
struct TermsMemo(std::collections::HashMap<Vec<u64>, Option<&'static str>>);

impl TermsMemo {
    /// The verdict kept for `fitted`, or `judge`'s, kept.
    fn get_or(
        &mut self,
        fitted: &[f64],
        judge: impl FnOnce() -> Result<Option<&'static str>, CheckError>,
    ) -> Result<Option<&'static str>, CheckError> {
        let key: Vec<u64> = fitted.iter().map(|v| v.to_bits()).collect();
        if let Some(&kept) = self.0.get(&key) {
            return Ok(kept);
        }
        let verdict = judge()?;
        self.0.insert(key, verdict);
        Ok(verdict)
    }
}

/// The term that refuses the mission `flown` at its own time scale (the path-error budget
/// first, then the chatter term), or `None` when both fit (or it has no bound).
fn terms_miss(flown: &Scenario) -> Result<Option<&'static str>, CheckError> {
    if let Some(b) = super::path_budget::Budget::new(flown)? {
        if !b.fits_at(1.0)? {
            return Ok(Some(BUDGET));
        }
    }
    if let Some(c) = super::chatter::Chatter::new(flown)? {
        if !c.fits_at(1.0)? {
            return Ok(Some(CHATTER));
        }
    }
    Ok(None)
}

/// `cfg` with the time law `speeds` (per part; `None`: constant speed), time scale 1 and a
/// duration that covers the whole path (and `extra` s beyond), validated.
fn with_law(
    cfg: &SimConfig,
    speeds: Option<&[f64]>,
    accel: Option<f64>,
    extra: f64,
) -> Result<Scenario, CheckError> {
    let invalid = |e: String| CheckError::Invalid(e);
    let mut c = cfg.clone();
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        ..
    } = c.trajectory
    else {
        return Err(invalid("not a waypoint mission".into()));
    };
    let list = match speeds {
        Some(s) => Some(
            SpeedList::new(&s.iter().map(|&v| v as f32).collect::<Vec<_>>())
                .map_err(|e| invalid(e.to_string()))?,
        ),
        None => None,
    };
    c.trajectory = TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        speeds: list,
        speed_change: accel.map(|a| a as f32),
    };
    c.time_scale = 1.0;
    let t = Trajectory::new(Mission {
        path: c.trajectory,
        heading: c.heading,
        time_scale: 1.0,
    })
    .map_err(|e| invalid(format!("the profiled mission: {e}")))?;
    // The path's time, refused under the key that sets its pace when no run could fly it:
    // never under `duration`, which this scenario sets and the file may not have (Choice 312).
    let path = path_time::path_time(&t).unwrap_or(0.0);
    if path + extra > MAX_DURATION {
        let what = match speeds {
            Some(_) => "with the proposed speed profile",
            None => "at the planned `speed`, at which check samples the path",
        };
        return Err(invalid(path_time::too_long(&t, path, what).to_string()));
    }
    c.duration = path + extra;
    Scenario::new(c).map_err(|e| invalid(e.to_string()))
}

/// The fastest feasible speed of every part (see the module docs, step 1), and the thruster
/// that limits it.
fn per_part_speeds(
    checker: &Checker,
    parts: &Parts,
) -> Result<(Vec<f64>, Vec<String>), CheckError> {
    let route = &parts.route;
    let n_parts = route.segment_part(route.segment_count() - 1) + 1;
    // The samples of each segment: σ = speed·s.
    let times: Vec<f64> = checker.sample_times().collect();
    let mut speeds = vec![f64::from(MAX_SPEED); n_parts];
    let mut limiting = vec![String::from("none"); n_parts];
    for i in 0..route.segment_count() {
        let (s0, len) = (
            f64::from(route.segment_start(i)),
            f64::from(route.segment_length(i)),
        );
        let first = times.partition_point(|&s| s * parts.speed < s0);
        let end = times.partition_point(|&s| s * parts.speed < s0 + len);
        if first >= end {
            continue;
        }
        let feasible = |v: f64| -> Result<Option<String>, CheckError> {
            let sweep = checker.sweep_samples(
                Scope::WholeBox,
                v / parts.speed,
                false,
                first..end,
                PROFILE_STRIDE,
            )?;
            Ok(sweep.first.map(|f| f.thruster))
        };
        let (mut lo, mut hi) = (MIN_PROFILE_SPEED, f64::from(MAX_SPEED));
        let mut limit = String::from("none");
        if let Some(thruster) = feasible(lo)? {
            // Not even slowly: no profile flies (Choice 175), and a path this slow could not
            // even be built for the tangent heading.
            return Err(CheckError::NoProfile {
                part: part_name(route.segment_part(i)),
                thruster,
            });
        }
        let p = route.segment_part(i);
        if let Some(cap) = parts.caps[p] {
            // The cap is the search's upper bound: feasible there, the leg flies at it.
            if feasible(cap)?.is_none() {
                speeds[p] = speeds[p].min(cap);
                limiting[p] = String::from(CAP);
                continue;
            }
        }
        match feasible(hi)? {
            None => lo = hi,
            Some(t) => {
                limit = t;
                while hi / lo > 1.0 + SPEED_TOLERANCE {
                    let mid = (lo * hi).sqrt();
                    match feasible(mid)? {
                        None => lo = mid,
                        Some(t) => {
                            hi = mid;
                            limit = t;
                        }
                    }
                }
            }
        }
        speeds[p] = speeds[p].min(lo);
        limiting[p] = limit;
    }
    Ok((speeds, limiting))
}

/// Part `p`'s name: part 2j is `leg j`, part 2j − 1 the `turn at j`.
fn part_name(p: usize) -> String {
    match p % 2 {
        0 => format!("leg {}", p / 2),
        _ => format!("turn at {}", p.div_ceil(2)),
    }
}

/// The speeds rounded down to [`SPEED_STEP`] (at least one step).
fn round_down(speeds: &[f64]) -> Vec<f64> {
    // Steps per m/s (100): n/100 is the double nearest the decimal n/100, so a cap written as
    // 0.3 stays 0.3 (0.3/0.01 = 29.999… would floor to 29 steps; +1e-9 of a step keeps 30).
    let per = (1.0 / SPEED_STEP).round();
    speeds
        .iter()
        .map(|&x| ((x * per + 1e-9).floor() / per).max(SPEED_STEP))
        .collect()
}

/// The speeds (already on [`SPEED_STEP`], [`round_down`]), each part slowed until the core's
/// speed changes fit in it (see the module docs, step 2). Terminates: speeds only fall, and a
/// part no faster than both neighbours has no change in it.
fn fit_changes(parts: &Parts, speeds: &[f64]) -> Vec<f64> {
    let route = &parts.route;
    let mut v = speeds.to_vec();
    let n = route.segment_count();
    let peak = 15.0 / 8.0;
    // The path a change from `a` down or up to `b` < `a` needs (with a 1 % allowance for the
    // core's f32 arithmetic).
    let room = |a: f64, b: f64| 1.01 * 0.5 * (a + b) * peak * (a - b) / parts.accel;
    let need = |v: &[f64], i: usize| {
        let vi = v[route.segment_part(i)];
        let mut d = 0.0;
        for j in [i.wrapping_sub(1), i + 1] {
            if j < n && v[route.segment_part(j)] < vi {
                d += room(vi, v[route.segment_part(j)]);
            }
        }
        d
    };
    loop {
        let mut changed = false;
        for i in 0..n {
            let p = route.segment_part(i);
            while need(&v, i) > f64::from(route.segment_length(i)) && v[p] > SPEED_STEP {
                v[p] = ((v[p] - SPEED_STEP) / SPEED_STEP).round() * SPEED_STEP;
                changed = true;
            }
        }
        if !changed {
            return v;
        }
    }
}

/// The profile's report: each part's time from the flown law, the totals.
fn report(
    parts: &Parts,
    flown: &Scenario,
    speeds: Vec<f64>,
    limiting: Vec<String>,
    uniform_speed: f64,
    shrink_rounds: usize,
) -> SpeedProfile {
    let route = &parts.route;
    let law = flown.trajectory().time_law();
    let n = route.segment_count();
    let parts_out = (0..n)
        .map(|i| {
            let p = route.segment_part(i);
            let start = f64::from(law.segment_time(i));
            let end = match i + 1 < n {
                true => f64::from(law.segment_time(i + 1)),
                false => f64::from(law.duration()),
            };
            PartTime {
                name: part_name(p),
                length: f64::from(route.segment_length(i)),
                speed: speeds[p],
                time: end - start,
                limiting: limiting[p].clone(),
            }
        })
        .collect();
    let length = f64::from(route.length());
    SpeedProfile {
        parts: parts_out,
        speeds,
        speed_change: parts.accel,
        total_time: f64::from(law.duration()),
        uniform_speed,
        uniform_time: length / uniform_speed,
        length,
        nominal_time: length / parts.speed,
        shrink_rounds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Choice 519: a profile pinned the same as one already judged is not judged again (its
    /// kept verdict, refused or not, is returned); one pinned differently, even in the last
    /// bit of one speed, is judged.
    #[test]
    fn the_terms_are_judged_once_per_pinned_profile() {
        let mut memo = TermsMemo::default();
        let judged = std::cell::Cell::new(0);
        let ask = |memo: &mut TermsMemo, speeds: &[f64], verdict: Option<&'static str>| {
            memo.get_or(speeds, || {
                judged.set(judged.get() + 1);
                Ok(verdict)
            })
            .unwrap()
        };
        assert_eq!(ask(&mut memo, &[0.36, 0.3], Some(BUDGET)), Some(BUDGET));
        // The same pinned speeds: the kept verdict, whatever a new judgement would say.
        assert_eq!(ask(&mut memo, &[0.36, 0.3], None), Some(BUDGET));
        assert_eq!(ask(&mut memo, &[0.35, 0.3], None), None);
        assert_eq!(ask(&mut memo, &[0.35, 0.3], Some(CHATTER)), None);
        let next = f64::from_bits(0.3f64.to_bits() + 1);
        assert_eq!(ask(&mut memo, &[0.35, next], Some(CHATTER)), Some(CHATTER));
        assert_eq!(judged.get(), 3);
        // An error is not kept: the next ask judges again.
        let failed = memo.get_or(&[0.2], || Err(CheckError::Interrupted));
        assert_eq!(failed, Err(CheckError::Interrupted));
        assert_eq!(ask(&mut memo, &[0.2], None), None);
        assert_eq!(judged.get(), 4);
    }
}
