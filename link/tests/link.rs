//! Frame round trips, corruption, resynchronisation, size bounds and fuzzing of the decoder.

use auv_link::sign::{AuthError, SIGNATURE_LEN};
use auv_link::{
    decode_frame, encode, AxisPriority, BoardStatus, Command, ConfigPatch, Envelope,
    FailSafeReason, FrameDecoder, Heading, LinkError, MissionPlan, MissionSpec, Msg, Refusal,
    StateFrame, Telemetry, ThrustUnit, UploadChunk, UploadHeader, UploadPart, UploadStatus,
    CRC_LEN, MAX_BODY, MAX_FRAME, PROTOCOL_VERSION,
};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Helpers

fn frame(env: &Envelope) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode(env, &mut out).expect("MAX_FRAME bytes always suffice");
    out[..n].to_vec()
}

/// Every result the decoder produces for `bytes`, pushed one at a time.
fn decode_stream(bytes: &[u8]) -> Vec<Result<Envelope, LinkError>> {
    let mut dec = FrameDecoder::new();
    bytes.iter().filter_map(|&b| dec.push(b)).collect()
}

/// The same, pushed in the given chunks (sizes taken cyclically; 0 means an empty chunk, then
/// a one-byte chunk).
fn decode_chunked(bytes: &[u8], chunks: &[usize]) -> Vec<Result<Envelope, LinkError>> {
    let mut dec = FrameDecoder::new();
    let mut results = Vec::new();
    let mut rest = bytes;
    let mut sizes = chunks.iter().cycle();
    while !rest.is_empty() {
        let mut n = *sizes.next().unwrap();
        if n == 0 {
            dec.push_slice(&[], |r| results.push(r));
            n = 1;
        }
        let n = n.min(rest.len());
        let (chunk, tail) = rest.split_at(n);
        dec.push_slice(chunk, |r| results.push(r));
        rest = tail;
    }
    results
}

// Reference COBS and CRC-16, written independently of the crate's (shared with the fuzz checks).
#[path = "common/frames.rs"]
mod frames;
use frames::{crc16, stuff};

/// A hand-made frame around an arbitrary body with a correct CRC.
fn frame_from_body(body: &[u8]) -> Vec<u8> {
    let mut b = body.to_vec();
    b.extend_from_slice(&crc16(body));
    stuff(&b)
}

fn telemetry(status: BoardStatus) -> Telemetry {
    Telemetry {
        tick: 123_456,
        status,
        voltages: [24.0, -24.0, 3.5, -0.25, 0.0],
        thrusts: [120.0, -80.5, 0.0, 1.0e-3, -3.0],
        tau: [500.0, -20.0, 3.0, 0.0, -7.5, 1.0e4],
        saturated: 0b1_0011,
        delta: 12.5,
        delta_clamped: true,
        w_norm: 0.75,
        controller_fault: 3,
        loop_overruns: 2,
        worst_update_ticks: 48_000,
        rx_frames: 1_000_000,
        rx_errors: 17,
        last_state_seq: 65_000,
        latched: Some(FailSafeReason::ControllerFault),
        refused_commands: 4,
        last_refusal: Some(Refusal::WhileArmed),
        rx_stale: 300,
        rx_auth_errors: 2,
        last_rx_seq: 65_001,
        signing: true,
        thrust_unit: ThrustUnit::Kgf,
        reversed_thrusters: 0b1_1110,
        rx_ahead: 5,
        upload: UploadStatus {
            crc: 0xDEAD_BEEF,
            chunks: 5,
            received: 0b1_0110,
            verified: false,
        },
        config_digest: 0x0BAD_F00D,
    }
}

