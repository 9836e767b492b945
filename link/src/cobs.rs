//! Consistent Overhead Byte Stuffing (Cheshire & Baker, 1999), this crate's own implementation.
//!
//! The encoded form contains no `0x00`, so `0x00` can delimit frames. The data is cut at each
//! zero (and after every run of 254 non-zero bytes) into blocks; each block is sent as a code
//! byte `c` (1..=255) followed by its `c − 1` non-zero bytes. A code below `0xFF` stands for its
//! bytes *and a zero*; `0xFF` stands for 254 bytes and no zero. The zero implied by the last
//! block is not part of the data.
//!
//! Neither function allocates or panics, whatever the input.

/// Worst-case encoded length of `n` data bytes (no delimiter): one code byte, plus one more for
/// every 254 data bytes.
pub const fn max_encoded_len(n: usize) -> usize {
    n + n / 254 + 1
}

/// Encodes `src` into `dst` (no delimiter) and returns the encoded length, or `None` if `dst` is
/// too short. At most [`max_encoded_len`]`(src.len())` bytes are written.
pub fn encode(src: &[u8], dst: &mut [u8]) -> Option<usize> {
    // Index of the pending block's code byte, the next free index, and the pending code.
    let mut code_at = 0;
    let mut out = 1;
    let mut code: u8 = 1;
    if dst.is_empty() {
        return None;
    }
    for &byte in src {
        if byte == 0 {
            *dst.get_mut(code_at)? = code;
            code_at = out;
            out += 1;
            code = 1;
        } else {
            *dst.get_mut(out)? = byte;
            out += 1;
            code += 1;
            if code == 0xFF {
                *dst.get_mut(code_at)? = code;
                code_at = out;
                out += 1;
                code = 1;
            }
        }
    }
    *dst.get_mut(code_at)? = code;
    Some(out)
}

/// The input is not a valid COBS encoding: it contains a `0x00`, or a code byte promises more
/// bytes than the frame has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CobsError;

/// Decodes `buf` (one frame without its delimiter) in place and returns the decoded length;
/// the decoded bytes are `buf[..len]`. Work is linear in `buf.len()`.
pub fn decode_in_place(buf: &mut [u8]) -> Result<usize, CobsError> {
    let len = buf.len();
    let mut read = 0;
    let mut write = 0;
    // Invariant: write < read ≤ len after each code byte, so the copy never overtakes the read.
    while read < len {
        let code = buf[read];
        if code == 0 {
            return Err(CobsError);
        }
        read += 1;
        let n = usize::from(code) - 1;
        let end = read + n;
        if end > len {
            return Err(CobsError);
        }
        if buf[read..end].contains(&0) {
            return Err(CobsError);
        }
        buf.copy_within(read..end, write);
        write += n;
        read = end;
        if code != 0xFF && read < len {
            buf[write] = 0;
            write += 1;
        }
    }
    Ok(write)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(data: &[u8]) {
        let mut enc = [0u8; 1024];
        let n = encode(data, &mut enc).unwrap();
        assert!(n <= max_encoded_len(data.len()));
        assert!(!enc[..n].contains(&0), "{data:?} -> {:?}", &enc[..n]);
        let m = decode_in_place(&mut enc[..n]).unwrap();
        assert_eq!(&enc[..m], data);
    }

    #[test]
    fn known_vectors() {
        // From the COBS paper / Wikipedia examples.
        let cases: &[(&[u8], &[u8])] = &[
            (&[], &[0x01]),
            (&[0x00], &[0x01, 0x01]),
            (&[0x00, 0x00], &[0x01, 0x01, 0x01]),
            (&[0x11, 0x22, 0x00, 0x33], &[0x03, 0x11, 0x22, 0x02, 0x33]),
            (&[0x11, 0x22, 0x33, 0x44], &[0x05, 0x11, 0x22, 0x33, 0x44]),
            (&[0x11, 0x00, 0x00, 0x00], &[0x02, 0x11, 0x01, 0x01, 0x01]),
        ];
        for (data, want) in cases {
            let mut enc = [0u8; 16];
            let n = encode(data, &mut enc).unwrap();
            assert_eq!(&enc[..n], *want);
            let mut buf = [0u8; 16];
            buf[..n].copy_from_slice(want);
            let m = decode_in_place(&mut buf[..n]).unwrap();
            assert_eq!(&buf[..m], *data);
        }
    }

    #[test]
    fn long_runs() {
        let mut data = [0u8; 600];
        for (i, b) in data.iter_mut().enumerate() {
            *b = (i % 255) as u8 + 1;
        }
        for len in [253, 254, 255, 507, 508, 509, 600] {
            round_trip(&data[..len]);
            let mut enc = [0u8; 1024];
            assert_eq!(encode(&data[..len], &mut enc), Some(max_encoded_len(len)));
        }
        data[254] = 0;
        data[0] = 0;
        round_trip(&data);
    }

    #[test]
    fn short_destination_is_refused() {
        let data = [1u8, 2, 0, 3];
        let mut enc = [0u8; 5];
        assert_eq!(encode(&data, &mut enc), Some(5));
        for len in 0..5 {
            assert_eq!(encode(&data, &mut enc[..len]), None, "len {len}");
        }
    }

    #[test]
    fn malformed_input_is_rejected() {
        assert_eq!(decode_in_place(&mut [0x03, 0x11]), Err(CobsError)); // truncated block
        assert_eq!(decode_in_place(&mut [0x00]), Err(CobsError)); // zero code
        assert_eq!(decode_in_place(&mut [0x03, 0x00, 0x11]), Err(CobsError)); // zero in a block
        assert_eq!(decode_in_place(&mut []), Ok(0));
    }
}
