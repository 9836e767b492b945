//! `[navigation]`: the navigation solution the law is told (docs/navigation.md). A preset
//! (`ideal`, `survey`, `low-cost`) and, over it, any key of its sources: the INS (attitude,
//! rates and the accelerometer bias it integrates when the DVL is lost), the DVL (velocity),
//! the pressure sensor (depth) and position fixes. The sources' models, the presets with the
//! datasheet figures they come from, and the checks on the values are here; the solution
//! they make is [`crate::sim::nav_model`].

use serde::{Deserialize, Serialize};

use super::fixed_arrays;
use super::ScenarioError;

type Res<T> = Result<T, ScenarioError>;

fn invalid(key: impl Into<String>, message: impl Into<String>) -> ScenarioError {
    ScenarioError::Invalid {
        key: key.into(),
        message: message.into(),
    }
}

/// A preset by name (`navigation.preset`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// The plant's exact state (today's navigation, bit for bit): no sources.
    Ideal,
    /// A survey-grade DVL-aided INS (docs/navigation.md#presets).
    Survey,
    /// A MEMS AHRS with a small DVL (docs/navigation.md#presets).
    LowCost,
}

impl Preset {
    /// Every preset, in the order a point of the mission space indexes them.
    pub const ALL: [Preset; 3] = [Preset::Ideal, Preset::Survey, Preset::LowCost];

    /// The name as written in a scenario.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Ideal => "ideal",
            Preset::Survey => "survey",
            Preset::LowCost => "low-cost",
        }
    }
}

/// One quantity's error: white noise of σ `sigma` on each sample, plus a bias that starts at
/// `bias`, plus a first-order Gauss–Markov process of steady σ `bias_sigma` and correlation
/// time `bias_tau` (started from its steady distribution), plus a random walk of `bias_walk`
/// per √s (started at 0). Units are the quantity's (the walk's per √s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorModel<const N: usize> {
    pub sigma: [f64; N],
    pub bias: [f64; N],
    pub bias_sigma: [f64; N],
    pub bias_tau: f64,
    pub bias_walk: [f64; N],
}

impl<const N: usize> ErrorModel<N> {
    /// No error at all.
    pub const EXACT: Self = ErrorModel {
        sigma: [0.0; N],
        bias: [0.0; N],
        bias_sigma: [0.0; N],
        bias_tau: 600.0,
        bias_walk: [0.0; N],
    };

    /// White noise `sigma` and a Gauss–Markov bias of steady σ `bias_sigma`, time `tau`.
    pub const fn white_gm(sigma: [f64; N], bias_sigma: [f64; N], tau: f64) -> Self {
        ErrorModel {
            sigma,
            bias: [0.0; N],
            bias_sigma,
            bias_tau: tau,
            bias_walk: [0.0; N],
        }
    }
}

/// When a source samples, how late its samples reach the solution, and when it has none.
#[derive(Clone, Debug, PartialEq)]
pub struct Timing {
    /// Samples per second (at most one per control period: a faster source samples every
    /// period).
    pub rate_hz: f64,
    /// From a sample's time to the period it enters the solution (s; rounded to periods).
    pub latency: f64,
    /// Windows `[from, to)` (s, sample time) in which the source gives no sample.
    pub outages: Vec<[f64; 2]>,
}

/// The INS: attitude (φ θ ψ, rad), body rates (p q r, rad/s) and the acceleration error (m/s²,
/// body axes) it integrates into the velocity between DVL pings and while the DVL has lost the
/// bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Ins {
    pub timing: Timing,
    pub attitude: ErrorModel<3>,
    pub rates: ErrorModel<3>,
    pub accel: ErrorModel<3>,
}

