//! The `frame_decoder` fuzz target (fuzz/fuzz_targets/frame_decoder.rs) as property tests, so
//! that the stable test suite checks the same properties without nightly or libFuzzer:
//!
//! - [`FrameDecoder::push`] never panics on any byte stream and reports exactly what a model
//!   built on [`decode_frame`] (run on a copy of each delimited frame) predicts, with matching
//!   counters;
//! - every `Ok(envelope)` re-encodes with [`encode`] to a well-formed frame that decodes,
//!   streaming and one-shot, to the same envelope, compared bit for bit (NaN-safe).
//!
//! Streams: arbitrary bytes; bytes rich in delimiters and COBS codes; arbitrary bodies given a
//! correct CRC and stuffed ("framed", as the fuzz target does); and bodies drawn from a grammar
//! of near-valid envelopes (right and wrong tags, overlong varints, NaN payloads, truncation,
//! trailing bytes), so that most frames reach the deserializer and many decode.

use auv_link::{decode_frame, Envelope, FrameDecoder, LinkError, MAX_BODY, PROTOCOL_VERSION};
use proptest::prelude::*;
use proptest::strategy::ValueTree;

// The model, the re-encode check, CRC/COBS and bitwise equality, shared with the fuzz target.
#[path = "common/frames.rs"]
mod frames;
use frames::*;

// ---------------------------------------------------------------------------------------------
// The checks (the same as the fuzz target's)

/// Feeds `bytes` to a fresh decoder one at a time and compares with the model; returns how many
/// envelopes were accepted.
fn check_stream(bytes: &[u8]) -> usize {
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
    let oks = got.iter().filter(|r| r.is_ok()).count();
    let errs = got.len() - oks;
    assert_eq!(
        (dec.rx_frames(), dec.rx_errors()),
        (oks as u32, errs as u32)
    );
    for env in got.iter().flatten() {
        assert_eq!(env.version, PROTOCOL_VERSION);
        check_reencode(env);
    }
    oks
}

/// The whole input as one frame: no panic; if it decodes, it re-encodes.
fn check_whole(bytes: &[u8]) {
    if let Ok(env) = decode_frame(&mut bytes.to_vec()) {
        check_reencode(&env);
    }
}

// ---------------------------------------------------------------------------------------------
// Framed interpretation (as in the fuzz target): length-prefixed bodies with a correct CRC

fn framed(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut rest = data;
    while let Some((&len, tail)) = rest.split_first() {
        // Up to a little beyond the largest body, so that oversize frames occur too.
        let len = (len as usize % (MAX_BODY + 8)).min(tail.len());
        let (body, tail) = tail.split_at(len);
        out.extend(frame_body(body));
        rest = tail;
    }
    out
}

/// `body` ‖ CRC, stuffed and delimited.
fn frame_body(body: &[u8]) -> Vec<u8> {
    let mut raw = body.to_vec();
    raw.extend_from_slice(&crc16(body));
    stuff(&raw)
}

// ---------------------------------------------------------------------------------------------
// A grammar of near-valid postcard envelopes, driven by entropy bytes (zero past the end), so
// that proptest shrinks the entropy and the body with it.

struct Entropy<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Entropy<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// `value` with probability 7/8 (and for zero entropy), else an arbitrary byte.
    fn tag(&mut self, value: u8) -> u8 {
        if self.byte() % 8 != 7 {
            value
        } else {
            self.byte()
        }
    }

    /// One of `0..n` mostly (0 for zero entropy), sometimes the invalid `n` or anything.
    fn choice(&mut self, n: u8) -> u8 {
        match self.byte() % 16 {
            14 => n,
            15 => self.byte(),
            _ => self.byte() % n,
        }
    }

    /// A LEB128 varint of at most `max` bytes, sometimes overlong or too long.
    fn varint(&mut self, max: u8, out: &mut Vec<u8>) {
        let len = 1 + self.byte() % (max + 1);
        for i in 0..len {
            let b = self.byte();
            out.push(if i + 1 < len { b | 0x80 } else { b & 0x7F });
        }
    }

    fn f32(&mut self, out: &mut Vec<u8>) {
        let x = match self.byte() % 8 {
            0 => 0,
            1 => f32::NAN.to_bits() ^ u32::from(self.byte()),
            2 => f32::INFINITY.to_bits() | (u32::from(self.byte() & 1) << 31),
            3 => u32::from(self.byte()), // subnormal
            _ => u32::from_le_bytes([self.byte(), self.byte(), self.byte(), self.byte()]),
        };
        out.extend_from_slice(&x.to_le_bytes());
    }

    fn f32s(&mut self, n: usize, out: &mut Vec<u8>) {
        for _ in 0..n {
            self.f32(out);
        }
    }

    fn bool(&mut self, out: &mut Vec<u8>) {
        out.push(self.choice(2));
    }

    fn option(&mut self, out: &mut Vec<u8>, value: impl FnOnce(&mut Self, &mut Vec<u8>)) {
        let tag = self.choice(2);
        out.push(tag);
        if tag == 1 {
            value(self, out);
        }
    }
}

