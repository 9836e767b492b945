//! Signed frames: the documented layout built by hand, the policy at each end, replay, every
//! single-byte corruption of a signed frame, and how far ahead the board lets a stamp run.

#[path = "common/frames.rs"]
mod frames;

use auv_link::sign::{
    AuthError, Direction, LinkKey, Signer, Verifier, CEILING, MAC_LEN, MAX_LEAD, MAX_TIMESTAMP,
    RESERVE, SIGNATURE_LEN, TIMESTAMP_LEN, UNITS_PER_SECOND,
};
use auv_link::{
    decode_frame, decode_frame_signed, encode, encode_signed, Command, ConfigPatch, Envelope,
    FrameDecoder, LinkError, Msg, StateFrame, Telemetry, MAX_FRAME,
};
use frames::{crc16, stuff};
use hmac::{Hmac, KeyInit, Mac};
use sha2::Sha256;

const KEY: [u8; 32] = [
    0x3c, 0x9e, 0x01, 0x77, 0xa4, 0x52, 0xe8, 0x10, 0x6b, 0xd3, 0x2f, 0x95, 0x48, 0xc1, 0x7a, 0x0e,
    0xf2, 0x36, 0x8d, 0x59, 0xb0, 0x14, 0xe7, 0x63, 0x2a, 0xcf, 0x81, 0x05, 0x9b, 0x4e, 0xd6, 0x38,
];

fn key() -> LinkKey {
    LinkKey::new(KEY)
}

fn signed(env: &Envelope, signer: &mut Signer) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode_signed(env, signer, &mut out).expect("MAX_FRAME bytes suffice");
    out[..n].to_vec()
}

fn push_all(dec: &mut FrameDecoder, wire: &[u8]) -> Vec<Result<Envelope, LinkError>> {
    wire.iter().filter_map(|&b| dec.push(b)).collect()
}

fn arm(seq: u16) -> Envelope {
    Envelope::new(seq, Msg::Command(Command::Arm))
}

#[test]
fn a_signed_frame_is_the_documented_layout() {
    // postcard(Envelope{8, seq 300, Command(Arm)}) ‖ link id 0 ‖ timestamp 5 (6 bytes LE) ‖
    // the first 6 bytes of HMAC-SHA-256(key, everything before the MAC) ‖ CRC-16 of it all.
    let covered = [8u8, 0xAC, 0x02, 0x01, 0x00];
    let id_time = [0u8, 5, 0, 0, 0, 0, 0];
    let mut mac = <Hmac<Sha256> as KeyInit>::new_from_slice(&KEY).unwrap();
    mac.update(&covered);
    mac.update(&id_time);
    let tag = mac.finalize().into_bytes();
    let mut body = [&covered[..], &id_time[..], &tag[..MAC_LEN]].concat();
    body.extend_from_slice(&crc16(&body));
    let by_hand = stuff(&body);

    let mut signer = Signer::new(&key(), Direction::ToBoard);
    signer.advance_to(4);
    assert_eq!(signed(&arm(300), &mut signer), by_hand);
    assert_eq!(SIGNATURE_LEN, 1 + TIMESTAMP_LEN + MAC_LEN);
}

#[test]
fn the_largest_signed_frame_is_max_frame() {
    // Protocol 8: a whole SetConfig, to the board.
    let env = Envelope::new(
        u16::MAX,
        Msg::Command(Command::SetConfig(ConfigPatch::LARGEST)),
    );
    let mut to_board = Signer::new(&key(), Direction::ToBoard);
    let wire = signed(&env, &mut to_board);
    assert_eq!(wire.len(), MAX_FRAME);
    let mut dec = FrameDecoder::signed(Verifier::new(&key(), Direction::ToBoard));
    assert_eq!(push_all(&mut dec, &wire), vec![Ok(env)]);
    // The largest telemetry, signed: the longest frame the board sends, 179 bytes (the
    // longest frame of every protocol before 8).
    let env = Envelope::new(u16::MAX, Msg::Telemetry(Telemetry::LARGEST));
    let mut signer = Signer::new(&key(), Direction::FromBoard);
    let wire = signed(&env, &mut signer);
    assert_eq!(wire.len(), 179);
    let mut dec = FrameDecoder::signed(Verifier::new(&key(), Direction::FromBoard));
    assert_eq!(push_all(&mut dec, &wire), vec![Ok(env)]);
    // The largest state frame, signed: what the navigation computer sends every period.
    let state = Envelope::new(
        u16::MAX,
        Msg::State(StateFrame {
            t_ticks: u64::MAX,
            eta: [f32::MAX; 6],
            nu: [f32::MAX; 6],
        }),
    );
    assert_eq!(signed(&state, &mut signer).len(), 80);
}

