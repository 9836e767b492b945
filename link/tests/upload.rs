//! The chunked mission upload (protocol 5): a mission of the largest size crosses real frames
//! chunk by chunk and comes back bit for bit; lost, repeated and reordered chunks are
//! acknowledged as such and resent; the whole-mission CRC is the documented layout (checked
//! against a bitwise CRC-32 written from its definition) and catches chunks of another upload;
//! what the board cannot hold is refused.

use auv_link::upload::{MAX_CHUNKS, MAX_WORDS};
use auv_link::{
    decode_frame, encode, Command, Envelope, MissionUpload, Msg, Refusal, UploadBuffer, UploadPart,
    MAX_FRAME,
};
use controller_core::trajectory::{SpeedList, WaypointList, MAX_PARTS, MAX_WAYPOINTS};
use controller_core::{HeadingMode, Mission, TrajectoryKind};
use proptest::prelude::*;

#[path = "common/frames.rs"]
mod frames;
use frames::crc32_by_hand;

/// The largest mission: MAX_WAYPOINTS points, MAX_PARTS speeds, every optional field set,
/// values with awkward bits (a subnormal, a negative zero, a NaN payload: the link carries
/// bits, the core judges them).
fn largest() -> TrajectoryKind {
    let points: Vec<[f32; 3]> = (0..MAX_WAYPOINTS)
        .map(|i| {
            let i = i as f32;
            [
                37.5 * i,
                if (i as usize).is_multiple_of(2) {
                    0.0
                } else {
                    110.25
                },
                5.0 + 0.125 * i,
            ]
        })
        .collect();
    let mut speeds: Vec<f32> = (0..MAX_PARTS).map(|i| 0.3 + 0.01 * i as f32).collect();
    speeds[3] = f32::from_bits(1);
    speeds[4] = -0.0;
    speeds[5] = f32::from_bits(0x7FC0_0BAD);
    TrajectoryKind::Waypoints {
        points: WaypointList::new(&points).expect("MAX_WAYPOINTS points"),
        speed: 1.25,
        turn_radius: Some(12.5),
        speeds: Some(SpeedList::new(&speeds).expect("MAX_PARTS speeds")),
        speed_change: Some(0.05),
    }
}

/// `path` as a mission: the tangent heading at time scale 1.5 (so that both travel too).
fn mission(path: TrajectoryKind) -> Mission {
    Mission {
        path,
        heading: HeadingMode::Tangent,
        time_scale: 1.5,
    }
}

fn small() -> TrajectoryKind {
    TrajectoryKind::Waypoints {
        points: WaypointList::new(&[[0.0, 0.0, 5.0], [60.0, 0.0, 5.0], [60.0, 40.0, 6.0]])
            .expect("3 points"),
        speed: 0.8,
        turn_radius: None,
        speeds: None,
        speed_change: None,
    }
}

/// Every f32 of a waypoint path, as bits, with the counts.
fn bits(k: &TrajectoryKind) -> Vec<u32> {
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        speeds,
        speed_change,
    } = k
    else {
        panic!("not a waypoint path")
    };
    let mut v = vec![points.as_slice().len() as u32];
    v.extend(points.as_slice().iter().flatten().map(|x| x.to_bits()));
    v.push(speed.to_bits());
    v.push(turn_radius.map_or(u32::MAX, f32::to_bits));
    v.push(speed_change.map_or(u32::MAX, f32::to_bits));
    match speeds {
        None => v.push(u32::MAX),
        Some(s) => {
            v.push(s.as_slice().len() as u32);
            v.extend(s.as_slice().iter().map(|x| x.to_bits()));
        }
    }
    v
}

/// `part` through a real frame and back.
fn over_the_wire(part: UploadPart, seq: u16) -> UploadPart {
    let env = Envelope::new(seq, Msg::Command(Command::Upload(part)));
    let mut wire = [0u8; MAX_FRAME];
    let n = encode(&env, &mut wire).expect("an upload part fits a frame");
    let back = decode_frame(&mut wire[..n - 1]).expect("the frame decodes");
    match back.msg {
        Msg::Command(Command::Upload(p)) => p,
        other => panic!("decoded {other:?}"),
    }
}