/// The DVL: body velocity (u v w, m/s) per ping, while it has bottom lock: the altitude above
/// the seabed (`seabed_depth` − z, when the seabed is given) within
/// [`min_altitude`, `max_altitude`] and outside the `timing.outages` (the schedule of losses).
#[derive(Clone, Debug, PartialEq)]
pub struct Dvl {
    pub timing: Timing,
    pub velocity: ErrorModel<3>,
    pub min_altitude: f64,
    pub max_altitude: f64,
    /// Depth of the seabed (m, NED z); `None`: always within the DVL's range.
    pub seabed_depth: Option<f64>,
}

/// A source of one error block: the pressure depth (z, m) or the position fixes (x y, m).
#[derive(Clone, Debug, PartialEq)]
pub struct Source<const N: usize> {
    pub timing: Timing,
    pub error: ErrorModel<N>,
}

/// A navigation solution's sources (a preset with the scenario's keys over it).
#[derive(Clone, Debug, PartialEq)]
pub struct NavigationModel {
    /// The preset the keys were laid over (reported by the run, written back).
    pub preset: Preset,
    pub seed: u64,
    pub ins: Ins,
    pub dvl: Dvl,
    pub depth: Source<1>,
    /// Acoustic or surface position fixes; `None`: dead reckoning only.
    pub fix: Option<Source<2>>,
}

const DEG: f64 = std::f64::consts::PI / 180.0;
/// Standard gravity (m/s²), for accelerometer figures given in g.
const G: f64 = 9.80665;

impl NavigationModel {
    /// The sources of `preset` (docs/navigation.md#presets gives each figure's source); `None`
    /// for `ideal`, which has none.
    ///
    /// **Choice 331:** two presets besides `ideal`, their figures from datasheets where a
    /// datasheet gives one and stated as an assumption where it does not (docs/navigation.md#presets).
    pub fn preset(preset: Preset, seed: u64) -> Option<NavigationModel> {
        let timing = |rate_hz, latency| Timing {
            rate_hz,
            latency,
            outages: Vec::new(),
        };
        match preset {
            Preset::Ideal => None,
            Preset::Survey => Some(NavigationModel {
                preset,
                seed,
                ins: Ins {
                    timing: timing(200.0, 0.01),
                    attitude: ErrorModel::white_gm(
                        [0.002 * DEG, 0.002 * DEG, 0.01 * DEG],
                        [0.01 * DEG, 0.01 * DEG, 0.05 * DEG],
                        600.0,
                    ),
                    rates: ErrorModel::white_gm([1e-5; 3], [5e-8; 3], 3600.0),
                    accel: ErrorModel::white_gm([0.0; 3], [0.01 * DEG * G; 3], 3600.0),
                },
                dvl: Dvl {
                    timing: timing(8.0, 0.03),
                    velocity: ErrorModel::white_gm([SURVEY_DVL_SIGMA; 3], [0.001; 3], 600.0),
                    min_altitude: 0.3,
                    max_altitude: 75.0,
                    seabed_depth: None,
                },
                depth: Source {
                    timing: timing(8.0, 0.02),
                    error: ErrorModel::white_gm([0.002], [0.005], 600.0),
                },
                // Choice 371: a survey AUV's LBL fixes bound the dead reckoning's drift.
                fix: Some(Source {
                    timing: timing(2.0, 0.1),
                    error: ErrorModel::white_gm([SURVEY_FIX_SIGMA; 2], [0.0; 2], 600.0),
                }),
            }),
            Preset::LowCost => Some(NavigationModel {
                preset,
                seed,
                ins: Ins {
                    timing: timing(100.0, 0.01),
                    attitude: ErrorModel::white_gm(
                        [0.02 * DEG, 0.02 * DEG, 0.1 * DEG],
                        [0.25 * DEG, 0.25 * DEG, 0.8 * DEG],
                        60.0,
                    ),
                    rates: ErrorModel::white_gm([6e-4; 3], [4e-5; 3], 300.0),
                    accel: ErrorModel::white_gm([0.0; 3], [0.25 * DEG * G; 3], 600.0),
                },
                dvl: Dvl {
                    timing: timing(10.0, 0.05),
                    velocity: ErrorModel::white_gm([0.01; 3], [0.005; 3], 600.0),
                    min_altitude: 0.05,
                    max_altitude: 50.0,
                    seabed_depth: None,
                },
                depth: Source {
                    timing: timing(20.0, 0.02),
                    error: ErrorModel::white_gm([0.005], [0.02], 600.0),
                },
                fix: None,
            }),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The file's shape: every key optional, laid over the preset.

/// `[navigation]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NavigationTable {
    /// Default `ideal`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preset: Option<Preset>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ins: Option<InsTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dvl: Option<DvlTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth: Option<SourceTable<1>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fix: Option<SourceTable<2>>,
}

/// `[navigation.ins]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InsTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latency: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outages: Option<Vec<[f64; 2]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attitude: Option<ErrorTable<3>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rates: Option<ErrorTable<3>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accel: Option<ErrorTable<3>>,
}

/// `[navigation.dvl]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DvlTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latency: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outages: Option<Vec<[f64; 2]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_altitude: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_altitude: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seabed_depth: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity: Option<ErrorTable<3>>,
}