/// One body: version, seq, then a State, Command or Telemetry (or a bad tag), then possibly
/// cut short, extended or with one byte flipped.
fn grammar_body(entropy: &[u8]) -> Vec<u8> {
    let mut e = Entropy {
        data: entropy,
        pos: 0,
    };
    let mut b = vec![e.tag(PROTOCOL_VERSION)];
    e.varint(3, &mut b);
    let msg = e.choice(3);
    b.push(msg);
    match msg {
        0 => {
            e.varint(10, &mut b);
            e.f32s(12, &mut b);
        }
        1 => {
            let cmd = e.choice(5);
            b.push(cmd);
            match cmd {
                2 => {
                    let kind = e.choice(4);
                    b.push(kind);
                    e.f32s(if kind == 3 { 4 } else { 3 }, &mut b);
                }
                4 => {
                    e.option(&mut b, |e, b| e.varint(5, b));
                    e.option(&mut b, |e, b| e.bool(b));
                    e.option(&mut b, |e, b| e.f32(b));
                    e.option(&mut b, |e, b| e.f32(b));
                    e.option(&mut b, |e, b| {
                        let x = e.byte();
                        b.push(x)
                    });
                    e.option(&mut b, |e, b| e.bool(b));
                }
                _ => {}
            }
        }
        2 => {
            e.varint(10, &mut b);
            let status = e.choice(4);
            b.push(status);
            if status == 3 {
                let reason = e.choice(5);
                b.push(reason);
            }
            e.f32s(5 + 5 + 6, &mut b); // voltages, thrusts, tau
            let saturated = e.byte();
            b.push(saturated);
            e.f32(&mut b); // delta
            e.bool(&mut b);
            e.f32(&mut b); // w_norm
            let fault = e.byte();
            b.push(fault);
            for _ in 0..4 {
                e.varint(5, &mut b);
            }
            e.varint(3, &mut b);
        }
        _ => {}
    }
    match e.byte() % 8 {
        5 => {
            let cut = usize::from(e.byte()) % (b.len() + 1);
            b.truncate(cut);
        }
        6 => {
            let extra = e.byte();
            b.push(extra);
        }
        7 => {
            let at = usize::from(e.byte()) % b.len();
            b[at] ^= 1 << (e.byte() % 8);
        }
        _ => {}
    }
    b
}

// ---------------------------------------------------------------------------------------------
// Properties

/// Bytes rich in delimiters, COBS codes and version bytes.
fn delimiter_rich() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(
        prop_oneof![
            2 => Just(0u8),
            1 => Just(1u8),
            1 => Just(2u8),
            1 => Just(0xFFu8),
            4 => any::<u8>(),
        ],
        0..400,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_decode_like_the_model(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        check_stream(&bytes);
        check_whole(&bytes);
        check_stream(&framed(&bytes));
    }

    #[test]
    fn delimiter_rich_bytes_decode_like_the_model(bytes in delimiter_rich()) {
        check_stream(&bytes);
        check_whole(&bytes);
        check_stream(&framed(&bytes));
    }

    #[test]
    fn near_valid_bodies_decode_like_the_model_and_reencode(
        bodies in prop::collection::vec(prop::collection::vec(any::<u8>(), 0..200), 1..6),
        noise in prop::collection::vec(any::<u8>(), 0..8),
    ) {
        let mut wire = noise;
        for entropy in &bodies {
            wire.extend(frame_body(&grammar_body(entropy)));
        }
        check_stream(&wire);
        for entropy in &bodies {
            let body = grammar_body(entropy);
            let mut frame = frame_body(&body);
            frame.pop();
            check_whole(&frame);
        }
    }
}

/// The grammar must actually reach `Ok` often, or the re-encode property above checks little.
#[test]
fn the_grammar_produces_valid_envelopes() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = prop::collection::vec(any::<u8>(), 0..200);
    let mut oks = 0;
    for _ in 0..500 {
        let entropy = strategy.new_tree(&mut runner).unwrap().current();
        oks += check_stream(&frame_body(&grammar_body(&entropy)));
    }
    assert!(oks > 50, "only {oks} of 500 grammar bodies decoded");
}
