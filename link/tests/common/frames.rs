//! What the link's fuzz target (`fuzz/fuzz_targets/frame_decoder.rs`) and its stable proptest
//! twin (`link/tests/fuzz_props.rs`) share, as source (both `#[path]`-include this file): the
//! decoder's reference model, the re-encode check, an independent CRC-16, CRC-32 and COBS stuffer, and
//! bitwise (NaN-safe) equality of envelopes with exhaustive destructuring, so that a new field
//! fails to compile here.

#![allow(dead_code)]

use auv_link::{
    decode_frame, encode, Command, ConfigPatch, Envelope, FrameDecoder, LinkError, MissionPlan,
    MissionSpec, Msg, StateFrame, Telemetry, MAX_FRAME,
};

/// What the decoder must report for `bytes`: each non-empty frame of at most `MAX_FRAME − 1`
/// bytes ended by a `0x00` is `decode_frame` of (a copy of) it; a frame that reaches
/// `MAX_FRAME` bytes is one `Overflow`, reported at its `MAX_FRAME`-th byte, and dropped up to
/// the next `0x00`; an unterminated short frame reports nothing.
pub fn model(bytes: &[u8]) -> Vec<Result<Envelope, LinkError>> {
    let mut out = Vec::new();
    let mut frame: Vec<u8> = Vec::new();
    for &b in bytes {
        if b == 0 {
            if frame.len() > MAX_FRAME - 1 {
                // Already reported; the one-shot decoder must agree it is too long.
                assert_eq!(decode_frame(&mut frame.clone()), Err(LinkError::Overflow));
            } else if !frame.is_empty() {
                out.push(decode_frame(&mut frame.clone()));
            }
            frame.clear();
        } else {
            frame.push(b);
            if frame.len() == MAX_FRAME {
                out.push(Err(LinkError::Overflow));
            }
        }
    }
    out
}

/// `env` → `encode` → a well-formed frame that decodes to `env` again, bit for bit.
pub fn check_reencode(env: &Envelope) {
    let mut wire = [0u8; MAX_FRAME];
    let n = encode(env, &mut wire).expect("MAX_FRAME bytes suffice for any envelope");
    assert!((2..=MAX_FRAME).contains(&n), "frame length {n}");
    assert_eq!(wire[n - 1], 0, "frame must end with the delimiter");
    assert!(!wire[..n - 1].contains(&0), "stuffed frame contains 0x00");

    let mut dec = FrameDecoder::new();
    let results: Vec<_> = wire[..n].iter().filter_map(|&b| dec.push(b)).collect();
    match results.as_slice() {
        [Ok(back)] => assert!(same_envelope(env, back), "{env:?} re-decoded as {back:?}"),
        other => panic!(
            "{env:?} re-encoded to {:?}, decoded as {other:?}",
            &wire[..n]
        ),
    }
    let back = decode_frame(&mut wire[..n - 1].to_vec()).expect("one-shot decode of re-encode");
    assert!(
        same_envelope(env, &back),
        "{env:?} one-shot re-decoded as {back:?}"
    );
}

/// CRC-16/IBM-3740 (poly 0x1021, init 0xFFFF), little-endian, bit by bit.
pub fn crc16(bytes: &[u8]) -> [u8; 2] {
    let mut crc: u16 = 0xFFFF;
    for &b in bytes {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc.to_le_bytes()
}

/// A bitwise CRC-32/ISO-HDLC (reflected polynomial 0xEDB88320, init and final XOR all ones),
/// written from the definition, not from the crate the link uses.
pub fn crc32_by_hand(bytes: &[u8]) -> u32 {
    let mut c = u32::MAX;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// Plain COBS plus the `0x00` delimiter.
pub fn stuff(body: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8];
    let mut code_at = 0;
    for &b in body {
        if b != 0 {
            out.push(b);
        }
        if b == 0 || out.len() - code_at == 0xFF {
            out[code_at] = (out.len() - code_at) as u8;
            code_at = out.len();
            out.push(0);
        }
    }
    out[code_at] = (out.len() - code_at) as u8;
    out.push(0);
    out
}

pub fn f(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits()
}

pub fn fs(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(&x, &y)| f(x, y))
}

pub fn of(a: Option<f32>, b: Option<f32>) -> bool {
    match (a, b) {
        (Some(x), Some(y)) => f(x, y),
        (None, None) => true,
        _ => false,
    }
}

pub fn same_envelope(a: &Envelope, b: &Envelope) -> bool {
    let Envelope { version, seq, msg } = a;
    *version == b.version && *seq == b.seq && same_msg(msg, &b.msg)
}

pub fn same_msg(a: &Msg, b: &Msg) -> bool {
    match (a, b) {
        (Msg::State(a), Msg::State(b)) => {
            let StateFrame { t_ticks, eta, nu } = a;
            *t_ticks == b.t_ticks && fs(eta, &b.eta) && fs(nu, &b.nu)
        }
        (Msg::Command(a), Msg::Command(b)) => same_command(a, b),
        (Msg::Telemetry(a), Msg::Telemetry(b)) => same_telemetry(a, b),
        _ => false,
    }
}

