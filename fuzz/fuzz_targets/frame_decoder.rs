//! Fuzzes the auv-link receiver.
//!
//! Every input is checked twice:
//!
//! 1. **Raw:** the bytes as they are, as a received byte stream (the whole input is also given
//!    to `decode_frame` as one frame).
//! 2. **Framed:** the bytes read as length-prefixed bodies (`L = byte % (MAX_BODY + 8)`, then
//!    `L` bytes), each given a correct CRC-16, COBS-stuffed and delimited, so that the postcard
//!    deserializer is reached without the fuzzer having to solve the CRC.
//!
//! For each stream: [`FrameDecoder::push`] byte by byte never panics and returns exactly what a
//! model built on [`decode_frame`] (run on a copy of each delimited frame) predicts, its counters
//! agree, and every `Ok(envelope)` re-encodes with [`encode`] to a well-formed frame that decodes
//! (streaming and one-shot) to the same envelope, compared bit for bit (NaN-safe).

#![no_main]

use auv_link::{decode_frame, Envelope, FrameDecoder, LinkError, MAX_BODY, PROTOCOL_VERSION};
use libfuzzer_sys::fuzz_target;

// The model, the re-encode check, CRC/COBS and bitwise equality, shared with the proptests.
#[path = "../../link/tests/common/frames.rs"]
mod frames;
use frames::*;

fuzz_target!(|data: &[u8]| {
    check_stream(data);
    check_stream(&framed(data));
    // The whole input as one frame (zeros and all): an error or a valid envelope, no panic.
    if let Ok(env) = decode_frame(&mut data.to_vec()) {
        check_reencode(&env);
    }
});

/// Feeds `bytes` to a fresh decoder one at a time and compares with the model.
fn check_stream(bytes: &[u8]) {
    let mut dec = FrameDecoder::new();
    let got: Vec<Result<Envelope, LinkError>> = bytes.iter().filter_map(|&b| dec.push(b)).collect();
    let want = model(bytes);
    assert_eq!(got.len(), want.len(), "results {got:?}, model {want:?}");
    for (g, w) in got.iter().zip(&want) {
        match (g, w) {
            (Ok(a), Ok(b)) => assert!(same_envelope(a, b), "{a:?} != {b:?}"),
            _ => assert_eq!(g, w),
        }
    }
    let oks = got.iter().filter(|r| r.is_ok()).count() as u32;
    let errs = got.len() as u32 - oks;
    assert_eq!((dec.rx_frames(), dec.rx_errors()), (oks, errs));
    for env in got.iter().flatten() {
        assert_eq!(env.version, PROTOCOL_VERSION);
        check_reencode(env);
    }
}

// ---------------------------------------------------------------------------------------------
// Framed interpretation

/// Length-prefixed bodies, each with a correct CRC, stuffed and delimited.
fn framed(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut rest = data;
    while let Some((&len, tail)) = rest.split_first() {
        // Up to a little beyond the largest body, so that oversize frames occur too.
        let len = (len as usize % (MAX_BODY + 8)).min(tail.len());
        let (body, tail) = tail.split_at(len);
        let mut raw = body.to_vec();
        raw.extend_from_slice(&crc16(body));
        out.extend(stuff(&raw));
        rest = tail;
    }
    out
}