/// At least one envelope of every message kind and variant.
fn every_kind() -> Vec<Envelope> {
    let mut msgs = vec![
        Msg::State(StateFrame {
            t_ticks: 7_000,
            eta: [10.0, -5.0, 20.0, 0.01, -0.02, 3.1],
            nu: [1.5, 0.1, -0.2, 0.0, 0.05, 0.1],
        }),
        Msg::Command(Command::Arm),
        Msg::Command(Command::Disarm),
        Msg::Command(Command::StopMission),
        Msg::Command(Command::StartMission(
            MissionSpec::Circle {
                radius: 10.0,
                omega: 0.1,
                depth: 20.0,
            }
            .into(),
        )),
        Msg::Command(Command::StartMission(MissionPlan {
            path: MissionSpec::FigureEight {
                amplitude: 15.0,
                omega: 0.1,
                depth: 20.0,
            },
            heading: Heading::Tangent,
            time_scale: 2.5,
        })),
        Msg::Command(Command::StartMission(MissionPlan {
            path: MissionSpec::LawnMower {
                scale: 1.0,
                omega: 0.05,
                depth: 20.0,
            },
            heading: Heading::Paper,
            time_scale: 1.0,
        })),
        Msg::Command(Command::StartMission(MissionPlan {
            path: MissionSpec::Helix {
                radius: 10.0,
                omega: 0.1,
                depth: 5.0,
                depth_rate: 0.1,
            },
            heading: Heading::Tangent,
            time_scale: 1.0,
        })),
        Msg::Command(Command::SetConfig(ConfigPatch::EMPTY)),
        Msg::Command(Command::StartMission(MissionPlan {
            path: MissionSpec::Waypoints { crc: 0x1234_5678 },
            heading: Heading::Tangent,
            time_scale: 1.0,
        })),
        Msg::Command(Command::Upload(UploadPart::Begin(UploadHeader {
            points: 3,
            speeds: Some(5),
            speed: 1.5,
            turn_radius: None,
            speed_change: Some(0.05),
            heading: Heading::Tangent,
            time_scale: 2.0,
            crc: 0xCAFE_F00D,
        }))),
        Msg::Command(Command::Upload(UploadPart::Chunk(UploadChunk {
            index: 2,
            words: [-3.25; auv_link::upload::CHUNK_WORDS],
        }))),
        Msg::Command(Command::SetConfig(ConfigPatch {
            rate_hz: Some(100),
            robust: Some(false),
            delta_max: Some(25.0),
            voltage_limit: Some(24.0),
            stale_periods: Some(5),
            lockstep: Some(true),
            thrust_unit: Some(ThrustUnit::Newton),
            reversed_thrusters: Some(0b0_0110),
            priority: Some(AxisPriority {
                rank: [5, 4, 3, 0, 2, 1],
                weight: [1.0, 2.0, 0.5, 1.0, 3.0, 0.25],
            }),
        })),
        Msg::Command(Command::SetConfig(ConfigPatch {
            delta_max: Some(10.0),
            ..ConfigPatch::default()
        })),
        Msg::Telemetry(telemetry(BoardStatus::Disarmed)),
        Msg::Telemetry(telemetry(BoardStatus::Armed)),
        Msg::Telemetry(telemetry(BoardStatus::Running)),
    ];
    for reason in FailSafeReason::ALL {
        msgs.push(Msg::Telemetry(telemetry(BoardStatus::FailSafe(reason))));
    }
    msgs.into_iter()
        .enumerate()
        .map(|(i, msg)| Envelope::new((i as u16).wrapping_mul(4099), msg))
        .collect()
}

/// The largest message: every varint at its maximum, every f32 at f32::MAX, every Option Some.
fn largest() -> Envelope {
    Envelope::new(u16::MAX, Msg::Telemetry(Telemetry::LARGEST))
}

fn postcard_len<T: serde::Serialize>(value: &T) -> usize {
    let mut buf = [0u8; 256];
    postcard::to_slice(value, &mut buf).unwrap().len()
}

