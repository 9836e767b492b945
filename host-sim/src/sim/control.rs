//! Where the control law runs: the seam between the closed loop and the law. On the host
//! ([`LocalController`]: software in the loop) or on a board ([`crate::board`]: processor or
//! hardware in the loop), a period's answer is a [`ControlOut`].

use controller_core::effectiveness::THRUSTERS;
use controller_core::{Controller, Estimate, Solution, Status, Trajectory};

use super::record::{BoardLoss, BoardReport, ControlStatus, UploadRound};
use crate::scenario::Scenario;

/// What one control period returns, whether the law ran here (SIL) or on the board (PIL).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOut {
    /// Whether the law ran ([`ControlStatus::is_ok`]); if not, the thrusters are off.
    pub status: ControlStatus,
    /// Commanded body force (used by ideal actuators).
    pub tau: [f32; 6],
    /// Voltages (used by the real actuator chain).
    pub voltage: [f32; THRUSTERS],
    /// The thrust (N) the law reports for each voltage, when the law ran here: the inverse map
    /// of the voltage, or an unclamped tunnel's command (Choice 526). The simulated thrusters
    /// take it where it is that map, already computed (**Choice 402**, Choice 525,
    /// [`Thrusters::target`](super::thrusters::Thrusters::target)). `None` from a board.
    pub thrust: Option<[f32; THRUSTERS]>,
    pub saturated: u8,
    pub delta: f32,
    pub delta_clamped: bool,
    pub w_norm: f32,
    /// η_d of the period as the law sampled it (its trajectory at the period's tick), when
    /// the law ran here and ran ([`ControlStatus::is_ok`]); `None` from a board and in
    /// fail-safe. The loop takes it for its own reference where nothing else is asked of
    /// the sample (Choice 569, [`super::fly`]).
    pub eta_d: Option<[f32; 6]>,
    /// What a board in the loop reported besides (PIL, HIL); none in SIL.
    pub board: Option<BoardReport>,
}

/// Why a control source has no control for a period: the run ends there, and what was
/// recorded before is kept.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// A stop was requested (Ctrl-C, SIGTERM) while the source waited for its answer: the run
    /// ends [`Outcome::Interrupted`](super::Outcome::Interrupted).
    Interrupted,
    /// The board in the loop is lost: the run ends
    /// [`Outcome::LostBoard`](super::Outcome::LostBoard) with `cause` and the runner's message.
    LostBoard { cause: BoardLoss, reason: String },
}

/// Where the control law runs.
pub trait ControlSource {
    /// The control for period `k` from the measured state. An `Err` ends the run ([`Stop`]);
    /// what was recorded is kept.
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, Stop>;

    /// The rounds of a waypoint mission's upload before the flight, if this source had one
    /// (a board).
    fn upload_rounds(&self) -> &[UploadRound] {
        &[]
    }

    /// Whether the law runs here, in this process, with no effect outside it: asking it for
    /// a period the run then stops at changes nothing anyone sees (a board would have been
    /// sent the period's frames). [`LocalController`] does.
    fn runs_here(&self) -> bool {
        false
    }
}

/// The f32 core on the host, as the firmware runs it (software in the loop): the scenario's
/// controller and trajectory, and the estimator's memory (docs/law.md#the-state-estimator;
/// untouched while the scenario's estimator is off).
pub struct LocalController<'a> {
    controller: &'a Controller,
    trajectory: &'a Trajectory,
    memory: Estimate,
}

impl<'a> LocalController<'a> {
    pub fn new(scenario: &'a Scenario) -> Self {
        LocalController {
            controller: scenario.controller(),
            trajectory: scenario.trajectory(),
            memory: Estimate::new(),
        }
    }
}

impl ControlSource for LocalController<'_> {
    fn control(&mut self, k: u64, eta: &[f32; 6], nu: &[f32; 6]) -> Result<ControlOut, Stop> {
        // The simulated solution holds at the period it is measured in (stamp = k).
        let solution = Solution {
            stamp: k,
            eta: *eta,
            nu: *nu,
        };
        let out =
            self.controller
                .update_from_solution(&mut self.memory, k, &solution, self.trajectory);
        Ok(ControlOut {
            status: ControlStatus::Law(out.status),
            tau: out.tau,
            voltage: out.voltage,
            thrust: Some(out.thrust),
            saturated: out.saturated,
            delta: out.delta,
            delta_clamped: out.delta_clamped,
            w_norm: out.w_norm,
            eta_d: (out.status == Status::Ok).then_some(out.eta_d),
            board: None,
        })
    }

    fn runs_here(&self) -> bool {
        true
    }
}
