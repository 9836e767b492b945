//! The self-test's checks: golden vectors against the host core, instruction counts of
//! `update`, the link and fail-safe exercise, the PWM mapping, and the failure injection that
//! proves each kind of failure is visible.

use auv_link::sign::{Direction, LinkKey, Signer, Verifier, MAX_TIMESTAMP};
use auv_link::{encode, encode_signed, Command, ConfigPatch, Envelope, FrameDecoder, Msg};
use auv_link::{AxisPriority, Heading, MissionPlan, MissionSpec, ThrustUnit};
use auv_link::{
    BoardStatus, FailSafeReason, Refusal, StateFrame, Telemetry, UploadPart, MAX_FRAME,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Status, Table1Case, Trajectory};
use cortex_m::peripheral::SYST;
use defmt::{error, info};
use firmware::board::{self, LinkBuffers};
use firmware::pwm;
use firmware::qemu_clock::INSTRUCTIONS_PER_TICK;
use firmware::semihosting::CMDLINE_LEN;
use firmware::supervisor::{BoardInfo, Mode, Supervisor};

use crate::counter::{elapsed, start_counter};
use crate::golden::{GOLDEN, SURVEY_CHUNKS, SURVEY_HEADER};
use crate::stack;

/// Target and host agree when the difference is within a few f32 roundings of the larger
/// magnitude: ≈ 8 ulp relative, with an absolute floor for values near zero.
fn close(a: f32, b: f32) -> bool {
    if a.is_nan() || b.is_nan() {
        return a.is_nan() && b.is_nan();
    }
    let scale = if a.abs() > b.abs() { a.abs() } else { b.abs() };
    (a - b).abs() <= 8.0 * f32::EPSILON * scale + 1e-6
}

fn ulps(a: f32, b: f32) -> u32 {
    if a.is_nan() || b.is_nan() {
        return 0;
    }
    let (x, y) = (a.to_bits() as i32, b.to_bits() as i32);
    x.wrapping_sub(y).unsigned_abs()
}

/// The target's output against one golden vector's: within [`close`] (voltages, τ, δ, ‖w‖ and
/// the status), bit for bit, and the largest difference in ulp.
fn compare(
    o: &controller_core::Output,
    status: u8,
    g: &crate::golden::Golden,
) -> (bool, bool, u32) {
    let mut same = status == g.status && close(o.delta, g.delta) && close(o.w_norm, g.w_norm);
    let mut worst = ulps(o.delta, g.delta);
    for (a, b) in o
        .voltage
        .iter()
        .zip(&g.voltage)
        .chain(o.tau.iter().zip(&g.tau))
    {
        same &= close(*a, *b);
        worst = worst.max(ulps(*a, *b));
    }
    let exact = o.voltage.map(f32::to_bits) == g.voltage.map(f32::to_bits)
        && o.tau.map(f32::to_bits) == g.tau.map(f32::to_bits)
        && o.delta.to_bits() == g.delta.to_bits()
        && o.w_norm.to_bits() == g.w_norm.to_bits()
        && status == g.status;
    (same, exact, worst)
}

