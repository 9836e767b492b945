//! The mission upload on the board (protocol 5, docs/link.md#the-mission-upload): a waypoint mission
//! uploaded over a lossy link is acknowledged chunk by chunk in telemetry, resent, verified,
//! and flown exactly as the core flies the same mission; it survives disarming; a new upload
//! replaces it; every part is refused while armed.

use auv_link::{
    BoardStatus, Command, Heading, MissionPlan, MissionSpec, MissionUpload, Msg, Refusal,
    UploadPart,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::trajectory::WaypointList;
use controller_core::{HeadingMode, Mission, Trajectory, TrajectoryKind};
use firmware::board::LinkBuffers;

mod common;
use common::{controller, supervisor, Host, NOW};

/// A lawn-mower survey of 12 waypoints (60 m legs, 20 m apart), its speeds unset: three chunks.
fn survey() -> TrajectoryKind {
    let mut points = Vec::new();
    for row in 0..6 {
        let y = 20.0 * row as f32;
        let (a, b) = if row % 2 == 0 {
            (0.0, 60.0)
        } else {
            (60.0, 0.0)
        };
        points.push([a, y, 5.0]);
        points.push([b, y, 5.0]);
    }
    TrajectoryKind::Waypoints {
        points: WaypointList::new(&points).expect("12 points"),
        speed: 0.8,
        turn_radius: Some(3.5),
        speeds: None,
        speed_change: None,
    }
}

fn mission() -> Mission {
    Mission {
        path: survey(),
        heading: HeadingMode::Tangent,
        time_scale: 1.0,
    }
}

fn start(crc: u32) -> Command {
    Command::StartMission(MissionPlan {
        path: MissionSpec::Waypoints { crc },
        heading: Heading::Tangent,
        time_scale: 1.0,
    })
}

#[test]
fn a_lost_chunk_is_acknowledged_resent_and_the_board_flies_the_cores_trajectory() {
    let up = MissionUpload::of(&mission()).expect("a waypoint path");
    assert_eq!(up.chunks(), 2, "36 coordinates: two chunks of 32 words");
    let mut s = supervisor();
    let mut link = LinkBuffers::new();
    let mut h = Host::new();
    // Begin and every chunk but the first through real frames: chunk 0 is lost.
    h.send(
        &mut s,
        &mut link,
        Msg::Command(Command::Upload(UploadPart::Begin(up.header()))),
    );
    for i in 1..up.chunks() {
        h.send(
            &mut s,
            &mut link,
            Msg::Command(Command::Upload(UploadPart::Chunk(up.chunk(i)))),
        );
    }
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.upload.crc, up.crc());
    assert_eq!(t.upload.missing().collect::<Vec<_>>(), vec![0]);
    assert!(!t.upload.verified);
    assert_eq!(t.refused_commands, 0);
    // Not verified: the mission is refused.
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.last_refusal, Some(Refusal::NoUpload));
    assert_eq!(t.status, BoardStatus::Armed);
    // Armed, a resend is refused; disarmed, it is taken and the upload verified.
    h.command(&mut s, Command::Upload(UploadPart::Chunk(up.chunk(0))));
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.last_refusal, Some(Refusal::WhileArmed));
    assert!(!t.upload.verified);
    h.command(&mut s, Command::Disarm);
    h.send(
        &mut s,
        &mut link,
        Msg::Command(Command::Upload(UploadPart::Chunk(up.chunk(0)))),
    );
    let t = s.step(false, NOW).telemetry;
    assert!(t.upload.verified, "{:?}", t.upload);
    assert_eq!(t.upload.missing().count(), 0);

    // Flown: the board's first period is the core's update on the same mission, bit for bit.
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    let tr = Trajectory::new(mission()).expect("a valid survey");
    let d = tr.sample(0, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    let mut eta: [f32; 6] = d.eta.into();
    eta[1] += 0.05;
    let nu: [f32; 6] = nu.into();
    h.give(
        &mut s,
        Msg::State(auv_link::StateFrame {
            t_ticks: 0,
            eta,
            nu,
        }),
    );
    let step = s.step(false, NOW);
    assert_eq!(step.telemetry.status, BoardStatus::Running);
    let want = controller().update(0, &eta, &nu, &tr);
    assert_eq!(
        step.voltages.map(f32::to_bits),
        want.voltage.map(f32::to_bits)
    );
    assert!(step.voltages.iter().any(|v| *v != 0.0));

    // Disarming drops the mission, not the upload: re-armed, the same CRC starts again.
    h.command(&mut s, Command::Disarm);
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.status, BoardStatus::Running);
    assert_eq!(t.last_refusal, Some(Refusal::WhileArmed), "no new refusal");

    // A new Begin (disarmed) drops the upload: the old CRC is refused.
    h.command(&mut s, Command::Disarm);
    h.command(&mut s, Command::Upload(UploadPart::Begin(up.header())));
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.last_refusal, Some(Refusal::NoUpload));
    assert_eq!(t.status, BoardStatus::Armed);
}