/// What `encode` must put on the wire for `env`, built with the reference CRC and COBS: the
/// postcard bytes, their CRC-16, stuffed, delimited.
fn reference_frame(env: &Envelope) -> Vec<u8> {
    let mut buf = [0u8; 256];
    frame_from_body(postcard::to_slice(env, &mut buf).unwrap())
}

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
    let Msg::Telemetry(t) = largest().msg else {
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
    let p = ConfigPatch {
        rate_hz: Some(u32::MAX),
        robust: Some(true),
        delta_max: Some(f32::MAX),
        voltage_limit: Some(f32::MAX),
        stale_periods: Some(u8::MAX),
        lockstep: Some(true),
        thrust_unit: Some(ThrustUnit::Newton),
        reversed_thrusters: Some(u8::MAX),
        priority: Some(AxisPriority {
            rank: [u8::MAX; 6],
            weight: [f32::MAX; 6],
        }),
    };
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
        postcard_len(&Command::Upload(UploadPart::Chunk(chunk))),
        Command::MAX_SIZE,
        "an upload chunk is the largest command"
    );
    assert_eq!(postcard_len(&Msg::Telemetry(t)), Msg::MAX_SIZE);
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
    assert_eq!(ConfigPatch::MAX_SIZE, 57);
    assert_eq!(MissionPlan::MAX_SIZE + 1, 23);
    // Protocol 5's upload chunk: the command's tag, the part's tag, the index, 32 words.
    assert_eq!(Command::MAX_SIZE, 1 + 1 + 1 + 32 * 4);
    // Protocol 4's telemetry counter is one u32 varint more (at most 5 bytes); protocol 5's
    // upload status is a u32 and a u32 varint, a u8 and a bool (12 bytes); protocol 6's
    // configuration digest one u32 varint more (5 bytes).
    assert_eq!(Envelope::MAX_SIZE, 145 + 12 + 5);
    assert_eq!(MAX_BODY, 160 + 12 + 5);
    assert_eq!(MAX_FRAME, 162 + 12 + 5);
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
// Corruption and resynchronisation

#[test]
fn any_single_byte_corruption_is_caught_and_the_stream_recovers() {
    let next = Envelope::new(0xBEEF, Msg::Command(Command::StopMission));
    let last = Envelope::new(0xBEF0, Msg::Command(Command::Disarm));
    let tail: Vec<u8> = [frame(&next), frame(&last)].concat();
    let mut cases = 0;
    for env in every_kind().into_iter().chain([largest()]) {
        let good = frame(&env);
        for pos in 0..good.len() {
            for mask in 1..=255u8 {
                let mut wire = good.clone();
                wire[pos] ^= mask;
                wire.extend_from_slice(&tail);
                let results = decode_stream(&wire);
                cases += 1;
                let oks: Vec<_> = results.iter().filter_map(|r| r.ok()).collect();
                let errs = results.iter().filter(|r| r.is_err()).count();
                let ctx = || format!("{env:?}: byte {pos} ^= {mask:#04x} -> {results:?}");
                assert!(errs >= 1, "corruption went unnoticed: {}", ctx());
                if pos == good.len() - 1 {
                    // The delimiter itself was hit: this frame swallows the next one.
                    assert_eq!(oks, vec![last], "{}", ctx());
                } else {
                    assert_eq!(oks, vec![next, last], "{}", ctx());
                }
            }
        }
    }
    assert!(cases > 100_000);
}

#[test]
fn wrong_version_is_rejected_before_parsing() {
    for version in [0u8, 1, 2, 3, 4, 5, 7, 0x7F, 0xFF] {
        let env = Envelope {
            version,
            ..Envelope::new(5, Msg::Command(Command::Arm))
        };
        let wire = frame(&env);
        assert_eq!(
            decode_stream(&wire),
            vec![Err(LinkError::Version { got: version })]
        );
        let mut body = wire[..wire.len() - 1].to_vec();
        assert_eq!(
            decode_frame(&mut body),
            Err(LinkError::Version { got: version })
        );
    }
    // A future version whose body this version cannot parse: still a Version error.
    let wire = frame_from_body(&[7, 0xFF, 0xFF, 0xFF, 0x7F, 0xEE]);
    assert_eq!(
        decode_stream(&wire),
        vec![Err(LinkError::Version { got: 7 })]
    );
}

