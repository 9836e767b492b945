//! The board's control supervisor: arming, missions, state-frame freshness and order, the
//! fail-safe, refusals, and one control period around `Controller::update`. Hardware-free, so
//! it is tested on the host. Its state machine is the table in firmware/README.md ("State
//! machine"), which `tests/state_table.rs` parses and walks cell by cell.
//!
//! Fail-safe (all thrusters neutral, 0 V) whenever:
//! - the board is disarmed ([`BoardStatus::Disarmed`]);
//! - armed but no mission is running ([`BoardStatus::Armed`]);
//! - no valid, in-order state frame arrived for more than `stale_periods` control periods
//!   ([`DEFAULT_STALE_PERIODS`] unless configured);
//! - the controller reports a fault (non-finite/implausible input, pitch limit, …);
//! - the previous control period overran its deadline.
//!
//! The last three **latch**: the board stays in fail-safe until it is disarmed and then armed
//! (a lone `Arm` is refused), and then flies only after a new `StartMission` (disarming drops
//! the mission). The latched reason — and the controller's fault code if a fault latched it —
//! is in every telemetry frame until the re-arm.
//!
//! Frames: a corrupt, unknown-version, badly authenticated or wrong-direction frame is counted
//! (`rx_errors`; failed authentication also in `rx_auth_errors`, and an authentic frame stamped
//! too far ahead also in `rx_ahead`) and dropped. A frame whose sequence number is not newer
//! than the last accepted one ([`auv_link::seq`]) is counted (`rx_stale`) and dropped; in
//! lock-step so is a state frame off the mission clock ([`MissionClock`]). A dropped frame never
//! restarts the stale-state timer. Every refused command is counted and its reason reported
//! ([`Refusal`]); a refused command changes nothing.

use auv_link::seq::SeqCheck;
use auv_link::sign::AuthError;
use auv_link::{
    BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason, LinkError, MissionPlan,
    MissionSpec, Msg, Refusal, StateFrame, Telemetry, UploadBuffer, DEFAULT_STALE_PERIODS,
};
use controller_core::effectiveness::{ThrusterGeometry, THRUSTERS};
use controller_core::trajectory::TrajectoryError;
use controller_core::{
    Controller, ControllerConfig, Estimate, EstimatorKind, Solution, Status, Trajectory,
};

use crate::limits;

/// What one control period commands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Voltage per thruster (0 V = neutral duty in fail-safe).
    pub voltages: [f32; THRUSTERS],
    pub telemetry: Telemetry,
    /// The period ran its long job ([`Supervisor::built_this_period`]) and did not fly: if its
    /// boundary passed meanwhile, the overrun is this period's ([`crate::board::period`]).
    pub long_job: bool,
}

/// What the supervisor needs to know about its board.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardInfo {
    /// H-bridge supply voltage V_s (V): `voltage_limit` may not exceed it.
    pub supply_voltage: f32,
    /// The link refuses unsigned frames (reported in telemetry; the decoder enforces it).
    pub signing: bool,
}

/// The supervisor's state, the rows and columns of the state table (firmware/README.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Thrusters off; nothing latched.
    Disarmed,
    /// Thrusters off; a fail-safe reason is still reported, until `Arm`.
    DisarmedLatched,
    /// Armed, no mission: thrusters off.
    Armed,
    /// Armed with a mission: flies while its state frames are fresh.
    Running,
    /// Armed, fail-safe latched: thrusters off until disarm, then arm.
    FailSafe,
}

impl Mode {
    /// Every mode, in the table's column order.
    pub const ALL: [Mode; 5] = [
        Mode::Disarmed,
        Mode::DisarmedLatched,
        Mode::Armed,
        Mode::Running,
        Mode::FailSafe,
    ];

    /// The name the state table uses.
    pub const fn as_str(self) -> &'static str {
        match self {
            Mode::Disarmed => "disarmed",
            Mode::DisarmedLatched => "disarmed (latched)",
            Mode::Armed => "armed",
            Mode::Running => "running",
            Mode::FailSafe => "fail-safe",
        }
    }
}