/// `[navigation.depth]`, `[navigation.fix]`: timing and the error inline.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, bound(serialize = "[f64; N]: Serialize"))]
pub struct SourceTable<const N: usize> {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latency: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub outages: Option<Vec<[f64; 2]>>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub sigma: Option<[f64; N]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias: Option<[f64; N]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias_sigma: Option<[f64; N]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_tau: Option<f64>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias_walk: Option<[f64; N]>,
}

/// An error block (`[navigation.ins.attitude]`, …): [`ErrorModel`]'s keys.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, bound(serialize = "[f64; N]: Serialize"))]
pub struct ErrorTable<const N: usize> {
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub sigma: Option<[f64; N]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias: Option<[f64; N]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias_sigma: Option<[f64; N]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bias_tau: Option<f64>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub bias_walk: Option<[f64; N]>,
}

fn over<T: Copy>(base: &mut T, given: Option<T>) {
    if let Some(v) = given {
        *base = v;
    }
}

fn over_error<const N: usize>(e: &mut ErrorModel<N>, t: &ErrorTable<N>) {
    over(&mut e.sigma, t.sigma);
    over(&mut e.bias, t.bias);
    over(&mut e.bias_sigma, t.bias_sigma);
    over(&mut e.bias_tau, t.bias_tau);
    over(&mut e.bias_walk, t.bias_walk);
}

fn over_timing(
    timing: &mut Timing,
    rate_hz: Option<f64>,
    latency: Option<f64>,
    outages: &Option<Vec<[f64; 2]>>,
) {
    over(&mut timing.rate_hz, rate_hz);
    over(&mut timing.latency, latency);
    if let Some(o) = outages {
        timing.outages = o.clone();
    }
}

fn over_source<const N: usize>(s: &mut Source<N>, t: &SourceTable<N>) {
    over_timing(&mut s.timing, t.rate_hz, t.latency, &t.outages);
    over_error(
        &mut s.error,
        &ErrorTable {
            sigma: t.sigma,
            bias: t.bias,
            bias_sigma: t.bias_sigma,
            bias_tau: t.bias_tau,
            bias_walk: t.bias_walk,
        },
    );
}

/// The navigation a real-chain scenario (`ideal_actuators = false`) flies on when its file has
/// no `[navigation]`: `survey` (**Choice 370**, docs/navigation.md#the-default). A file on the
/// ideal actuators keeps the exact state (Table 1 and the paper's missions bit for bit).
pub fn real_chain_default(seed: u64) -> Option<NavigationModel> {
    NavigationModel::preset(Preset::Survey, seed)
}

