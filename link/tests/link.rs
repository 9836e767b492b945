//! Frame round trips, size bounds, and the closed sets' examples on the wire (corruption and
//! resynchronisation: `link_errors.rs`; fuzzing the decoder: `link_props.rs`).

use auv_link::sign::SIGNATURE_LEN;
use auv_link::{
    decode_frame, encode, BBound, BoardStatus, Command, ConfigPatch, Envelope, FailSafeReason,
    FrameDecoder, Heading, LawSettings, LinkError, MissionPlan, MissionSpec, Msg, RobustLaw,
    StateFrame, Telemetry, ThrustUnit, UploadChunk, UploadHeader, UploadPart, CRC_LEN, MAX_BODY,
    MAX_FRAME, PROTOCOL_VERSION,
};
use controller_core::TrajectoryKind;

// Reference COBS and CRC-16, written independently of the crate's (shared with the fuzz checks),
// and the envelopes every test here sends.
#[path = "common/envelopes.rs"]
mod envelopes;
#[path = "common/frames.rs"]
mod frames;
use envelopes::{
    decode_chunked, decode_stream, every_kind, frame, largest, largest_telemetry, postcard_len,
    reference_frame,
};

// ---------------------------------------------------------------------------------------------
// Round trips

#[test]
fn every_kind_round_trips_byte_by_byte() {
    for env in every_kind() {
        let wire = frame(&env);
        assert_eq!(
            wire,
            reference_frame(&env),
            "{env:?}: wire bytes differ from the reference"
        );
        assert_eq!(*wire.last().unwrap(), 0, "{env:?}");
        assert!(!wire[..wire.len() - 1].contains(&0), "{env:?}");
        let mut dec = FrameDecoder::new();
        for (i, &b) in wire.iter().enumerate() {
            let r = dec.push(b);
            if i + 1 < wire.len() {
                assert_eq!(r, None, "{env:?} byte {i}");
            } else {
                assert_eq!(r, Some(Ok(env)));
            }
        }
        assert_eq!((dec.rx_frames(), dec.rx_errors()), (1, 0));

        let mut body = wire[..wire.len() - 1].to_vec();
        assert_eq!(decode_frame(&mut body), Ok(env));
    }
}

#[test]
fn a_stream_of_every_kind_decodes_in_order() {
    let envs = every_kind();
    let wire: Vec<u8> = envs.iter().flat_map(frame).collect();
    let want: Vec<_> = envs.iter().map(|e| Ok(*e)).collect();
    assert_eq!(decode_stream(&wire), want);
    for chunks in [
        &[1usize][..],
        &[2],
        &[7],
        &[95],
        &[1000],
        &[0, 3, 1, 50, 13],
    ] {
        assert_eq!(decode_chunked(&wire, chunks), want, "chunks {chunks:?}");
    }
}

#[test]
fn empty_frames_are_ignored() {
    let env = Envelope::new(9, Msg::Command(Command::Arm));
    let mut wire = vec![0, 0, 0];
    wire.extend(frame(&env));
    wire.extend([0, 0]);
    wire.extend(frame(&env));
    let mut dec = FrameDecoder::new();
    let results: Vec<_> = wire.iter().filter_map(|&b| dec.push(b)).collect();
    assert_eq!(results, vec![Ok(env), Ok(env)]);
    assert_eq!(dec.rx_errors(), 0);
}

// ---------------------------------------------------------------------------------------------
// Sizes