/// The lock-step mission clock: the mission tick of the last accepted state frame, and the
/// control periods run since.
///
/// **Choice:** in lock-step (a simulation mode: `host-sim pil`) the navigation computer owns
/// mission time: each state frame's `t_ticks` is the mission tick it holds at, and the board
/// runs one period per state frame. The first state frame after `StartMission` sets the clock
/// (0 for a new mission; where the mission resumes after a re-arm). After it, a frame is on the
/// clock when its tick is above the last accepted one and at most the number of periods run
/// since then ahead of it. So the clock advances by exactly one tick per period while one frame
/// arrives per period; a frame lost on the link is a period the board ran without it (its wait
/// ends after one period), after which the next frame may be that many ticks ahead; and no
/// frame may run the clock backwards, stand it still or jump it ahead of the board's own
/// periods (before this, `t_ticks` could jump by 10¹⁵ or run backwards in flight). Off the
/// clock, a frame is counted (`rx_stale`) and dropped. In free-running mode the board counts
/// mission time itself (one tick per period since `StartMission`) and `t_ticks` is not used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MissionClock {
    last: Option<u64>,
    periods: u64,
}

impl MissionClock {
    /// A mission just started: no frame yet, no period run.
    pub const START: MissionClock = MissionClock {
        last: None,
        periods: 0,
    };

    /// True if a state frame at mission tick `t` is on the clock.
    pub const fn admits(&self, t: u64) -> bool {
        match self.last {
            None => true,
            Some(last) => t > last && t - last <= self.periods,
        }
    }

    fn accept(&mut self, t: u64) {
        self.last = Some(t);
        self.periods = 0;
    }

    fn period(&mut self) {
        self.periods = self.periods.saturating_add(1);
    }
}

/// A latched fail-safe: why, and the controller's fault code if a fault latched it (else 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Latch {
    reason: FailSafeReason,
    fault: u8,
}

/// What one period's control gave the thrusters and reports: the controller's output, or zeros
/// (0 V, 0 N) when it did not fly.
#[derive(Clone, Copy, Default)]
struct Control {
    voltages: [f32; THRUSTERS],
    thrusts: [f32; THRUSTERS],
    tau: [f32; 6],
    saturated: u8,
    delta: f32,
    delta_clamped: bool,
    w_norm: f32,
}

/// Board state around the controller.
pub struct Supervisor {
    controller: Controller,
    board: BoardInfo,
    /// The board tick the mission started at (`None`: no mission).
    mission: Option<u64>,
    /// The mission's trajectory, built in place by `StartMission` (`Trajectory::set`: a
    /// waypoint path's route and time law are 8.6 kB, never copied on the stack) and flown
    /// while `mission` is set.
    trajectory: Trajectory,
    /// The waypoint mission uploaded while disarmed (auv_link::upload): kept across disarming
    /// and fail-safes, dropped by the next upload's `Begin`.
    upload: UploadBuffer,
    /// The upload `trajectory` was last built from (its CRC) and how that went; `None` when it
    /// holds anything else (Choice 169), or the upload's data changed since (Choice 229).
    built: Option<(u32, Result<(), Refusal>)>,
    /// Trajectories built since boot (for tests and the self-test).
    builds: u32,
    /// A build ran in this period: the controller's (a `SetConfig` that changes the law) or a
    /// waypoint trajectory's (a verified upload, `StartMission` of one not built, or the idle
    /// rebuild). It is the period's **long job** (Choice 226): the board reads no further frame
    /// in the period ([`crate::board::pump`]), the step does not fly, and an overrun it causes
    /// is counted in this period rather than latching the next.
    long_job: bool,
    /// [`ConfigPatch::digest`] of the whole configuration flown ([`ConfigPatch::whole`]),
    /// reported in every telemetry frame (protocol 6, Choice 228).
    config_digest: u32,
    clock: MissionClock,
    armed: bool,
    latched: Option<Latch>,
    state: Option<StateFrame>,
    periods_since_state: u32,
    stale_periods: u8,
    lockstep: bool,
    rx_seq: SeqCheck,
    tick: u64,
    seq_out: u16,
    rx_frames: u32,
    rx_errors: u32,
    rx_stale: u32,
    rx_auth_errors: u32,
    rx_ahead: u32,
    refused_commands: u32,
    last_refusal: Option<Refusal>,
    loop_overruns: u32,
    worst_update_ticks: u32,
    last_state_seq: u16,
    state_fresh: bool,
    /// The controller's thruster mounting as the link's reversed-thruster mask, computed when
    /// the controller is set ([`mounting_of`]).
    mounting: u8,
    /// The state estimator's memory (docs/law.md#the-state-estimator): a new mission and a
    /// new configuration start it afresh; untouched while the estimator is off.
    memory: Estimate,
}

