//! What a team can configure, as a map from draws to a scenario (docs/search.md#the-mission-space):
//! the preflight contract's random missions ([`super::validation`]) and the falsifier's
//! candidates ([`super::falsify`]) are made by the one function [`mission`], from a source of
//! draws ([`Draws`]) that is either a seeded generator (the contract: its draws in the order it
//! has always made them) or a point of [0, 1]ⁿ ([`Point`]: the falsifier, whose random search
//! and optimiser share the map).
//!
//! **Choice 410:** each quantity has a fixed coordinate ([`slot`]), so a point of the unit cube
//! is a mission and a step in one coordinate changes one quantity; a generator ignores the
//! coordinate and draws the next number, so the contract's missions keep their bytes.
//! **Choice 411:** [`Reach::Realities`] adds, after the contract's coordinates, what the
//! contract does not draw and a team writes: the depth, a Gauss–Markov current, a navigation
//! preset with its error figures scaled within ×[`NAV_SCALE`] and its latencies up to
//! ×[`NAV_SCALE`]`.1`, a thruster lag up to [`MAX_LAG`], and a start offset up to
//! [`MAX_OFFSET`] (m) / [`MAX_OFFSET_ANGLE`] (rad) per axis.

use controller_core::effectiveness::{ThrusterGeometry, THRUSTERS};
use controller_core::model::VARIED_PARAMETERS;
use controller_core::trajectory::{Circle, FigureEight, LawnMower};
use controller_core::uncertainty::ParamBox;
use controller_core::{HeadingMode, TrajectoryKind};
use rand::RngExt;

use crate::plant::{CurrentModel, VariationProfile};
use crate::scenario::navigation::{NavigationModel, Preset};
use crate::scenario::{Scenario, ScenarioError, SimConfig};

/// Largest current speed of a random mission (m/s).
pub const RANDOM_MAX_CURRENT: f64 = 0.3;
/// Depth range of a [`Reach::Realities`] mission (m); the contract's missions hold 5 m.
pub const DEPTH_RANGE: [f64; 2] = [2.0, 50.0];
/// Largest Gauss–Markov σ per horizontal axis (m/s) and the range of its τ (s).
pub const MAX_GM_SIGMA: f64 = 0.1;
pub const GM_TAU_RANGE: [f64; 2] = [10.0, 300.0];
/// A navigation preset's error figures are scaled by a factor in this range; its latencies by
/// one in [1, `NAV_SCALE.1`].
pub const NAV_SCALE: (f64, f64) = (0.5, 2.0);
/// Largest thruster lag (s): real thrusters answer in about 0.1 s (docs/thrusters.md).
pub const MAX_LAG: f64 = 0.3;
/// Largest start offset per position axis (m) and per attitude axis (rad).
pub const MAX_OFFSET: f64 = 0.02;
pub const MAX_OFFSET_ANGLE: f64 = 0.01;

/// The coordinates: one a quantity, the contract's first, in the order it draws them.
pub mod slot {
    use controller_core::model::VARIED_PARAMETERS;

    pub const SPEED: usize = 0;
    pub const KIND: usize = 1;
    pub const SIZE: usize = 2;
    pub const MOUNTING: usize = 3;
    /// Δp, one coordinate a parameter of the Table-3 box.
    pub const PAYLOAD: usize = 4;
    pub const PROFILE: usize = PAYLOAD + VARIED_PARAMETERS;
    /// abs-sin's ω, or the staircase's first step.
    pub const PROFILE_A: usize = PROFILE + 1;
    /// The staircase's second step.
    pub const PROFILE_B: usize = PROFILE + 2;
    pub const CURRENT_SPEED: usize = PROFILE + 3;
    pub const CURRENT_DIRECTION: usize = PROFILE + 4;
    /// How many the contract draws.
    pub const CONTRACT: usize = PROFILE + 5;
    // The realities (Choice 411).
    pub const DEPTH: usize = CONTRACT;
    pub const CURRENT_MODEL: usize = CONTRACT + 1;
    pub const GM_SIGMA: usize = CONTRACT + 2;
    pub const GM_TAU: usize = CONTRACT + 3;
    pub const GM_SEED: usize = CONTRACT + 4;
    pub const NAV_PRESET: usize = CONTRACT + 5;
    pub const NAV_ERROR: usize = CONTRACT + 6;
    pub const NAV_LATENCY: usize = CONTRACT + 7;
    pub const NAV_SEED: usize = CONTRACT + 8;
    pub const LAG: usize = CONTRACT + 9;
    /// Six: x y z φ θ ψ.
    pub const OFFSET: usize = CONTRACT + 10;
    /// How many a [`super::Reach::Realities`] mission has.
    pub const REALITIES: usize = OFFSET + 6;
}