#[test]
fn hand_made_frames_match_the_documented_format() {
    // Envelope { version 6, seq 300 (varint AC 02), Command(Arm) } built from the docs alone.
    assert_eq!(PROTOCOL_VERSION, 6);
    let wire = frame_from_body(&[6, 0xAC, 0x02, 0x01, 0x00]);
    let env = Envelope::new(300, Msg::Command(Command::Arm));
    assert_eq!(wire, frame(&env));
    // A body with a byte left over (or 12, or 14: not a signature), or a bad variant, or cut
    // short: Deserialize.
    for body in [
        &[6, 0xAC, 0x02, 0x01, 0x00, 0x00][..],
        &[&[6, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN - 1]].concat()[..],
        &[&[6, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN + 1]].concat()[..],
        &[6, 0x00, 0x03][..],
        &[6, 0x00, 0x01, 0x06][..],
        &[6, 0x00, 0x00, 0x01][..],
        &[6][..],
    ] {
        assert_eq!(
            decode_stream(&frame_from_body(body)),
            vec![Err(LinkError::Deserialize)],
            "{body:?}"
        );
    }
    // Exactly a signature's length left over: a signed frame, which an unsigned link refuses.
    let signed = [&[6, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN]].concat();
    assert_eq!(
        decode_stream(&frame_from_body(&signed)),
        vec![Err(LinkError::Auth(AuthError::SigningOff))]
    );
    // A bad CRC.
    let mut body = vec![PROTOCOL_VERSION, 0xAC, 0x02, 0x01, 0x00];
    let crc = crc16(&body);
    body.extend_from_slice(&[crc[0] ^ 1, crc[1]]);
    assert_eq!(decode_stream(&stuff(&body)), vec![Err(LinkError::Crc)]);
    // A COBS code byte that runs past the end of the frame.
    assert_eq!(decode_stream(&[0x05, 1, 2, 0]), vec![Err(LinkError::Cobs)]);
}

#[test]
fn oversize_frame_overflows_once_then_the_next_frame_decodes() {
    let env = Envelope::new(77, Msg::Command(Command::Arm));
    for junk_len in [MAX_FRAME, MAX_FRAME + 1, 3 * MAX_FRAME, 10_000] {
        let mut wire = vec![0x42u8; junk_len];
        wire.push(0);
        wire.extend(frame(&env));
        let mut dec = FrameDecoder::new();
        let results: Vec<_> = wire.iter().filter_map(|&b| dec.push(b)).collect();
        assert_eq!(
            results,
            vec![Err(LinkError::Overflow), Ok(env)],
            "{junk_len}"
        );
        assert_eq!((dec.rx_frames(), dec.rx_errors()), (1, 1));
    }
    // The longest frame the decoder buffers is MAX_FRAME − 1 bytes: that is not an overflow.
    let mut wire = vec![0x42u8; MAX_FRAME - 1];
    wire.push(0);
    assert_ne!(decode_stream(&wire), vec![Err(LinkError::Overflow)]);
    assert_eq!(
        decode_frame(&mut [0x42u8; MAX_FRAME]),
        Err(LinkError::Overflow)
    );
    // The oversize frame's bytes are reported at the byte that overflows.
    let mut dec = FrameDecoder::new();
    for _ in 0..MAX_FRAME - 1 {
        assert_eq!(dec.push(0x42), None);
    }
    assert_eq!(dec.push(0x42), Some(Err(LinkError::Overflow)));
    for _ in 0..1000 {
        assert_eq!(dec.push(0x42), None);
    }
    assert_eq!(dec.push(0), None);
}

#[test]
fn errors_display() {
    for e in [
        LinkError::Overflow,
        LinkError::Cobs,
        LinkError::Crc,
        LinkError::Deserialize,
        LinkError::Version { got: 9 },
        LinkError::BufferTooSmall,
        LinkError::Serialize,
        LinkError::Auth(AuthError::BadMac),
    ] {
        let s = e.to_string();
        assert!(!s.is_empty(), "{e:?}");
        let _: &dyn std::error::Error = &e;
    }
}

// ---------------------------------------------------------------------------------------------
// Property tests

fn any_f32() -> BoxedStrategy<f32> {
    // Every bit pattern: NaNs (with payloads), infinities, subnormals, signed zeros.
    prop_oneof![
        any::<u32>().prop_map(f32::from_bits),
        Just(f32::MAX),
        Just(f32::MIN),
        Just(0.0f32),
        -100.0f32..100.0,
    ]
    .boxed()
}

fn any_reason() -> BoxedStrategy<FailSafeReason> {
    proptest::sample::select(FailSafeReason::ALL.to_vec()).boxed()
}

