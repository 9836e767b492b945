//! Property tests of the link: arbitrary envelopes round trip, other versions are refused,
//! any chunking decodes the same, garbage costs at most the frame it hits, and arbitrary bytes
//! never panic.

use auv_link::{
    decode_frame, AxisPriority, BBound, BoardStatus, Command, ConfigPatch, Envelope,
    EstimatorSettings, FailSafeReason, FrameDecoder, Heading, LawSettings, LinkError, MissionPlan,
    MissionSpec, Msg, Refusal, RobustLaw, StateFrame, Telemetry, ThrustUnit, UploadChunk,
    UploadHeader, UploadPart, UploadStatus, MAX_FRAME, PROTOCOL_VERSION,
};
use controller_core::TrajectoryKind;
use proptest::prelude::*;

// Reference COBS and CRC-16, written independently of the crate's (shared with the fuzz checks),
// and the envelopes every test here sends.
#[path = "common/envelopes.rs"]
mod envelopes;
#[path = "common/frames.rs"]
mod frames;
use envelopes::{decode_chunked, decode_stream, frame, reference_frame};

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

/// A wire path of every kind: a closed form of `TrajectoryKind::EXAMPLES` with every parameter
/// arbitrary, or an uploaded mission by an arbitrary CRC.
fn any_mission() -> BoxedStrategy<MissionSpec> {
    let closed: Vec<TrajectoryKind> = TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .collect();
    let most = closed
        .iter()
        .map(|k| {
            let mut n = 0;
            k.clone().parameters(&mut |_, _| n += 1);
            n
        })
        .max()
        .unwrap_or(0);
    prop_oneof![
        (
            0..closed.len(),
            prop::collection::vec(any_f32(), most..=most)
        )
            .prop_map(move |(i, values)| {
                let mut path = closed[i];
                let mut next = values.into_iter();
                path.parameters(&mut |_, v| *v = next.next().unwrap_or(0.0));
                MissionSpec::from(path)
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
        proptest::option::of(any_estimator()),
        proptest::option::of(any_law()),
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
                estimator,
                law,
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
                estimator,
                law,
            },
        )
        .boxed()
}

/// Any law settings (protocol 8): every f32 bit pattern, both laws and both bounds.
fn any_law() -> BoxedStrategy<LawSettings> {
    (
        prop::array::uniform6(any_f32()),
        prop::array::uniform6(any_f32()),
        prop::array::uniform2(any_f32()),
        (any_f32(), any_f32(), any_f32()),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(k1, k2, q, (beta, mu, pitch_limit), theorem4, literal)| LawSettings {
                k1,
                k2,
                q,
                beta,
                mu,
                law: if theorem4 {
                    RobustLaw::BoundaryLayer
                } else {
                    RobustLaw::Discontinuous
                },
                b_bound: if literal {
                    BBound::Literal
                } else {
                    BBound::ControlledRows
                },
                pitch_limit,
            },
        )
        .boxed()
}

fn any_estimator() -> BoxedStrategy<EstimatorSettings> {
    (
        any::<bool>(),
        prop::array::uniform6(any_f32()),
        prop::array::uniform6(any_f32()),
        prop::array::uniform6(any_f32()),
    )
        .prop_map(
            |(kalman, position_sigma, velocity_sigma, accel_sigma)| EstimatorSettings {
                kalman,
                position_sigma,
                velocity_sigma,
                accel_sigma,
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

/// Every command of `Command::EXAMPLES`, its payload arbitrary.
fn any_command() -> BoxedStrategy<Command> {
    let each = Command::EXAMPLES.map(|example| match example {
        Command::StartMission(_) => any_plan().prop_map(Command::StartMission).boxed(),
        Command::SetConfig(_) => any_patch().prop_map(Command::SetConfig).boxed(),
        Command::Upload(_) => any_upload_part().prop_map(Command::Upload).boxed(),
        Command::Arm | Command::Disarm | Command::StopMission => Just(example).boxed(),
    });
    proptest::strategy::Union::new(each).boxed()
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
