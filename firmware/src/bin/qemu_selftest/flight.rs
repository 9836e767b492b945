//! The board's long jobs at the flight clock (issue 29, items 14 and 15; Choices 225–226): what
//! a `SetConfig` costs field by field, and the loop itself — `board::period`, as the flying
//! images run it — on a board whose period is the STM32F405's at 168 MHz.
//!
//! Under `-icount shift=0` an instruction is a nanosecond and SysTick counts one per 40
//! (`firmware::qemu_clock`), so a SysTick period of `FLIGHT_CLOCK_HZ / rate / 40` counts holds as
//! many instructions as the flight board's core has cycles in its period, at one instruction a
//! cycle: the flight image's instruction rate. CMSDK TIMER0 (25 MHz, 40 instructions a count too)
//! times each period's work, from the end of its wait to its watchdog feed, and the time between
//! two feeds. Frames go in signed, as the flight image takes them. Each scenario is one of the
//! issue's: a law-changing `SetConfig` sent with `Arm`, `StartMission` and a state (26 M
//! instructions before Choice 225, which latched the overrun and tripped the STM32's watchdog); the
//! largest upload's last chunk after a full receive queue of small signed frames (the costliest
//! period the link can make); `StopMission` + `StartMission` of an upload the slot does not hold;
//! and the idle rebuild followed by `StartMission`. Each must never latch, fly on, keep every
//! period's work within its budget (`budget::WorkBudget`), and feed the watchdog within its
//! shortest timeout (`firmware::watchdog`).

use core::ptr::{read_volatile, write_volatile};

use auv_link::sign::{Direction, LinkKey, Signer};
use auv_link::{
    encode, encode_signed, AxisPriority, BoardStatus, Command, ConfigPatch, Envelope, Heading,
    LawSettings, MissionPlan, MissionSpec, MissionUpload, Msg, StateFrame, ThrustUnit, UploadPart,
    MAX_FRAME,
};
use controller_core::effectiveness::THRUSTERS;
use controller_core::trajectory::{SpeedList, WaypointList, MAX_PARTS, MAX_WAYPOINTS};
use controller_core::TrajectoryKind;
use controller_core::{Controller, ControllerConfig, HeadingMode, Mission, Trajectory};
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use defmt::{error, info};
use firmware::board::{self, Board, LinkBuffers};
use firmware::budget::WorkBudget;
use firmware::pwm::MemPwm;
use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;
use firmware::serial::RX_CAPACITY;
use firmware::supervisor::{BoardInfo, Supervisor};
use firmware::watchdog::{flight_us, shortest_timeout_us, FLIGHT_CLOCK_HZ};

use crate::counter::{elapsed, start_counter};

/// The vehicle's state on a mission at a tick (the self-test's: on the reference).
pub type StateOf = fn(&Trajectory, u64) -> StateFrame;

/// The self-test's circle: its plan on the link, its trajectory, and the state on it at a tick.
pub struct Circle<'a> {
    pub plan: MissionPlan,
    pub trajectory: &'a Trajectory,
    pub state: StateOf,
}

/// CMSDK APB TIMER0 of mps2-an386: a 32-bit down-counter at the 25 MHz peripheral clock.
const TIMER0: usize = 0x4000_0000;
const TIMER_CTRL: usize = 0x0;
const TIMER_VALUE: usize = 0x4;
const TIMER_RELOAD: usize = 0x8;

/// Starts TIMER0 free-running from 2³² − 1.
fn start_timer() {
    // SAFETY: TIMER0's registers; nothing else in the self-test uses the timer.
    unsafe {
        write_volatile((TIMER0 + TIMER_CTRL) as *mut u32, 0);
        write_volatile((TIMER0 + TIMER_RELOAD) as *mut u32, u32::MAX);
        write_volatile((TIMER0 + TIMER_VALUE) as *mut u32, u32::MAX);
        write_volatile((TIMER0 + TIMER_CTRL) as *mut u32, 1);
    }
}

/// Instructions since [`start_timer`] (40 a count).
fn now() -> u64 {
    // SAFETY: reads TIMER0's counter.
    let v = unsafe { read_volatile((TIMER0 + TIMER_VALUE) as *const u32) };
    u64::from(u32::MAX - v) * u64::from(INSTRUCTIONS_PER_TICK)
}