/// The estimator a real-chain scenario flies on when its `[controller]` does not say
/// `estimator` (**Choice 370**): on, with the survey preset's own figures for what it filters —
/// σₚ of x y the LBL fix's 0.01 m, σᵥ of x y z the DVL's single ping 0.005 m/s — and the model
/// error σₐ per axis of [`REAL_CHAIN_ACCEL_SIGMA`] (Choice 506); roll's and pitch's and
/// the other σ keep `EstimatorConfig::default`'s (docs/navigation.md#the-default, measured
/// there).
pub fn real_chain_estimator() -> controller_core::EstimatorConfig {
    let mut e = controller_core::EstimatorConfig {
        kind: controller_core::EstimatorKind::Kalman,
        ..Default::default()
    };
    e.position_sigma[..2].copy_from_slice(&[SURVEY_FIX_SIGMA as f32; 2]);
    e.velocity_sigma[..3].copy_from_slice(&[SURVEY_DVL_SIGMA as f32; 3]);
    for (axis, sigma) in REAL_CHAIN_ACCEL_SIGMA {
        e.accel_sigma[axis] = sigma;
    }
    e
}

/// The real chain's estimator's model error per axis (m/s², rad/s²), the axes it sets
/// (**Choice 506**, docs/law.md#the-state-estimator): x y 0.004, where the disturbance state
/// takes a current (Choice 510) and the white part follows its onset; z 0.001, where no current
/// acts and the trimmed payload is steady, so the white part only passes the depth's and the
/// DVL's noise to the vertical pair; yaw 0.002 rad/s², the horizontal pair's share of the
/// noise. Measured on the `real-circle` campaign: σₐ 0.003 on x y z (Choice 511) reversed the
/// vertical pair over 2 /s on a payload whose mean command sits in the ±0.5 V band.
const REAL_CHAIN_ACCEL_SIGMA: [(usize, f32); 4] = [(0, 0.004), (1, 0.004), (2, 0.001), (5, 0.002)];
/// The survey preset's LBL fix σ per horizontal axis (m, Choice 371).
const SURVEY_FIX_SIGMA: f64 = 0.01;
/// The survey preset's DVL single-ping σ (m/s, Choice 331).
const SURVEY_DVL_SIGMA: f64 = 0.005;

/// The model `[navigation]` describes: its preset with the given keys over it; `None` for
/// `ideal` (which takes no other key than `seed`). A `[fix]` over a preset without fixes
/// starts from fixes at 1 Hz, 0 s late, exact.
pub fn build(t: &NavigationTable, default_seed: u64) -> Res<Option<NavigationModel>> {
    // A `[navigation]` without a preset is the exact state; a real-chain file without the
    // table at all flies `real_chain_default` (Choice 370).
    let preset = t.preset.unwrap_or(Preset::Ideal);
    let seed = t.seed.unwrap_or(default_seed);
    let Some(mut m) = NavigationModel::preset(preset, seed) else {
        for (key, given) in [
            ("ins", t.ins.is_some()),
            ("dvl", t.dvl.is_some()),
            ("depth", t.depth.is_some()),
            ("fix", t.fix.is_some()),
        ] {
            if given {
                return Err(invalid(
                    format!("navigation.{key}"),
                    "preset \"ideal\" is the exact state and has no sources: start from \
                     preset = \"survey\" or \"low-cost\"",
                ));
            }
        }
        return Ok(None);
    };
    if let Some(i) = &t.ins {
        over_timing(&mut m.ins.timing, i.rate_hz, i.latency, &i.outages);
        for (e, given) in [
            (&mut m.ins.attitude, &i.attitude),
            (&mut m.ins.rates, &i.rates),
            (&mut m.ins.accel, &i.accel),
        ] {
            if let Some(g) = given {
                over_error(e, g);
            }
        }
    }
    if let Some(d) = &t.dvl {
        over_timing(&mut m.dvl.timing, d.rate_hz, d.latency, &d.outages);
        over(&mut m.dvl.min_altitude, d.min_altitude);
        over(&mut m.dvl.max_altitude, d.max_altitude);
        if d.seabed_depth.is_some() {
            m.dvl.seabed_depth = d.seabed_depth;
        }
        if let Some(v) = &d.velocity {
            over_error(&mut m.dvl.velocity, v);
        }
    }
    if let Some(d) = &t.depth {
        over_source(&mut m.depth, d);
    }
    if let Some(f) = &t.fix {
        let mut fix = m.fix.take().unwrap_or(Source {
            timing: Timing {
                rate_hz: 1.0,
                latency: 0.0,
                outages: Vec::new(),
            },
            error: ErrorModel::EXACT,
        });
        over_source(&mut fix, f);
        m.fix = Some(fix);
    }
    Ok(Some(m))
}

