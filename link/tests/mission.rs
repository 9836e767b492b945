//! The link's one mission conversion: every `TrajectoryKind` (and every heading and time scale
//! of a `Mission`) crosses a real frame and comes back equal, and the wire bytes are the
//! documented postcard layout of `MissionSpec` and `MissionPlan`.

use auv_link::{
    decode_frame, encode, AxisPriority, Command, Envelope, Heading, MissionPlan, MissionSpec, Msg,
    ThrustUnit, MAX_FRAME,
};
use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower};
use controller_core::{HeadingMode, Mission, Table1Case, Trajectory, TrajectoryKind};

/// The kind's place in `TrajectoryKind::EXAMPLES` (declaration order: its wire variant index).
fn kind_index(k: &TrajectoryKind) -> usize {
    TrajectoryKind::NAMES
        .iter()
        .position(|name| *name == k.name())
        .expect("every kind is listed")
}

/// The kinds that cross in one `StartMission` frame: the closed forms (the waypoint path crosses
/// as a mission upload named by its CRC: tests/upload.rs), first in declaration order.
fn closed_forms() -> Vec<TrajectoryKind> {
    TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .collect()
}

/// Missions of every closed-form kind: the six Table-1 cases, each kind's example, and odd
/// values (negative depth, a rising helix, a subnormal, a NaN with a payload — the link carries
/// bits, `Trajectory::new` judges them).
fn missions() -> Vec<TrajectoryKind> {
    let mut m: Vec<TrajectoryKind> = Table1Case::ALL.iter().map(|c| c.kind()).collect();
    m.extend(closed_forms());
    m.extend([
        TrajectoryKind::Helix(Helix {
            radius: 10.0,
            omega: 0.1,
            depth: 5.0,
            depth_rate: 0.2,
        }),
        TrajectoryKind::Helix(Helix {
            radius: 3.5,
            omega: 0.25,
            depth: 40.0,
            depth_rate: -0.05,
        }),
        TrajectoryKind::Circle(Circle {
            radius: 1e-3,
            omega: f32::from_bits(1),
            depth: -2.0,
        }),
        TrajectoryKind::FigureEight(FigureEight {
            amplitude: f32::from_bits(0x7FC0_1234),
            omega: 0.1,
            depth: 0.0,
        }),
        TrajectoryKind::LawnMower(LawnMower {
            scale: 2.5,
            omega: 0.02,
            depth: 12.0,
        }),
    ]);
    m
}

/// The fields in declaration order (`TrajectoryKind::parameters`).
fn fields(k: &TrajectoryKind) -> Vec<f32> {
    let mut k = *k;
    let mut v = Vec::new();
    k.parameters(&mut |_, x| v.push(*x));
    v
}

/// Bitwise equality (NaN payloads included).
fn same_bits(a: &TrajectoryKind, b: &TrajectoryKind) -> bool {
    let bits = |k| fields(k).into_iter().map(f32::to_bits).collect::<Vec<_>>();
    kind_index(a) == kind_index(b) && bits(a) == bits(b)
}

#[test]
fn every_kind_round_trips_through_a_frame() {
    let mut seen = vec![false; closed_forms().len()];
    for (seq, kind) in missions().into_iter().enumerate() {
        seen[kind_index(&kind)] = true;
        for (heading, time_scale) in [(HeadingMode::Paper, 1.0), (HeadingMode::Tangent, 3.25)] {
            let mission = Mission {
                path: kind,
                heading,
                time_scale,
            };
            let env = Envelope::new(
                seq as u16,
                Msg::Command(Command::StartMission(MissionPlan::from(mission))),
            );
            let mut wire = [0u8; MAX_FRAME];
            let n = encode(&env, &mut wire).expect("a mission fits a frame");
            let back = decode_frame(&mut wire[..n - 1]).expect("the frame decodes");
            let Msg::Command(Command::StartMission(plan)) = back.msg else {
                panic!("decoded {back:?}");
            };
            let again = Mission::try_from(plan).expect("a closed-form path");
            assert!(
                same_bits(&again.path, &kind),
                "{kind:?} came back as {again:?}"
            );
            assert_eq!((again.heading, again.time_scale), (heading, time_scale));
            if fields(&kind).iter().all(|x| !x.is_nan()) {
                assert_eq!(again, mission);
            }
        }
    }
    assert!(seen.iter().all(|s| *s), "some kind never crossed the link");
    // A bare path is the paper's mission.
    assert_eq!(
        Mission::try_from(MissionPlan::from(Table1Case::Circular10R.kind())).expect("closed form"),
        Mission::paper(Table1Case::Circular10R.kind())
    );
    for u in controller_core::ThrustUnit::ALL {
        assert_eq!(controller_core::ThrustUnit::from(ThrustUnit::from(u)), u);
    }
    // The axis priority, field for field (a non-default one, so a swapped field would show).
    let p = controller_core::allocation::AxisPriority {
        rank: [1, 5, 2, 0, 4, 3],
        weight: [0.5, 1.0, 2.0, 3.0, 4.0, 8.0],
    };
    let wire = AxisPriority::from(p);
    assert_eq!((wire.rank, wire.weight), (p.rank, p.weight));
    assert_eq!(controller_core::allocation::AxisPriority::from(wire), p);
}