pub use auv_link::{mounting_of, NOT_AUV150};

/// The digest telemetry reports of the whole configuration `config`, `stale_periods`,
/// `lockstep` ([`ConfigPatch::digest`]; a whole patch always has one).
fn digest_of(config: &ControllerConfig, stale_periods: u8, lockstep: bool) -> u32 {
    ConfigPatch::whole(config, stale_periods, lockstep)
        .digest()
        .unwrap_or_default()
}

/// Bits of a valid reversed-thruster mask: one per thruster.
const MOUNTING_BITS: u8 = (1 << THRUSTERS) - 1;

/// Why the core refused a mission, as the board reports it: the time scale and the tangent
/// heading (protocol 3) have their own reasons, any other parameter is an invalid mission.
pub fn mission_refusal(e: &TrajectoryError) -> Refusal {
    match e {
        TrajectoryError::TooSlowForTangent { .. } | TrajectoryError::WaypointTooSlow { .. } => {
            Refusal::TangentTooSlow
        }
        e if e.parameter() == "time_scale" => Refusal::InvalidTimeScale,
        _ => Refusal::InvalidMission,
    }
}

impl Supervisor {
    pub fn new(controller: Controller, board: BoardInfo) -> Self {
        Supervisor {
            mounting: mounting_of(controller.config()),
            config_digest: digest_of(controller.config(), DEFAULT_STALE_PERIODS, false),
            long_job: false,
            controller,
            board,
            mission: None,
            trajectory: Trajectory::EMPTY,
            upload: UploadBuffer::EMPTY,
            built: None,
            builds: 0,
            clock: MissionClock::START,
            armed: false,
            latched: None,
            state: None,
            periods_since_state: u32::MAX,
            stale_periods: DEFAULT_STALE_PERIODS,
            lockstep: false,
            rx_seq: SeqCheck::new(),
            tick: 0,
            seq_out: 0,
            rx_frames: 0,
            rx_errors: 0,
            rx_stale: 0,
            rx_auth_errors: 0,
            rx_ahead: 0,
            refused_commands: 0,
            last_refusal: None,
            loop_overruns: 0,
            worst_update_ticks: 0,
            last_state_seq: 0,
            state_fresh: false,
            memory: Estimate::new(),
        }
    }

    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// Control-loop rate (Hz) of the current configuration.
    pub fn rate_hz(&self) -> u32 {
        self.controller.config().rate_hz
    }

    /// Control periods a state frame stays valid.
    pub fn stale_periods(&self) -> u8 {
        self.stale_periods
    }

    /// Lock-step mode (processor in the loop): one period per state frame, and the state
    /// frame's `t_ticks` is the mission time, on the [`MissionClock`].
    pub fn lockstep(&self) -> bool {
        self.lockstep
    }

    /// True once a state frame was accepted since the last period (lock-step pacing).
    pub fn state_fresh(&self) -> bool {
        self.state_fresh
    }

