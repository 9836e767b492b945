//! The campaign file (TOML): its shape, checked like a scenario's (unknown keys named with
//! their line, values out of range named by their dotted key), and its bases loaded and
//! validated as scenarios.
//!
//! ```toml
//! name = "circle-robustness"   # file-name safe; default: the file stem
//! runs = 1000                  # 1 ..= MAX_CAMPAIGN_RUNS
//! seed = 1                     # run i's draw depends on (seed, i) only
//! bases = ["circle.toml"]      # one or more scenario files, relative to this file; run i
//!                              # flies base ⌊i·B/runs⌋ (B bases: equal blocks of indices)
//! metrics = ["max_path", "rms_path"]  # reported metrics, the first is "the error" of the
//!                              # scatter plots; default all (METRIC_NAMES)
//! plant_step = "control-period"  # study-grade flight (Choice 400): one midpoint step per
//!                              # control period instead of each base's plant_step; default: the base's
//! noise_draws = "at-samples"   # study-grade noise (Choice 536): each navigation error drawn at
//!                              # its source's samples, Xoshiro256++; default: the base's
//!
//! [draw]                       # what each run draws; a key left out draws nothing
//! parameters = "uniform"       # "uniform" in the Table-3 box | "corners" of it | "none"
//! current = 0.2                # a constant horizontal current, speed uniform in [0, v] m/s,
//!                              # direction uniform
//! noise_seed = true            # the seed of the run's sensor noise, drawn: [noise]'s and the
//!                              # navigation model's (Choice 460; the base must have one)
//! initial_offset = [0.05, 0.05, 0.05, 0.0, 0.0, 0.05]  # uniform in ±w, added to the base's
//! time_scale = [1.0, 1.5]      # the mission's time scale k, uniform in [lo, hi] ⊂ [1, 100]
//! mountings = [["vert fore", "horz fore", "horz aft"], []]  # thruster mountings, one drawn
//!                              # per run with equal chance, each a controller.reversed_thrusters
//!
//! [bound]                      # replaces each base's bound; default: each base's own
//! max_path = 0.05              # m, > 0
//! saturated = 0.01             # fraction of periods, [0, 1]
//! max_reversals_per_s = 2.0    # 1/s, ≥ 0: any thruster's sign reversals through ±0.5 V
//! max_command_tv = 100.0       # V/s, ≥ 0: any thruster's command total variation
//! fraction = 0.99              # `campaign merge` exits 4 when fewer runs are within bound;
//!                              # default: no such verdict (exit 0)
//! ```
//!
//! What a draw replaces must be absent from the base: drawn parameters replace `[variation]`
//! (the base must have none, like `monte-carlo`), a drawn current replaces `[current]` (none
//! in the base).

use std::path::{Path, PathBuf};

use controller_core::effectiveness::THRUSTER_NAMES;
use controller_core::readable::Readable;
use serde::{Deserialize, Serialize};

use super::METRIC_NAMES;
use crate::plant::{CurrentModel, Integrator, VariationProfile};
use crate::scenario::{
    reversed_mask, Bound, Scenario, ScenarioError, SimConfig, MAX_CURRENT_SPEED,
};
use crate::sim::nav_model::NoiseDraws;

/// Most runs of one campaign: 10⁹ (a run's index is recorded exactly, and a campaign of more is
/// more likely a typo than a plan).
pub const MAX_CAMPAIGN_RUNS: u64 = 1_000_000_000;

/// Why a campaign file could not be loaded.
#[derive(Debug)]
pub enum CampaignError {
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Not valid TOML, an unknown key, a missing required key or a value of the wrong type
    /// (the `toml` crate's message: line, column, key).
    Toml(String),
    /// A value out of range: `key` is the dotted key.
    Invalid { key: String, message: String },
    /// A base scenario that does not load or validate.
    Base {
        path: PathBuf,
        source: ScenarioError,
    },
}