#[test]
fn the_largest_mission_crosses_chunk_by_chunk_bit_for_bit() {
    let kind = largest();
    let up = MissionUpload::of(&mission(kind)).expect("a waypoint path");
    assert_eq!(up.chunks() as usize, MAX_CHUNKS);
    assert_eq!(up.header().words(), MAX_WORDS);
    let mut board = UploadBuffer::EMPTY;
    let mut seq = 0u16;
    let mut wire_bytes = 0usize;
    let mut send = |board: &mut UploadBuffer, part: UploadPart| {
        let env = Envelope::new(seq, Msg::Command(Command::Upload(part)));
        let mut wire = [0u8; MAX_FRAME];
        wire_bytes += encode(&env, &mut wire).expect("fits");
        seq += 1;
        board.take(&over_the_wire(part, seq))
    };
    send(&mut board, UploadPart::Begin(up.header())).expect("fits the board");
    for i in 0..up.chunks() {
        assert!(!board.status().verified);
        send(&mut board, UploadPart::Chunk(up.chunk(i))).expect("a chunk");
    }
    let status = board.status();
    assert!(status.verified, "{status:?}");
    assert_eq!(status.missing().count(), 0);
    assert_eq!(status.crc, up.crc());
    let back = board.mission(up.crc()).expect("the verified upload");
    assert_eq!(bits(&back.path), bits(&kind));
    assert_eq!((back.heading, back.time_scale), (HeadingMode::Tangent, 1.5));
    // The whole largest upload on the wire, unsigned (the figure of docs/link.md#the-mission-upload), at the
    // board's baud rate.
    let ms = firmware_images::wire_seconds(wire_bytes as u64) * 1e3;
    assert!(wire_bytes <= (MAX_CHUNKS + 1) * MAX_FRAME, "{wire_bytes} B");
    println!(
        "largest upload: {wire_bytes} bytes on the wire, {ms:.1} ms at {} baud",
        firmware_images::LinkBaud
    );
}

#[test]
fn the_crc_is_the_documented_layout() {
    for kind in [largest(), small()] {
        let up = MissionUpload::of(&mission(kind)).expect("a waypoint path");
        let h = up.header();
        let TrajectoryKind::Waypoints {
            points,
            speed,
            turn_radius,
            speeds,
            speed_change,
        } = kind
        else {
            unreachable!()
        };
        let mut bytes = vec![
            points.as_slice().len() as u8,
            speeds.map_or(0xFF, |s| s.as_slice().len() as u8),
        ];
        bytes.extend(speed.to_le_bytes());
        for v in [turn_radius, speed_change] {
            match v {
                None => bytes.push(0xFF),
                Some(x) => {
                    bytes.push(1);
                    bytes.extend(x.to_le_bytes());
                }
            }
        }
        bytes.push(1); // the tangent heading
        bytes.extend(1.5f32.to_le_bytes());
        for p in points.as_slice().iter().flatten() {
            bytes.extend(p.to_le_bytes());
        }
        for s in speeds.iter().flat_map(|s| s.as_slice()) {
            bytes.extend(s.to_le_bytes());
        }
        assert_eq!(h.crc, crc32_by_hand(&bytes));
        assert_eq!(crc32_by_hand(b"123456789"), 0xCBF4_3926, "the check value");
    }
}