/// A source of draws: a number in [0, 1) or an index below `n`, for a coordinate.
pub trait Draws {
    fn unit(&mut self, slot: usize) -> f64;
    fn below_u32(&mut self, slot: usize, n: u32) -> u32;
    fn below_u8(&mut self, slot: usize, n: u8) -> u8;
}

/// A seeded generator draws the next number whatever the coordinate (the contract's order).
impl<R: rand::Rng> Draws for R {
    fn unit(&mut self, _: usize) -> f64 {
        self.random::<f64>()
    }
    fn below_u32(&mut self, _: usize, n: u32) -> u32 {
        self.random_range(0..n)
    }
    fn below_u8(&mut self, _: usize, n: u8) -> u8 {
        self.random_range(0..n)
    }
}

/// A point of [0, 1]ⁿ: coordinate `slot` is the draw (clamped into the cube; an index is
/// ⌊u·n⌋, the last one at u = 1).
#[derive(Clone, Copy, Debug)]
pub struct Point<'a>(pub &'a [f64]);

impl Point<'_> {
    fn at(&self, slot: usize) -> f64 {
        let u = self.0.get(slot).copied().unwrap_or(0.5);
        if u.is_nan() {
            0.5
        } else {
            u.clamp(0.0, 1.0)
        }
    }
}

impl Draws for Point<'_> {
    fn unit(&mut self, slot: usize) -> f64 {
        self.at(slot)
    }
    fn below_u32(&mut self, slot: usize, n: u32) -> u32 {
        ((self.at(slot) * f64::from(n)) as u32).min(n.saturating_sub(1))
    }
    fn below_u8(&mut self, slot: usize, n: u8) -> u8 {
        ((self.at(slot) * f64::from(n)) as u8).min(n.saturating_sub(1))
    }
}

/// How much of what a team configures a mission draws.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Reach {
    /// The contract's random missions: path kind, size, speed, mounting, payload and profile,
    /// a constant current; depth 5 m, no navigation error, no lag, no offset.
    Contract,
    /// Those and the realities of Choice 411.
    Realities,
}

impl Reach {
    /// The dimension of its cube.
    pub fn dims(self) -> usize {
        match self {
            Reach::Contract => slot::CONTRACT,
            Reach::Realities => slot::REALITIES,
        }
    }
}

