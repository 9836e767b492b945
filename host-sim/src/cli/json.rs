//! The JSON a command prints with `--json`: one object, keys sorted.

use std::io::Write;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::studies::contract_statistics::PresetStatistics;
use crate::studies::preflight::Preflight;
use crate::studies::validation::ContractSummary;

/// The JSON object a command prints: `{"cases": [...]}`, `"incomplete": [...]` when an
/// output could not be written completely (each entry names the file and why), and
/// `"preflight": [...]` with the preflight check of each mission (`run`, `table1`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cases<T> {
    pub cases: Vec<T>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub incomplete: Vec<String>,
    /// The preflight checks of the missions (`run`, `table1`; docs/real-vehicle.md#preflight-feasibility).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub preflight: Vec<Preflight>,
    /// Whether the preflight's verdicts held over its validation campaign (`table1`;
    /// docs/real-vehicle.md#the-preflights-contract).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contract: Option<ContractSummary>,
    /// The contract's statistics per navigation preset, sampled and searched (`table1`;
    /// docs/search.md#the-contract-in-the-main-jobs-report).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contract_statistics: Vec<PresetStatistics>,
}

/// One JSON line: the value through `serde_json::Value`, so the keys come out sorted.
pub(super) fn print_json(stdout: &mut dyn Write, value: &impl Serialize) -> Result<()> {
    let v = serde_json::to_value(value).context("serialising the JSON output")?;
    writeln!(stdout, "{v}").context("writing stdout")
}
