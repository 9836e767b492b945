//! The link tests' envelopes and frames: one of every message kind (from the closed sets'
//! `EXAMPLES`), the largest, and frames built by the crate and by the independent reference
//! (`frames.rs`). Included by `link.rs`, `link_errors.rs` and `link_props.rs`.

#![allow(dead_code)]

use auv_link::{
    encode, AxisPriority, BBound, BoardStatus, Command, ConfigPatch, Envelope, EstimatorSettings,
    FailSafeReason, FrameDecoder, Heading, LawSettings, LinkError, MissionPlan, Msg, Refusal,
    RobustLaw, StateFrame, Telemetry, ThrustUnit, UploadChunk, UploadHeader, UploadPart,
    UploadStatus, MAX_FRAME,
};
use controller_core::TrajectoryKind;

use super::frames::{crc16, stuff};
// ---------------------------------------------------------------------------------------------
// Helpers

pub fn frame(env: &Envelope) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode(env, &mut out).expect("MAX_FRAME bytes always suffice");
    out[..n].to_vec()
}

/// Every result the decoder produces for `bytes`, pushed one at a time.
pub fn decode_stream(bytes: &[u8]) -> Vec<Result<Envelope, LinkError>> {
    let mut dec = FrameDecoder::new();
    bytes.iter().filter_map(|&b| dec.push(b)).collect()
}

/// The same, pushed in the given chunks (sizes taken cyclically; 0 means an empty chunk, then
/// a one-byte chunk).
pub fn decode_chunked(bytes: &[u8], chunks: &[usize]) -> Vec<Result<Envelope, LinkError>> {
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

/// A hand-made frame around an arbitrary body with a correct CRC.
pub fn frame_from_body(body: &[u8]) -> Vec<u8> {
    let mut b = body.to_vec();
    b.extend_from_slice(&crc16(body));
    stuff(&b)
}

pub fn telemetry(status: BoardStatus) -> Telemetry {
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

/// At least one envelope of every message kind and variant: a state frame, every command of
/// `Command::EXAMPLES`, a mission of every path kind of `TrajectoryKind::EXAMPLES` (the
/// headings and time scales alternating), the upload's parts and full and partial patches,
/// and a telemetry frame of every status.
pub fn every_kind() -> Vec<Envelope> {
    let mut msgs = vec![Msg::State(StateFrame {
        t_ticks: 7_000,
        eta: [10.0, -5.0, 20.0, 0.01, -0.02, 3.1],
        nu: [1.5, 0.1, -0.2, 0.0, 0.05, 0.1],
    })];
    msgs.extend(Command::EXAMPLES.map(Msg::Command));
    for (i, path) in TrajectoryKind::EXAMPLES.into_iter().enumerate() {
        msgs.push(Msg::Command(Command::StartMission(MissionPlan {
            path: path.into(),
            heading: if i % 2 == 0 {
                Heading::Paper
            } else {
                Heading::Tangent
            },
            time_scale: 1.0 + 0.75 * i as f32,
        })));
    }
    msgs.extend([
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
            estimator: Some(EstimatorSettings {
                kalman: true,
                position_sigma: [0.005, 0.005, 0.005, 0.001, 0.001, 0.001],
                velocity_sigma: [0.002, 0.002, 0.002, 0.0005, 0.0005, 0.0005],
                accel_sigma: [f32::MAX, 0.02, -0.0, 0.004, f32::MIN_POSITIVE, 1e-30],
            }),
            law: Some(LawSettings {
                k1: [5.0, 4.0, 4.0, 0.0, 4.0, 4.0],
                k2: [4.0, 4.0, 4.0, -0.0, 4.0, 3.0],
                q: [1.0, f32::MIN_POSITIVE],
                beta: 0.605,
                mu: 0.15,
                law: RobustLaw::Discontinuous,
                b_bound: BBound::Literal,
                pitch_limit: 1.3962634,
            }),
        })),
        Msg::Command(Command::SetConfig(ConfigPatch {
            delta_max: Some(10.0),
            ..ConfigPatch::default()
        })),
        Msg::Telemetry(telemetry(BoardStatus::Disarmed)),
        Msg::Telemetry(telemetry(BoardStatus::Armed)),
        Msg::Telemetry(telemetry(BoardStatus::Running)),
    ]);
    for reason in FailSafeReason::ALL {
        msgs.push(Msg::Telemetry(telemetry(BoardStatus::FailSafe(reason))));
    }
    msgs.into_iter()
        .enumerate()
        .map(|(i, msg)| Envelope::new((i as u16).wrapping_mul(4099), msg))
        .collect()
}

/// The largest message (protocol 8: a whole `SetConfig`): every varint at its maximum, every
/// f32 at f32::MAX, every Option Some.
pub fn largest() -> Envelope {
    Envelope::new(
        u16::MAX,
        Msg::Command(Command::SetConfig(ConfigPatch::LARGEST)),
    )
}

/// The largest telemetry: the longest frame the board sends.
pub fn largest_telemetry() -> Envelope {
    Envelope::new(u16::MAX, Msg::Telemetry(Telemetry::LARGEST))
}

pub fn postcard_len<T: serde::Serialize>(value: &T) -> usize {
    let mut buf = [0u8; 256];
    postcard::to_slice(value, &mut buf).unwrap().len()
}

/// What `encode` must put on the wire for `env`, built with the reference CRC and COBS: the
/// postcard bytes, their CRC-16, stuffed, delimited.
pub fn reference_frame(env: &Envelope) -> Vec<u8> {
    let mut buf = [0u8; 256];
    frame_from_body(postcard::to_slice(env, &mut buf).unwrap())
}