#[test]
fn a_chunk_of_another_upload_fails_the_crc_and_every_chunk_is_asked_again() {
    let a = MissionUpload::of(&mission(largest())).expect("waypoints");
    // The same counts, one coordinate changed: every chunk but the first is the same.
    let TrajectoryKind::Waypoints {
        points,
        speed,
        turn_radius,
        speeds,
        speed_change,
    } = largest()
    else {
        unreachable!()
    };
    let mut p = points.as_slice().to_vec();
    p[1][0] += 0.5;
    let b = MissionUpload::of(&mission(TrajectoryKind::Waypoints {
        points: WaypointList::new(&p).expect("points"),
        speed,
        turn_radius,
        speeds,
        speed_change,
    }))
    .expect("waypoints");
    assert_ne!(a.crc(), b.crc());
    let mut board = UploadBuffer::EMPTY;
    board.take(&UploadPart::Begin(a.header())).expect("fits");
    board.take(&UploadPart::Chunk(b.chunk(0))).expect("a chunk");
    for i in 1..a.chunks() - 1 {
        board.take(&UploadPart::Chunk(a.chunk(i))).expect("a chunk");
    }
    let last = UploadPart::Chunk(a.chunk(a.chunks() - 1));
    assert_eq!(board.take(&last), Err(Refusal::UploadCrc));
    let s = board.status();
    assert!(!s.verified);
    assert_eq!(s.missing().count(), a.chunks() as usize, "{s:?}");
    assert_eq!(board.mission(a.crc()), Err(Refusal::NoUpload));
    // Sent again, right: verified.
    for i in 0..a.chunks() {
        board.take(&UploadPart::Chunk(a.chunk(i))).expect("a chunk");
    }
    assert!(board.status().verified);
    // A flipped bit in one word of a complete upload: resent chunk 2 with it, refused.
    let mut bad = a.chunk(2);
    bad.words[7] = f32::from_bits(bad.words[7].to_bits() ^ 1);
    assert_eq!(board.take(&UploadPart::Chunk(bad)), Err(Refusal::UploadCrc));
    assert_eq!(board.mission(a.crc()), Err(Refusal::NoUpload));
}

#[test]
fn what_the_board_cannot_hold_is_refused_and_changes_nothing_it_should_not() {
    let up = MissionUpload::of(&mission(small())).expect("waypoints");
    let mut board = UploadBuffer::EMPTY;
    // A chunk before any Begin.
    assert_eq!(
        board.take(&UploadPart::Chunk(up.chunk(0))),
        Err(Refusal::InvalidUpload)
    );
    for (points, speeds) in [
        (0u8, None),
        (1, None),
        (MAX_WAYPOINTS as u8 + 1, None),
        (u8::MAX, None),
        (3, Some(MAX_PARTS as u8 + 1)),
    ] {
        let h = auv_link::UploadHeader {
            points,
            speeds,
            ..up.header()
        };
        assert_eq!(
            board.take(&UploadPart::Begin(h)),
            Err(Refusal::InvalidUpload),
            "{h:?}"
        );
    }
    board.take(&UploadPart::Begin(up.header())).expect("fits");
    board
        .take(&UploadPart::Chunk(up.chunk(0)))
        .expect("chunk 0");
    assert!(board.status().verified, "a 3-point mission is one chunk");
    // A chunk past the last, and a refused Begin, leave the verified upload as it is.
    let mut past = up.chunk(0);
    past.index = up.chunks();
    assert_eq!(
        board.take(&UploadPart::Chunk(past)),
        Err(Refusal::InvalidUpload)
    );
    let too_many = auv_link::UploadHeader {
        points: 200,
        ..up.header()
    };
    assert_eq!(
        board.take(&UploadPart::Begin(too_many)),
        Err(Refusal::InvalidUpload)
    );
    assert!(board.status().verified);
    assert_eq!(board.mission(up.crc()), Ok(mission(small())));
    // Another CRC is not this upload.
    assert_eq!(board.mission(up.crc() ^ 1), Err(Refusal::NoUpload));
    // A new Begin drops it.
    board.take(&UploadPart::Begin(up.header())).expect("fits");
    assert_eq!(board.mission(up.crc()), Err(Refusal::NoUpload));
    // The chunk's words past the mission's end are zeros.
    assert!(up.chunk(0).words[3 * 3..].iter().all(|w| *w == 0.0));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any order, any losses and repeats: the acknowledgement names exactly the chunks not yet
    /// taken, and resending those completes the upload, bit for bit.
    #[test]
    fn lost_repeated_and_reordered_chunks_are_acknowledged_and_resent(
        order in Just((0..MAX_CHUNKS as u8).collect::<Vec<u8>>()).prop_shuffle(),
        lost in prop::collection::vec(any::<bool>(), MAX_CHUNKS),
        repeat in prop::collection::vec(0..MAX_CHUNKS as u8, 0..4),
    ) {
        let kind = largest();
        let up = MissionUpload::of(&mission(kind)).expect("waypoints");
        let mut board = UploadBuffer::EMPTY;
        board.take(&UploadPart::Begin(up.header())).expect("fits");
        for &i in order.iter().chain(repeat.iter()) {
            if !lost[i as usize] {
                board.take(&UploadPart::Chunk(up.chunk(i))).expect("a chunk");
            }
        }
        let s = board.status();
        let missing: Vec<u8> = s.missing().collect();
        let want: Vec<u8> = (0..MAX_CHUNKS as u8).filter(|&i| lost[i as usize]).collect();
        prop_assert_eq!(&missing, &want);
        prop_assert_eq!(s.verified, want.is_empty());
        for i in missing {
            board.take(&UploadPart::Chunk(up.chunk(i))).expect("a chunk");
        }
        prop_assert!(board.status().verified);
        let back = board.mission(up.crc()).expect("verified");
        prop_assert_eq!(bits(&back.path), bits(&kind));
    }
}