fn error_table<const N: usize>(e: &ErrorModel<N>) -> ErrorTable<N> {
    ErrorTable {
        sigma: Some(e.sigma),
        bias: Some(e.bias),
        bias_sigma: Some(e.bias_sigma),
        bias_tau: Some(e.bias_tau),
        bias_walk: Some(e.bias_walk),
    }
}

fn source_table<const N: usize>(s: &Source<N>) -> SourceTable<N> {
    SourceTable {
        rate_hz: Some(s.timing.rate_hz),
        latency: Some(s.timing.latency),
        outages: Some(s.timing.outages.clone()),
        sigma: Some(s.error.sigma),
        bias: Some(s.error.bias),
        bias_sigma: Some(s.error.bias_sigma),
        bias_tau: Some(s.error.bias_tau),
        bias_walk: Some(s.error.bias_walk),
    }
}

/// The table that reads back to `m` (every key written).
pub fn table(m: &NavigationModel) -> NavigationTable {
    NavigationTable {
        preset: Some(m.preset),
        seed: Some(m.seed),
        ins: Some(InsTable {
            rate_hz: Some(m.ins.timing.rate_hz),
            latency: Some(m.ins.timing.latency),
            outages: Some(m.ins.timing.outages.clone()),
            attitude: Some(error_table(&m.ins.attitude)),
            rates: Some(error_table(&m.ins.rates)),
            accel: Some(error_table(&m.ins.accel)),
        }),
        dvl: Some(DvlTable {
            rate_hz: Some(m.dvl.timing.rate_hz),
            latency: Some(m.dvl.timing.latency),
            outages: Some(m.dvl.timing.outages.clone()),
            min_altitude: Some(m.dvl.min_altitude),
            max_altitude: Some(m.dvl.max_altitude),
            seabed_depth: m.dvl.seabed_depth,
            velocity: Some(error_table(&m.dvl.velocity)),
        }),
        depth: Some(source_table(&m.depth)),
        fix: m.fix.as_ref().map(source_table),
    }
}

// ---------------------------------------------------------------------------------------------
// Values.

/// Longest latency a source may have (s): a solution older than this is not one a vehicle
/// is flown on.
pub const MAX_LATENCY: f64 = 10.0;

fn check(key: &str, ok: bool, what: &str, x: f64) -> Res<()> {
    if ok {
        Ok(())
    } else {
        Err(invalid(key, format!("must be {what}, got {x}")))
    }
}

fn check_timing(key: &str, t: &Timing) -> Res<()> {
    let r = t.rate_hz;
    check(
        &format!("{key}.rate_hz"),
        r.is_finite() && r > 0.0,
        "a finite number > 0",
        r,
    )?;
    let l = t.latency;
    check(
        &format!("{key}.latency"),
        (0.0..=MAX_LATENCY).contains(&l),
        "in [0, 10] s",
        l,
    )?;
    for (i, [a, b]) in t.outages.iter().enumerate() {
        check(
            &format!("{key}.outages[{i}]"),
            a.is_finite() && b.is_finite() && a < b,
            "[from, to) with from < to, finite (s)",
            *a,
        )?;
    }
    Ok(())
}