impl std::fmt::Display for CampaignError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CampaignError::Io { path, .. } => {
                write!(f, "cannot read campaign file {}", path.display())
            }
            CampaignError::Toml(m) => write!(f, "invalid campaign: {}", m.trim_end()),
            CampaignError::Invalid { key, message } => {
                write!(f, "invalid campaign value `{key}`: {message}")
            }
            CampaignError::Base { path, .. } => {
                write!(f, "campaign base scenario {}", path.display())
            }
        }
    }
}

impl std::error::Error for CampaignError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CampaignError::Io { source, .. } => Some(source),
            CampaignError::Base { source, .. } => Some(source),
            _ => None,
        }
    }
}

fn invalid(key: &str, message: impl Into<String>) -> CampaignError {
    CampaignError::Invalid {
        key: key.to_string(),
        message: message.into(),
    }
}

/// How the Table-3 parameters are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ParameterDraw {
    /// Not drawn: the base's own (none).
    None,
    /// Each Δ uniform in [0, Table-3 max].
    Uniform,
    /// Each Δ at 0 or its Table-3 max, with equal chance: the box's 512 corners.
    Corners,
}

/// `[draw]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrawSpec {
    #[serde(default = "no_parameters")]
    pub parameters: ParameterDraw,
    pub current: Option<f64>,
    #[serde(default)]
    pub noise_seed: bool,
    pub initial_offset: Option<[f64; 6]>,
    pub time_scale: Option<[f64; 2]>,
    /// Thruster mountings to draw from, each the `controller.reversed_thrusters` list of one.
    pub mountings: Option<Vec<Vec<String>>>,
}

fn no_parameters() -> ParameterDraw {
    ParameterDraw::None
}

impl Default for DrawSpec {
    fn default() -> Self {
        DrawSpec {
            parameters: ParameterDraw::None,
            current: None,
            noise_seed: false,
            initial_offset: None,
            time_scale: None,
            mountings: None,
        }
    }
}

/// The plant step a campaign flies its runs at (**Choice 400**, docs/campaigns.md#study-grade-flight).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlantStep {
    /// Study-grade flight: one explicit-midpoint step per control period (the thrust is held
    /// over the period anyway; **Choice 542**), the step and integrator a base gives replaced.
    /// Agrees with the 1 ms RK4 within [`STUDY_PATH_TOLERANCE`] (tests/study_step.rs).
    ControlPeriod,
}

impl PlantStep {
    /// Sets this step on a run's configuration.
    pub fn apply(self, c: &mut SimConfig) {
        match self {
            PlantStep::ControlPeriod => {
                c.plant_step = 1.0 / f64::from(c.controller.rate_hz);
                c.plant_integrator = Integrator::Midpoint;
            }
        }
    }
}

/// How far a study-grade run's max path error may be from the 1 ms RK4's (**Choice 400**):
/// [`STUDY_PATH_TOLERANCE`]`.0` m absolute plus `.1` of the reference's value. The absolute
/// part, 1 % of the real vehicle's 0.05 m bound, decides every run near the bound (a verdict
/// can only change within it of the bound); the thruster lag sets it (0.22 mm at worst over
/// the contract's missions with a 0.3 s lag; without lag the two agree to 10⁻⁶ m). The
/// relative part covers saturated runs metres off their path, whose error the step length
/// moves by a fraction of a percent.
pub const STUDY_PATH_TOLERANCE: (f64, f64) = (5e-4, 0.02);

/// `[bound]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundSpec {
    pub max_path: Option<f64>,
    pub saturated: Option<f64>,
    pub max_reversals_per_s: Option<f64>,
    pub max_command_tv: Option<f64>,
    pub fraction: Option<f64>,
}