#[test]
fn max_sizes_are_exact() {
    let Msg::Telemetry(t) = largest_telemetry().msg else {
        unreachable!()
    };
    assert_eq!(postcard_len(&t), Telemetry::MAX_SIZE);
    assert_eq!(postcard_len(&t.status), BoardStatus::MAX_SIZE);
    assert_eq!(
        postcard_len(&FailSafeReason::Overrun),
        FailSafeReason::MAX_SIZE
    );
    let s = StateFrame {
        t_ticks: u64::MAX,
        eta: [f32::MAX; 6],
        nu: [f32::MAX; 6],
    };
    assert_eq!(postcard_len(&s), StateFrame::MAX_SIZE);
    let m = MissionSpec::Helix {
        radius: 1.0,
        omega: 1.0,
        depth: 1.0,
        depth_rate: 1.0,
    };
    assert_eq!(postcard_len(&m), MissionSpec::MAX_SIZE);
    let plan = MissionPlan {
        path: m,
        heading: Heading::Tangent,
        time_scale: f32::MAX,
    };
    assert_eq!(postcard_len(&plan), MissionPlan::MAX_SIZE);
    assert_eq!(postcard_len(&ThrustUnit::Newton), ThrustUnit::MAX_SIZE);
    let p = ConfigPatch::LARGEST;
    assert!(p.is_whole());
    let law = p.law.unwrap();
    assert_eq!(postcard_len(&law), LawSettings::MAX_SIZE);
    assert_eq!(postcard_len(&law.law), RobustLaw::MAX_SIZE);
    assert_eq!(postcard_len(&law.b_bound), BBound::MAX_SIZE);
    assert_eq!(postcard_len(&p), ConfigPatch::MAX_SIZE);
    let begin = UploadHeader {
        points: u8::MAX,
        speeds: Some(u8::MAX),
        speed: f32::MAX,
        turn_radius: Some(f32::MAX),
        speed_change: Some(f32::MAX),
        heading: Heading::Tangent,
        time_scale: f32::MAX,
        crc: u32::MAX,
    };
    assert_eq!(postcard_len(&begin), UploadHeader::MAX_SIZE);
    let chunk = UploadChunk {
        index: u8::MAX,
        words: [f32::MAX; auv_link::upload::CHUNK_WORDS],
    };
    assert_eq!(postcard_len(&chunk), UploadChunk::MAX_SIZE);
    assert_eq!(postcard_len(&t.upload), auv_link::UploadStatus::MAX_SIZE);
    assert_eq!(
        postcard_len(&Command::SetConfig(p)),
        Command::MAX_SIZE,
        "a whole SetConfig is the largest command (protocols 7 and 8)"
    );
    assert!(postcard_len(&Command::Upload(UploadPart::Chunk(chunk))) < Command::MAX_SIZE);
    // Protocol 8: a whole SetConfig is the largest message, longer than any telemetry.
    assert_eq!(
        postcard_len(&Msg::Command(Command::SetConfig(p))),
        Msg::MAX_SIZE
    );
    assert!(postcard_len(&Msg::Telemetry(t)) < Msg::MAX_SIZE);
    assert_eq!(postcard_len(&largest()), Envelope::MAX_SIZE);
    // Every other kind is no larger.
    for env in every_kind() {
        assert!(postcard_len(&env) <= Envelope::MAX_SIZE);
    }
}

#[test]
fn largest_message_fits_max_frame_exactly() {
    // Protocol 3's commands, by hand from the layout: a full ConfigPatch is 6 + 2 + 5 + 5 + 2
    // + 2 (protocol 2) + 2 (unit) + 2 (mask) + 31 (priority: 6 ranks, 6 weights) bytes; a
    // StartMission is its tag, the path (17), the heading (1) and the time scale (4).
    // Protocol 7 adds the estimator's settings: a tag, a bool and 18 f32 (74 bytes); protocol 8
    // the law's: a tag, K₁ and K₂ (12 f32), q (2), β, μ, the law's and the bound's variant
    // bytes and the pitch limit (1 + 64 + 2 + 4 = 71 bytes).
    assert_eq!(ConfigPatch::MAX_SIZE, 57 + 74 + 71);
    assert_eq!(MissionPlan::MAX_SIZE + 1, 23);
    // Protocol 5's upload chunk (the command's tag, the part's tag, the index, 32 words: 131
    // bytes) was the largest command; protocol 7's whole SetConfig was one byte more, and
    // protocol 8's is 72 more than that.
    assert_eq!(Command::MAX_SIZE, 1 + 57 + 74 + 71);
    // Until protocol 7 the largest message was a telemetry frame (157 postcard bytes; its
    // envelope 162 with protocol 4's counter, protocol 5's upload status and protocol 6's
    // digest). Protocol 8's whole SetConfig is longer: the envelope's version and seq (1 + 3
    // bytes), the message's tag and the command.
    assert_eq!(Telemetry::MAX_SIZE, 145 + 12 + 5 - 5);
    assert_eq!(Envelope::MAX_SIZE, 1 + 3 + 1 + Command::MAX_SIZE);
    assert_eq!(Envelope::MAX_SIZE, 208);
    assert_eq!(MAX_BODY, 208 + 13 + 2);
    // COBS adds one code byte per 254 (one here) and the delimiter one more.
    assert_eq!(MAX_FRAME, 225);
    // Unsigned, the largest frame is the signature's length short of MAX_FRAME (the signed one
    // is exactly MAX_FRAME: tests/sign.rs).
    let env = largest();
    let unsigned = MAX_FRAME - SIGNATURE_LEN;
    let mut out = [0u8; MAX_FRAME];
    assert_eq!(encode(&env, &mut out), Ok(unsigned));
    assert_eq!(
        encode(&env, &mut [0u8; MAX_FRAME - SIGNATURE_LEN - 1]),
        Err(LinkError::BufferTooSmall)
    );
    assert_eq!(decode_stream(&out[..unsigned]), vec![Ok(env)]);
}