#[test]
fn wire_bytes_are_the_documented_layout() {
    // postcard: the variant index (declaration order: circle 0, figure-eight 1, lawn-mower 2,
    // helix 3, …) as one byte, then each f32 little-endian in field order. These are the bytes
    // the protocol has always had; the conversion must not change them.
    for kind in missions() {
        let mut want = vec![kind_index(&kind) as u8];
        for x in fields(&kind) {
            want.extend(x.to_le_bytes());
        }
        let mut buf = [0u8; MissionSpec::MAX_SIZE];
        let got = postcard::to_slice(&MissionSpec::from(kind), &mut buf).expect("fits MAX_SIZE");
        assert_eq!(got, &want[..], "{kind:?}");
        // A plan: the path's bytes, the heading's variant index (paper 0, tangent 1), then the
        // time scale as an f32 little-endian.
        let plan = MissionPlan {
            path: kind.into(),
            heading: Heading::Tangent,
            time_scale: 2.5,
        };
        want.push(1);
        want.extend(2.5f32.to_le_bytes());
        let mut buf = [0u8; MissionPlan::MAX_SIZE];
        let got = postcard::to_slice(&plan, &mut buf).expect("fits MAX_SIZE");
        assert_eq!(got, &want[..], "{plan:?}");
    }
}

#[test]
fn the_receiver_validates_what_it_converts() {
    // A valid helix builds the same trajectory on both sides of the conversion; a negative
    // radius converts (the link carries it) and is refused by Trajectory::new.
    let helix = TrajectoryKind::Helix(Helix {
        radius: 10.0,
        omega: 0.1,
        depth: 5.0,
        depth_rate: 0.2,
    });
    let spec = MissionSpec::from(helix);
    assert_eq!(
        Trajectory::new(TrajectoryKind::try_from(spec).expect("closed form")),
        Trajectory::new(helix)
    );
    let bad = MissionSpec::Circle {
        radius: -1.0,
        omega: 0.1,
        depth: 5.0,
    };
    assert!(Trajectory::new(TrajectoryKind::try_from(bad).expect("closed form")).is_err());
}

#[test]
fn a_waypoint_path_crosses_as_its_uploads_crc_and_only_the_board_resolves_it() {
    let points = controller_core::WaypointList::new(&[[0.0, 0.0, 5.0], [50.0, 0.0, 5.0]])
        .expect("two points");
    let kind = TrajectoryKind::Waypoints {
        points,
        speed: 0.5,
        turn_radius: None,
        speeds: None,
        speed_change: None,
    };
    let upload = auv_link::MissionUpload::of(&Mission::paper(kind)).expect("a waypoint path");
    assert_eq!(
        MissionSpec::from(kind),
        MissionSpec::Waypoints { crc: upload.crc() }
    );
    let plan = MissionPlan::from(Mission::paper(kind));
    // Another heading or time scale is another mission: another CRC.
    let tangent = Mission {
        heading: HeadingMode::Tangent,
        ..Mission::paper(kind)
    };
    assert_ne!(MissionPlan::from(tangent).path, plan.path);
    // Without the board's buffer, the wire path names an upload and nothing more.
    assert_eq!(
        Mission::try_from(plan),
        Err(auv_link::mission::Uploaded { crc: upload.crc() })
    );
    let mut board = auv_link::UploadBuffer::EMPTY;
    assert_eq!(plan.resolve(&board), Err(auv_link::Refusal::NoUpload));
    board
        .take(&auv_link::UploadPart::Begin(upload.header()))
        .expect("fits");
    for i in 0..upload.chunks() {
        board
            .take(&auv_link::UploadPart::Chunk(upload.chunk(i)))
            .expect("a chunk");
    }
    assert_eq!(plan.resolve(&board), Ok(Mission::paper(kind)));
    // The upload's CRC with another time scale in the plan is not this upload.
    let slower = MissionPlan {
        time_scale: 2.0,
        ..plan
    };
    assert_eq!(slower.resolve(&board), Err(auv_link::Refusal::NoUpload));
}
