//! The scenario file's one shape, [`ScenarioFile`]: every key of a scenario TOML, as written
//! (a key left out is `None`, not its default). The reader deserializes it
//! ([`ScenarioFile::from_toml`]) and builds the [`SimConfig`](super::SimConfig) from it
//! (`parse.rs`); every writer fills one in (by hand, or [`ScenarioFile::try_from`] a
//! configuration) and serializes it (`write.rs`): no other code spells a key. The keys, their
//! meaning, units, ranges and defaults: `scenarios/example-all-knobs.toml`.

use std::fmt;

use controller_core::model::{VARIED_PARAMETERS, VARIED_PARAMETER_NAMES};
use controller_core::TrajectoryKind;
use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::fixed_arrays;
use super::{Bound, ScenarioError};

/// A scenario file: the top-level keys and the tables. Only `[trajectory]` is required.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// A [`Table1Case`](controller_core::Table1Case) by name (checked when built).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table1_case: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plant_step: Option<f64>,
    /// An [`Integrator`](crate::plant::Integrator) by name (checked when built).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plant_integrator: Option<String>,
    /// A [`NoiseDraws`](crate::scenario::navigation::NoiseDraws) by name (checked when built).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_draws: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ideal_actuators: Option<bool>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub initial_offset: Option<[f64; 6]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub divergence_limit: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thruster_lag: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expect_faults: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_attitude: Option<AttitudeName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expect_missed: Option<bool>,
    pub trajectory: TrajectoryTable,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub variation: Option<VariationTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub current: Option<CurrentTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise: Option<NoiseTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub navigation: Option<super::navigation::NavigationTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bound: Option<BoundTable>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link_faults: Option<LinkFaultsTable>,
}

impl ScenarioFile {
    /// A file with only `[trajectory]`, the path `path`: everything else left out.
    pub fn new(path: TrajectoryKind) -> Self {
        ScenarioFile {
            name: None,
            table1_case: None,
            duration: None,
            plant_step: None,
            plant_integrator: None,
            noise_draws: None,
            ideal_actuators: None,
            initial_offset: None,
            divergence_limit: None,
            thruster_lag: None,
            expect_faults: None,
            initial_attitude: None,
            expect_missed: None,
            trajectory: TrajectoryTable::new(path),
            variation: None,
            current: None,
            noise: None,
            navigation: None,
            controller: None,
            bound: None,
            link_faults: None,
        }
    }

    /// Reads a scenario TOML text: its shape only (unknown keys, types, array lengths, required
    /// keys); the values are checked when the configuration is built. The error is the `toml`
    /// crate's, naming the line, column and key.
    pub fn from_toml(text: &str) -> Result<Self, ScenarioError> {
        toml::from_str(text).map_err(|e| ScenarioError::Toml(e.to_string()))
    }
}

/// `[trajectory]`: the path is the core's own type (kind-specific keys, defaults and unknown
/// keys are its serde form's), plus how the mission is flown.
///
/// Written, the path's keys come first (`kind`, then the kind's keys in the core's order); a
/// key of the kind whose value is its default (the paper's `omega`, `depth`, …) is left out:
/// the file reads back to the same path either way.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
pub struct TrajectoryTable {
    #[serde(flatten, serialize_with = "serialize_path")]
    pub path: TrajectoryKind,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading: Option<HeadingName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_scale: Option<f64>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub origin: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_limits: Option<Vec<f64>>,
}

impl TrajectoryTable {
    /// The path alone.
    pub fn new(path: TrajectoryKind) -> Self {
        TrajectoryTable {
            path,
            heading: None,
            time_scale: None,
            origin: None,
            speed_limits: None,
        }
    }
}

fn serialize_path<S: Serializer>(path: &TrajectoryKind, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_map(path_keys(path).map_err(serde::ser::Error::custom)?)
}