    /// The state-table mode the supervisor is in.
    pub fn mode(&self) -> Mode {
        match (self.armed, self.latched, &self.mission) {
            (false, None, _) => Mode::Disarmed,
            (false, Some(_), _) => Mode::DisarmedLatched,
            (true, Some(_), _) => Mode::FailSafe,
            (true, None, None) => Mode::Armed,
            (true, None, Some(_)) => Mode::Running,
        }
    }

    /// The latched fail-safe reason, until re-armed.
    pub fn latched(&self) -> Option<FailSafeReason> {
        self.latched.map(|l| l.reason)
    }

    pub fn rx_frames(&self) -> u32 {
        self.rx_frames
    }

    pub fn rx_errors(&self) -> u32 {
        self.rx_errors
    }

    pub fn rx_stale(&self) -> u32 {
        self.rx_stale
    }

    pub fn rx_auth_errors(&self) -> u32 {
        self.rx_auth_errors
    }

    /// Authentic frames refused for a timestamp too far ahead (`AuthError::Ahead`).
    pub fn rx_ahead(&self) -> u32 {
        self.rx_ahead
    }

    pub fn refused_commands(&self) -> u32 {
        self.refused_commands
    }

    pub fn last_refusal(&self) -> Option<Refusal> {
        self.last_refusal
    }

    /// The byte stream broke (a UART line error): counted, like a frame that failed to decode.
    pub fn on_rx_error(&mut self) {
        self.rx_errors = self.rx_errors.saturating_add(1);
    }

    /// A frame failed to decode or to authenticate: counted (authentication failures also in
    /// `rx_auth_errors`, a timestamp too far ahead also in `rx_ahead`) and dropped.
    pub fn on_link_error(&mut self, e: &LinkError) {
        self.on_rx_error();
        if let LinkError::Auth(a) = e {
            self.rx_auth_errors = self.rx_auth_errors.saturating_add(1);
            if *a == AuthError::Ahead {
                self.rx_ahead = self.rx_ahead.saturating_add(1);
            }
        }
    }

    /// Acts on one decoded frame: drops it unless it is newer than the last accepted one (and,
    /// for a lock-step state frame, on the mission clock).
    pub fn on_envelope(&mut self, env: &Envelope) {
        // A board never receives telemetry: wrong direction, a receive error.
        if let Msg::Telemetry(_) = env.msg {
            self.on_rx_error();
            return;
        }
        let on_clock = match env.msg {
            Msg::State(s) if self.lockstep && self.mission.is_some() => {
                self.clock.admits(s.t_ticks)
            }
            _ => true,
        };
        if !on_clock || !self.rx_seq.accept(env.seq) {
            self.rx_stale = self.rx_stale.saturating_add(1);
            return;
        }
        self.rx_frames = self.rx_frames.saturating_add(1);
        match env.msg {
            Msg::State(s) => {
                self.state = Some(s);
                self.periods_since_state = 0;
                self.last_state_seq = env.seq;
                self.state_fresh = true;
                if self.lockstep && self.mission.is_some() {
                    self.clock.accept(s.t_ticks);
                }
            }
            Msg::Command(c) => {
                if let Err(r) = self.on_command(&c) {
                    self.refused_commands = self.refused_commands.saturating_add(1);
                    self.last_refusal = Some(r);
                }
            }
            Msg::Telemetry(_) => {}
        }
    }

