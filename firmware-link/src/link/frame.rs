//! campanile-link framing: header, bounded payload, CRC-32C, COBS.

use crate::cobs::{self, CobsError};
use crc::{CRC_32_ISCSI, Crc, NoTable};
use thiserror::Error;

/// The protocol version this crate speaks.
pub const VERSION: u8 = 1;
/// Largest payload, bytes.
pub const MAX_PAYLOAD: usize = 24;
/// Version, sequence number (2 bytes) and kind.
pub const HEADER_LEN: usize = 4;
/// CRC-32C trailer.
pub const CRC_LEN: usize = 4;
/// Largest decoded frame.
pub const MAX_RAW: usize = HEADER_LEN + MAX_PAYLOAD + CRC_LEN;
/// Largest frame on the wire, delimiter included.
pub const MAX_WIRE: usize = cobs::max_encoded_len(MAX_RAW) + 1;

/// CRC-32C without a lookup table: small enough for any microcontroller.
pub(crate) const CRC32C: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISCSI);

/// Why a received block is not a valid frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum FrameError {
    /// The COBS layer failed.
    #[error("COBS: {0}")]
    Cobs(#[from] CobsError),
    /// Fewer bytes than a header and a CRC.
    #[error("frame of {0} bytes is shorter than header and CRC")]
    TooShort(usize),
    /// More bytes than the largest frame.
    #[error("frame longer than {MAX_WIRE} bytes")]
    TooLong,
    /// The CRC does not match.
    #[error("CRC mismatch: computed {computed:#010x}, received {received:#010x}")]
    Crc {
        /// CRC of the received header and payload.
        computed: u32,
        /// CRC in the trailer.
        received: u32,
    },
    /// A payload longer than [`MAX_PAYLOAD`] was given to [`Frame::new`].
    #[error("payload of {0} bytes exceeds {MAX_PAYLOAD}")]
    PayloadTooLong(usize),
}

/// One decoded frame. The version is kept so that the receiver can answer a
/// mismatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// Protocol version of the sender.
    pub version: u8,
    /// Sequence number.
    pub seq: u16,
    /// Message kind (see [`super::message`]).
    pub kind: u8,
    payload: [u8; MAX_PAYLOAD],
    len: u8,
}

impl Frame {
    /// A frame of this crate's [`VERSION`].
    pub fn new(seq: u16, kind: u8, payload: &[u8]) -> Result<Self, FrameError> {
        if payload.len() > MAX_PAYLOAD {
            return Err(FrameError::PayloadTooLong(payload.len()));
        }
        let mut p = [0u8; MAX_PAYLOAD];
        p[..payload.len()].copy_from_slice(payload);
        Ok(Self {
            version: VERSION,
            seq,
            kind,
            payload: p,
            len: payload.len() as u8,
        })
    }

    /// The payload bytes.
    pub fn payload(&self) -> &[u8] {
        &self.payload[..usize::from(self.len)]
    }

    /// The CRC-32C of header and payload (the value in the trailer).
    pub fn crc(&self) -> u32 {
        let mut raw = [0u8; MAX_RAW];
        let n = self.write_body(&mut raw);
        CRC32C.checksum(&raw[..n])
    }

    fn write_body(&self, raw: &mut [u8; MAX_RAW]) -> usize {
        raw[0] = self.version;
        raw[1..3].copy_from_slice(&self.seq.to_le_bytes());
        raw[3] = self.kind;
        let n = HEADER_LEN + usize::from(self.len);
        raw[HEADER_LEN..n].copy_from_slice(self.payload());
        n
    }