/// The keys of a path as the core's serde form writes them (`kind` first, then the kind's
/// fields in their order, a field left out when it is `None`), without the ones whose value is
/// the kind's default: a key is dropped when the table without it reads back to the same path.
/// The core's numbers are f32: each is written as the shortest decimal of its f32 (what
/// `toml` writes for an f32), not as the f64 that holds it (10.3 and not 10.300000190734863).
fn path_keys(path: &TrajectoryKind) -> Result<Vec<(String, toml::Value)>, String> {
    let text = toml::to_string(path).map_err(|e| e.to_string())?;
    // The order of the keys, as written; their values, with the f32's decimals.
    let order: toml_edit::DocumentMut = text.parse().map_err(|e| format!("{e}"))?;
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| e.to_string())?;
    let keys: Vec<String> = order.iter().map(|(k, _)| k.to_string()).collect();
    for key in &keys {
        let Some(value) = table.remove(key) else {
            continue;
        };
        let same = toml::Value::Table(table.clone())
            .try_into::<TrajectoryKind>()
            .is_ok_and(|p| p == *path);
        if !same {
            table.insert(key.clone(), value);
        }
    }
    Ok(keys
        .into_iter()
        .filter_map(|k| table.remove(&k).map(|v| (k, v)))
        .collect())
}

/// How a file spells `value` (its serde name), e.g. `abs-sin` for [`ProfileName::AbsSin`].
pub(super) fn spelled<T: Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}

/// `trajectory.heading`: [`HeadingMode`](controller_core::HeadingMode) by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeadingName {
    Paper,
    Tangent,
}

/// `initial_attitude`: [`InitialAttitude`](super::InitialAttitude) by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum AttitudeName {
    Level,
    Trim,
}

impl From<Bound> for BoundTable {
    /// Every limit of `b`, written out.
    fn from(b: Bound) -> Self {
        BoundTable {
            max_path: Some(b.max_path),
            saturated: Some(b.saturated),
            max_reversals_per_s: Some(b.max_reversals_per_s),
            max_command_tv: Some(b.max_command_tv),
        }
    }
}

/// `[bound]`: the bound a run must fly within; a key left out takes the real vehicle's.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_path: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub saturated: Option<f64>,
    /// Most sign reversals per second of any thruster's command through ±0.5 V.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_reversals_per_s: Option<f64>,
    /// Largest total variation per second of any thruster's command (V/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_command_tv: Option<f64>,
}

/// `controller.thrust_unit`: [`ThrustUnit`](controller_core::ThrustUnit) by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThrustUnitName {
    Kgf,
    Newton,
}

/// `[link_faults]`: tick ranges "A..B" (processor in the loop only).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LinkFaultsTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drop: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corrupt: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay_ticks: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub silent: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lose_upload_chunks: Option<Vec<u8>>,
}

/// `variation.profile`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProfileName {
    None,
    Constant,
    AbsSin,
    Staircase,
    Table3Staircase,
}

/// The nine Δ of a table, by [`VARIED_PARAMETER_NAMES`]; `None`: not given.
pub type Delta = [Option<f64>; VARIED_PARAMETERS];

/// `[variation]`: `profile`, `trimmed`, `omega`, `steps` and the nine Δ keys.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VariationTable {
    pub profile: ProfileName,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trimmed: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    #[serde(flatten, serialize_with = "serialize_delta")]
    pub delta: Delta,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steps: Option<Vec<StepTable>>,
}

/// One `[[variation.steps]]`: `until` and the nine Δ keys.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StepTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub until: Option<f64>,
    #[serde(flatten, serialize_with = "serialize_delta")]
    pub delta: Delta,
}

/// Writes the Δ keys that are given, by name.
fn serialize_delta<S: Serializer>(delta: &Delta, serializer: S) -> Result<S::Ok, S::Error> {
    let given = VARIED_PARAMETER_NAMES.iter().zip(delta);
    serializer.collect_map(given.filter_map(|(name, x)| x.map(|x| (name, x))))
}