    fn on_command(&mut self, c: &Command) -> Result<(), Refusal> {
        match c {
            Command::Arm => self.arm(),
            Command::Disarm => {
                self.armed = false;
                self.mission = None;
                Ok(())
            }
            Command::StartMission(plan) => self.start_mission(plan),
            Command::StopMission => {
                self.mission = None;
                Ok(())
            }
            Command::SetConfig(patch) => self.configure(patch),
            // Refused while armed, like every setting: a mission is never changed under a
            // running loop (Choice 164).
            Command::Upload(_) if self.armed => Err(Refusal::WhileArmed),
            Command::Upload(part) => {
                // A part that changes the upload's data (a `Begin`, a chunk with other words)
                // leaves the slot standing for data the buffer no longer holds: the next build
                // validates what it then holds (Choice 229). Keyed by the CRC alone, an upload
                // with the built mission's CRC-32 was never validated and flew the old path.
                let revision = self.upload.revision();
                let taken = self.upload.take(part);
                if self.upload.revision() != revision {
                    self.built = None;
                }
                taken?;
                // Verified: built now, disarmed, so that `StartMission` costs it nothing (a
                // 32-point path is ~1 M instructions, more than a 200 Hz period).
                self.build_upload()
            }
        }
    }

    /// Arming from disarmed clears the latch; arming while armed changes nothing, and is
    /// refused if a fail-safe is latched (only disarm, then arm, clears it).
    fn arm(&mut self) -> Result<(), Refusal> {
        if self.armed {
            return match self.latched {
                Some(_) => Err(Refusal::Latched),
                None => Ok(()),
            };
        }
        self.armed = true;
        self.latched = None;
        Ok(())
    }

    /// Only armed, unlatched and without a mission; the mission must validate. The state
    /// checks come first (a running mission is reported as running, whatever the new one).
    fn start_mission(&mut self, plan: &MissionPlan) -> Result<(), Refusal> {
        if !self.armed {
            return Err(Refusal::NotArmed);
        }
        if self.latched.is_some() {
            return Err(Refusal::Latched);
        }
        if self.mission.is_some() {
            return Err(Refusal::MissionRunning);
        }
        // The link's one conversion (auv_link::mission; an uploaded path from the upload
        // buffer), validated by the core: path, heading and time scale.
        let mission = plan.resolve(&self.upload)?;
        let uploaded = match plan.path {
            MissionSpec::Waypoints { crc } => Some(crc),
            _ => None,
        };
        match (uploaded, self.built) {
            // Built when it was verified (or since): the slot holds exactly this mission (its
            // CRC covers the heading and time scale, and `resolve` checked the plan's).
            (Some(crc), Some((b, result))) if b == crc => result?,
            // No mission runs here, so the slot is free to build into (a refused mission
            // leaves it unflown). A waypoint path's build is the period's long job.
            _ => {
                self.built = None;
                self.builds = self.builds.wrapping_add(1);
                self.long_job |= uploaded.is_some();
                self.trajectory
                    .set(&mission)
                    .map_err(|e| mission_refusal(&e))?;
                self.built = uploaded.map(|crc| (crc, Ok(())));
            }
        }
        self.mission = Some(self.tick);
        self.clock = MissionClock::START;
        self.memory = Estimate::new();
        // A state frame from before the mission is not its state, in either pacing (Choice 227:
        // "a new mission counts from its start"): the mission waits for its first with the
        // `stale_periods` grace. Kept, an old frame made a free-running mission latch stale
        // state in its first period; in lock-step it is also off the mission clock.
        self.state = None;
        Ok(())
    }

    /// Builds the verified upload into the trajectory slot unless it holds it already
    /// (Choice 169); the core's refusal of it is kept, and returned now and by `StartMission`.
    /// Called only while no mission runs; the build (up to ~1 M instructions) is the period's
    /// long job (Choice 226).
    fn build_upload(&mut self) -> Result<(), Refusal> {
        let Some(crc) = self.upload.verified() else {
            return Ok(());
        };
        if let Some((b, result)) = self.built {
            if b == crc {
                return result;
            }
        }
        let result = match self.upload.mission(crc) {
            Ok(m) => {
                self.builds = self.builds.wrapping_add(1);
                self.long_job = true;
                self.trajectory.set(&m).map_err(|e| mission_refusal(&e))
            }
            Err(r) => Err(r),
        };
        self.built = Some((crc, result));
        result
    }