#[test]
fn each_end_refuses_what_its_policy_does_not_allow() {
    let mut signer = Signer::new(&key(), Direction::ToBoard);
    let signed_arm = signed(&arm(1), &mut signer);
    let mut plain = [0u8; MAX_FRAME];
    let n = encode(&arm(2), &mut plain).unwrap();
    let plain = &plain[..n];

    // Signing on: unsigned refused, signed accepted.
    let mut on = FrameDecoder::signed(Verifier::new(&key(), Direction::ToBoard));
    assert_eq!(
        push_all(&mut on, plain),
        vec![Err(LinkError::Auth(AuthError::Unsigned))]
    );
    assert_eq!(push_all(&mut on, &signed_arm), vec![Ok(arm(1))]);
    // Signing off: signed refused, unsigned accepted.
    let mut off = FrameDecoder::new();
    assert_eq!(
        push_all(&mut off, &signed_arm),
        vec![Err(LinkError::Auth(AuthError::SigningOff))]
    );
    assert_eq!(push_all(&mut off, plain), vec![Ok(arm(2))]);
    assert_eq!(
        decode_frame(&mut signed_arm[..signed_arm.len() - 1].to_vec()),
        Err(LinkError::Auth(AuthError::SigningOff))
    );
}

#[test]
fn a_replayed_or_reflected_or_forged_frame_is_refused() {
    let mut signer = Signer::new(&key(), Direction::ToBoard);
    let first = signed(&arm(1), &mut signer);
    let second = signed(&arm(2), &mut signer);
    let mut rx = Verifier::new(&key(), Direction::ToBoard);
    let one_shot = |wire: &[u8], rx: &mut Verifier| {
        decode_frame_signed(&mut wire[..wire.len() - 1].to_vec(), rx)
    };
    assert_eq!(one_shot(&second, &mut rx), Ok(arm(2)));
    // The same frame again, and an older one: replays.
    assert_eq!(
        one_shot(&second, &mut rx),
        Err(LinkError::Auth(AuthError::Replay))
    );
    assert_eq!(
        one_shot(&first, &mut rx),
        Err(LinkError::Auth(AuthError::Replay))
    );
    // A frame the board signed (the other direction), sent back to it.
    let mut board = Signer::new(&key(), Direction::FromBoard);
    board.advance_to(100);
    let reflected = signed(&arm(3), &mut board);
    assert_eq!(
        one_shot(&reflected, &mut rx),
        Err(LinkError::Auth(AuthError::WrongDirection { got: 1 }))
    );
    // A forger without the key: a valid CRC, a newer timestamp, a wrong MAC.
    let mut forger = Signer::new(&LinkKey::new([0x55; 32]), Direction::ToBoard);
    forger.advance_to(1_000);
    let forged = signed(&arm(4), &mut forger);
    assert_eq!(
        one_shot(&forged, &mut rx),
        Err(LinkError::Auth(AuthError::BadMac))
    );
    // None of the refusals moved the timestamp on: the sender's next frame is accepted.
    assert_eq!(one_shot(&signed(&arm(5), &mut signer), &mut rx), Ok(arm(5)));
}

