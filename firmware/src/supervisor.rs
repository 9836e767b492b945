//! The board's control supervisor: arming, missions, state-frame freshness, fail-safe, and one
//! control period around `Controller::update`. Hardware-free, so it is tested on the host.
//!
//! Fail-safe (all thrusters neutral, 0 V) whenever:
//! - the board is disarmed ([`BoardStatus::Disarmed`]);
//! - armed but no mission is running ([`BoardStatus::Armed`]);
//! - no valid state frame arrived for more than `stale_periods` control periods
//!   ([`DEFAULT_STALE_PERIODS`] unless configured);
//! - the controller reports a fault (non-finite/implausible input, pitch limit, …);
//! - the previous control period overran its deadline.
//!
//! The last three **latch**: the board stays in fail-safe until it is disarmed and re-armed,
//! and then resumes on the next valid state frame. A corrupt or unknown frame is counted and
//! dropped, never acted on.

use auv_link::{
    BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason, Msg, StateFrame, Telemetry,
    DEFAULT_STALE_PERIODS,
};
use controller_core::{Controller, ControllerConfig, Status, Trajectory, TrajectoryKind};

/// What one control period commands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Voltage per thruster (0 V = neutral duty in fail-safe).
    pub voltages: [f32; 5],
    pub telemetry: Telemetry,
}

/// Board state around the controller.
pub struct Supervisor {
    controller: Controller,
    mission: Option<(Trajectory, u64)>,
    armed: bool,
    latched: Option<FailSafeReason>,
    state: Option<StateFrame>,
    periods_since_state: u32,
    stale_periods: u8,
    lockstep: bool,
    tick: u64,
    seq_out: u16,
    rx_frames: u32,
    rx_errors: u32,
    rejected_commands: u32,
    loop_overruns: u32,
    worst_update_ticks: u32,
    last_state_seq: u16,
    state_fresh: bool,
}

impl Supervisor {
    pub fn new(controller: Controller) -> Self {
        Supervisor {
            controller,
            mission: None,
            armed: false,
            latched: None,
            state: None,
            periods_since_state: u32::MAX,
            stale_periods: DEFAULT_STALE_PERIODS,
            lockstep: false,
            tick: 0,
            seq_out: 0,
            rx_frames: 0,
            rx_errors: 0,
            rejected_commands: 0,
            loop_overruns: 0,
            worst_update_ticks: 0,
            last_state_seq: 0,
            state_fresh: false,
        }
    }

    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// Control-loop rate (Hz) of the current configuration.
    pub fn rate_hz(&self) -> u32 {
        self.controller.config().rate_hz
    }

    /// Lock-step mode (processor in the loop): one period per state frame, and the state
    /// frame's `t_ticks` is the mission time.
    pub fn lockstep(&self) -> bool {
        self.lockstep
    }

    /// True once a state frame arrived since the last period (lock-step pacing).
    pub fn state_fresh(&self) -> bool {
        self.state_fresh
    }

    pub fn rx_errors(&self) -> u32 {
        self.rx_errors
    }

    pub fn rejected_commands(&self) -> u32 {
        self.rejected_commands
    }

    /// A frame failed to decode (COBS, CRC, version, size): counted and dropped.
    pub fn on_rx_error(&mut self) {
        self.rx_errors = self.rx_errors.saturating_add(1);
    }

    /// Acts on one valid frame.
    pub fn on_envelope(&mut self, env: &Envelope) {
        self.rx_frames = self.rx_frames.saturating_add(1);
        match env.msg {
            Msg::State(s) => {
                self.state = Some(s);
                self.periods_since_state = 0;
                self.last_state_seq = env.seq;
                self.state_fresh = true;
            }
            Msg::Command(c) => self.on_command(&c),
            // A board never receives telemetry: unknown direction, dropped.
            Msg::Telemetry(_) => self.on_rx_error(),
        }
    }