    /// Trajectories built since boot (`StartMission`s that built one, and verified uploads).
    pub fn trajectory_builds(&self) -> u32 {
        self.builds
    }

    /// The period's long job ran (Choice 226): a controller rebuild or a waypoint trajectory's
    /// build since the last [`step`](Self::step). The board then reads no further frame in the
    /// period, and the step does not fly.
    pub fn built_this_period(&self) -> bool {
        self.long_job
    }

    /// The boundary of a period that ran its long job passed during it ([`Step::long_job`]):
    /// the overrun is counted here, in the period that did the work, which did not fly; it
    /// latches nothing (Choice 226).
    pub fn long_job_overran(&mut self) {
        self.loop_overruns = self.loop_overruns.saturating_add(1);
    }

    /// [`ConfigPatch::digest`] of the whole configuration the board flies, as telemetry
    /// reports it.
    pub fn config_digest(&self) -> u32 {
        self.config_digest
    }

    /// Validates the whole patch against the board's limits and the core, then applies all of
    /// it, or nothing. Refused while armed, whatever it holds.
    ///
    /// The thruster chain (protocol 3, docs/link.md#what-crosses-the-link): the thrust unit of Eqs 31–32, the
    /// mounting as the AUV-150's reversed-thruster mask (a bit above the fifth is refused,
    /// [`Refusal::InvalidMounting`]) and the allocator's axis priority (a weight the core
    /// refuses is [`Refusal::InvalidPriority`]). Each changes the controller's configuration,
    /// so the core revalidates all of it (the envelope and the allocator's blocks are rebuilt
    /// by `Controller::rebuild`, which keeps the suprema over the parameter box computed
    /// at boot: Choice 225) before anything is applied. A rebuild is the period's long job
    /// (Choice 226). The law's settings (protocol 8, Choice 508: K₁, K₂, Q, β, μ, the robust
    /// law, the ‖b‖ bound, the pitch limit) go through the same rebuild: whatever the core
    /// refuses (β below β̂, Theorem 2, the loop-rate rule, a gain that is not finite and > 0)
    /// is [`Refusal::ControllerConfig`], and nothing changes.
    fn configure(&mut self, p: &ConfigPatch) -> Result<(), Refusal> {
        if self.armed {
            return Err(Refusal::WhileArmed);
        }
        let mut cfg: ControllerConfig = *self.controller.config();
        if let Some(r) = p.rate_hz {
            cfg.rate_hz = r;
        }
        if let Some(r) = p.robust {
            cfg.robust = r;
        }
        if let Some(d) = p.delta_max {
            cfg.delta_max = d;
        }
        if let Some(v) = p.voltage_limit {
            cfg.voltage_limit = v;
        }
        if let Some(u) = p.thrust_unit {
            cfg.thrust_unit = u.into();
        }
        if let Some(m) = p.reversed_thrusters {
            if m & !MOUNTING_BITS != 0 {
                return Err(Refusal::InvalidMounting);
            }
            cfg.geometry = ThrusterGeometry::auv150(m);
        }
        if let Some(q) = p.priority {
            cfg.priority = q.into();
        }
        if let Some(e) = p.estimator {
            cfg.estimator = e.into();
        }
        // Protocol 8 (Choice 508): the law's settings, validated below by the core's own
        // checks in the rebuild (Assumption 2, Theorem 2, the loop-rate rule).
        if let Some(law) = p.law {
            law.apply(&mut cfg);
        }
        let stale_periods = p.stale_periods.unwrap_or(self.stale_periods);
        let lockstep = p.lockstep.unwrap_or(self.lockstep);

        // The board's limits first, then the core's validation (only if the law changes; the
        // bounds over the box are reused, Choice 225).
        if cfg.rate_hz > limits::MAX_RATE_HZ {
            return Err(Refusal::RateTooHigh);
        }
        // `>` lets NaN through to the core, which refuses it as non-finite.
        if cfg.voltage_limit > self.board.supply_voltage {
            return Err(Refusal::VoltageAboveSupply);
        }
        if !limits::stale_limit_ok(stale_periods, cfg.rate_hz) {
            return Err(Refusal::StaleLimit);
        }
        let controller = if cfg == *self.controller.config() {
            None
        } else {
            Some(self.controller.rebuild(cfg).map_err(|e| match e.field() {
                Some(f) if f.name == "priority" => Refusal::InvalidPriority,
                _ => Refusal::ControllerConfig,
            })?)
        };

        // Everything validated: apply all of it.
        if let Some(c) = controller {
            self.mounting = mounting_of(c.config());
            self.controller = c;
            self.memory = Estimate::new();
            self.long_job = true;
        }
        self.stale_periods = stale_periods;
        self.lockstep = lockstep;
        self.config_digest = digest_of(self.controller.config(), stale_periods, lockstep);
        Ok(())
    }