fn any_status() -> BoxedStrategy<BoardStatus> {
    prop_oneof![
        Just(BoardStatus::Disarmed),
        Just(BoardStatus::Armed),
        Just(BoardStatus::Running),
        any_reason().prop_map(BoardStatus::FailSafe),
    ]
    .boxed()
}

fn any_plan() -> BoxedStrategy<MissionPlan> {
    (
        any_mission(),
        prop_oneof![Just(Heading::Paper), Just(Heading::Tangent)],
        any_f32(),
    )
        .prop_map(|(path, heading, time_scale)| MissionPlan {
            path,
            heading,
            time_scale,
        })
        .boxed()
}

fn any_unit() -> BoxedStrategy<ThrustUnit> {
    prop_oneof![Just(ThrustUnit::Kgf), Just(ThrustUnit::Newton)].boxed()
}

fn any_mission() -> BoxedStrategy<MissionSpec> {
    let f = any_f32;
    prop_oneof![
        (f(), f(), f()).prop_map(|(radius, omega, depth)| MissionSpec::Circle {
            radius,
            omega,
            depth
        }),
        (f(), f(), f()).prop_map(|(amplitude, omega, depth)| MissionSpec::FigureEight {
            amplitude,
            omega,
            depth
        }),
        (f(), f(), f()).prop_map(|(scale, omega, depth)| MissionSpec::LawnMower {
            scale,
            omega,
            depth
        }),
        (f(), f(), f(), f()).prop_map(|(radius, omega, depth, depth_rate)| {
            MissionSpec::Helix {
                radius,
                omega,
                depth,
                depth_rate,
            }
        }),
        any::<u32>().prop_map(|crc| MissionSpec::Waypoints { crc }),
    ]
    .boxed()
}

fn any_upload_status() -> BoxedStrategy<UploadStatus> {
    (any::<u32>(), any::<u8>(), any::<u32>(), any::<bool>())
        .prop_map(|(crc, chunks, received, verified)| UploadStatus {
            crc,
            chunks,
            received,
            verified,
        })
        .boxed()
}

fn any_upload_part() -> BoxedStrategy<UploadPart> {
    prop_oneof![
        (
            any::<u8>(),
            any::<Option<u8>>(),
            any_f32(),
            proptest::option::of(any_f32()),
            proptest::option::of(any_f32()),
            prop_oneof![Just(Heading::Paper), Just(Heading::Tangent)],
            any_f32(),
            any::<u32>(),
        )
            .prop_map(
                |(points, speeds, speed, turn_radius, speed_change, heading, time_scale, crc)| {
                    UploadPart::Begin(UploadHeader {
                        points,
                        speeds,
                        speed,
                        turn_radius,
                        speed_change,
                        heading,
                        time_scale,
                        crc,
                    })
                }
            ),
        (any::<u8>(), prop::array::uniform32(any_f32()))
            .prop_map(|(index, words)| UploadPart::Chunk(UploadChunk { index, words })),
    ]
    .boxed()
}

fn any_patch() -> BoxedStrategy<ConfigPatch> {
    (
        any::<Option<u32>>(),
        any::<Option<bool>>(),
        proptest::option::of(any_f32()),
        proptest::option::of(any_f32()),
        any::<Option<u8>>(),
        any::<Option<bool>>(),
        proptest::option::of(any_unit()),
        any::<Option<u8>>(),
        proptest::option::of(any_priority()),
    )
        .prop_map(
            |(
                rate_hz,
                robust,
                delta_max,
                voltage_limit,
                stale_periods,
                lockstep,
                thrust_unit,
                reversed_thrusters,
                priority,
            )| ConfigPatch {
                rate_hz,
                robust,
                delta_max,
                voltage_limit,
                stale_periods,
                lockstep,
                thrust_unit,
                reversed_thrusters,
                priority,
            },
        )
        .boxed()
}

fn any_priority() -> BoxedStrategy<AxisPriority> {
    (
        any::<[u8; 6]>(),
        [
            any_f32(),
            any_f32(),
            any_f32(),
            any_f32(),
            any_f32(),
            any_f32(),
        ],
    )
        .prop_map(|(rank, weight)| AxisPriority { rank, weight })
        .boxed()
}

