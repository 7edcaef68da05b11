//! The Enttec DMX USB Pro widget API (lights).
//!
//! Every message is `7E label lenLSB lenMSB data… E7`, with 0..=600 data
//! bytes. The labels this crate uses:
//!
//! | label | direction | meaning |
//! | --- | --- | --- |
//! | 3 | host → widget → host | get widget parameters (request: 2 bytes of user-config size; reply: firmware LSB, MSB, break time, mark-after-break time, refresh rate) |
//! | 6 | host → widget | output-only send DMX: the data is the DMX start code (0 for dimmer data) then channel 1, 2, … |
//! | 10 | host → widget → host | get serial number (request empty; reply 4 bytes, BCD, LSB first) |
//!
//! The widget's manual asks for 24 to 512 channels in label 6 (data length
//! 25..=513 with the start code); [`host`] pads shorter universes with zeros.
//! RDM and the DMX-input labels are not supported.

pub mod device;
#[cfg(feature = "std")]
pub mod host;

use thiserror::Error;

/// Start-of-message delimiter.
pub const START: u8 = 0x7E;
/// End-of-message delimiter.
pub const END: u8 = 0xE7;
/// Largest data length the widget accepts.
pub const MAX_DATA: usize = 600;
/// DMX channels in a universe.
pub const UNIVERSE: usize = 512;
/// Fewest channels a label 6 message should carry.
pub const MIN_CHANNELS: usize = 24;

/// Message labels.
pub mod label {
    /// Get widget parameters.
    pub const GET_PARAMETERS: u8 = 3;
    /// Output-only send DMX packet.
    pub const SEND_DMX: u8 = 6;
    /// Get widget serial number.
    pub const GET_SERIAL: u8 = 10;
}

/// Why bytes are not a valid widget message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum EnttecError {
    /// The data length field exceeds [`MAX_DATA`].
    #[error("data length {0} exceeds {MAX_DATA}")]
    TooLong(usize),
    /// The byte after the data is not `E7`.
    #[error("missing E7 end delimiter (found {0:#04x})")]
    NoEnd(u8),
    /// The output buffer is too small.
    #[error("output buffer too small")]
    Overflow,
}

/// Encode a message; returns the number of bytes written.
pub fn encode(label: u8, data: &[u8], out: &mut [u8]) -> Result<usize, EnttecError> {
    if data.len() > MAX_DATA {
        return Err(EnttecError::TooLong(data.len()));
    }
    let n = data.len() + 5;
    if out.len() < n {
        return Err(EnttecError::Overflow);
    }
    let [lo, hi] = (data.len() as u16).to_le_bytes();
    out[0] = START;
    out[1] = label;
    out[2] = lo;
    out[3] = hi;
    out[4..4 + data.len()].copy_from_slice(data);
    out[n - 1] = END;
    Ok(n)
}

/// Encode a label 6 message carrying start code 0 and `levels` (channel 1
/// first); returns the number of bytes written.
pub fn encode_dmx(levels: &[u8], out: &mut [u8]) -> Result<usize, EnttecError> {
    if levels.len() > UNIVERSE {
        return Err(EnttecError::TooLong(levels.len() + 1));
    }
    let n = levels.len() + 6;
    if out.len() < n {
        return Err(EnttecError::Overflow);
    }
    let [lo, hi] = (levels.len() as u16 + 1).to_le_bytes();
    out[..5].copy_from_slice(&[START, label::SEND_DMX, lo, hi, 0]);
    out[5..5 + levels.len()].copy_from_slice(levels);
    out[n - 1] = END;
    Ok(n)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Start,
    Label,
    LenLo,
    LenHi,
    Data,
    End,
}

/// Finds widget messages in a byte stream, with a fixed buffer.
#[derive(Debug, Clone)]
pub struct Deframer {
    state: State,
    label: u8,
    len: usize,
    got: usize,
    data: [u8; MAX_DATA],
}

impl Default for Deframer {
    fn default() -> Self {
        Self {
            state: State::Start,
            label: 0,
            len: 0,
            got: 0,
            data: [0; MAX_DATA],
        }
    }
}

