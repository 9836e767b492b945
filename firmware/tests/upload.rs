//! The mission upload on the board (protocol 5, docs/link.md#the-mission-upload): a waypoint mission
//! uploaded over a lossy link is acknowledged chunk by chunk in telemetry, resent, verified,
//! and flown exactly as the core flies the same mission; it survives disarming; a new upload
//! replaces it; every part is refused while armed.

use auv_link::upload::{mission_crc, CHUNK_WORDS};
use auv_link::{
    BoardStatus, Command, Heading, MissionPlan, MissionSpec, MissionUpload, Msg, Refusal,
    UploadChunk, UploadHeader, UploadPart,
};
use controller_core::kinematics::{self, Attitude};
use controller_core::trajectory::WaypointList;
use controller_core::{HeadingMode, Mission, Trajectory, TrajectoryKind};
use firmware::board::LinkBuffers;
use firmware::supervisor::{Mode, Supervisor};

mod common;
use common::{controller, supervisor, Host, NOW};

fn mission() -> Mission {
    common::survey()
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

/// The word `k` of `words` that makes [`mission_crc`] of `header` and `words` equal `target`,
/// set in place. CRC-32 is affine in the message's bits (for a fixed length), and any 32
/// contiguous bits reach every value: the word is solved over GF(2) from the CRC of each of
/// its bits alone.
fn forge_word(header: &UploadHeader, words: &mut [f32], k: usize, target: u32) {
    let mut crc_with = |bits: u32| {
        words[k] = f32::from_bits(bits);
        mission_crc(header, words)
    };
    let base = crc_with(0);
    let columns: Vec<u32> = (0..32).map(|i| crc_with(1 << i) ^ base).collect();
    let want = target ^ base;
    // Row j: which bits of the word flip bit j of the CRC, and whether bit j must flip.
    let mut rows: Vec<(u32, bool)> = (0..32)
        .map(|j| {
            let a = (0..32).fold(0u32, |a, i| a | ((columns[i] >> j) & 1) << i);
            (a, (want >> j) & 1 == 1)
        })
        .collect();
    let mut pivots = Vec::new();
    for col in 0..32 {
        let r = pivots.len();
        let Some(p) = (r..32).find(|&k| (rows[k].0 >> col) & 1 == 1) else {
            continue;
        };
        rows.swap(r, p);
        for k in 0..32 {
            if k != r && (rows[k].0 >> col) & 1 == 1 {
                rows[k].0 ^= rows[r].0;
                rows[k].1 ^= rows[r].1;
            }
        }
        pivots.push(col);
    }
    assert_eq!(pivots.len(), 32, "32 contiguous bits reach every CRC");
    let bits = pivots
        .iter()
        .enumerate()
        .fold(0u32, |x, (r, &col)| x | u32::from(rows[r].1) << col);
    words[k] = f32::from_bits(bits);
    assert_eq!(mission_crc(header, words), target);
}

/// Uploads `header` and `words` (chunk by chunk) into `s`, disarmed; the last refusal after.
fn upload_words(s: &mut Supervisor, h: &mut Host, header: UploadHeader, words: &[f32]) {
    h.command(s, Command::Upload(UploadPart::Begin(header)));
    for (index, part) in words.chunks(CHUNK_WORDS).enumerate() {
        let mut chunk = UploadChunk {
            index: index as u8,
            words: [0.0; CHUNK_WORDS],
        };
        chunk.words[..part.len()].copy_from_slice(part);
        h.command(s, Command::Upload(UploadPart::Chunk(chunk)));
    }
    s.step(false, NOW);
}

/// Regression (issue 29, item 17): the built mission was cached by its CRC alone, and a new
/// `Begin` kept the cache. An upload crafted to the CRC-32 of the mission already built, with
/// a 1e30 coordinate that a fresh board refuses, was accepted unvalidated, and `StartMission`
/// flew the old path. The cache is keyed by the data now (Choice 229): the new upload is
/// validated, and refused as a fresh board refuses it.
#[test]
fn an_upload_with_the_built_missions_crc_is_validated_not_taken_from_the_cache() {
    let good = MissionUpload::of(&mission()).expect("a waypoint path");
    let header = good.header();
    let mut words: Vec<f32> = (0..good.chunks())
        .flat_map(|i| good.chunk(i).words)
        .take(header.words())
        .collect();
    words[0] = 1.0e30;
    forge_word(&header, &mut words, header.words() - 1, good.crc());
    assert_ne!(
        words[0],
        good.chunk(0).words[0],
        "other data, the same CRC-32"
    );

    // A fresh board refuses the crafted upload (the reason is the core's) and never flies it.
    let mut fresh = supervisor();
    let mut h = Host::new();
    upload_words(&mut fresh, &mut h, header, &words);
    let refused = fresh.last_refusal();
    assert!(refused.is_some(), "a fresh board refuses it");
    h.command(&mut fresh, Command::Arm);
    h.command(&mut fresh, start(good.crc()));
    assert_eq!(fresh.mode(), Mode::Armed);

    // A board that built the good mission: the crafted one replaces it, is validated the
    // same way, and nothing flies.
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Upload(UploadPart::Begin(header)));
    for i in 0..good.chunks() {
        h.command(&mut s, Command::Upload(UploadPart::Chunk(good.chunk(i))));
    }
    s.step(false, NOW);
    assert_eq!((s.trajectory_builds(), s.refused_commands()), (1, 0));
    upload_words(&mut s, &mut h, header, &words);
    let t = s.step(false, NOW).telemetry;
    assert!(t.upload.verified, "the CRC matches: verified as data");
    assert_eq!(
        s.last_refusal(),
        refused,
        "validated as a fresh board validates it"
    );
    assert_eq!(s.trajectory_builds(), 2, "built from the new data");
    h.command(&mut s, Command::Arm);
    h.command(&mut s, start(good.crc()));
    assert_eq!(s.mode(), Mode::Armed, "the old path does not fly");
    assert_eq!(s.last_refusal(), refused);
}
