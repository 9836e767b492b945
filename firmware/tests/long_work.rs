//! Issue 29, items 14 and 15: the board's long jobs — a `SetConfig` that rebuilds the controller,
//! and a waypoint trajectory's build (a verified upload, `StartMission` of one not built, the
//! idle rebuild) — through the whole loop (`board::period` on the bench board of
//! `common::bench`). Each is its period's one long job (Choice 226): the link's next frames
//! wait for the next period, the period does not fly, and an overrun the job causes is counted
//! in that period instead of latching a mission started after it. A late period here is one
//! whose boundary passes during its work, as it did on the target: before Choice 225 a
//! law-changing `SetConfig` cost ~26 M instructions (≥ 156 ms at 168 MHz), and the largest
//! waypoint build costs ~1.05 M, more than a 200 Hz period (the self-test counts both, and
//! flies these sequences at the flight clock: `firmware/src/bin/qemu_selftest/flight.rs`).

use auv_link::{
    AxisPriority, BoardStatus, Command, ConfigPatch, FailSafeReason, Heading, MissionPlan,
    MissionSpec, MissionUpload, Msg, Telemetry, ThrustUnit, UploadPart,
};
use firmware::board::{self, LinkBuffers};
use firmware::supervisor::Supervisor;

mod common;
use common::bench::Bench;
use common::{state, supervisor, Host, CIRCLE};

/// The board in its loop, and its navigation computer.
struct Rig {
    bench: Bench,
    sup: Supervisor,
    link: LinkBuffers,
    nav: Host,
}

impl Rig {
    fn new() -> Rig {
        Rig {
            bench: Bench::new(),
            sup: supervisor(),
            link: LinkBuffers::new(),
            nav: Host::new(),
        }
    }

    /// The navigation computer sends `msgs`, back to back.
    fn send(&mut self, msgs: &[Msg]) {
        for &m in msgs {
            let w = self.nav.wire(m);
            self.bench.wire.to_board.extend(w);
        }
    }

    /// One period of the board's loop; whether it flew (a voltage ≠ 0), and its telemetry.
    fn period(&mut self) -> (bool, Telemetry) {
        let step = board::period(&mut self.bench, &mut self.sup, &mut self.link);
        self.bench.wire.from_board.clear();
        (step.voltages.iter().any(|v| *v != 0.0), step.telemetry)
    }

    /// A period whose work outlasts it.
    fn late_period(&mut self) -> (bool, Telemetry) {
        self.bench.late();
        self.period()
    }

    /// `burst` in a late period, then `n` periods with a state frame each (ticks from 1):
    /// whether each period flew, and its telemetry.
    fn burst_then_states(&mut self, burst: &[Msg], n: u64) -> Vec<(bool, Telemetry)> {
        self.send(burst);
        let mut periods = vec![self.late_period()];
        for k in 1..=n {
            self.send(&[Msg::State(state(k))]);
            periods.push(self.period());
        }
        periods
    }

    /// `n` periods with a state frame each (ticks from `k`); each must fly, unlatched.
    fn fly(&mut self, k: u64, n: u64) -> Telemetry {
        let mut last = None;
        for t in k..k + n {
            self.send(&[Msg::State(state(t))]);
            let (on, tel) = self.period();
            assert_eq!(
                (tel.status, tel.latched),
                (BoardStatus::Running, None),
                "tick {t}"
            );
            assert!(on, "tick {t}: flies");
            last = Some(tel);
        }
        last.expect("n > 0")
    }
}

/// A patch that changes the law (the unit, the mounting and the priority: a rebuild).
fn law_change() -> ConfigPatch {
    let mut priority = AxisPriority::from(controller_core::allocation::AxisPriority::default());
    priority.weight[0] = 2.0;
    ConfigPatch {
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(0),
        priority: Some(priority),
        ..ConfigPatch::EMPTY
    }
}

/// Regression (issue 29, item 15): `SetConfig` + `Arm` + `StartMission` + the first state in
/// one burst, the rebuild outlasting its period. It latched `fail-safe: overrun` after one
/// flying period; the mission now starts in the next period and flies on.
#[test]
fn a_configuration_sent_with_arm_and_start_never_latches_the_mission() {
    let mut r = Rig::new();
    let periods = r.burst_then_states(
        &[
            Msg::Command(Command::SetConfig(law_change())),
            Msg::Command(Command::Arm),
            Msg::Command(Command::StartMission(CIRCLE)),
            Msg::State(state(0)),
        ],
        20,
    );
    let latched: Vec<_> = periods.iter().map(|(_, t)| t.latched).collect();
    assert!(latched.iter().all(Option::is_none), "{latched:?}");
    // The period that rebuilt the controller applied it and did not fly; Arm and the rest
    // waited for the next period, which flies on the state the burst carried.
    let (on, t) = periods[0];
    assert!(!on);
    assert_eq!(t.thrust_unit, ThrustUnit::Newton, "applied");
    assert_eq!(t.status, BoardStatus::Disarmed, "Arm waits a period");
    for (on, t) in &periods[1..] {
        assert!(on);
        assert_eq!(t.status, BoardStatus::Running);
    }
    let last = periods[20].1;
    assert_eq!(
        last.loop_overruns, 1,
        "counted, in the period that did the work"
    );
    assert_eq!(last.refused_commands, 0);
}