fn check_error<const N: usize>(key: &str, e: &ErrorModel<N>) -> Res<()> {
    for (name, xs) in [
        ("sigma", &e.sigma),
        ("bias_sigma", &e.bias_sigma),
        ("bias_walk", &e.bias_walk),
    ] {
        for (i, &x) in xs.iter().enumerate() {
            check(
                &format!("{key}.{name}[{i}]"),
                x.is_finite() && x >= 0.0,
                "a finite number ≥ 0",
                x,
            )?;
        }
    }
    for (i, &x) in e.bias.iter().enumerate() {
        check(
            &format!("{key}.bias[{i}]"),
            x.is_finite(),
            "a finite number",
            x,
        )?;
    }
    check(
        &format!("{key}.bias_tau"),
        e.bias_tau.is_finite() && e.bias_tau > 0.0,
        "a finite number > 0 (s)",
        e.bias_tau,
    )
}

/// Every value of `m` in its range (each refusal names its key).
pub fn validate(m: &NavigationModel) -> Res<()> {
    check_timing("navigation.ins", &m.ins.timing)?;
    check_error("navigation.ins.attitude", &m.ins.attitude)?;
    check_error("navigation.ins.rates", &m.ins.rates)?;
    check_error("navigation.ins.accel", &m.ins.accel)?;
    check_timing("navigation.dvl", &m.dvl.timing)?;
    check_error("navigation.dvl.velocity", &m.dvl.velocity)?;
    let (lo, hi) = (m.dvl.min_altitude, m.dvl.max_altitude);
    check(
        "navigation.dvl.min_altitude",
        lo.is_finite() && lo >= 0.0,
        "a finite number ≥ 0 (m)",
        lo,
    )?;
    check(
        "navigation.dvl.max_altitude",
        hi.is_finite() && hi > lo,
        "finite and above min_altitude (m)",
        hi,
    )?;
    if let Some(s) = m.dvl.seabed_depth {
        check(
            "navigation.dvl.seabed_depth",
            s.is_finite(),
            "a finite number (m)",
            s,
        )?;
    }
    check_timing("navigation.depth", &m.depth.timing)?;
    check_error("navigation.depth", &m.depth.error)?;
    if let Some(f) = &m.fix {
        check_timing("navigation.fix", &f.timing)?;
        check_error("navigation.fix", &f.error)?;
    }
    Ok(())
}

/// How a run draws its navigation errors and `[noise]` (scenario key `noise_draws`).
///
/// **Choice 536** (docs/navigation.md#the-noise-draws): `every-period` is the default and what
/// Table 1 and the shipped missions fly — each source's error process drawn from ChaCha12
/// (`StdRng`) and every bias stepped every control period, sampled or not (two normals per
/// axis a period, a zero σ drawn and multiplied by 0). `at-samples` is the study-grade
/// scheme a campaign declares with `noise_draws = "at-samples"`: Xoshiro256++ generators
/// (the same ziggurat normal), each source's bias stepped only when the source samples, over
/// the periods since its last sample by the exact transition (Eq N1:
/// b ← a^n·b + σ_b·√(1 − a^(2n))·w₁, walk ← walk + σ_w·√(n·dt)·w₂, a = e^(−dt/τ)), and
/// no normal drawn for a zero σ. Both are the same processes at every sample (the n-step
/// transition is the composition of n one-step ones), not the same realisations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseDraws {
    /// ChaCha12, every bias stepped every period (today's streams, bit for bit).
    #[default]
    EveryPeriod,
    /// Xoshiro256++, each error drawn at its source's samples only.
    AtSamples,
}

impl NoiseDraws {
    /// Every scheme, in the order the scenario key lists them.
    pub const ALL: [NoiseDraws; 2] = [NoiseDraws::EveryPeriod, NoiseDraws::AtSamples];

    /// The scenario key's value.
    pub fn name(self) -> &'static str {
        match self {
            NoiseDraws::EveryPeriod => "every-period",
            NoiseDraws::AtSamples => "at-samples",
        }
    }

    /// The scheme named `name`, if any.
    pub fn from_name(name: &str) -> Option<NoiseDraws> {
        NoiseDraws::ALL.into_iter().find(|d| d.name() == name)
    }
}