impl Deframer {
    /// Push one byte; when a message completes, returns its label (read its
    /// data with [`Deframer::data`]), or why it was rejected.
    pub fn push(&mut self, b: u8) -> Option<Result<u8, EnttecError>> {
        match self.state {
            State::Start => {
                if b == START {
                    self.state = State::Label;
                }
                None
            }
            State::Label => {
                self.label = b;
                self.state = State::LenLo;
                None
            }
            State::LenLo => {
                self.len = usize::from(b);
                self.state = State::LenHi;
                None
            }
            State::LenHi => {
                self.len |= usize::from(b) << 8;
                self.got = 0;
                if self.len > MAX_DATA {
                    self.state = State::Start;
                    return Some(Err(EnttecError::TooLong(self.len)));
                }
                self.state = if self.len == 0 { State::End } else { State::Data };
                None
            }
            State::Data => {
                self.data[self.got] = b;
                self.got += 1;
                if self.got == self.len {
                    self.state = State::End;
                }
                None
            }
            State::End => {
                self.state = State::Start;
                if b == END {
                    Some(Ok(self.label))
                } else {
                    // The byte may begin the next message.
                    if b == START {
                        self.state = State::Label;
                    }
                    Some(Err(EnttecError::NoEnd(b)))
                }
            }
        }
    }

    /// The data of the message last returned by [`Deframer::push`].
    pub fn data(&self) -> &[u8] {
        &self.data[..self.got.min(self.len)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn label6_layout_matches_the_api() {
        let mut out = [0u8; 600];
        // Three channels: length 4 = start code + 3, LSB first.
        let n = encode_dmx(&[0xFF, 0x80, 0x00], &mut out).unwrap();
        assert_eq!(&out[..n], &[0x7E, 0x06, 0x04, 0x00, 0x00, 0xFF, 0x80, 0x00, 0xE7]);
        // A full universe: 7E 06 01 02 00 <512 levels> E7 (length 513 = 0x0201).
        let mut big = [0u8; 520];
        let n = encode_dmx(&[7u8; 512], &mut big).unwrap();
        assert_eq!(n, 518);
        assert_eq!(&big[..5], &[0x7E, 0x06, 0x01, 0x02, 0x00]);
        assert_eq!(big[517], 0xE7);
        // Get serial number: empty request.
        let n = encode(label::GET_SERIAL, &[], &mut out).unwrap();
        assert_eq!(&out[..n], &[0x7E, 0x0A, 0x00, 0x00, 0xE7]);
    }

    #[test]
    fn deframer_rejects_and_resyncs() {
        let mut d = Deframer::default();
        let stream = [0x7E, 0x06, 0x02, 0x00, 0x00, 0x10, 0x00, 0x7E, 0x0A, 0x00, 0x00, 0xE7];
        let got: Vec<_> = stream.iter().filter_map(|&b| d.push(b)).collect();
        assert_eq!(got, [Err(EnttecError::NoEnd(0x00)), Ok(label::GET_SERIAL)]);
        assert_eq!(d.push(0x7E), None);
        assert_eq!(d.push(0x06), None);
        assert_eq!(d.push(0xFF), None);
        assert_eq!(d.push(0xFF), Some(Err(EnttecError::TooLong(0xFFFF))));
    }

    proptest! {
        #[test]
        fn round_trip(label: u8, data in proptest::collection::vec(any::<u8>(), 0..=MAX_DATA)) {
            let mut out = [0u8; MAX_DATA + 5];
            let n = encode(label, &data, &mut out).unwrap();
            let mut d = Deframer::default();
            let got: Vec<_> = out[..n].iter().filter_map(|&b| d.push(b)).collect();
            prop_assert_eq!(got, vec![Ok(label)]);
            prop_assert_eq!(d.data(), &data[..]);
        }

        #[test]
        fn deframer_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..1500)) {
            let mut d = Deframer::default();
            for b in bytes { let _ = d.push(b); let _ = d.data(); }
        }
    }
}