fn any_command() -> BoxedStrategy<Command> {
    prop_oneof![
        Just(Command::Arm),
        Just(Command::Disarm),
        Just(Command::StopMission),
        any_plan().prop_map(Command::StartMission),
        any_patch().prop_map(Command::SetConfig),
        any_upload_part().prop_map(Command::Upload),
    ]
    .boxed()
}

fn any_telemetry() -> BoxedStrategy<Telemetry> {
    (
        (
            any::<u64>(),
            any_status(),
            prop::array::uniform5(any_f32()),
            prop::array::uniform5(any_f32()),
            prop::array::uniform6(any_f32()),
            any::<u8>(),
            any_f32(),
            any::<bool>(),
        ),
        (
            any_f32(),
            any::<u8>(),
            any::<u32>(),
            any::<u32>(),
            any::<u32>(),
            any::<u32>(),
            any::<u16>(),
        ),
        (
            prop::option::of(any_reason()),
            any::<u32>(),
            prop::option::of(any_refusal()),
            any::<u32>(),
            any::<u32>(),
            any::<u16>(),
            any::<bool>(),
            any_unit(),
            any::<u8>(),
            any::<u32>(),
            any_upload_status(),
            any::<u32>(),
        ),
    )
        .prop_map(
            |(
                (tick, status, voltages, thrusts, tau, saturated, delta, delta_clamped),
                (
                    w_norm,
                    controller_fault,
                    loop_overruns,
                    worst_update_ticks,
                    rx_frames,
                    rx_errors,
                    last_state_seq,
                ),
                (
                    latched,
                    refused_commands,
                    last_refusal,
                    rx_stale,
                    rx_auth_errors,
                    last_rx_seq,
                    signing,
                    thrust_unit,
                    reversed_thrusters,
                    rx_ahead,
                    upload,
                    config_digest,
                ),
            )| Telemetry {
                tick,
                status,
                voltages,
                thrusts,
                tau,
                saturated,
                delta,
                delta_clamped,
                w_norm,
                controller_fault,
                loop_overruns,
                worst_update_ticks,
                rx_frames,
                rx_errors,
                last_state_seq,
                latched,
                refused_commands,
                last_refusal,
                rx_stale,
                rx_auth_errors,
                last_rx_seq,
                signing,
                thrust_unit,
                reversed_thrusters,
                rx_ahead,
                upload,
                config_digest,
            },
        )
        .boxed()
}

fn any_refusal() -> BoxedStrategy<Refusal> {
    prop::sample::select(Refusal::ALL.to_vec()).boxed()
}

fn any_msg() -> BoxedStrategy<Msg> {
    prop_oneof![
        (
            any::<u64>(),
            prop::array::uniform6(any_f32()),
            prop::array::uniform6(any_f32())
        )
            .prop_map(|(t_ticks, eta, nu)| Msg::State(StateFrame { t_ticks, eta, nu })),
        any_command().prop_map(Msg::Command),
        any_telemetry().prop_map(Msg::Telemetry),
    ]
    .boxed()
}

fn any_envelope() -> BoxedStrategy<Envelope> {
    (any::<u16>(), any_msg())
        .prop_map(|(seq, msg)| Envelope::new(seq, msg))
        .boxed()
}

/// Byte streams rich in delimiters, COBS codes and fragments of real frames.
fn nasty_bytes() -> impl Strategy<Value = Vec<u8>> {
    let piece = prop_oneof![
        4 => prop::collection::vec(any::<u8>(), 0..64),
        2 => prop::collection::vec(prop_oneof![Just(0u8), Just(1), Just(0xFF), Just(0xFE)], 0..16),
        2 => (any_envelope(), any::<usize>(), any::<usize>()).prop_map(|(e, a, b)| {
            let f = frame(&e);
            let (a, b) = (a % (f.len() + 1), b % (f.len() + 1));
            f[a.min(b)..a.max(b)].to_vec()
        }),
        1 => (1usize..400).prop_map(|n| vec![0x5A; n]),
    ];
    prop::collection::vec(piece, 0..12).prop_map(|v| v.concat())
}