/// The file as written (its canonical form, serialised, is part of the campaign's hash).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSpec {
    pub name: Option<String>,
    pub runs: u64,
    pub seed: u64,
    pub bases: Vec<String>,
    pub metrics: Option<Vec<String>>,
    /// Absent: each base's plant step (a campaign without the key hashes as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plant_step: Option<PlantStep>,
    /// Absent: each base's own `noise_draws` (Choice 536; a campaign without the key hashes
    /// as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_draws: Option<NoiseDraws>,
    #[serde(default)]
    pub draw: DrawSpec,
    pub bound: Option<BoundSpec>,
}

/// A base scenario: its file name as the campaign gives it, its text, and it validated.
#[derive(Clone, Debug)]
pub struct Base {
    pub path: String,
    pub text: String,
    pub scenario: Scenario,
}

/// Parses campaign `text` (its bases are read relative to `dir`), checks every value and loads
/// every base; `stem` names a campaign without `name`.
pub fn parse(
    text: &str,
    stem: &str,
    dir: &Path,
) -> Result<(CampaignSpec, Vec<Base>), CampaignError> {
    let mut spec: CampaignSpec =
        toml::from_str(text).map_err(|e| CampaignError::Toml(e.to_string()))?;
    spec.name.get_or_insert_with(|| stem.to_string());
    check(&spec)?;
    let bases = spec
        .bases
        .iter()
        .map(|b| load_base(dir, b, &spec))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((spec, bases))
}