/// Each vector's mission is built in one slot, in place (`Golden::set`).
#[inline(never)]
fn golden_vectors() -> (bool, u32, u32) {
    let with = Controller::new(ControllerConfig::default());
    let without = Controller::new(ControllerConfig {
        robust: false,
        ..ControllerConfig::default()
    });
    let (with, without) = match (with, without) {
        (Ok(a), Ok(b)) => (a, b),
        _ => {
            error!("controller configuration rejected on the target");
            return (false, 0, 0);
        }
    };
    let mut ok = true;
    let mut worst_ulps = 0u32;
    // The survey's vectors must be bit for bit (the waypoint path's evaluation is the same
    // f32 code on both sides, docs/board.md#the-self-test-and-its-budgets).
    let (mut survey, mut survey_exact) = (0u32, 0u32);
    let (mut max_ticks, mut sum_ticks, mut timed) = (0u32, 0u64, 0u32);
    let mut tr = Trajectory::EMPTY;
    for (i, g) in GOLDEN.iter().enumerate() {
        if !g.set(&mut tr) {
            ok = false;
            error!("golden vector {}: the target refuses its mission", i);
            continue;
        }
        let c = if g.robust { &with } else { &without };
        let t0 = SYST::get_current();
        let o = c.update(g.ticks, &g.eta, &g.nu, &tr);
        let t1 = SYST::get_current();
        let status = match o.status {
            Status::Ok => 0,
            Status::Fault(_) => 1,
        };
        if status == 0 {
            let dt = elapsed(t0, t1);
            max_ticks = max_ticks.max(dt);
            sum_ticks += dt as u64;
            timed += 1;
        }
        let (mut same, exact, diff) = compare(&o, status, g);
        worst_ulps = worst_ulps.max(diff);
        if g.is_survey() {
            survey += 1;
            survey_exact += u32::from(exact);
            same &= exact;
        }
        if !same {
            ok = false;
            error!(
                "golden vector {}: target tau {} delta {} status {} vs host tau {} delta {} status {}",
                i, o.tau, o.delta, status, g.tau, g.delta, g.status
            );
        }
    }
    info!(
        "golden vectors: {} of {} agree with the host (largest difference {} ulp)",
        if ok { GOLDEN.len() } else { 0 },
        GOLDEN.len(),
        worst_ulps
    );
    info!(
        "golden vectors on the shipped survey (waypoints, rebuilt from its upload): {} of {} bit for bit",
        survey_exact, survey
    );
    ok &= survey > 0;
    let max = max_ticks * INSTRUCTIONS_PER_TICK;
    let mean = if timed > 0 {
        (sum_ticks / timed as u64) as u32 * INSTRUCTIONS_PER_TICK
    } else {
        0
    };
    (ok, max, mean)
}

/// A test key for the self-test's signed link (not a secret: it signs nothing real).
const SELFTEST_KEY: [u8; 32] = [0x5E; 32];

/// Encodes `env` and feeds it to the board's end of the link, as the UART would (signed with
/// `signer` if given; `corrupt` flips a bit in the middle). Returns the frame's bytes.
fn frame(
    sup: &mut Supervisor,
    link: &mut LinkBuffers,
    env: &Envelope,
    signer: Option<&mut Signer>,
    corrupt: bool,
) -> ([u8; MAX_FRAME], usize) {
    let mut buf = [0u8; MAX_FRAME];
    let n = match signer {
        None => encode(env, &mut buf),
        Some(s) => encode_signed(env, s, &mut buf),
    }
    .unwrap_or(0);
    if corrupt && n > 3 {
        buf[n / 2] ^= 0x10;
    }
    board::receive(sup, link, &buf[..n]);
    (buf, n)
}

/// The paper's circle, built once into static memory (a trajectory is 8.6 kB: on the stack of
/// `run` it would sit under every exercise). `None` on a second call.
#[inline(never)]
fn circle() -> Option<&'static Trajectory> {
    let t: Option<&'static mut Trajectory> =
        cortex_m::singleton!(: Trajectory = Trajectory::table1(Table1Case::Circular10R));
    t.map(|t| &*t)
}

