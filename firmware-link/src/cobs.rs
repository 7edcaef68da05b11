//! Consistent Overhead Byte Stuffing (Cheshire and Baker, 1999).
//!
//! COBS rewrites a block so that it contains no zero byte, at a cost of at
//! most one byte per 254 plus one. A zero byte can then delimit frames on the
//! wire: a receiver that loses sync (a dropped or corrupted byte) regains it
//! at the next zero. Works on caller-provided slices; no allocation.

use thiserror::Error;

/// Why a COBS block could not be encoded or decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum CobsError {
    /// The output slice is too small.
    #[error("output buffer too small")]
    Overflow,
    /// The block contains a zero byte, which COBS never produces.
    #[error("zero byte inside an encoded block")]
    ZeroInBlock,
    /// A code byte points past the end of the block.
    #[error("truncated block")]
    Truncated,
}

/// Largest encoded size for `n` input bytes.
pub const fn max_encoded_len(n: usize) -> usize {
    n + n / 254 + 1
}

/// Encode `src` into `dst` (without the trailing zero delimiter); returns the
/// encoded length.
pub fn encode(src: &[u8], dst: &mut [u8]) -> Result<usize, CobsError> {
    if dst.is_empty() {
        return Err(CobsError::Overflow);
    }
    let mut code_at = 0usize;
    let mut out = 1usize;
    let mut code: u8 = 1;
    let mut open = true;
    for &b in src {
        if !open {
            // A full 254-byte run closed the previous block and more input follows.
            code_at = out;
            out += 1;
            code = 1;
            open = true;
            if code_at >= dst.len() {
                return Err(CobsError::Overflow);
            }
        }
        if b == 0 {
            dst[code_at] = code;
            code_at = out;
            out += 1;
            code = 1;
            if code_at >= dst.len() {
                return Err(CobsError::Overflow);
            }
        } else {
            if out >= dst.len() {
                return Err(CobsError::Overflow);
            }
            dst[out] = b;
            out += 1;
            code += 1;
            if code == 0xFF {
                dst[code_at] = code;
                open = false;
            }
        }
    }
    if open {
        dst[code_at] = code;
    }
    Ok(out)
}

/// Decode one block `src` (without its delimiter) into `dst`; returns the
/// decoded length. Never panics.
pub fn decode(src: &[u8], dst: &mut [u8]) -> Result<usize, CobsError> {
    let mut i = 0usize;
    let mut out = 0usize;
    while i < src.len() {
        let code = src[i];
        if code == 0 {
            return Err(CobsError::ZeroInBlock);
        }
        i += 1;
        let run = usize::from(code) - 1;
        if i + run > src.len() {
            return Err(CobsError::Truncated);
        }
        for &b in &src[i..i + run] {
            if b == 0 {
                return Err(CobsError::ZeroInBlock);
            }
            if out >= dst.len() {
                return Err(CobsError::Overflow);
            }
            dst[out] = b;
            out += 1;
        }
        i += run;
        if code != 0xFF && i < src.len() {
            if out >= dst.len() {
                return Err(CobsError::Overflow);
            }
            dst[out] = 0;
            out += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn enc(src: &[u8]) -> Vec<u8> {
        let mut buf = vec![0u8; max_encoded_len(src.len())];
        let n = encode(src, &mut buf).unwrap();
        buf.truncate(n);
        buf
    }

    /// The worked examples from the COBS paper / the usual published table.
    #[test]
    fn published_examples() {
        assert_eq!(enc(&[0x00]), [0x01, 0x01]);
        assert_eq!(enc(&[0x00, 0x00]), [0x01, 0x01, 0x01]);
        assert_eq!(enc(&[0x11, 0x22, 0x00, 0x33]), [0x03, 0x11, 0x22, 0x02, 0x33]);
        assert_eq!(enc(&[0x11, 0x22, 0x33, 0x44]), [0x05, 0x11, 0x22, 0x33, 0x44]);
        assert_eq!(enc(&[0x11, 0x00, 0x00, 0x00]), [0x02, 0x11, 0x01, 0x01, 0x01]);
        assert_eq!(enc(&[]), [0x01]);
        let ones: Vec<u8> = (1..=254).collect();
        let e = enc(&ones);
        assert_eq!(e.len(), 255);
        assert_eq!(e[0], 0xFF);
        assert_eq!(&e[1..], &ones[..]);
        let ones255: Vec<u8> = (1..=255).collect();
        let e = enc(&ones255);
        assert_eq!(e.len(), 257);
        assert_eq!(&e[..2], &[0xFF, 0x01]);
        assert_eq!(&e[254..], &[0xFE, 0x02, 0xFF]);
    }

    #[test]
    fn rejects_bad_blocks() {
        let mut out = [0u8; 8];
        assert_eq!(decode(&[0x05, 0x11], &mut out), Err(CobsError::Truncated));
        assert_eq!(decode(&[0x02, 0x00], &mut out), Err(CobsError::ZeroInBlock));
        assert_eq!(decode(&[0x00], &mut out), Err(CobsError::ZeroInBlock));
    }

    proptest! {
        #[test]
        fn round_trip(data in proptest::collection::vec(any::<u8>(), 0..600)) {
            let e = enc(&data);
            prop_assert!(!e.contains(&0));
            prop_assert!(e.len() <= max_encoded_len(data.len()));
            let mut out = vec![0u8; data.len()];
            let n = decode(&e, &mut out).unwrap();
            prop_assert_eq!(&out[..n], &data[..]);
        }

        #[test]
        fn decode_never_panics(data in proptest::collection::vec(any::<u8>(), 0..300)) {
            let mut out = [0u8; 64];
            let _ = decode(&data, &mut out);
        }
    }
}