/// Reads a campaign file ([`parse`]): its text, spec and bases.
pub fn load(path: &Path) -> Result<(String, CampaignSpec, Vec<Base>), CampaignError> {
    let text = std::fs::read_to_string(path).map_err(|source| CampaignError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("campaign");
    let (spec, bases) = parse(&text, stem, path.parent().unwrap_or(Path::new(".")))?;
    Ok((text, spec, bases))
}

/// Parses the texts a shard's manifest keeps (the campaign and its bases, by name): the same
/// campaign as [`load`] gave, without the files.
pub fn from_texts(
    text: &str,
    stem: &str,
    bases: &[(String, String)],
) -> Result<(CampaignSpec, Vec<Base>), CampaignError> {
    let mut spec: CampaignSpec =
        toml::from_str(text).map_err(|e| CampaignError::Toml(e.to_string()))?;
    spec.name.get_or_insert_with(|| stem.to_string());
    check(&spec)?;
    let loaded = bases
        .iter()
        .map(|(path, text)| base_from_text(path, text, &spec))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((spec, loaded))
}

fn load_base(dir: &Path, name: &str, spec: &CampaignSpec) -> Result<Base, CampaignError> {
    let path = dir.join(name);
    let text = std::fs::read_to_string(&path).map_err(|source| CampaignError::Base {
        path: path.clone(),
        source: ScenarioError::Io {
            path: path.clone(),
            source,
        },
    })?;
    // Parsed from the text read once: the hash and the runs see the same bytes.
    base_from_text(name, &text, spec)
}

fn base_from_text(name: &str, text: &str, spec: &CampaignSpec) -> Result<Base, CampaignError> {
    let err = |source| CampaignError::Base {
        path: PathBuf::from(name),
        source,
    };
    let scenario =
        crate::scenario::parse_scenario(text).map_err(|e| err(without_quoted_lines(e)))?;
    let cfg = scenario.config();
    if spec.draw.parameters != ParameterDraw::None && cfg.variation != VariationProfile::None {
        return Err(invalid(
            "draw.parameters",
            format!(
                "base {name} has its own [variation], which the drawn Δp would replace; remove \
                 it from the base (or set parameters = \"none\")"
            ),
        ));
    }
    if spec.draw.current.is_some() && cfg.current != CurrentModel::None {
        return Err(invalid(
            "draw.current",
            format!("base {name} has its own [current], which the drawn current would replace"),
        ));
    }
    if let Some(step) = spec.plant_step {
        // A base the study-grade step refuses (a Gauss–Markov τ below the period) would make
        // every run of it `invalid`: say so at load.
        scenario.with(|c| step.apply(c)).map_err(|e| {
            invalid(
                "plant_step",
                format!("base {name} cannot fly at the control period: {e}"),
            )
        })?;
    }
    if spec.draw.noise_seed && cfg.noise.is_none() && cfg.navigation.is_none() {
        return Err(invalid(
            "draw.noise_seed",
            format!("base {name} has no [noise] and no navigation model whose seed could be drawn"),
        ));
    }
    Ok(Base {
        path: name.to_string(),
        text: text.to_string(),
        scenario,
    })
}

/// A base's TOML error without the lines of the file it quotes: a campaign may name any file as
/// a base (`/etc/…`), and the error says where (line, column) and what, not what the file holds
/// (**Choice 247**).
fn without_quoted_lines(e: ScenarioError) -> ScenarioError {
    match e {
        ScenarioError::Toml(m) => ScenarioError::Toml(
            m.lines()
                .filter(|l| !is_quoted_line(l))
                .collect::<Vec<_>>()
                .join("\n"),
        ),
        other => other,
    }
}

/// A line of the `toml` crate's excerpt: `  |`, `12 | text`, `   |     ^`: a gutter (spaces and
/// a line number) and a bar.
fn is_quoted_line(l: &str) -> bool {
    l.trim_start()
        .trim_start_matches(|c: char| c.is_ascii_digit())
        .trim_start()
        .starts_with('|')
}

/// Every value's range.
fn check(spec: &CampaignSpec) -> Result<(), CampaignError> {
    let name = spec.name.as_deref().unwrap_or_default();
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
    {
        return Err(invalid(
            "name",
            format!("must be letters, digits, `-`, `_` or `.` (a file name), got {name:?}"),
        ));
    }
    if !(1..=MAX_CAMPAIGN_RUNS).contains(&spec.runs) {
        return Err(invalid(
            "runs",
            format!("must be in [1, {MAX_CAMPAIGN_RUNS}], got {}", spec.runs),
        ));
    }
    if spec.bases.is_empty() || spec.bases.len() as u64 > spec.runs {
        return Err(invalid(
            "bases",
            format!(
                "give one to `runs` base scenario files, got {}",
                spec.bases.len()
            ),
        ));
    }
    if let Some(m) = &spec.metrics {
        if m.is_empty() {
            return Err(invalid("metrics", "give at least one metric"));
        }
        if let Some(bad) = m.iter().find(|x| !METRIC_NAMES.contains(&x.as_str())) {
            return Err(invalid(
                "metrics",
                format!("unknown metric {bad:?}, expected one of {METRIC_NAMES:?}"),
            ));
        }
        if let Some((k, twice)) = m.iter().enumerate().find(|(k, x)| m[..*k].contains(x)) {
            return Err(invalid(
                "metrics",
                format!("{twice:?} is listed twice (again at position {k}); list each once"),
            ));
        }
    }
    check_draw(&spec.draw)?;
    if let Some(b) = &spec.bound {
        positive("bound.max_path", b.max_path)?;
        unit("bound.saturated", b.saturated)?;
        non_negative("bound.max_reversals_per_s", b.max_reversals_per_s)?;
        non_negative("bound.max_command_tv", b.max_command_tv)?;
        unit("bound.fraction", b.fraction)?;
    }
    Ok(())
}

fn check_draw(d: &DrawSpec) -> Result<(), CampaignError> {
    if let Some(v) = d.current {
        if !(v.is_finite() && (0.0..=MAX_CURRENT_SPEED).contains(&v)) {
            return Err(invalid(
                "draw.current",
                format!(
                    "must be a speed in [0, {MAX_CURRENT_SPEED}] m/s, got {}",
                    Readable(v)
                ),
            ));
        }
    }
    if let Some(w) = d.initial_offset {
        // Roll and yaw within ±π, pitch inside ±π/2; the sum with the base's offset is checked
        // by each run's scenario (a run beyond it is recorded `invalid`). A position's
        // half-width has no upper limit of its own, and none is printed (it was f64::MAX's
        // 309 digits).
        use std::f64::consts::{FRAC_PI_2, PI};
        let limits = [None, None, None, Some(PI), Some(FRAC_PI_2), Some(PI)];
        for (i, (x, lim)) in w.iter().zip(limits).enumerate() {
            if !(x.is_finite() && *x >= 0.0 && lim.is_none_or(|l| *x <= l)) {
                let range = match lim {
                    None => "a half-width ≥ 0 m".to_string(),
                    Some(l) => format!("a half-width in [0, {}] rad", Readable(l)),
                };
                return Err(invalid(
                    &format!("draw.initial_offset[{i}]"),
                    format!("must be {range}, got {}", Readable(*x)),
                ));
            }
        }
    }
    if let Some(m) = &d.mountings {
        mounting_masks(m)?;
    }
    if let Some([lo, hi]) = d.time_scale {
        if !(lo.is_finite() && hi.is_finite() && 1.0 <= lo && lo <= hi && hi <= 100.0) {
            return Err(invalid(
                "draw.time_scale",
                format!(
                    "must be [lo, hi] with 1 ≤ lo ≤ hi ≤ 100, got [{}, {}]",
                    Readable(lo),
                    Readable(hi)
                ),
            ));
        }
    }
    Ok(())
}

/// The reversed-thruster masks (`ThrusterGeometry::auv150`) of `draw.mountings`: each list
/// names thrusters of [`THRUSTER_NAMES`], each at most once; at least one list.
pub fn mounting_masks(lists: &[Vec<String>]) -> Result<Vec<u8>, CampaignError> {
    if lists.is_empty() {
        return Err(invalid("draw.mountings", "give at least one mounting"));
    }
    lists
        .iter()
        .enumerate()
        .map(|(k, names)| {
            reversed_mask(&format!("draw.mountings[{k}]"), names).map_err(|e| match e {
                ScenarioError::Invalid { key, message } => invalid(&key, message),
                other => invalid("draw.mountings", other.to_string()),
            })
        })
        .collect()
}

/// The names of the thrusters reversed in `mask` (the inverse of [`mounting_masks`]).
pub fn mounting_names(mask: u8) -> Vec<&'static str> {
    THRUSTER_NAMES
        .iter()
        .enumerate()
        .filter(|(i, _)| mask & (1 << i) != 0)
        .map(|(_, n)| *n)
        .collect()
}