#[test]
fn any_single_byte_corruption_of_a_signed_frame_is_refused_and_the_stream_recovers() {
    let mut signer = Signer::new(&key(), Direction::ToBoard);
    let frames: Vec<Envelope> = vec![
        arm(10),
        Envelope::new(
            11,
            Msg::State(StateFrame {
                t_ticks: 77,
                eta: [1.0, 2.0, 3.0, 0.1, 0.2, 0.3],
                nu: [0.5, 0.0, 0.0, 0.0, 0.0, 0.01],
            }),
        ),
    ];
    for env in frames {
        signer.advance_to(signer.timestamp() + 10);
        let good = signed(&env, &mut signer);
        for pos in 0..good.len() - 1 {
            for mask in [0x01u8, 0x80, 0xFF, 0x5A] {
                let mut wire = good.clone();
                wire[pos] ^= mask;
                let next = signed(&arm(env.seq + 1), &mut signer);
                wire.extend_from_slice(&next);
                let mut dec = FrameDecoder::signed(Verifier::new(&key(), Direction::ToBoard));
                let got = push_all(&mut dec, &wire);
                let oks: Vec<_> = got.iter().filter_map(|r| r.as_ref().ok()).collect();
                assert_eq!(oks, vec![&arm(env.seq + 1)], "byte {pos} ^= {mask:#04x}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The board's end: how far ahead a timestamp may run (Choices 95–96)

/// A frame signed by a key holder whose next stamp is `ts`.
fn stamped(env: &Envelope, ts: u64) -> Vec<u8> {
    let mut s = Signer::new(&key(), Direction::ToBoard);
    s.advance_to(ts - 1);
    signed(env, &mut s)
}

fn one_shot(wire: &[u8], rx: &mut Verifier) -> Result<Envelope, LinkError> {
    decode_frame_signed(&mut wire[..wire.len() - 1].to_vec(), rx)
}

const AHEAD: Result<Envelope, LinkError> = Err(LinkError::Auth(AuthError::Ahead));

/// 2026-01-01 in MAVLink time (10 µs units since 2015-01-01: 11 years, 3 of them leap).
const JAN_2026: u64 = (11 * 365 + 3) * 86_400 * UNITS_PER_SECOND;

#[test]
fn the_boards_verifier_refuses_a_stamp_too_far_ahead_and_keeps_its_peer() {
    let mut rx = Verifier::bounded(&key(), Direction::ToBoard);
    assert_eq!(one_shot(&stamped(&arm(1), JAN_2026), &mut rx), Ok(arm(1)));
    // Ten minutes and 10 µs ahead of the last accepted stamp, nothing counted since: refused,
    // and the peer's next frame on its clock is still taken.
    let ten_minutes = 600 * 100_000;
    assert_eq!(MAX_LEAD, ten_minutes);
    let wild = stamped(&arm(2), JAN_2026 + ten_minutes + 1);
    assert_eq!(one_shot(&wild, &mut rx), AHEAD);
    assert_eq!(rx.last_timestamp(), Some(JAN_2026));
    assert_eq!(
        one_shot(&stamped(&arm(3), JAN_2026 + 1_000), &mut rx),
        Ok(arm(3))
    );
    // Exactly ten minutes ahead is taken.
    let t = JAN_2026 + 1_000 + ten_minutes;
    assert_eq!(one_shot(&stamped(&arm(4), t), &mut rx), Ok(arm(4)));
    // A night the board counted (10 h of 100 Hz periods): the peer's clock moved on by as much
    // and may be up to ten minutes further.
    for _ in 0..10 * 3600 * 100 {
        rx.elapse(1_000);
    }
    let night = 10 * 3600 * 100_000;
    assert_eq!(
        one_shot(&stamped(&arm(5), t + night + ten_minutes + 1), &mut rx),
        AHEAD
    );
    assert_eq!(
        one_shot(&stamped(&arm(6), t + night + ten_minutes), &mut rx),
        Ok(arm(6))
    );
    // The count starts again at each accepted frame.
    assert_eq!(
        one_shot(&stamped(&arm(7), t + night + 2 * ten_minutes + 1), &mut rx),
        AHEAD
    );
}

#[test]
fn no_stamp_above_the_ceiling_is_taken_even_first() {
    assert_eq!(CEILING, (1 << 48) - 1 - (1 << 40));
    for ts in [MAX_TIMESTAMP, MAX_TIMESTAMP - 1, CEILING + 1] {
        let mut rx = Verifier::bounded(&key(), Direction::ToBoard);
        assert_eq!(one_shot(&stamped(&arm(1), ts), &mut rx), AHEAD, "{ts}");
        assert_eq!(rx.last_timestamp(), None);
    }
    // The first frame after a reset may carry any stamp up to the ceiling (the board cannot
    // know its peer's clock); later ones are bounded from it, and by the ceiling.
    let mut rx = Verifier::bounded(&key(), Direction::ToBoard);
    assert_eq!(
        one_shot(&stamped(&arm(1), CEILING - 5), &mut rx),
        Ok(arm(1))
    );
    assert_eq!(one_shot(&stamped(&arm(2), CEILING + 1), &mut rx), AHEAD);
    assert_eq!(one_shot(&stamped(&arm(3), CEILING), &mut rx), Ok(arm(3)));
}

#[test]
fn only_authentic_frames_count_as_ahead_and_the_navigation_end_is_unbounded() {
    let mut rx = Verifier::bounded(&key(), Direction::ToBoard);
    assert_eq!(one_shot(&stamped(&arm(1), 1_000), &mut rx), Ok(arm(1)));
    // A forger's far-ahead stamp is a bad MAC, not a clock that jumped.
    let mut forger = Signer::new(&LinkKey::new([0x55; 32]), Direction::ToBoard);
    forger.advance_to(MAX_TIMESTAMP - 1);
    assert_eq!(
        one_shot(&signed(&arm(2), &mut forger), &mut rx),
        Err(LinkError::Auth(AuthError::BadMac))
    );
    // The navigation computer's end keeps MAVLink's rule: the board's stamps jump from its own
    // count to its peer's clock as soon as it hears it, and that is accepted.
    let mut nav = Verifier::new(&key(), Direction::FromBoard);
    let mut board = Signer::new(&key(), Direction::FromBoard);
    let first = signed(&arm(1), &mut board);
    board.advance_to(JAN_2026);
    let jumped = signed(&arm(2), &mut board);
    assert_eq!(one_shot(&first, &mut nav), Ok(arm(1)));
    assert_eq!(one_shot(&jumped, &mut nav), Ok(arm(2)));
    assert_eq!(nav.limit(), MAX_TIMESTAMP);
}

/// What a key holder sends the board, and the time the board counts between frames.
#[derive(Clone, Debug)]
enum Event {
    /// A frame stamped this far above the peer's previous stamp (anything up to 2⁴⁸).
    Step(u64),
    /// A frame at this absolute stamp.
    At(u64),
    /// Control periods of 1/`rate` s the board counts (`rate` 1 ..= 200 Hz).
    Periods(u32, u32),
}

fn event() -> impl Strategy<Value = Event> {
    prop_oneof![
        6 => prop_oneof![
            1u64..2_000,
            MAX_LEAD - 2_000..MAX_LEAD + 2_000,
            0..=MAX_TIMESTAMP,
        ]
        .prop_map(Event::Step),
        1 => prop_oneof![0..=MAX_TIMESTAMP, CEILING - 10..=MAX_TIMESTAMP].prop_map(Event::At),
        3 => (0u32..10_000, 1u32..=200).prop_map(|(n, r)| Event::Periods(n, r)),
    ]
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// After any sequence of frames from a key holder, the board (a bounded verifier, and a
    /// signer that follows it as `firmware::board::LinkBuffers` does) accepted exactly what
    /// the documented rule allows, can still sign, and has at least `RESERVE` minus the frames
    /// it sent left; the navigation computer verifies every one of them.
    #[test]
    fn a_key_holder_cannot_exhaust_the_boards_stamps(
        events in prop::collection::vec(event(), 1..48),
    ) {
        let mut rx = Verifier::bounded(&key(), Direction::ToBoard);
        let mut board = Signer::new(&key(), Direction::FromBoard);
        let mut nav = Verifier::new(&key(), Direction::FromBoard);
        let (mut peer, mut last, mut counted, mut sent) = (0u64, None::<u64>, 0u64, 0u64);
        for (i, e) in events.iter().enumerate() {
            let ts = match *e {
                Event::Periods(n, rate) => {
                    for _ in 0..n {
                        rx.elapse(100_000u64.div_ceil(u64::from(rate)));
                    }
                    counted += u64::from(n) * 100_000u64.div_ceil(u64::from(rate));
                    continue;
                }
                Event::Step(s) => peer.saturating_add(s),
                Event::At(t) => t,
            };
            if ts == 0 || ts > MAX_TIMESTAMP {
                continue;
            }
            peer = ts;
            let env = arm(i as u16);
            let got = one_shot(&stamped(&env, ts), &mut rx);
            // The rule, from the docs: above the last; at most the ceiling; at most ten minutes
            // plus the time counted ahead of the last.
            let want = match last {
                Some(l) if ts <= l => Err(LinkError::Auth(AuthError::Replay)),
                _ if ts > CEILING => AHEAD,
                Some(l) if ts - l > MAX_LEAD + counted => AHEAD,
                _ => Ok(env),
            };
            prop_assert_eq!(got, want, "ts {}, last {:?}, counted {}", ts, last, counted);
            if got.is_ok() {
                last = Some(ts);
                counted = 0;
            }
            // The board answers: one above the larger of its last stamp and the last accepted.
            if let Some(t) = rx.last_timestamp() {
                board.advance_to(t);
            }
            let frame = signed(&Envelope::new(i as u16, Msg::Command(Command::Disarm)), &mut board);
            sent += 1;
            prop_assert!(board.timestamp() <= CEILING + sent);
            prop_assert!(MAX_TIMESTAMP - board.timestamp() >= RESERVE - sent);
            prop_assert!(one_shot(&frame, &mut nav).is_ok());
        }
    }
}