/// The mission `d` draws, on `base` (the real vehicle's circle: its chain, unit and
/// bound), named `name`, `duration` s long at time scale 1. A draw the core refuses (a
/// tangent heading too slow somewhere) is [`ScenarioError::Invalid`] with a `trajectory` key.
pub fn mission(
    base: &Scenario,
    reach: Reach,
    name: String,
    duration: f64,
    d: &mut dyn Draws,
) -> Result<Scenario, ScenarioError> {
    let speed = 0.5 + 2.0 * d.unit(slot::SPEED);
    let kinds = kinds();
    let kind = kinds[d.below_u32(slot::KIND, kinds.len() as u32) as usize];
    let mut path = kind(speed, d);
    let mask = d.below_u8(slot::MOUNTING, 1u8 << THRUSTERS);
    let payload = ParamBox::table3().lerp(&std::array::from_fn::<f64, VARIED_PARAMETERS, _>(|j| {
        d.unit(slot::PAYLOAD + j)
    }));
    let variation = match d.below_u32(slot::PROFILE, 3) {
        0 => VariationProfile::Constant(payload),
        1 => VariationProfile::AbsSin {
            max: payload,
            omega: 0.05 + 0.1 * d.unit(slot::PROFILE_A),
        },
        _ => {
            let t1 = 10.0 + 30.0 * d.unit(slot::PROFILE_A);
            let t2 = t1 + 10.0 + 30.0 * d.unit(slot::PROFILE_B);
            VariationProfile::Staircase(vec![
                (t1, payload),
                (t2, payload.scaled(0.6)),
                (f64::INFINITY, payload.scaled(0.3)),
            ])
        }
    };
    let current_speed = RANDOM_MAX_CURRENT * d.unit(slot::CURRENT_SPEED);
    let dir = std::f64::consts::TAU * d.unit(slot::CURRENT_DIRECTION);
    let mean = [current_speed * dir.cos(), current_speed * dir.sin(), 0.0];
    let realities = (reach == Reach::Realities).then(|| Realities::draw(mean, d));
    if let Some(r) = &realities {
        set_depth(&mut path, r.depth as f32);
    }
    base.with(|c: &mut SimConfig| {
        c.name = name;
        c.trajectory = path;
        c.heading = HeadingMode::Tangent;
        c.time_scale = 1.0;
        c.duration = duration;
        c.controller.geometry = ThrusterGeometry::auv150(mask);
        c.variation = variation;
        c.trimmed = true;
        c.current = CurrentModel::Constant(mean);
        // The contract's missions are told the exact state, without a filter, as its `ideal`
        // preset flies them (Choice 373); the realities draw their navigation, and a drawn
        // `ideal` is flown the same way.
        let told = c.controller.estimator.kind;
        c.navigation = None;
        c.controller.estimator.kind = controller_core::EstimatorKind::Off;
        if let Some(r) = realities {
            c.current = r.current;
            if r.navigation.is_some() {
                c.controller.estimator.kind = told;
            }
            c.navigation = r.navigation;
            c.thruster_lag = r.lag;
            c.initial_offset = r.offset;
        }
    })
}

/// `mission` told its state through `preset` as the contract flies every mission under it
/// (Choice 373): the preset's sources from `seed`, the exact state told as is (the estimator
/// off) for `ideal`, the real chain's filter `filter` otherwise.
pub fn under_preset(
    mission: &Scenario,
    preset: Preset,
    seed: u64,
    filter: controller_core::EstimatorKind,
) -> Result<Scenario, ScenarioError> {
    mission.with(|c| {
        c.navigation = NavigationModel::preset(preset, seed);
        c.controller.estimator.kind = if preset == Preset::Ideal {
            controller_core::EstimatorKind::Off
        } else {
            filter
        };
    })
}

/// The point `x` with its navigation preset coordinate ([`slot::NAV_PRESET`]) set to
/// `preset` (the middle of its cell).
pub fn with_preset(x: &[f64], preset: Preset) -> Vec<f64> {
    let mut y = x.to_vec();
    if let (Some(u), Some(i)) = (
        y.get_mut(slot::NAV_PRESET),
        Preset::ALL.iter().position(|&p| p == preset),
    ) {
        *u = (i as f64 + 0.5) / Preset::ALL.len() as f64;
    }
    y
}

/// What [`Reach::Realities`] adds to a contract mission.
struct Realities {
    depth: f64,
    current: CurrentModel,
    navigation: Option<NavigationModel>,
    lag: Option<f64>,
    offset: [f64; 6],
}

/// A seed from a coordinate (within a TOML integer).
fn seed(d: &mut dyn Draws, slot: usize) -> u64 {
    (d.unit(slot) * f64::from(u32::MAX)) as u64
}

impl Realities {
    fn draw(mean: [f64; 3], d: &mut dyn Draws) -> Self {
        let lerp = |[lo, hi]: [f64; 2], u: f64| lo + (hi - lo) * u;
        let depth = lerp(DEPTH_RANGE, d.unit(slot::DEPTH));
        let current = match d.below_u32(slot::CURRENT_MODEL, 2) {
            0 => CurrentModel::Constant(mean),
            _ => {
                let s = MAX_GM_SIGMA * d.unit(slot::GM_SIGMA);
                CurrentModel::GaussMarkov {
                    mean,
                    sigma: [s, s, 0.0],
                    tau: lerp(GM_TAU_RANGE, d.unit(slot::GM_TAU)),
                    seed: seed(d, slot::GM_SEED),
                }
            }
        };
        let preset = Preset::ALL[d.below_u32(slot::NAV_PRESET, Preset::ALL.len() as u32) as usize];
        let error = NAV_SCALE.0 * (NAV_SCALE.1 / NAV_SCALE.0).powf(d.unit(slot::NAV_ERROR));
        let latency = NAV_SCALE.1.powf(d.unit(slot::NAV_LATENCY));
        let navigation = NavigationModel::preset(preset, seed(d, slot::NAV_SEED))
            .map(|m| scaled(m, error, latency));
        let lag = MAX_LAG * d.unit(slot::LAG);
        let offset = std::array::from_fn(|j| {
            let w = if j < 3 { MAX_OFFSET } else { MAX_OFFSET_ANGLE };
            w * (2.0 * d.unit(slot::OFFSET + j) - 1.0)
        });
        Realities {
            depth,
            current,
            navigation,
            lag: (lag > 0.0).then_some(lag),
            offset,
        }
    }
}