/// Choice 229: the revision moves whenever the upload's data changes and only then, so that a
/// board keys what it built by it: a `Begin` (even the same header again: its chunks are
/// dropped), a chunk with any other bit; not a chunk resent unchanged, nor a refused part.
#[test]
fn the_revision_moves_exactly_when_the_uploads_data_changes() {
    let up = MissionUpload::of(&mission(small())).expect("waypoints");
    let mut board = UploadBuffer::EMPTY;
    let mut last = board.revision();
    let mut moved = |board: &UploadBuffer| {
        let m = board.revision() != last;
        last = board.revision();
        m
    };
    board.take(&UploadPart::Begin(up.header())).expect("fits");
    assert!(moved(&board), "a Begin");
    for i in 0..up.chunks() {
        board
            .take(&UploadPart::Chunk(up.chunk(i)))
            .expect("a chunk");
        assert!(moved(&board), "chunk {i}, new words");
    }
    assert!(board.status().verified);
    // Every chunk again, unchanged: still verified, the same data.
    for i in 0..up.chunks() {
        board
            .take(&UploadPart::Chunk(up.chunk(i)))
            .expect("a chunk");
        assert!(!moved(&board), "chunk {i} resent unchanged");
    }
    assert!(board.status().verified);
    // One bit of one word: moved (and refused by the CRC).
    let mut flipped = up.chunk(0);
    flipped.words[3] = f32::from_bits(flipped.words[3].to_bits() ^ 1);
    assert_eq!(
        board.take(&UploadPart::Chunk(flipped)),
        Err(Refusal::UploadCrc)
    );
    assert!(moved(&board), "one bit changed");
    // −0 for +0 is another bit pattern, though equal as numbers.
    let mut zero = up.chunk(0);
    let i = zero
        .words
        .iter()
        .position(|w| *w == 0.0)
        .expect("a zero word");
    zero.words[i] = -zero.words[i];
    let _ = board.take(&UploadPart::Chunk(zero));
    assert!(moved(&board), "-0 for +0");
    // The same header again drops the chunks: moved.
    board.take(&UploadPart::Begin(up.header())).expect("fits");
    assert!(moved(&board), "the same Begin again");
    // A refused part changes nothing.
    let too_many = auv_link::UploadHeader {
        points: MAX_WAYPOINTS as u8 + 1,
        ..up.header()
    };
    assert_eq!(
        board.take(&UploadPart::Begin(too_many)),
        Err(Refusal::InvalidUpload)
    );
    assert!(!moved(&board), "a refused Begin");
}