    /// Encode for the wire, trailing `0x00` delimiter included; returns the
    /// number of bytes written to `out`.
    pub fn encode(&self, out: &mut [u8; MAX_WIRE]) -> usize {
        let mut raw = [0u8; MAX_RAW];
        let n = self.write_body(&mut raw);
        let crc = CRC32C.checksum(&raw[..n]);
        raw[n..n + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
        // MAX_WIRE is sized for MAX_RAW, so encoding cannot overflow.
        let m = cobs::encode(&raw[..n + CRC_LEN], &mut out[..MAX_WIRE - 1]).unwrap_or(0);
        out[m] = 0;
        m + 1
    }

    /// Decode one COBS block (the bytes between two delimiters).
    pub fn decode(block: &[u8]) -> Result<Self, FrameError> {
        if block.len() > MAX_WIRE - 1 {
            return Err(FrameError::TooLong);
        }
        let mut raw = [0u8; MAX_RAW];
        let n = cobs::decode(block, &mut raw).map_err(|e| match e {
            CobsError::Overflow => FrameError::TooLong,
            e => FrameError::Cobs(e),
        })?;
        if n < HEADER_LEN + CRC_LEN {
            return Err(FrameError::TooShort(n));
        }
        let body = n - CRC_LEN;
        let computed = CRC32C.checksum(&raw[..body]);
        let received = u32::from_le_bytes([raw[body], raw[body + 1], raw[body + 2], raw[body + 3]]);
        if computed != received {
            return Err(FrameError::Crc { computed, received });
        }
        let mut f = Frame::new(u16::from_le_bytes([raw[1], raw[2]]), raw[3], &raw[HEADER_LEN..body])?;
        f.version = raw[0];
        Ok(f)
    }
}

/// Splits a byte stream into frames at `0x00` delimiters, with a fixed
/// buffer. An overlong block is discarded up to the next delimiter.
#[derive(Debug, Clone)]
pub struct Deframer {
    buf: [u8; MAX_WIRE],
    len: usize,
    overflowed: bool,
}

impl Default for Deframer {
    fn default() -> Self {
        Self {
            buf: [0; MAX_WIRE],
            len: 0,
            overflowed: false,
        }
    }
}

impl Deframer {
    /// Push one byte; at a delimiter, returns the decoded frame or why it is
    /// invalid. Empty blocks (back-to-back delimiters) return `None`.
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, FrameError>> {
        if byte == 0 {
            let result = if self.overflowed {
                Some(Err(FrameError::TooLong))
            } else if self.len == 0 {
                None
            } else {
                Some(Frame::decode(&self.buf[..self.len]))
            };
            self.len = 0;
            self.overflowed = false;
            return result;
        }
        if self.len < self.buf.len() {
            self.buf[self.len] = byte;
            self.len += 1;
        } else {
            self.overflowed = true;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn wire(f: &Frame) -> Vec<u8> {
        let mut out = [0u8; MAX_WIRE];
        let n = f.encode(&mut out);
        out[..n].to_vec()
    }

    #[test]
    fn crc32c_check_value() {
        // The catalogue check value of CRC-32C over "123456789".
        assert_eq!(CRC32C.checksum(b"123456789"), 0xE306_9283);
    }

    #[test]
    fn known_frame_bytes() {
        // Heartbeat (kind 0x31), seq 0x0102, empty payload.
        // Raw: 01 02 01 31, then CRC-32C LE over those four bytes.
        let f = Frame::new(0x0102, 0x31, &[]).unwrap();
        let crc = CRC32C.checksum(&[0x01, 0x02, 0x01, 0x31]).to_le_bytes();
        let w = wire(&f);
        // No zero in the raw bytes unless the CRC has one; check by decoding.
        let mut raw = [0u8; 16];
        let n = cobs::decode(&w[..w.len() - 1], &mut raw).unwrap();
        assert_eq!(&raw[..n], &[0x01, 0x02, 0x01, 0x31, crc[0], crc[1], crc[2], crc[3]]);
        assert_eq!(*w.last().unwrap(), 0);
        assert_eq!(Frame::decode(&w[..w.len() - 1]).unwrap(), f);
    }

    #[test]
    fn every_single_bit_flip_is_caught() {
        let f = Frame::new(7, 0x01, &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
        let w = wire(&f);
        let body = &w[..w.len() - 1];
        for i in 0..body.len() {
            for bit in 0..8 {
                let mut b = body.to_vec();
                b[i] ^= 1 << bit;
                if let Ok(g) = Frame::decode(&b) {
                    panic!("flip of byte {i} bit {bit} accepted as {g:?}");
                }
            }
        }
    }

    #[test]
    fn deframer_resyncs_after_garbage() {
        let f = Frame::new(9, 0x06, &[]).unwrap();
        let mut stream = vec![0x55, 0x13, 0x00];
        stream.extend(wire(&f));
        let mut d = Deframer::default();
        let got: Vec<_> = stream.iter().filter_map(|&b| d.push(b)).collect();
        assert_eq!(got.len(), 2);
        assert!(got[0].is_err());
        assert_eq!(got[1], Ok(f));
    }

    proptest! {
        #[test]
        fn round_trip(seq: u16, kind: u8, payload in proptest::collection::vec(any::<u8>(), 0..=MAX_PAYLOAD)) {
            let f = Frame::new(seq, kind, &payload).unwrap();
            let w = wire(&f);
            prop_assert!(w.len() <= MAX_WIRE);
            prop_assert!(!w[..w.len() - 1].contains(&0));
            let mut d = Deframer::default();
            let got: Vec<_> = w.iter().filter_map(|&b| d.push(b)).collect();
            prop_assert_eq!(got, vec![Ok(f)]);
        }

        #[test]
        fn deframer_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let mut d = Deframer::default();
            for b in bytes {
                let _ = d.push(b);
            }
        }
    }
}