#[test]
fn the_longest_body_is_the_message_the_signature_and_the_crc() {
    // That the longest frame fits a period at the board's baud is the board's limit, checked
    // with its baud in firmware/src/limits.rs.
    assert_eq!(MAX_BODY, Envelope::MAX_SIZE + SIGNATURE_LEN + CRC_LEN);
}

// ---------------------------------------------------------------------------------------------
// The closed sets' examples

/// The first byte of `value`'s postcard encoding: an enum's tag.
fn first_byte<T: serde::Serialize>(value: &T) -> usize {
    let mut buf = [0u8; 256];
    postcard::to_slice(value, &mut buf).unwrap()[0] as usize
}

/// True if postcard refuses `tag` as naming no variant of `T`.
fn no_such_variant<T: serde::de::DeserializeOwned + core::fmt::Debug>(tag: usize) -> bool {
    // The tag, then zeros enough for any payload: a variant at `tag` would decode.
    let mut bytes = vec![0u8; 256];
    bytes[0] = tag as u8;
    // serde's "invalid value: expected variant index 0 <= i < n", which postcard reports as a
    // custom error; any variant decodes from zeros (the tests below check the last one does).
    matches!(
        postcard::from_bytes::<T>(&bytes),
        Err(postcard::Error::SerdeDeCustom)
    )
}

#[test]
fn no_command_variant_lacks_an_example() {
    // Command::EXAMPLES is in wire order, and no variant follows its last: a new command
    // fails here until it has its example.
    for (i, c) in Command::EXAMPLES.iter().enumerate() {
        assert_eq!(first_byte(c), i, "{c:?}");
        assert_eq!(usize::from(c.wire_index()), i, "{c:?}");
    }
    assert!(no_such_variant::<Command>(Command::EXAMPLES.len()));
    assert!(!no_such_variant::<Command>(Command::EXAMPLES.len() - 1));
}

#[test]
fn every_path_kind_has_its_wire_variant_in_order() {
    // TrajectoryKind::EXAMPLES, one per kind in declaration order, are the wire's MissionSpec
    // variants in order, and the wire has no other: a kind the link does not carry fails to
    // compile (crate::mission), one the wire has beyond the core's fails here.
    for (i, kind) in TrajectoryKind::EXAMPLES.iter().enumerate() {
        let spec = MissionSpec::from(*kind);
        assert_eq!(first_byte(&spec), i, "{kind:?}");
        assert!(postcard_len(&spec) <= MissionSpec::MAX_SIZE, "{kind:?}");
    }
    assert!(no_such_variant::<MissionSpec>(
        TrajectoryKind::EXAMPLES.len()
    ));
    assert_eq!(TrajectoryKind::NAMES.len(), TrajectoryKind::EXAMPLES.len());
}

#[test]
fn a_new_wire_variant_comes_with_a_new_protocol_version() {
    // What each protocol version's wire carries of the closed sets: (version, path kinds,
    // commands). A board refuses a tag past its own variants, so a variant added to
    // `MissionSpec` or `Command` is a new protocol: this fails until PROTOCOL_VERSION is
    // bumped and its row added here.
    const CARRIED: [(u8, usize, usize); 4] = [(5, 5, 6), (6, 5, 6), (7, 5, 6), (8, 5, 6)];
    let now = (
        PROTOCOL_VERSION,
        TrajectoryKind::EXAMPLES.len(),
        Command::EXAMPLES.len(),
    );
    assert!(
        CARRIED.contains(&now),
        "the wire carries {now:?} (version, path kinds, commands): bump PROTOCOL_VERSION and add it"
    );
}