/// The same value, compared bit for bit (NaN-safe): equal frames.
fn same(a: &Envelope, b: &Envelope) -> bool {
    frame(a) == frame(b)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_envelopes_round_trip(env in any_envelope()) {
        let wire = frame(&env);
        prop_assert_eq!(&wire, &reference_frame(&env));
        prop_assert!(wire.len() <= MAX_FRAME);
        prop_assert!(!wire[..wire.len() - 1].contains(&0));
        prop_assert_eq!(*wire.last().unwrap(), 0);
        let results = decode_stream(&wire);
        prop_assert_eq!(results.len(), 1);
        let got = results[0].expect("valid frame");
        prop_assert!(same(&got, &env), "{:?} != {:?}", got, env);
        let mut body = wire[..wire.len() - 1].to_vec();
        let got = decode_frame(&mut body).expect("valid frame");
        prop_assert!(same(&got, &env));
    }

    #[test]
    fn any_version_but_ours_is_rejected(version in any::<u8>(), msg in any_msg()) {
        let env = Envelope { version, seq: 1, msg };
        let results = decode_stream(&frame(&env));
        if version == PROTOCOL_VERSION {
            prop_assert!(matches!(results[..], [Ok(_)]));
        } else {
            prop_assert_eq!(results, vec![Err(LinkError::Version { got: version })]);
        }
    }

    #[test]
    fn streams_decode_the_same_in_any_chunking(
        envs in prop::collection::vec(any_envelope(), 1..8),
        noise in nasty_bytes(),
        chunks in prop::collection::vec(0usize..40, 1..10),
    ) {
        let mut wire = noise;
        wire.push(0);
        for e in &envs {
            wire.extend(frame(e));
        }
        let byte_by_byte = decode_stream(&wire);
        let chunked = decode_chunked(&wire, &chunks);
        prop_assert_eq!(byte_by_byte.len(), chunked.len());
        for (a, b) in byte_by_byte.iter().zip(&chunked) {
            match (a, b) {
                (Ok(a), Ok(b)) => prop_assert!(same(a, b)),
                _ => prop_assert_eq!(a, b),
            }
        }
        // The frames after the delimiter all come out, in order, at the end.
        let tail = &byte_by_byte[byte_by_byte.len() - envs.len()..];
        for (got, want) in tail.iter().zip(&envs) {
            prop_assert!(same(got.as_ref().expect("valid frame"), want));
        }
    }

    #[test]
    fn garbage_before_a_frame_costs_at_most_that_frame(
        garbage in nasty_bytes(),
        a in any_envelope(),
        b in any_envelope(),
    ) {
        // Without a delimiter after the garbage, the first frame may be lost, never the second.
        let mut wire = garbage;
        wire.extend(frame(&a));
        wire.extend(frame(&b));
        let results = decode_stream(&wire);
        let last = results.last().expect("a result").as_ref().expect("valid frame");
        prop_assert!(same(last, &b));
    }

    #[test]
    fn arbitrary_bytes_never_panic_and_are_counted(bytes in nasty_bytes()) {
        let mut dec = FrameDecoder::new();
        let (mut oks, mut errs) = (0u32, 0u32);
        for &byte in &bytes {
            match dec.push(byte) {
                Some(Ok(env)) => {
                    oks += 1;
                    prop_assert_eq!(env.version, PROTOCOL_VERSION);
                }
                Some(Err(_)) => errs += 1,
                None => {}
            }
        }
        prop_assert_eq!((dec.rx_frames(), dec.rx_errors()), (oks, errs));
        // Whatever came before, a delimiter and a good frame decode.
        let env = Envelope::new(1, Msg::Command(Command::Arm));
        let mut tail = vec![0];
        tail.extend(frame(&env));
        let mut last = None;
        dec.push_slice(&tail, |r| last = Some(r));
        prop_assert_eq!(last, Some(Ok(env)));
    }

    #[test]
    fn decode_frame_never_panics(mut bytes in prop::collection::vec(any::<u8>(), 0..2 * MAX_FRAME)) {
        let _ = decode_frame(&mut bytes);
    }
}
