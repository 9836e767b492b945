//! The serial link between the AUV-150's navigation computer (or the desktop simulator
//! `host-sim`) and the thruster board. `#![no_std]`, no heap, no panics on any input.
//!
//! # Frame
//!
//! ```text
//! wire:  COBS( body ) ‖ 0x00
//! body:  postcard(Envelope) ‖ [signature] ‖ CRC-16 of everything before it, little-endian (2 bytes)
//! signature (signed links only, 13 bytes): link id (1) ‖ timestamp (6, LE) ‖ truncated MAC (6)
//! ```
//!
//! - **Serialization:** [postcard](https://docs.rs/postcard) 1.x of [`Envelope`]. The first
//!   byte of the body is always [`Envelope::version`] (a `u8` is one byte in postcard), so a
//!   receiver checks the version before it interprets anything else.
//! - **Signature:** optional, in the manner of MAVLink 2 signing: truncated HMAC-SHA-256 with a
//!   48-bit timestamp that increases strictly per direction and, at the board, may not run
//!   too far ahead ([`sign`]). postcard's encoding of an `Envelope` ends where the envelope
//!   ends, so what follows it is the trailer: nothing on an unsigned frame, exactly
//!   [`sign::SIGNATURE_LEN`] bytes on a signed one, anything else malformed. Each end has
//!   signing on or off ([`FrameDecoder::signed`], [`encode_signed`]); with it on, unsigned
//!   frames are refused, and with it off, signed ones are.
//! - **CRC:** CRC-16/IBM-3740, a.k.a. CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, not
//!   reflected, no final XOR; check value 0x29B1), over the postcard bytes and the signature,
//!   appended little-endian. It detects every error of up to 3 bits and every burst of up to
//!   16 bits in the body (it is not authentication: anyone can compute it).
//! - **Framing:** Consistent Overhead Byte Stuffing of the body, by the
//!   [`cobs`](https://docs.rs/cobs) crate (not postcard's COBS helpers, which would stuff the
//!   postcard bytes without the CRC): code byte `c` = 1..=255 followed by `c − 1` non-zero
//!   bytes, `c < 0xFF` implying a zero after them. The stuffed frame contains no `0x00`; a
//!   single `0x00` ends each frame. A sender may also send a `0x00` before a frame (e.g. after
//!   reset): empty frames are ignored.
//! - **Size:** at most [`MAX_FRAME`] = 225 bytes on the wire, delimiter included
//!   ([`Envelope::MAX_SIZE`] = 208 postcard bytes + 13 signature bytes + 2 CRC bytes + 1 COBS
//!   code byte + 1 delimiter; a whole `SetConfig` is the largest message since protocol 8,
//!   sent during the set-up; a telemetry frame is at most 179 bytes signed, a state frame at
//!   most 80). At 460 800 baud (46 080 bytes/s, the STM32 board's link) the largest telemetry
//!   frame takes 3.9 ms, so a State frame in one direction and a Telemetry frame in the other
//!   fit in a 10 ms (100 Hz) control period (telemetry at 100 Hz uses 39 % of the board's
//!   transmit bandwidth); 115 200 baud (14.1 ms) would not. The largest frame takes 4.9 ms.
//!
//! # Receiving
//!
//! [`FrameDecoder::push`] takes one byte at a time; when a `0x00` completes a frame it undoes
//! COBS in place, checks the CRC, then the version byte, then deserializes, then checks the
//! trailer (none, or a signature its verifier accepts). Anything that fails is reported as a
//! [`LinkError`] (to be counted in [`Telemetry::rx_errors`], never acted on) and the decoder
//! starts afresh at the next `0x00`. A frame longer than `MAX_FRAME − 1` bytes is reported as
//! [`LinkError::Overflow`] when it overflows and dropped up to the next `0x00`.
//!
//! # Messages
//!
//! [`Envelope`] `{ version: u8 = PROTOCOL_VERSION, seq: u16, msg: Msg }`; `seq` counts frames
//! per sender (wrapping), and a receiver accepts only a frame newer than the last it accepted,
//! in serial-number arithmetic with a window ([`seq`]). The navigation computer sends
//! [`Msg::State`] (the navigation solution η, ν at a control tick) and [`Msg::Command`] (arm /
//! disarm, start a [`MissionPlan`] /
//! stop, or change settings with a [`ConfigPatch`]); the board answers with
//! [`Msg::Telemetry`], whose [`Telemetry::last_state_seq`] echoes the `seq` of the last State
//! frame it accepted, and which names the thrust unit and mounting the board flies. A
//! [`MissionPlan`] is the wire form of `controller_core::Mission` (a [`MissionSpec`] path, a
//! [`Heading`], a time scale), and [`ThrustUnit`] of the core's unit: both ends convert with
//! the `From` impls of [`mission`], the only place that maps one to the other.
//!
//! postcard lays a message out as follows (worst-case sizes in the `MAX_SIZE` constants of each
//! type): fields in declaration order, no padding, no field names; `u8` and `bool` as one byte;
//! `f32` as 4 bytes little-endian (IEEE 754 bits, NaN payloads kept); `u16`/`u32`/`u64` as
//! unsigned LEB128 varints (at most 3/5/10 bytes); `Option` as a `0`/`1` byte then the value;
//! enums as the variant index (declaration order, one byte) then the variant's fields;
//! `[f32; N]` as N floats without a length. Any change to a type's fields or variants changes
//! the wire format and needs a new [`PROTOCOL_VERSION`].
//!
//! # Example
//!
//! ```
//! use auv_link::{encode, Command, Envelope, FrameDecoder, Msg, MAX_FRAME};
//!
//! let env = Envelope::new(42, Msg::Command(Command::Arm));
//! let mut wire = [0u8; MAX_FRAME];
//! let n = encode(&env, &mut wire).unwrap();
//!
//! let mut rx = FrameDecoder::new();
//! let mut got = None;
//! rx.push_slice(&wire[..n], |result| got = Some(result));
//! assert_eq!(got, Some(Ok(env)));
//! ```
//!
//! # Features
//!
//! `defmt`: `defmt::Format` for every message type and [`LinkError`] (defmt 1.x).

#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod config;
mod frame;
mod heading;
pub mod mission;
mod msg;
mod refusal;
pub mod seq;
pub mod sign;
pub mod upload;

pub use config::{mounting_of, ConfigMismatch};
pub use frame::{
    decode_frame, decode_frame_signed, encode, encode_signed, FrameDecoder, LinkError, CRC_LEN,
    MAX_BODY, MAX_FRAME,
};
pub use heading::Heading;
pub use msg::{
    AxisPriority, BBound, BoardStatus, Command, ConfigPatch, Envelope, EstimatorSettings,
    FailSafeReason, LawSettings, MissionPlan, MissionSpec, Msg, RobustLaw, StateFrame, Telemetry,
    ThrustUnit, DEFAULT_STALE_PERIODS, NOT_AUV150, PROTOCOL_VERSION,
};
pub use refusal::Refusal;
pub use upload::{
    MissionUpload, UploadBuffer, UploadChunk, UploadHeader, UploadPart, UploadStatus,
};