pub fn same_command(a: &Command, b: &Command) -> bool {
    match (a, b) {
        (Command::Arm, Command::Arm)
        | (Command::Disarm, Command::Disarm)
        | (Command::StopMission, Command::StopMission) => true,
        (Command::StartMission(a), Command::StartMission(b)) => {
            let MissionPlan {
                path,
                heading,
                time_scale,
            } = a;
            same_mission(path, &b.path) && *heading == b.heading && f(*time_scale, b.time_scale)
        }
        (Command::SetConfig(a), Command::SetConfig(b)) => {
            let ConfigPatch {
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
            } = a;
            let same_law = match (law, &b.law) {
                (None, None) => true,
                (Some(l), Some(m)) => {
                    fs(&l.k1, &m.k1)
                        && fs(&l.k2, &m.k2)
                        && fs(&l.q, &m.q)
                        && f(l.beta, m.beta)
                        && f(l.mu, m.mu)
                        && l.law == m.law
                        && l.b_bound == m.b_bound
                        && f(l.pitch_limit, m.pitch_limit)
                }
                _ => false,
            };
            let same_estimator = match (estimator, &b.estimator) {
                (None, None) => true,
                (Some(e), Some(g)) => {
                    e.kalman == g.kalman
                        && fs(&e.position_sigma, &g.position_sigma)
                        && fs(&e.velocity_sigma, &g.velocity_sigma)
                        && fs(&e.accel_sigma, &g.accel_sigma)
                }
                _ => false,
            };
            let same_priority = match (priority, &b.priority) {
                (None, None) => true,
                (Some(p), Some(q)) => p.rank == q.rank && fs(&p.weight, &q.weight),
                _ => false,
            };
            same_priority
                && same_estimator
                && same_law
                && *thrust_unit == b.thrust_unit
                && *reversed_thrusters == b.reversed_thrusters
                && *rate_hz == b.rate_hz
                && *robust == b.robust
                && of(*delta_max, b.delta_max)
                && of(*voltage_limit, b.voltage_limit)
                && *stale_periods == b.stale_periods
                && *lockstep == b.lockstep
        }
        _ => false,
    }
}

pub fn same_mission(a: &MissionSpec, b: &MissionSpec) -> bool {
    match (*a, *b) {
        (
            MissionSpec::Circle {
                radius,
                omega,
                depth,
            },
            MissionSpec::Circle {
                radius: r,
                omega: o,
                depth: d,
            },
        ) => f(radius, r) && f(omega, o) && f(depth, d),
        (
            MissionSpec::FigureEight {
                amplitude,
                omega,
                depth,
            },
            MissionSpec::FigureEight {
                amplitude: a,
                omega: o,
                depth: d,
            },
        ) => f(amplitude, a) && f(omega, o) && f(depth, d),
        (
            MissionSpec::LawnMower {
                scale,
                omega,
                depth,
            },
            MissionSpec::LawnMower {
                scale: s,
                omega: o,
                depth: d,
            },
        ) => f(scale, s) && f(omega, o) && f(depth, d),
        (
            MissionSpec::Helix {
                radius,
                omega,
                depth,
                depth_rate,
            },
            MissionSpec::Helix {
                radius: r,
                omega: o,
                depth: d,
                depth_rate: dr,
            },
        ) => f(radius, r) && f(omega, o) && f(depth, d) && f(depth_rate, dr),
        _ => false,
    }
}

pub fn same_telemetry(a: &Telemetry, b: &Telemetry) -> bool {
    let Telemetry {
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
    } = a;
    *config_digest == b.config_digest
        && *upload == b.upload
        && *thrust_unit == b.thrust_unit
        && *rx_ahead == b.rx_ahead
        && *reversed_thrusters == b.reversed_thrusters
        && *tick == b.tick
        && *status == b.status
        && fs(voltages, &b.voltages)
        && fs(thrusts, &b.thrusts)
        && fs(tau, &b.tau)
        && *saturated == b.saturated
        && f(*delta, b.delta)
        && *delta_clamped == b.delta_clamped
        && f(*w_norm, b.w_norm)
        && *controller_fault == b.controller_fault
        && *loop_overruns == b.loop_overruns
        && *worst_update_ticks == b.worst_update_ticks
        && *rx_frames == b.rx_frames
        && *rx_errors == b.rx_errors
        && *last_state_seq == b.last_state_seq
        && *latched == b.latched
        && *refused_commands == b.refused_commands
        && *last_refusal == b.last_refusal
        && *rx_stale == b.rx_stale
        && *rx_auth_errors == b.rx_auth_errors
        && *last_rx_seq == b.last_rx_seq
        && *signing == b.signing
}