/// The self-test's link key (not a secret).
const KEY: [u8; 32] = [0x5E; 32];

/// The link's bytes as the navigation computer sent them, at most what the boards' receive
/// queue holds (`serial::RX_CAPACITY`): the board reads what is there.
struct Script {
    buf: [u8; RX_CAPACITY],
    len: usize,
    at: usize,
}

impl embedded_io::ErrorType for Script {
    type Error = core::convert::Infallible;
}

impl embedded_io::Read for Script {
    fn read(&mut self, out: &mut [u8]) -> Result<usize, Self::Error> {
        let n = out.len().min(self.len - self.at);
        out[..n].copy_from_slice(&self.buf[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

impl embedded_io::ReadReady for Script {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        Ok(self.at < self.len)
    }
}

impl embedded_io::Write for Script {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        Ok(buf.len())
    }
    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// The thruster board at the flight clock: SysTick periods of the STM32's length, RAM PWM, the
/// scripted link, and a watchdog that records how long it went unfed.
struct FlightBoard<'a> {
    syst: &'a mut SYST,
    thrusters: [MemPwm; THRUSTERS],
    link: Script,
    rate: u32,
    /// When the period's wait ended, and when the watchdog was last fed.
    work_start: u64,
    fed: u64,
    /// The longest period's work, and the longest time between feeds over the shortest timeout
    /// allowed then (µs): (gap, timeout, rate).
    longest_work: u64,
    longest_gap: (u64, u64, u32),
    unfed_too_long: bool,
}

impl<'a> FlightBoard<'a> {
    /// Not yet started: `set_rate` starts its periods.
    fn new(syst: &'a mut SYST) -> Self {
        FlightBoard {
            syst,
            thrusters: [MemPwm::neutral(1000); THRUSTERS],
            link: Script {
                buf: [0; RX_CAPACITY],
                len: 0,
                at: 0,
            },
            rate: 0,
            work_start: now(),
            fed: now(),
            longest_work: 0,
            longest_gap: (0, 0, 0),
            unfed_too_long: false,
        }
    }

    fn feed(&mut self) {
        let t = now();
        let gap = t - self.fed;
        let (gap_us, timeout_us) = (flight_us(gap), shortest_timeout_us(self.rate));
        if gap > self.longest_gap.0 {
            self.longest_gap = (gap, timeout_us, self.rate);
        }
        self.unfed_too_long |= gap_us >= timeout_us;
        self.fed = t;
    }
}

impl Board for FlightBoard<'_> {
    type Thruster = MemPwm;
    type Link = Script;

    fn supply_voltage(&self) -> f32 {
        firmware::mps2_an386::SUPPLY_VOLTAGE
    }
    fn thrusters(&mut self) -> &mut [MemPwm; THRUSTERS] {
        &mut self.thrusters
    }
    fn link(&mut self) -> &mut Script {
        &mut self.link
    }
    /// The STM32's period, and (as its `set_rate` reprograms the IWDG) a feed.
    fn set_rate(&mut self, hz: u32) {
        self.rate = hz;
        let ticks = FLIGHT_CLOCK_HZ / hz.max(1) / INSTRUCTIONS_PER_TICK;
        self.syst.disable_counter();
        self.syst.set_clock_source(SystClkSource::Core);
        self.syst.set_reload(ticks.clamp(2, 1 << 24) - 1);
        self.syst.clear_current();
        self.syst.enable_counter();
        self.feed();
    }
    fn period_elapsed(&mut self) -> bool {
        self.syst.has_wrapped()
    }
    /// Polls the flag every `WAIT_POLL_CYCLES`, as the QEMU board does (each read of a device
    /// register leaves QEMU's translated code).
    fn wait_period(&mut self) -> bool {
        let overrun = self.period_elapsed();
        if !overrun {
            while !self.period_elapsed() {
                cortex_m::asm::delay(firmware::mps2_an386::WAIT_POLL_CYCLES);
            }
        }
        self.work_start = now();
        overrun
    }
    fn now(&self) -> u32 {
        0
    }
    fn feed_watchdog(&mut self) {
        self.longest_work = self.longest_work.max(now() - self.work_start);
        self.feed();
    }
}

/// The navigation computer's end: numbers and signs its frames and puts them on the link.
struct Nav {
    signer: Signer,
    seq: u16,
}

impl Nav {
    fn send(&mut self, board: &mut FlightBoard, msgs: &[Msg]) -> bool {
        let s = &mut board.link;
        if s.at == s.len {
            (s.at, s.len) = (0, 0);
        }
        for &m in msgs {
            self.seq = self.seq.wrapping_add(1);
            let mut frame = [0u8; MAX_FRAME];
            let Ok(n) = encode_signed(&Envelope::new(self.seq, m), &mut self.signer, &mut frame)
            else {
                return false;
            };
            if s.len + n > s.buf.len() {
                return false;
            }
            s.buf[s.len..s.len + n].copy_from_slice(&frame[..n]);
            s.len += n;
        }
        true
    }
}

/// The board, its link and its navigation computer, flying the self-test's circle (each
/// borrowed: a supervisor is ~10 kB, moved into a struct it would be on the stack twice).
struct Rig<'a, 'b> {
    board: &'a mut FlightBoard<'b>,
    sup: &'a mut Supervisor,
    link: &'a mut LinkBuffers,
    nav: Nav,
    circle: &'a Trajectory,
    state: StateOf,
    /// Mission tick of the next state frame.
    k: u64,
}

/// What one scenario did.
#[derive(Default)]
struct Outcome {
    periods: u32,
    latched: bool,
    flew_last: bool,
    overruns: u32,
}

impl Rig<'_, '_> {
    /// The navigation computer sends `msgs`, back to back; false if they did not fit.
    fn send(&mut self, msgs: &[Msg]) -> bool {
        self.nav.send(self.board, msgs)
    }