/// Reads a table whose keys are the nine Δ keys and the ones `own` takes (it returns false for
/// a key it does not know); anything else is an unknown-field error.
fn visit_delta_table<'de, A: MapAccess<'de>>(
    map: &mut A,
    own_keys: &str,
    mut own: impl FnMut(&str, &mut A) -> Result<bool, A::Error>,
) -> Result<Delta, A::Error> {
    let mut delta = [None; VARIED_PARAMETERS];
    while let Some(key) = map.next_key::<String>()? {
        if own(&key, map)? {
            continue;
        }
        match VARIED_PARAMETER_NAMES.iter().position(|n| *n == key) {
            Some(i) => delta[i] = Some(map.next_value()?),
            None => {
                return Err(de::Error::custom(format_args!(
                    "unknown field `{key}`, expected {own_keys} or one of `{}`",
                    VARIED_PARAMETER_NAMES.join("`, `")
                )))
            }
        }
    }
    Ok(delta)
}

impl<'de> Deserialize<'de> for VariationTable {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> Visitor<'de> for Table {
            type Value = VariationTable;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a [variation] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<VariationTable, A::Error> {
                let (mut profile, mut omega, mut steps, mut trimmed) = (None, None, None, None);
                let own = "`profile`, `trimmed`, `omega`, `steps`";
                let delta = visit_delta_table(&mut map, own, |k, m| {
                    match k {
                        "profile" => profile = Some(m.next_value()?),
                        "trimmed" => trimmed = Some(m.next_value()?),
                        "omega" => omega = Some(m.next_value()?),
                        "steps" => steps = Some(m.next_value()?),
                        _ => return Ok(false),
                    }
                    Ok(true)
                })?;
                Ok(VariationTable {
                    profile: profile.ok_or_else(|| de::Error::missing_field("profile"))?,
                    trimmed,
                    omega,
                    steps,
                    delta,
                })
            }
        }
        deserializer.deserialize_map(Table)
    }
}

impl<'de> Deserialize<'de> for StepTable {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> Visitor<'de> for Table {
            type Value = StepTable;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a [[variation.steps]] table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<StepTable, A::Error> {
                let mut until = None;
                let delta = visit_delta_table(&mut map, "`until`", |k, m| {
                    if k != "until" {
                        return Ok(false);
                    }
                    until = Some(m.next_value()?);
                    Ok(true)
                })?;
                Ok(StepTable { until, delta })
            }
        }
        deserializer.deserialize_map(Table)
    }
}

/// `current.model`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurrentName {
    None,
    Constant,
    GaussMarkov,
}

/// `[current]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CurrentTable {
    pub model: CurrentName,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub velocity: Option<[f64; 3]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub mean: Option<[f64; 3]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub sigma: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tau: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl CurrentTable {
    /// A table of `model` with nothing else given.
    pub fn new(model: CurrentName) -> Self {
        CurrentTable {
            model,
            velocity: None,
            mean: None,
            sigma: None,
            tau: None,
            seed: None,
        }
    }
}

/// `[noise]` (present: measurement noise on).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseTable {
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub eta_sigma: Option<[f64; 6]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub nu_sigma: Option<[f64; 6]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// `controller.law`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LawName {
    BoundaryLayer,
    Discontinuous,
}

/// `controller.b_bound`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BBoundName {
    ControlledRows,
    Literal,
}

/// `[controller]`: the controller's numbers as written (f64; made f32 when built).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerTable {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robust: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub law: Option<LawName>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub k1: Option<[f64; 6]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub k2: Option<[f64; 6]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub q: Option<[f64; 2]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_max: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch_limit_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub voltage_limit: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b_bound: Option<BBoundName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thrust_unit: Option<ThrustUnitName>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_priority: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reversed_thrusters: Option<Vec<String>>,
    /// The state estimator the law flies on (docs/law.md#the-state-estimator): `"off"` (the
    /// default) or `"kalman"`, and its noise settings per axis of η.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimator: Option<EstimatorName>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub estimator_position_sigma: Option<[f64; 6]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub estimator_velocity_sigma: Option<[f64; 6]>,
    #[serde(
        default,
        deserialize_with = "fixed_arrays::option",
        skip_serializing_if = "Option::is_none"
    )]
    pub estimator_accel_sigma: Option<[f64; 6]>,
}

/// `controller.estimator`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EstimatorName {
    Off,
    Kalman,
}