/// The survey's upload (12 points, tangent heading: two chunks).
fn survey() -> MissionUpload {
    MissionUpload::of(&common::survey()).expect("a waypoint path")
}

fn start_upload(up: &MissionUpload) -> Msg {
    Msg::Command(Command::StartMission(MissionPlan {
        path: MissionSpec::Waypoints { crc: up.crc() },
        heading: Heading::Tangent,
        time_scale: 1.0,
    }))
}

/// Uploaded and verified, armed, flying the circle (which took the trajectory's slot) for five
/// periods; the last period's telemetry.
fn flying_the_circle_with_an_upload_held(up: &MissionUpload) -> (Rig, Telemetry) {
    let mut r = Rig::new();
    r.send(&[Msg::Command(Command::Upload(UploadPart::Begin(
        up.header(),
    )))]);
    for i in 0..up.chunks() {
        r.send(&[Msg::Command(Command::Upload(UploadPart::Chunk(
            up.chunk(i),
        )))]);
    }
    r.send(&[Msg::Command(Command::Arm)]);
    let (_, t) = r.period();
    assert!(t.upload.verified);
    r.send(&[Msg::Command(Command::StartMission(CIRCLE))]);
    let t = r.fly(0, 5);
    (r, t)
}

/// Regression (issue 29, item 15): `StopMission` + `StartMission` of the upload in one burst,
/// the slot holding a closed form, so `StartMission` builds the upload, outlasting a 200 Hz
/// period (1 of 2 trials latched at an STM32-like 125 M instructions/s). Now the build's period
/// does not fly and the mission flies from the next, unlatched.
#[test]
fn starting_an_upload_that_must_be_built_never_latches_the_mission() {
    let up = survey();
    let (mut r, before) = flying_the_circle_with_an_upload_held(&up);
    let builds = r.sup.trajectory_builds();
    let periods = r.burst_then_states(
        &[
            Msg::Command(Command::StopMission),
            start_upload(&up),
            Msg::State(state(0)),
        ],
        10,
    );
    let latched: Vec<_> = periods.iter().map(|(_, t)| t.latched).collect();
    assert!(latched.iter().all(Option::is_none), "{latched:?}");
    assert_eq!(
        r.sup.trajectory_builds(),
        builds + 1,
        "StartMission built it"
    );
    let (on, t) = periods[0];
    assert!(!on, "the period that built it does not fly");
    assert_eq!(t.status, BoardStatus::Running);
    assert!(periods[1..].iter().all(|(on, _)| *on));
    assert_eq!(periods[10].1.loop_overruns, before.loop_overruns + 1);
}

/// Regression (issue 29, item 15): the idle rebuild of the upload (a closed form took its slot)
/// in the period after `StopMission` outlasts it; `StartMission` of the upload in the next
/// period latched the overrun of the period before. Now that overrun is the rebuild's own.
#[test]
fn the_idle_rebuild_never_latches_the_mission_started_after_it() {
    let up = survey();
    let (mut r, before) = flying_the_circle_with_an_upload_held(&up);
    let builds = r.sup.trajectory_builds();
    r.send(&[Msg::Command(Command::StopMission)]);
    let (on, t) = r.late_period();
    assert_eq!(
        r.sup.trajectory_builds(),
        builds + 1,
        "rebuilt with no mission"
    );
    assert!(!on);
    assert_eq!(t.status, BoardStatus::Armed);
    r.send(&[start_upload(&up), Msg::State(state(0))]);
    let (on, t) = r.period();
    assert_eq!((t.status, t.latched), (BoardStatus::Running, None));
    assert!(on);
    assert_eq!(
        r.sup.trajectory_builds(),
        builds + 1,
        "started without building"
    );
    let t = r.fly(1, 10);
    assert_eq!(t.loop_overruns, before.loop_overruns + 1);
}

/// The overrun fail-safe still latches a flying period that overran (no long job in it): the
/// change accounts long work where it happens, it does not excuse the loop.
#[test]
fn a_flying_period_that_overruns_still_latches() {
    let mut r = Rig::new();
    r.send(&[
        Msg::Command(Command::Arm),
        Msg::Command(Command::StartMission(CIRCLE)),
    ]);
    r.period();
    r.fly(0, 3);
    r.send(&[Msg::State(state(3))]);
    let (on, _) = r.late_period();
    assert!(on, "the late period flew");
    r.send(&[Msg::State(state(4))]);
    let (on, t) = r.period();
    assert!(!on);
    assert_eq!(t.latched, Some(FailSafeReason::Overrun));
}

/// Item 14's other half: a flood of law-changing configurations costs one rebuild a period,
/// so the watchdog, fed once a period, is fed after at most one long job; the rest of the
/// flood waits on the link, in order, and nothing is lost or refused.
#[test]
fn a_flood_of_configurations_is_applied_one_rebuild_per_period() {
    let mut r = Rig::new();
    let rates = [50u32, 60, 70, 80, 90];
    let flood: Vec<Msg> = rates
        .iter()
        .map(|&hz| {
            Msg::Command(Command::SetConfig(ConfigPatch {
                rate_hz: Some(hz),
                ..ConfigPatch::EMPTY
            }))
        })
        .collect();
    r.send(&flood);
    for &hz in &rates {
        r.period();
        assert_eq!(r.sup.rate_hz(), hz, "one rebuild in this period");
    }
    let (_, t) = r.period();
    assert_eq!((t.rx_frames, t.refused_commands), (5, 0));
}