fn positive(key: &str, v: Option<f64>) -> Result<(), CampaignError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(invalid(
            key,
            format!("must be a finite number > 0, got {x}"),
        )),
        _ => Ok(()),
    }
}

fn non_negative(key: &str, v: Option<f64>) -> Result<(), CampaignError> {
    match v {
        Some(x) if !(x.is_finite() && x >= 0.0) => Err(invalid(
            key,
            format!("must be a finite number ≥ 0, got {x}"),
        )),
        _ => Ok(()),
    }
}

fn unit(key: &str, v: Option<f64>) -> Result<(), CampaignError> {
    match v {
        Some(x) if !(0.0..=1.0).contains(&x) => {
            Err(invalid(key, format!("must be in [0, 1], got {x}")))
        }
        _ => Ok(()),
    }
}

impl CampaignSpec {
    /// The bound the campaign sets on every run, if it sets one: its keys, the real vehicle's
    /// for a key left out.
    pub fn bound(&self) -> Option<Bound> {
        let b = self.bound.as_ref()?;
        if b.max_path.is_none()
            && b.saturated.is_none()
            && b.max_reversals_per_s.is_none()
            && b.max_command_tv.is_none()
        {
            return None;
        }
        Some(Bound::with_defaults(
            b.max_path,
            b.saturated,
            b.max_reversals_per_s,
            b.max_command_tv,
        ))
    }

    /// The least fraction of runs within bound for the merge's verdict.
    pub fn required_fraction(&self) -> Option<f64> {
        self.bound.as_ref().and_then(|b| b.fraction)
    }

    /// The campaign's name (the file stem when the file gives none).
    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("campaign")
    }
}