#[test]
fn an_uploaded_mission_the_core_refuses_is_an_invalid_mission() {
    // Two points 5 cm apart: the link carries them, the core refuses a repeated point.
    let bad = TrajectoryKind::Waypoints {
        points: WaypointList::new(&[[0.0, 0.0, 5.0], [0.05, 0.0, 5.0]]).expect("2 points"),
        speed: 0.5,
        turn_radius: None,
        speeds: None,
        speed_change: None,
    };
    let up = MissionUpload::of(&Mission {
        heading: HeadingMode::Tangent,
        ..Mission::paper(bad)
    })
    .expect("a waypoint path");
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Upload(UploadPart::Begin(up.header())));
    h.command(&mut s, Command::Upload(UploadPart::Chunk(up.chunk(0))));
    assert!(s.step(false, NOW).telemetry.upload.verified);
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    let t = s.step(false, NOW).telemetry;
    assert_eq!(t.last_refusal, Some(Refusal::InvalidMission));
    assert_eq!(t.status, BoardStatus::Armed);
}

/// Choice 169: the board builds an uploaded mission when the upload is verified (disarmed), so
/// that `StartMission` builds nothing; after a closed-form mission took the trajectory's slot
/// it is rebuilt in the first period with no mission, before it is started again.
#[test]
fn an_upload_is_built_when_verified_and_started_without_building() {
    let up = MissionUpload::of(&mission()).expect("a waypoint path");
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Upload(UploadPart::Begin(up.header())));
    h.command(&mut s, Command::Upload(UploadPart::Chunk(up.chunk(0))));
    assert_eq!(s.trajectory_builds(), 0, "not verified yet");
    h.command(&mut s, Command::Upload(UploadPart::Chunk(up.chunk(1))));
    assert_eq!(s.trajectory_builds(), 1, "built when verified");
    // Periods with no mission change nothing, and a repeated chunk builds nothing.
    s.step(false, NOW);
    h.command(&mut s, Command::Upload(UploadPart::Chunk(up.chunk(1))));
    s.step(false, NOW);
    assert_eq!(s.trajectory_builds(), 1);
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(up.crc()));
    assert_eq!(s.mode(), firmware::supervisor::Mode::Running);
    assert_eq!(s.trajectory_builds(), 1, "StartMission built nothing");
    // The plan must be the upload's mission: another time scale is refused.
    h.command(&mut s, Command::StopMission);
    let slower = Command::StartMission(MissionPlan {
        path: MissionSpec::Waypoints { crc: up.crc() },
        heading: Heading::Tangent,
        time_scale: 2.0,
    });
    h.command(&mut s, slower);
    assert_eq!(s.last_refusal(), Some(Refusal::NoUpload));
    // A closed form takes the slot; stopped, the next period rebuilds the upload.
    h.command(&mut s, Command::StartMission(common::CIRCLE));
    assert_eq!(s.trajectory_builds(), 2);
    h.command(&mut s, Command::StopMission);
    s.step(false, NOW);
    assert_eq!(s.trajectory_builds(), 3, "rebuilt with no mission running");
    h.command(&mut s, start(up.crc()));
    assert_eq!(s.mode(), firmware::supervisor::Mode::Running);
    assert_eq!(s.trajectory_builds(), 3);
}