/// A preset's sources with every error figure times `error` and every latency times `latency`.
fn scaled(mut m: NavigationModel, error: f64, latency: f64) -> NavigationModel {
    use crate::scenario::navigation::ErrorModel;
    fn e<const N: usize>(x: &mut ErrorModel<N>, k: f64) {
        for v in [
            &mut x.sigma,
            &mut x.bias,
            &mut x.bias_sigma,
            &mut x.bias_walk,
        ] {
            v.iter_mut().for_each(|y| *y *= k);
        }
    }
    e(&mut m.ins.attitude, error);
    e(&mut m.ins.rates, error);
    e(&mut m.ins.accel, error);
    e(&mut m.dvl.velocity, error);
    e(&mut m.depth.error, error);
    for t in [&mut m.ins.timing, &mut m.dvl.timing, &mut m.depth.timing] {
        t.latency *= latency;
    }
    if let Some(f) = m.fix.as_mut() {
        e(&mut f.error, error);
        f.timing.latency *= latency;
    }
    m
}

fn set_depth(path: &mut TrajectoryKind, depth: f32) {
    match path {
        TrajectoryKind::Circle(p) => p.depth = depth,
        TrajectoryKind::FigureEight(p) => p.depth = depth,
        TrajectoryKind::LawnMower(p) => p.depth = depth,
        TrajectoryKind::Helix(p) => p.depth = depth,
        TrajectoryKind::Waypoints { .. } => {}
    }
}

/// Draws a path of one kind for a horizontal speed (m/s): its size, and ω from the speed.
type DrawPath = fn(f64, &mut dyn Draws) -> TrajectoryKind;

/// The kinds the random missions fly, in `TrajectoryKind::EXAMPLES`' order, each with its
/// draw. A new kind does not compile here until it says whether they fly it (the match is
/// exhaustive); flying one more kind draws other missions for every seed.
fn kinds() -> Vec<DrawPath> {
    TrajectoryKind::EXAMPLES
        .iter()
        .filter_map(|kind| -> Option<DrawPath> {
            match kind {
                // R ω = speed.
                TrajectoryKind::Circle(_) => Some(|speed, d| {
                    let radius = 8.0 + 32.0 * d.unit(slot::SIZE);
                    TrajectoryKind::Circle(Circle {
                        radius: radius as f32,
                        omega: (speed / radius) as f32,
                        depth: 5.0,
                    })
                }),
                // A ω = speed.
                TrajectoryKind::FigureEight(_) => Some(|speed, d| {
                    let amplitude = 10.0 + 30.0 * d.unit(slot::SIZE);
                    TrajectoryKind::FigureEight(FigureEight {
                        amplitude: amplitude as f32,
                        omega: (speed / amplitude) as f32,
                        depth: 5.0,
                    })
                }),
                // 15 s ω = speed on the cross-track legs, ω within the paper's range.
                TrajectoryKind::LawnMower(_) => Some(|speed, d| {
                    let scale = 0.5 + d.unit(slot::SIZE);
                    TrajectoryKind::LawnMower(LawnMower {
                        scale: scale as f32,
                        omega: (speed / (15.0 * scale)).clamp(0.02, 0.08) as f32,
                        depth: 5.0,
                    })
                }),
                // Level paths only: the contract's random missions hold their depth. The
                // waypoint missions have their own speed profiles (`host-sim check`).
                TrajectoryKind::Helix(_) | TrajectoryKind::Waypoints { .. } => None,
            }
        })
        .collect()
}
