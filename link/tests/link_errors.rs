//! Corruption and resynchronisation: every single-byte corruption caught and the stream
//! recovered, other versions refused before parsing, the documented format built by hand,
//! oversize frames, and the errors' text.

use auv_link::sign::{AuthError, SIGNATURE_LEN};
use auv_link::{
    decode_frame, Command, Envelope, FrameDecoder, LinkError, Msg, MAX_FRAME, PROTOCOL_VERSION,
};

// Reference COBS and CRC-16, written independently of the crate's (shared with the fuzz checks),
// and the envelopes every test here sends.
#[path = "common/envelopes.rs"]
mod envelopes;
#[path = "common/frames.rs"]
mod frames;
use envelopes::{decode_stream, every_kind, frame, frame_from_body, largest};
use frames::{crc16, stuff};

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
    for version in [0u8, 1, 2, 3, 4, 5, 6, 7, 9, 0x7F, 0xFF] {
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
    let wire = frame_from_body(&[9, 0xFF, 0xFF, 0xFF, 0x7F, 0xEE]);
    assert_eq!(
        decode_stream(&wire),
        vec![Err(LinkError::Version { got: 9 })]
    );
}

#[test]
fn hand_made_frames_match_the_documented_format() {
    // Envelope { version 8, seq 300 (varint AC 02), Command(Arm) } built from the docs alone.
    assert_eq!(PROTOCOL_VERSION, 8);
    let wire = frame_from_body(&[8, 0xAC, 0x02, 0x01, 0x00]);
    let env = Envelope::new(300, Msg::Command(Command::Arm));
    assert_eq!(wire, frame(&env));
    // A body with a byte left over (or 12, or 14: not a signature), or a bad variant, or cut
    // short: Deserialize.
    for body in [
        &[8, 0xAC, 0x02, 0x01, 0x00, 0x00][..],
        &[&[8, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN - 1]].concat()[..],
        &[&[8, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN + 1]].concat()[..],
        &[8, 0x00, 0x03][..],
        &[8, 0x00, 0x01, 0x06][..],
        &[8, 0x00, 0x00, 0x01][..],
        &[8][..],
    ] {
        assert_eq!(
            decode_stream(&frame_from_body(body)),
            vec![Err(LinkError::Deserialize)],
            "{body:?}"
        );
    }
    // Exactly a signature's length left over: a signed frame, which an unsigned link refuses.
    let signed = [&[8, 0xAC, 0x02, 0x01, 0x00][..], &[7; SIGNATURE_LEN]].concat();
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