    /// One period of the loop as `rt::fly` runs it (the rate followed when a `SetConfig`
    /// changed it); true if it flew.
    fn period(&mut self, out: &mut Outcome) -> bool {
        let step = board::period(self.board, self.sup, self.link);
        if self.sup.rate_hz() != self.board.rate {
            let hz = self.sup.rate_hz();
            self.board.set_rate(hz);
        }
        out.periods += 1;
        // A fail-safe entered while armed (a latch from before, reported while disarmed until
        // the next Arm, is not this scenario's).
        out.latched |= matches!(step.telemetry.status, BoardStatus::FailSafe(_));
        out.overruns = step.telemetry.loop_overruns;
        step.voltages.iter().any(|v| *v != 0.0)
    }

    /// `burst`, then `n` periods with a state frame each; the outcome (whether the last
    /// `n − 1` periods all flew).
    fn burst_then_fly(&mut self, burst: &[Msg], n: u32) -> Outcome {
        let mut out = Outcome::default();
        let mut ok = self.send(burst);
        self.period(&mut out);
        let mut flew = true;
        for i in 0..n {
            let s = Msg::State((self.state)(self.circle, self.k));
            self.k += 1;
            ok &= self.send(&[s]);
            let on = self.period(&mut out);
            flew &= on || i == 0;
        }
        out.flew_last = flew && ok;
        out
    }
}

/// The largest waypoint mission the board takes: 32 points (a lawn-mower of 16 rows of 60 m,
/// 20 m apart), a time law of 61 parts, tangent heading.
pub fn largest_waypoints() -> Option<Mission> {
    let mut points = [[0.0f32; 3]; MAX_WAYPOINTS];
    for (i, p) in points.iter_mut().enumerate() {
        let row = (i / 2) as f32;
        let east = (i % 2 == 0) == ((i / 2) % 2 == 0);
        *p = [if east { 0.0 } else { 60.0 }, 20.0 * row, 5.0];
    }
    let mut speeds = [0.5f32; MAX_PARTS];
    for (i, v) in speeds.iter_mut().enumerate() {
        if i % 4 == 0 {
            *v = 0.8;
        }
    }
    Some(Mission {
        path: TrajectoryKind::Waypoints {
            points: WaypointList::new(&points).ok()?,
            speed: 0.5,
            turn_radius: Some(3.0),
            speeds: Some(SpeedList::new(&speeds).ok()?),
            speed_change: None,
        },
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    })
}

fn board_info() -> BoardInfo {
    BoardInfo {
        supply_voltage: firmware::mps2_an386::SUPPLY_VOLTAGE,
        signing: true,
    }
}

/// A priority other than the default (a rebuild).
fn other_priority() -> AxisPriority {
    let mut p = AxisPriority::from(controller_core::allocation::AxisPriority::default());
    p.weight[0] = 2.0;
    p
}

/// Instructions the board spends on one unsigned `SetConfig` frame (decode, validation, the
/// rebuild if the law changes, the digest).
fn set_config_cost(
    sup: &mut Supervisor,
    link: &mut LinkBuffers,
    seq: &mut u16,
    p: ConfigPatch,
) -> u32 {
    *seq = seq.wrapping_add(1);
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(
        &Envelope::new(*seq, Msg::Command(Command::SetConfig(p))),
        &mut buf,
    )
    .unwrap_or(0);
    let t0 = SYST::get_current();
    board::receive(sup, link, &buf[..n]);
    let t1 = SYST::get_current();
    elapsed(t0, t1) * INSTRUCTIONS_PER_TICK
}

/// One field changed from nothing (the rest `None`).
fn one(set: fn(&mut ConfigPatch)) -> ConfigPatch {
    let mut p = ConfigPatch::EMPTY;
    set(&mut p);
    p
}

/// Law settings other than the defaults (a rebuild): μ = 0.15 and changed K₁, K₂ (protocol
/// 8, Choice 508).
fn other_law() -> LawSettings {
    let mut law = LawSettings::of(&ControllerConfig::default());
    law.mu = 0.15;
    law.k1[0] = 5.0;
    law.k2[5] = 3.0;
    law
}

/// Each field the link sets, changed alone from the defaults, and the whole patch host-sim's
/// set-up sends (with the rate, unit, mounting, priority and law changed).
fn field_patches(defaults: ConfigPatch) -> [(&'static str, ConfigPatch); 11] {
    [
        ("rate_hz", one(|p| p.rate_hz = Some(200))),
        ("robust", one(|p| p.robust = Some(false))),
        ("delta_max", one(|p| p.delta_max = Some(12.5))),
        ("voltage_limit", one(|p| p.voltage_limit = Some(20.0))),
        (
            "thrust_unit",
            one(|p| p.thrust_unit = Some(ThrustUnit::Newton)),
        ),
        ("mounting", one(|p| p.reversed_thrusters = Some(0))),
        ("priority", one(|p| p.priority = Some(other_priority()))),
        ("stale_periods", one(|p| p.stale_periods = Some(3))),
        ("lockstep", one(|p| p.lockstep = Some(true))),
        ("law", one(|p| p.law = Some(other_law()))),
        (
            "whole",
            ConfigPatch {
                rate_hz: Some(200),
                thrust_unit: Some(ThrustUnit::Newton),
                reversed_thrusters: Some(0),
                priority: Some(other_priority()),
                law: Some(other_law()),
                ..defaults
            },
        ),
    ]
}

/// What a `SetConfig` costs the board, field by field from the defaults (each a rebuild but
/// the stale limit and the pacing), and what `Controller::reconfigure` alone costs. Returns the
/// largest, or `None` if a patch was refused.
#[inline(never)]
fn config_costs(syst: &mut SYST) -> Option<u32> {
    start_counter(syst);
    let cfg = ControllerConfig::default();
    let controller = Controller::new(cfg).ok()?;
    let faster = ControllerConfig {
        rate_hz: 200,
        ..cfg
    };
    let t0 = SYST::get_current();
    let rebuilt = controller.reconfigure(faster);
    let t1 = SYST::get_current();
    info!(
        "Controller::reconfigure to 200 Hz, the bounds over the box kept from boot (Choice 225): {} instructions",
        elapsed(t0, t1) * INSTRUCTIONS_PER_TICK
    );
    rebuilt.ok()?;
    let mut sup = Supervisor::new(controller, board_info());
    let mut link = LinkBuffers::new();
    let mut seq = 0u16;
    let defaults = ConfigPatch::whole(&cfg, auv_link::DEFAULT_STALE_PERIODS, false);
    let fields = field_patches(defaults);
    let mut costs = [0u32; 11];
    for ((_, p), cost) in fields.iter().zip(costs.iter_mut()) {
        *cost = set_config_cost(&mut sup, &mut link, &mut seq, *p);
        sup.step(false, &|| 0);
        // Back to the defaults, uncounted.
        set_config_cost(&mut sup, &mut link, &mut seq, defaults);
        sup.step(false, &|| 0);
    }
    info!(
        "SetConfig instructions by field, from the defaults ({=[?]}): {=[?]}",
        fields.map(|(name, _)| name),
        costs
    );
    let refused = sup.refused_commands();
    if refused != 0 {
        error!("{} of the SetConfig patches were refused", refused);
        return None;
    }
    costs.iter().copied().max()
}

fn cmd(c: Command) -> Msg {
    Msg::Command(c)
}

/// The missions the scenarios fly: the paper's circle, and the largest upload by its CRC.
struct Plans {
    circle: MissionPlan,
    upload: MissionPlan,
}

impl Plans {
    fn new(circle: MissionPlan, up: &MissionUpload) -> Plans {
        Plans {
            circle,
            upload: MissionPlan {
                path: MissionSpec::Waypoints { crc: up.crc() },
                heading: Heading::Tangent,
                time_scale: 1.0,
            },
        }
    }

    /// Disarm, arm, start the circle: each scenario starts from an unlatched board (a latch of
    /// the one before, on a board without Choice 226, would otherwise carry over).
    fn restart(&self) -> [Msg; 3] {
        [
            cmd(Command::Disarm),
            cmd(Command::Arm),
            cmd(Command::StartMission(self.circle)),
        ]
    }
}

/// Scenario 1, at 100 Hz: a law-changing `SetConfig` with `Arm`, `StartMission` and a state (not
/// the rate: a new rate restarts the period timer, which hid the overrun before Choice 226).
fn config_burst(rig: &mut Rig, plans: &Plans) -> Outcome {
    let law = ConfigPatch {
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(0),
        priority: Some(other_priority()),
        ..ConfigPatch::EMPTY
    };
    let first = Msg::State((rig.state)(rig.circle, 0));
    rig.k = 1;
    rig.burst_then_fly(
        &[
            cmd(Command::SetConfig(law)),
            cmd(Command::Arm),
            cmd(Command::StartMission(plans.circle)),
            first,
        ],
        20,
    )
}

/// Scenario 2, disarmed, to 200 Hz: the largest upload, its last chunk after a receive queue full
/// of small signed frames (the costliest period the link can make); then the circle, which takes
/// the trajectory's slot.
fn upload_after_a_full_queue(rig: &mut Rig, up: &MissionUpload, plans: &Plans) -> Outcome {
    let mut out = Outcome::default();
    let faster = one(|p| p.rate_hz = Some(200));
    let mut ok = rig.send(&[cmd(Command::Disarm), cmd(Command::SetConfig(faster))]);
    rig.period(&mut out);
    ok &= rig.sup.rate_hz() == 200;
    ok &= rig.send(&[cmd(Command::Upload(UploadPart::Begin(up.header())))]);
    let last = up.chunks() - 1;
    for i in 0..last {
        ok &= rig.send(&[cmd(Command::Upload(UploadPart::Chunk(up.chunk(i))))]);
        rig.period(&mut out);
    }
    while rig.board.link.len + MAX_FRAME + 32 <= RX_CAPACITY {
        ok &= rig.send(&[cmd(Command::Disarm)]);
    }
    ok &= rig.send(&[cmd(Command::Upload(UploadPart::Chunk(up.chunk(last))))]);
    let builds = rig.sup.trajectory_builds();
    rig.period(&mut out);
    ok &= rig.sup.trajectory_builds() == builds + 1;
    rig.k = 0;
    let mut o = rig.burst_then_fly(
        &[cmd(Command::Arm), cmd(Command::StartMission(plans.circle))],
        10,
    );
    o.flew_last &= ok;
    o
}

/// Scenario 3: `StopMission` + `StartMission` of the upload, which the slot does not hold (the
/// circle took it): built in that period.
fn start_upload_to_build(rig: &mut Rig, plans: &Plans) -> Outcome {
    rig.k = 0;
    rig.burst_then_fly(&plans.restart(), 3);
    rig.k = 0;
    rig.burst_then_fly(
        &[
            cmd(Command::StopMission),
            cmd(Command::StartMission(plans.upload)),
        ],
        10,
    )
}

/// Scenario 4: the circle, then `StopMission` alone: the idle rebuild of the upload in that period;
/// then `StartMission` of it.
fn idle_rebuild_then_start(rig: &mut Rig, plans: &Plans) -> Outcome {
    rig.k = 0;
    let mut o = rig.burst_then_fly(&plans.restart(), 5);
    let sent = rig.send(&[cmd(Command::StopMission)]);
    rig.period(&mut o);
    rig.k = 0;
    let mut o2 = rig.burst_then_fly(&[cmd(Command::StartMission(plans.upload))], 10);
    o2.latched |= o.latched;
    o2.flew_last &= o.flew_last && sent;
    o2
}

/// The sequences through the loop at the flight clock; true if every one held.
#[inline(never)]
fn flight_loop(syst: &mut SYST, circle: &Circle, budget: &WorkBudget) -> bool {
    let Ok(controller) = Controller::new(ControllerConfig::default()) else {
        return false;
    };
    let Some(up) = largest_waypoints().as_ref().and_then(MissionUpload::of) else {
        return false;
    };
    let key = LinkKey::new(KEY);
    start_timer();
    let mut board = FlightBoard::new(syst);
    let mut sup = Supervisor::new(controller, board_info());
    let mut link = LinkBuffers::signed(&key);
    let mut rig = Rig {
        board: &mut board,
        sup: &mut sup,
        link: &mut link,
        nav: Nav {
            signer: Signer::new(&key, Direction::ToBoard),
            seq: 0,
        },
        circle: circle.trajectory,
        state: circle.state,
        k: 0,
    };
    let rate = rig.sup.rate_hz();
    rig.board.set_rate(rate);
    let plans = Plans::new(circle.plan, &up);
    let outcomes = [
        (
            "SetConfig + Arm + StartMission in one burst at 100 Hz",
            config_burst(&mut rig, &plans),
        ),
        (
            "the largest upload after a full queue, then the circle at 200 Hz",
            upload_after_a_full_queue(&mut rig, &up, &plans),
        ),
        (
            "StopMission + StartMission of the upload, built in its period",
            start_upload_to_build(&mut rig, &plans),
        ),
        (
            "StopMission (the idle rebuild), then StartMission of the upload",
            idle_rebuild_then_start(&mut rig, &plans),
        ),
    ];
    let mut ok = true;
    for (name, o) in &outcomes {
        info!(
            "flight clock, {=str}: {} periods, never latched {}, flew on {}",
            name, o.periods, !o.latched, o.flew_last
        );
        ok &= !o.latched && o.flew_last;
    }
    let b = &*rig.board;
    let (gap, timeout_us, at) = b.longest_gap;
    info!(
        "flight clock, longest period's work {} instructions (budget {}); longest between watchdog feeds {} instructions = {} us at 168 MHz, the watchdog's shortest timeout {} us at {} Hz; periods that overran {} (each a long job's, counted there; instructions)",
        b.longest_work,
        budget.period,
        gap,
        flight_us(gap),
        timeout_us,
        at,
        outcomes[3].1.overruns
    );
    let within = b.longest_work <= u64::from(budget.period) && !b.unfed_too_long;
    if !within {
        error!("a period's work is over its budget, or the watchdog went unfed past its timeout");
    }
    ok && within
}

/// The configuration costs and the flight-clock loop, on the self-test's `circle`; true if both
/// held. Leaves SysTick counting as `counter::start_counter` sets it.
pub fn run(syst: &mut SYST, circle: &Circle) -> bool {
    let backend = controller_core::math::BACKEND;
    let Some(budget) = firmware::budget::for_backend(backend).map(|b| b.work) else {
        error!(
            "no budget for the {=str} backend (firmware::budget)",
            backend
        );
        return false;
    };
    let set_config = config_costs(syst);
    let config_ok = set_config.is_some_and(|n| n <= budget.set_config);
    if !config_ok {
        error!(
            "a SetConfig costs more than its budget of {} instructions (firmware/src/budget.rs)",
            budget.set_config
        );
    }
    let loop_ok = flight_loop(syst, circle, &budget);
    start_counter(syst);
    config_ok && loop_ok
}
