//! A run with the board in the loop against the same scenario in SIL: the comparison the
//! `pil` and `hil` commands report and CI holds to [`PIL_SIL_TOLERANCE`].

use serde::{Deserialize, Serialize};

use super::stats::BoardStats;
use crate::sim::record::{RunResult, RunSummary};

/// Largest |PIL − SIL| of the max path error (m) that a fault-free PIL run may show: 1 mm.
/// PIL equals SIL bit for bit today (the same f32 core, the same state frames); this is the
/// margin the `pil` command (exit 1 beyond it) and CI hold it to.
pub const PIL_SIL_TOLERANCE: f64 = 1e-3;

/// What a comparison is of: `"pil"` (processor in the loop, QEMU on a socket) or `"hil"`
/// (the board on a serial port), against SIL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Pil,
    Hil,
}

impl Mode {
    /// `"PIL"` or `"HIL"`, as messages and progress name the mode.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Pil => "PIL",
            Mode::Hil => "HIL",
        }
    }

    /// `"pil"` or `"hil"`: the flight log's `source` of the board's run
    /// ([`crate::output::log::Source`]).
    pub fn source(self) -> &'static str {
        match self {
            Mode::Pil => "pil",
            Mode::Hil => "hil",
        }
    }
}

/// One PIL run compared with SIL: an entry of `host-sim pil --json`'s `cases` (read it back
/// with `serde_json::from_str::<Cases<PilComparison>>`). The PIL run's summary, its SIL twin's
/// max path error and the difference, and the board and link figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoardComparison {
    /// The PIL run (`case`, `robust`, metrics, `diverged`, `lost_board`).
    #[serde(flatten)]
    pub run: RunSummary,
    pub mode: Mode,
    /// Max path error of the same scenario in SIL (m).
    pub sil_max_path: f64,
    /// PIL − SIL max path error (m).
    pub pil_minus_sil_max_path: f64,
    /// The board's and the link's figures.
    pub pil: BoardStats,
}

impl BoardComparison {
    /// The comparison of a PIL (or HIL: `mode`) run with the SIL run of the same scenario.
    pub fn new(pil_run: &RunResult, sil_run: &RunResult, stats: BoardStats, mode: Mode) -> Self {
        BoardComparison {
            run: pil_run.summary(),
            mode,
            sil_max_path: sil_run.metrics.max_path,
            pil_minus_sil_max_path: pil_run.metrics.max_path - sil_run.metrics.max_path,
            pil: stats,
        }
    }

    /// PIL and SIL agree: |PIL − SIL| of the max path error within [`PIL_SIL_TOLERANCE`] (a NaN
    /// difference does not agree).
    pub fn agrees(&self) -> bool {
        self.pil_minus_sil_max_path.abs() <= PIL_SIL_TOLERANCE
    }
}
