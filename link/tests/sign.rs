//! Signed frames: the documented layout built by hand, the policy at each end, replay, and
//! every single-byte corruption of a signed frame.

#[path = "common/frames.rs"]
mod frames;

use auv_link::sign::{
    AuthError, Direction, LinkKey, Signer, Verifier, MAC_LEN, SIGNATURE_LEN, TIMESTAMP_LEN,
};
use auv_link::{
    decode_frame, decode_frame_signed, encode, encode_signed, Command, Envelope, FrameDecoder,
    LinkError, Msg, StateFrame, Telemetry, MAX_FRAME,
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
    // postcard(Envelope{3, seq 300, Command(Arm)}) ‖ link id 0 ‖ timestamp 5 (6 bytes LE) ‖
    // the first 6 bytes of HMAC-SHA-256(key, everything before the MAC) ‖ CRC-16 of it all.
    let covered = [3u8, 0xAC, 0x02, 0x01, 0x00];
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
    let env = Envelope::new(u16::MAX, Msg::Telemetry(Telemetry::LARGEST));
    let mut signer = Signer::new(&key(), Direction::FromBoard);
    let wire = signed(&env, &mut signer);
    assert_eq!(wire.len(), MAX_FRAME);
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