    /// One control period. `overrun`: the previous period missed its deadline. `now` reads a
    /// free-running up-counting timer (any unit) to time `update`.
    pub fn step(&mut self, overrun: bool, now: &dyn Fn() -> u32) -> Step {
        self.state_fresh = false;
        if self.mission.is_none() && !self.long_job {
            // A closed-form mission flown since the upload was built took its slot: rebuilt
            // here, with no mission running, so that starting the upload again is free; the
            // period's long job, unless it had one already (then the next period's).
            let _ = self.build_upload();
        }
        if overrun {
            self.loop_overruns = self.loop_overruns.saturating_add(1);
        }
        let (status, control) = self.control(overrun, now);
        let telemetry = self.telemetry(status, &control);
        self.periods_since_state = self.periods_since_state.saturating_add(1);
        self.clock.period();
        self.tick += 1;
        Step {
            voltages: control.voltages,
            telemetry,
            long_job: core::mem::take(&mut self.long_job),
        }
    }

    /// This period's status, and the controller's output if it flew (zeros otherwise: the
    /// thrusters off).
    fn control(&mut self, overrun: bool, now: &dyn Fn() -> u32) -> (BoardStatus, Control) {
        let off = Control::default();
        let stale = self.periods_since_state > u32::from(self.stale_periods);
        // The mission's start tick only: the trajectory (8.6 kB with a waypoint path's route and
        // time law, docs/missions.md#built-in-place) is borrowed in `fly`, not copied every period.
        let mission = self.mission.map(|start| ((), start));
        match (self.armed, self.latched, mission, self.state) {
            (false, _, _, _) => (BoardStatus::Disarmed, off),
            (true, Some(l), _, _) => (BoardStatus::FailSafe(l.reason), off),
            (true, None, None, _) => (BoardStatus::Armed, off),
            (true, None, Some(_), _) if overrun => (self.latch(FailSafeReason::Overrun, 0), off),
            // The period's long job ran (a mission can only have started after it): its output
            // would be late, so the mission flies from the next period (Choice 226).
            (true, None, Some(_), _) if self.long_job => (BoardStatus::Running, off),
            // A mission still waiting for its first state frame: StartMission and that frame
            // may straddle a period edge, so the mission gets the same `stale_periods` grace
            // as a state that stops arriving (thrusters off meanwhile), then latches.
            (true, None, Some((_, start)), None) => {
                if self.tick.wrapping_sub(start) > u64::from(self.stale_periods) {
                    (self.latch(FailSafeReason::StaleState, 0), off)
                } else {
                    (BoardStatus::Running, off)
                }
            }
            (true, None, Some(_), Some(_)) if stale => {
                (self.latch(FailSafeReason::StaleState, 0), off)
            }
            (true, None, Some(((), start)), Some(s)) => self.fly(start, &s, now),
        }
    }