/// The state on the paper's circle (`circle`: its trajectory, built once by [`run`]: a
/// trajectory is 8.6 kB, docs/missions.md#built-in-place) at tick `k`.
fn circle_state(circle: &Trajectory, k: u64) -> StateFrame {
    let d = circle.sample(k, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    StateFrame {
        t_ticks: k,
        eta: d.eta.into(),
        nu: nu.into(),
    }
}

/// The paper's 10 m circle, as the paper flies it.
const MISSION: MissionPlan = MissionPlan::EXAMPLE;

fn board_info(signing: bool) -> BoardInfo {
    BoardInfo {
        supply_voltage: firmware::mps2_an386::SUPPLY_VOLTAGE,
        signing,
    }
}

/// The navigation computer's end of the self-test's link: numbers the frames it sends.
struct Host {
    seq: u16,
}

impl Host {
    fn env(&mut self, msg: Msg) -> Envelope {
        self.seq = self.seq.wrapping_add(1);
        Envelope::new(self.seq, msg)
    }

    fn send(&mut self, sup: &mut Supervisor, link: &mut LinkBuffers, msg: Msg, corrupt: bool) {
        let env = self.env(msg);
        frame(sup, link, &env, None, corrupt);
    }

    /// Disarm, arm, start the mission: what clears a latched fail-safe and flies again.
    fn restart(&mut self, sup: &mut Supervisor, link: &mut LinkBuffers) {
        for c in [
            Command::Disarm,
            Command::Arm,
            Command::StartMission(MISSION),
        ] {
            self.send(sup, link, Msg::Command(c), false);
        }
    }
}

/// One period; logs its status and checks it (and 0 V unless running).
fn expect(
    sup: &mut Supervisor,
    ok: &mut bool,
    what: &str,
    want: BoardStatus,
    overrun: bool,
) -> Telemetry {
    let s = sup.step(overrun, &|| 0u32);
    let off = s.voltages.iter().all(|v| *v == 0.0);
    let good = s.telemetry.status == want && (want == BoardStatus::Running || off);
    info!("{}: {}", what, s.telemetry.status.as_str());
    if !good {
        error!("expected {}", want.as_str());
    }
    *ok &= good;
    s.telemetry
}

/// Arm, fly, lose the link, get a corrupt frame, a lone arm, re-arm, a repeated frame, fault,
/// overrun — through real encoded frames — and check each status, that fail-safe means 0 V,
/// and that what must latch stays reported.
// Long: one scripted sequence of link events, each followed by the status it must give; its
// log lines are the snapshot's, in this order, and the script reads best whole.
#[inline(never)]
fn fail_safe_exercise(circle: &Trajectory) -> bool {
    let controller = match Controller::new(ControllerConfig::default()) {
        Ok(c) => c,
        Err(_) => return false,
    };
    let mut sup = Supervisor::new(controller, board_info(false));
    let mut link = LinkBuffers::new();
    let mut host = Host { seq: 0 };
    let mut ok = true;
    let sup = &mut sup;
    let link = &mut link;
    expect(sup, &mut ok, "power-up", BoardStatus::Disarmed, false);
    host.send(sup, link, Msg::Command(Command::Arm), false);
    expect(sup, &mut ok, "armed, no mission", BoardStatus::Armed, false);
    host.send(
        sup,
        link,
        Msg::Command(Command::StartMission(MISSION)),
        false,
    );
    for k in 0..3 {
        host.send(sup, link, Msg::State(circle_state(circle, k)), false);
        expect(sup, &mut ok, "state frame", BoardStatus::Running, false);
    }
    expect(
        sup,
        &mut ok,
        "link silent 1 period",
        BoardStatus::Running,
        false,
    );
    expect(
        sup,
        &mut ok,
        "link silent 2 periods",
        BoardStatus::Running,
        false,
    );
    let stale = BoardStatus::FailSafe(FailSafeReason::StaleState);
    expect(sup, &mut ok, "link silent 3 periods", stale, false);
    let errors = sup.rx_errors();
    host.send(sup, link, Msg::Command(Command::Disarm), true);
    let counted = sup.rx_errors() == errors + 1;
    info!("corrupt frame counted and dropped: {}", counted);
    host.send(sup, link, Msg::State(circle_state(circle, 6)), false);
    expect(sup, &mut ok, "link back, not re-armed", stale, false);
    host.send(sup, link, Msg::Command(Command::Arm), false);
    let t = expect(sup, &mut ok, "lone arm", stale, false);
    let lone_refused = t.last_refusal == Some(Refusal::Latched) && t.latched.is_some();
    info!("lone arm refused, reason still reported: {}", lone_refused);
    host.restart(sup, link);
    let env = host.env(Msg::State(circle_state(circle, 7)));
    let (again, n) = frame(sup, link, &env, None, false);
    expect(
        sup,
        &mut ok,
        "disarmed, armed, mission restarted",
        BoardStatus::Running,
        false,
    );
    let dropped_before = sup.rx_stale();
    board::receive(sup, link, &again[..n]);
    let repeat_dropped = sup.rx_stale() == dropped_before + 1;
    info!("repeated state frame dropped: {}", repeat_dropped);
    let mut bad = circle_state(circle, 8);
    bad.eta[2] = f32::NAN;
    host.send(sup, link, Msg::State(bad), false);
    let fault = BoardStatus::FailSafe(FailSafeReason::ControllerFault);
    let first = expect(sup, &mut ok, "NaN depth", fault, false);
    let next = expect(sup, &mut ok, "next period", fault, false);
    let fault_kept = first.controller_fault != 0 && next.controller_fault == first.controller_fault;
    info!("fault code reported while latched: {}", fault_kept);
    host.restart(sup, link);
    host.send(sup, link, Msg::State(circle_state(circle, 9)), false);
    expect(
        sup,
        &mut ok,
        "overrun",
        BoardStatus::FailSafe(FailSafeReason::Overrun),
        true,
    );
    ok && counted && lone_refused && repeat_dropped && fault_kept
}

/// Instructions `board::receive` spends on one frame (decode, then the supervisor's work).
fn timed_frame(sup: &mut Supervisor, link: &mut LinkBuffers, host: &mut Host, msg: Msg) -> u32 {
    let env = host.env(msg);
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(&env, &mut buf).unwrap_or(0);
    let t0 = SYST::get_current();
    board::receive(sup, link, &buf[..n]);
    let t1 = SYST::get_current();
    elapsed(t0, t1) * INSTRUCTIONS_PER_TICK
}

/// The thruster chain and the mission settings of protocol 3 through real frames: a
/// `SetConfig` of the thrust unit, mounting and priority is applied whole and reported in
/// telemetry, refused while armed and with an invalid mask; a `StartMission` with the tangent
/// heading and a time scale flies, one with a time scale below 1 is refused with its reason.
/// Logs the instructions each costs the board.
#[inline(never)]
fn real_chain_exercise() -> bool {
    let Ok(controller) = Controller::new(ControllerConfig::default()) else {
        return false;
    };
    let mut sup = Supervisor::new(controller, board_info(false));
    let mut link = LinkBuffers::new();
    let mut host = Host { seq: 0 };
    let (sup, link) = (&mut sup, &mut link);
    let now = || 0u32;
    let boot = sup.step(false, &now).telemetry;
    let kgf_reported = boot.thrust_unit == ThrustUnit::Kgf
        && boot.reversed_thrusters == controller_core::effectiveness::AUV150_REVERSED;
    let chain = ConfigPatch {
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(0),
        priority: Some(AxisPriority::from(
            controller_core::allocation::AxisPriority::default(),
        )),
        ..ConfigPatch::EMPTY
    };
    let set_config = timed_frame(
        sup,
        link,
        &mut host,
        Msg::Command(Command::SetConfig(chain)),
    );
    let t = sup.step(false, &now).telemetry;
    let applied =
        t.thrust_unit == ThrustUnit::Newton && t.reversed_thrusters == 0 && t.refused_commands == 0;
    let bad_mask = ConfigPatch {
        reversed_thrusters: Some(1 << 5),
        ..ConfigPatch::EMPTY
    };
    host.send(sup, link, Msg::Command(Command::SetConfig(bad_mask)), false);
    let mask_refused = sup.last_refusal() == Some(Refusal::InvalidMounting);
    host.send(sup, link, Msg::Command(Command::Arm), false);
    host.send(sup, link, Msg::Command(Command::SetConfig(chain)), false);
    let armed_refused = sup.last_refusal() == Some(Refusal::WhileArmed);
    let slow = MissionPlan {
        time_scale: 0.5,
        ..MISSION
    };
    host.send(sup, link, Msg::Command(Command::StartMission(slow)), false);
    let scale_refused = sup.last_refusal() == Some(Refusal::InvalidTimeScale);
    let tangent = MissionPlan {
        heading: Heading::Tangent,
        time_scale: 2.0,
        ..MISSION
    };
    let start = timed_frame(
        sup,
        link,
        &mut host,
        Msg::Command(Command::StartMission(tangent)),
    );
    let flying = sup.mode() == Mode::Running && sup.refused_commands() == 3;
    info!(
        "real chain: boot reports kgf and the default mounting {}, SetConfig newton/mounting/priority applied {}, invalid mask refused {}, refused while armed {}, time scale 0.5 refused {}, tangent mission at k = 2 running {}",
        kgf_reported, applied, mask_refused, armed_refused, scale_refused, flying
    );
    info!(
        "real chain instructions (a SetConfig of unit, mounting and priority; a StartMission, tangent at twice the time): set_config={} start_mission={}",
        set_config, start
    );
    kgf_reported && applied && mask_refused && armed_refused && scale_refused && flying
}

/// The shipped survey's upload through real frames (docs/link.md#the-mission-upload): refused while armed;
/// disarmed, a `Begin` and its chunks with the second lost, the telemetry's acknowledgement
/// naming it, the resend verifying the mission; then `StartMission` of it by its CRC flies.
/// Logs the instructions each part and the start cost the board.
#[inline(never)]
fn upload_exercise() -> bool {
    let Ok(controller) = Controller::new(ControllerConfig::default()) else {
        return false;
    };
    let mut sup = Supervisor::new(controller, board_info(false));
    let mut link = LinkBuffers::new();
    let mut host = Host { seq: 0 };
    let (sup, link) = (&mut sup, &mut link);
    let now = || 0u32;
    let begin = Msg::Command(Command::Upload(UploadPart::Begin(SURVEY_HEADER)));
    host.send(sup, link, Msg::Command(Command::Arm), false);
    host.send(sup, link, begin, false);
    let armed_refused = sup.last_refusal() == Some(Refusal::WhileArmed);
    host.send(sup, link, Msg::Command(Command::Disarm), false);
    let begin_cost = timed_frame(sup, link, &mut host, begin);
    let mut chunk_cost = 0;
    for (i, c) in SURVEY_CHUNKS.iter().enumerate() {
        if i != 1 {
            let msg = Msg::Command(Command::Upload(UploadPart::Chunk(*c)));
            chunk_cost = chunk_cost.max(timed_frame(sup, link, &mut host, msg));
        }
    }
    let ack = sup.step(false, &now).telemetry.upload;
    let one_missing = ack.crc == SURVEY_HEADER.crc && ack.missing().eq([1u8]) && !ack.verified;
    let resend = Msg::Command(Command::Upload(UploadPart::Chunk(SURVEY_CHUNKS[1])));
    let last_cost = timed_frame(sup, link, &mut host, resend);
    let verified = sup.step(false, &now).telemetry.upload.verified;
    host.send(sup, link, Msg::Command(Command::Arm), false);
    let plan = MissionPlan {
        path: MissionSpec::Waypoints {
            crc: SURVEY_HEADER.crc,
        },
        heading: Heading::Tangent,
        time_scale: 1.0,
    };
    let start = timed_frame(
        sup,
        link,
        &mut host,
        Msg::Command(Command::StartMission(plan)),
    );
    let flying = sup.mode() == Mode::Running && sup.refused_commands() == 1;
    info!(
        "survey upload: refused while armed {}, chunk 1 lost and named missing {}, verified after its resend {}, its mission running {}",
        armed_refused, one_missing, verified, flying
    );
    info!(
        "survey upload instructions (its Begin; a chunk, the largest; the last chunk: the CRC check and the 12-point mission built, disarmed; StartMission of the built mission): begin={} chunk={} last_chunk={} start_mission={}",
        begin_cost, chunk_cost, last_cost, start
    );
    let largest = largest_set_cost();
    armed_refused && one_missing && verified && flying && largest.is_some()
}

/// Instructions of `Trajectory::set` on the largest waypoint path the board takes
/// (`flight::largest_waypoints`: 32 points, 61 parts), within its budget (`budget::WorkBudget`).
#[inline(never)]
fn largest_set_cost() -> Option<u32> {
    let mission = crate::flight::largest_waypoints()?;
    let slot = cortex_m::singleton!(: Trajectory = Trajectory::EMPTY)?;
    let t0 = SYST::get_current();
    let ok = slot.set(&mission).is_ok();
    let t1 = SYST::get_current();
    let n = elapsed(t0, t1) * INSTRUCTIONS_PER_TICK;
    info!(
        "Trajectory::set of the largest waypoint path (32 points, 61 parts): {} instructions, valid {}",
        n, ok
    );
    let budget =
        firmware::budget::for_backend(controller_core::math::BACKEND).map_or(0, |b| b.work.build);
    if n > budget {
        error!(
            "the largest waypoint build is over its budget of {} instructions (firmware/src/budget.rs)",
            budget
        );
    }
    (ok && n <= budget).then_some(n)
}

/// A signed link: an unsigned frame, a replayed signed frame and one stamped at 2⁴⁸ − 1 are
/// refused, a signed one is taken; the telemetry says signing is on, counts the stamp too far
/// ahead, and is still signed.
#[inline(never)]
fn signed_link_exercise() -> bool {
    let Ok(controller) = Controller::new(ControllerConfig::default()) else {
        return false;
    };
    let key = LinkKey::new(SELFTEST_KEY);
    let mut sup = Supervisor::new(controller, board_info(true));
    let mut link = LinkBuffers::signed(&key);
    let mut host = Signer::new(&key, Direction::ToBoard);
    let now = || 0u32;
    frame(
        &mut sup,
        &mut link,
        &Envelope::new(1, Msg::Command(Command::Arm)),
        None,
        false,
    );
    let unsigned_refused = sup.mode() == Mode::Disarmed && sup.rx_auth_errors() == 1;
    let (signed, n) = frame(
        &mut sup,
        &mut link,
        &Envelope::new(2, Msg::Command(Command::Arm)),
        Some(&mut host),
        false,
    );
    let signed_taken = sup.mode() == Mode::Armed;
    frame(
        &mut sup,
        &mut link,
        &Envelope::new(3, Msg::Command(Command::Disarm)),
        Some(&mut host),
        false,
    );
    board::receive(&mut sup, &mut link, &signed[..n]);
    let replay_refused = sup.mode() == Mode::Disarmed && sup.rx_auth_errors() == 2;
    let t = sup.step(false, &now).telemetry;
    info!(
        "signed link: unsigned refused {}, signed taken {}, replay refused {}, telemetry says signing {}",
        unsigned_refused, signed_taken, replay_refused, t.signing
    );
    // A key holder's frame stamped 2^48 - 1 (Choices 95-96): refused and counted, and the
    // board still signs its telemetry.
    host.advance_to(MAX_TIMESTAMP - 1);
    frame(
        &mut sup,
        &mut link,
        &Envelope::new(4, Msg::Command(Command::Arm)),
        Some(&mut host),
        false,
    );
    let ahead = sup.step(false, &now).telemetry;
    let ahead_refused = sup.mode() == Mode::Disarmed && ahead.rx_ahead == 1;
    let still_signed = link.encode(&sup.envelope(ahead)).is_ok();
    info!(
        "signed link: a stamp at 2^48 - 1 refused {} (rx_ahead {}), telemetry still signed {}",
        ahead_refused, ahead.rx_ahead, still_signed
    );
    unsigned_refused && signed_taken && replay_refused && t.signing && ahead_refused && still_signed
}

/// The largest telemetry frame the board sends.
fn largest_telemetry() -> Envelope {
    Envelope::new(u16::MAX, Msg::Telemetry(Telemetry::LARGEST))
}

/// Instructions to sign (encode) the largest telemetry frame and to receive (decode and
/// verify) a state frame, signed and unsigned: what signing costs the board per frame, twice
/// per period. Returns (sign, verify) of the signed link, or `None` if a frame failed.
#[inline(never)]
fn signing_cost(circle: &Trajectory) -> Option<(u32, u32)> {
    let key = LinkKey::new(SELFTEST_KEY);
    let telemetry = largest_telemetry();
    let state = Envelope::new(7, Msg::State(circle_state(circle, 1234)));
    let mut counts = [[0u32; 2]; 2];
    let mut ok = true;
    for (i, signed) in [false, true].into_iter().enumerate() {
        let mut board_end = LinkBuffers::with_key(signed.then_some(&key));
        let t0 = SYST::get_current();
        let sent = board_end.encode(&telemetry).map(|f| f.len());
        let t1 = SYST::get_current();
        counts[i][0] = elapsed(t0, t1) * INSTRUCTIONS_PER_TICK;
        ok &= sent.is_ok();
        let mut host = Signer::new(&key, Direction::ToBoard);
        let mut wire = [0u8; MAX_FRAME];
        let n = if signed {
            encode_signed(&state, &mut host, &mut wire)
        } else {
            encode(&state, &mut wire)
        }
        .unwrap_or(0);
        let mut dec = if signed {
            FrameDecoder::signed(Verifier::bounded(&key, Direction::ToBoard))
        } else {
            FrameDecoder::new()
        };
        let mut got = None;
        let t0 = SYST::get_current();
        for &b in &wire[..n] {
            if let Some(r) = dec.push(b) {
                got = Some(r);
            }
        }
        let t1 = SYST::get_current();
        counts[i][1] = elapsed(t0, t1) * INSTRUCTIONS_PER_TICK;
        ok &= got == Some(Ok(state));
        let link = if signed { "signed" } else { "unsigned" };
        info!(
            "{} link: the largest telemetry frame is {} bytes, a state frame {} bytes",
            link,
            sent.unwrap_or(0),
            n
        );
        info!(
            "{} link: sending that telemetry frame {} instructions, receiving that state frame {} instructions",
            link, counts[i][0], counts[i][1]
        );
    }
    info!(
        "signing instructions per frame: sign={} verify={}",
        counts[1][0].saturating_sub(counts[0][0]),
        counts[1][1].saturating_sub(counts[0][1])
    );
    ok.then_some((counts[1][0], counts[1][1]))
}

fn pwm_mapping() -> bool {
    let neutral = pwm::duty_counts(0.0, 24.0, 1000);
    let full = pwm::duty_counts(24.0, 24.0, 1000);
    let reverse = pwm::duty_counts(-24.0, 24.0, 1000);
    info!(
        "duty (of 1000) at 0 V: {}, +24 V: {}, -24 V: {}",
        neutral, full, reverse
    );
    neutral == 500 && full == 1000 && reverse == 0
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

/// CI proves that each kind of failure is visible: `-append inject=wrong|panic|hardfault|hang`
/// makes the self-test fail in that way.
fn inject_faults() -> bool {
    let mut buf = [0u8; CMDLINE_LEN];
    let Some(cmd) = firmware::semihosting::command_line(&mut buf) else {
        // Say so: CI's injections would otherwise pass for a self-test that cannot fail.
        defmt::warn!(
            "semihosting command line unreadable (longer than {} bytes?): no failure injection",
            CMDLINE_LEN
        );
        return false;
    };
    if contains(cmd, b"inject=panic") {
        info!("injecting a panic");
        let v: [u32; 2] = [1, 2];
        let i = cmd.len() % 7 + 2; // always out of bounds, unknown to the compiler
        info!("{}", v[i]);
    }
    if contains(cmd, b"inject=hardfault") {
        info!("injecting a HardFault");
        // SAFETY: deliberately not: reads an address outside every memory region.
        let x = unsafe { core::ptr::read_volatile(0xF000_0000 as *const u32) };
        info!("{}", x);
    }
    if contains(cmd, b"inject=hang") {
        info!("injecting a hang");
        #[allow(clippy::empty_loop)]
        loop {}
    }
    contains(cmd, b"inject=wrong")
}

/// Runs every check; returns true if all passed.
pub fn run(mut syst: SYST) -> bool {
    let wrong = inject_faults();
    info!(
        "AUV-150 firmware self-test (controller-core, {} backend)",
        controller_core::math::BACKEND
    );
    start_counter(&mut syst);
    let t0 = SYST::get_current();
    let cfg = Controller::new(ControllerConfig::default());
    let t1 = SYST::get_current();
    let config_ok = cfg.is_ok();
    info!(
        "Controller::new (bounds over 2^9 box corners): ~{} instructions",
        elapsed(t0, t1) * INSTRUCTIONS_PER_TICK
    );
    let (golden_ok, max, mean) = golden_vectors();
    info!("update instructions: max={} mean={}", max, mean);
    let budget_ok = crate::cost::run(max);
    let Some(circle) = circle() else {
        error!("the circle's trajectory was built twice");
        return false;
    };
    let link_ok = fail_safe_exercise(circle)
        && signed_link_exercise()
        && real_chain_exercise()
        && upload_exercise();
    let signing_ok = signing_cost(circle).is_some();
    let flight_ok = crate::flight::run(
        &mut syst,
        &crate::flight::Circle {
            plan: MISSION,
            trajectory: circle,
            state: circle_state,
        },
    );
    let pwm_ok = pwm_mapping();
    info!("stack high-water mark: {} bytes", stack::high_water());
    if wrong {
        error!("injected wrong answer: treating the golden vectors as failed");
    }
    let ok = config_ok
        && golden_ok
        && !wrong
        && budget_ok
        && link_ok
        && signing_ok
        && flight_ok
        && pwm_ok;
    if ok {
        info!("self-test passed");
    } else {
        error!("self-test FAILED");
    }
    ok
}