    fn on_command(&mut self, c: &Command) {
        match c {
            Command::Arm => {
                self.armed = true;
                self.latched = None;
            }
            Command::Disarm => self.armed = false,
            // The link's one conversion (auv_link::mission), validated by the core.
            Command::StartMission(spec) => match Trajectory::new(TrajectoryKind::from(*spec)) {
                Ok(t) => self.mission = Some((t, self.tick)),
                Err(_) => self.rejected_commands = self.rejected_commands.saturating_add(1),
            },
            Command::StopMission => self.mission = None,
            Command::SetConfig(patch) => {
                if !self.apply(patch) {
                    self.rejected_commands = self.rejected_commands.saturating_add(1);
                }
            }
        }
    }

    /// Applies a configuration patch; only while disarmed, and only if the result validates.
    fn apply(&mut self, p: &ConfigPatch) -> bool {
        if let Some(n) = p.stale_periods {
            if n == 0 {
                return false;
            }
            self.stale_periods = n;
        }
        if let Some(l) = p.lockstep {
            self.lockstep = l;
        }
        let touches_law = p.rate_hz.is_some()
            || p.robust.is_some()
            || p.delta_max.is_some()
            || p.voltage_limit.is_some();
        if !touches_law {
            return true;
        }
        if self.armed {
            return false;
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
        match Controller::new(cfg) {
            Ok(c) => {
                self.controller = c;
                true
            }
            Err(_) => false,
        }
    }

    /// One control period. `overrun`: the previous period missed its deadline. `now` reads a
    /// free-running up-counting timer (any unit) to time `update`.
    pub fn step(&mut self, overrun: bool, now: &dyn Fn() -> u32) -> Step {
        self.state_fresh = false;
        if overrun {
            self.loop_overruns = self.loop_overruns.saturating_add(1);
        }
        let mut voltages = [0.0f32; 5];
        let mut thrusts = [0.0f32; 5];
        let mut tau = [0.0f32; 6];
        let (mut saturated, mut delta, mut delta_clamped, mut w_norm, mut fault) =
            (0u8, 0.0f32, false, 0.0f32, 0u8);
        let stale = self.periods_since_state > self.stale_periods as u32;
        let status = match (self.armed, self.latched, self.mission, self.state) {
            (false, _, _, _) => BoardStatus::Disarmed,
            (true, Some(r), _, _) => BoardStatus::FailSafe(r),
            (true, None, None, _) => BoardStatus::Armed,
            (true, None, Some(_), _) if overrun => self.latch(FailSafeReason::Overrun),
            (true, None, Some(_), None) => self.latch(FailSafeReason::StaleState),
            (true, None, Some(_), Some(_)) if stale => self.latch(FailSafeReason::StaleState),
            (true, None, Some((traj, start)), Some(s)) => {
                // Mission time: the board's own ticks since StartMission; in lock-step the
                // state frame's t_ticks, which the navigation computer counts from the
                // mission start (so PIL does not depend on host speed).
                let mission_ticks = if self.lockstep {
                    s.t_ticks
                } else {
                    self.tick.wrapping_sub(start)
                };
                let t0 = now();
                let out = self.controller.update(mission_ticks, &s.eta, &s.nu, &traj);
                let dt = now().wrapping_sub(t0);
                self.worst_update_ticks = self.worst_update_ticks.max(dt);
                match out.status {
                    Status::Ok => {
                        voltages = out.voltage;
                        thrusts = out.thrust;
                        tau = out.tau;
                        saturated = out.saturated;
                        delta = out.delta;
                        delta_clamped = out.delta_clamped;
                        w_norm = out.w_norm;
                        BoardStatus::Running
                    }
                    Status::Fault(f) => {
                        fault = f.code();
                        self.latch(FailSafeReason::ControllerFault)
                    }
                }
            }
        };
        let telemetry = Telemetry {
            tick: self.tick,
            status,
            voltages,
            thrusts,
            tau,
            saturated,
            delta,
            delta_clamped,
            w_norm,
            controller_fault: fault,
            loop_overruns: self.loop_overruns,
            worst_update_ticks: self.worst_update_ticks,
            rx_frames: self.rx_frames,
            rx_errors: self.rx_errors,
            last_state_seq: self.last_state_seq,
        };
        self.periods_since_state = self.periods_since_state.saturating_add(1);
        self.tick += 1;
        Step {
            voltages,
            telemetry,
        }
    }

    fn latch(&mut self, reason: FailSafeReason) -> BoardStatus {
        self.latched = Some(reason);
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