    /// `update` on the latest state frame (through the state estimator when it is on), timed;
    /// a fault latches the fail-safe.
    ///
    /// **Choice 362:** the solution's stamp and the period's tick. Mission time is the board's
    /// own ticks since `StartMission`, or in lock-step the state frame's `t_ticks` (so PIL
    /// does not depend on host speed). The solution holds at the period its frame was taken
    /// in: in lock-step its `t_ticks`, free-running the board's tick of that period (the
    /// board does not mix the navigation computer's clock with its own). A period without a
    /// fresh frame (`stale_periods` allows a few) flies the last one `age` periods old: the
    /// estimator predicts it forward over those periods with the thrust it applied; with the
    /// estimator off the law is given the frame as it was (in lock-step at its own tick, as
    /// before the estimator).
    fn fly(&mut self, start: u64, s: &StateFrame, now: &dyn Fn() -> u32) -> (BoardStatus, Control) {
        let traj = &self.trajectory;
        let age = u64::from(self.periods_since_state);
        let estimating = self.controller.config().estimator.kind != EstimatorKind::Off;
        let (ticks, stamp) = if self.lockstep {
            let ahead = if estimating { age } else { 0 };
            (s.t_ticks.saturating_add(ahead), s.t_ticks)
        } else {
            let ticks = self.tick.wrapping_sub(start);
            (ticks, ticks.saturating_sub(age))
        };
        let solution = Solution {
            stamp,
            eta: s.eta,
            nu: s.nu,
        };
        let t0 = now();
        let out = self
            .controller
            .update_from_solution(&mut self.memory, ticks, &solution, traj);
        let dt = now().wrapping_sub(t0);
        self.worst_update_ticks = self.worst_update_ticks.max(dt);
        match out.status {
            Status::Ok => (
                BoardStatus::Running,
                Control {
                    voltages: out.voltage,
                    thrusts: out.thrust,
                    tau: out.tau,
                    saturated: out.saturated,
                    delta: out.delta,
                    delta_clamped: out.delta_clamped,
                    w_norm: out.w_norm,
                },
            ),
            Status::Fault(f) => (
                self.latch(FailSafeReason::ControllerFault, f.code()),
                Control::default(),
            ),
        }
    }

    /// The period's telemetry: its status and control, and the board's counters.
    fn telemetry(&self, status: BoardStatus, c: &Control) -> Telemetry {
        Telemetry {
            tick: self.tick,
            status,
            voltages: c.voltages,
            thrusts: c.thrusts,
            tau: c.tau,
            saturated: c.saturated,
            delta: c.delta,
            delta_clamped: c.delta_clamped,
            w_norm: c.w_norm,
            controller_fault: self.latched.map_or(0, |l| l.fault),
            loop_overruns: self.loop_overruns,
            worst_update_ticks: self.worst_update_ticks,
            rx_frames: self.rx_frames,
            rx_errors: self.rx_errors,
            last_state_seq: self.last_state_seq,
            latched: self.latched(),
            refused_commands: self.refused_commands,
            last_refusal: self.last_refusal,
            rx_stale: self.rx_stale,
            rx_auth_errors: self.rx_auth_errors,
            last_rx_seq: self.rx_seq.last().unwrap_or(0),
            signing: self.board.signing,
            thrust_unit: self.controller.config().thrust_unit.into(),
            reversed_thrusters: self.mounting,
            rx_ahead: self.rx_ahead,
            upload: self.upload.status(),
            config_digest: self.config_digest,
        }
    }

    fn latch(&mut self, reason: FailSafeReason, fault: u8) -> BoardStatus {
        self.latched = Some(Latch { reason, fault });
        BoardStatus::FailSafe(reason)
    }

    /// Wraps telemetry in an envelope with the next sequence number.
    pub fn envelope(&mut self, telemetry: Telemetry) -> Envelope {
        let seq = self.seq_out;
        self.seq_out = self.seq_out.wrapping_add(1);
        Envelope {
            version: auv_link::PROTOCOL_VERSION,
            seq,
            msg: Msg::Telemetry(telemetry),
        }
    }
}
