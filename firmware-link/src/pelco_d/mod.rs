//! Pelco-D, the de-facto serial protocol of PTZ heads.
//!
//! A frame is seven bytes, `FF addr cmd1 cmd2 data1 data2 sum`, where `sum`
//! is the sum of bytes 2 to 6 (address to data2) modulo 256. Besides the
//! "standard" motion bits in `cmd1`/`cmd2`, this crate encodes the extended
//! commands the station needs:
//!
//! | cmd2 | meaning | data |
//! | --- | --- | --- |
//! | `03` / `05` / `07` | set / clear / go to preset | data2 = preset |
//! | `4B` | set pan position | 1/100°, 0..=35999, MSB first |
//! | `4D` | set tilt position | 1/100°, 0..=35999, MSB first |
//! | `51` / `53` | query pan / tilt position | |
//! | `59` / `5B` | pan / tilt position response | 1/100°, MSB first |
//!
//! Angles are carried modulo 360°: a tilt of −10° goes out as 35000. Pelco-D
//! has no acknowledgement of motion commands; only the queries are answered.
//! Zoom, focus, iris and auxiliary commands are passed as raw
//! [`Frame`]s (no typed [`Command`]).

pub mod device;
#[cfg(feature = "std")]
pub mod host;

use thiserror::Error;

/// The first byte of every frame.
pub const SYNC: u8 = 0xFF;
/// Frame length.
pub const FRAME_LEN: usize = 7;
/// Hundredths of a degree in a full turn.
pub const FULL_TURN: i32 = 36_000;

/// Why bytes are not a valid Pelco-D frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum PelcoError {
    /// The first byte is not `FF`.
    #[error("missing FF sync byte")]
    NoSync,
    /// The checksum byte does not match.
    #[error("checksum {received:#04x}, expected {computed:#04x}")]
    Checksum {
        /// Sum of bytes 2-6 mod 256.
        computed: u8,
        /// Byte 7.
        received: u8,
    },
}

/// One Pelco-D frame, without the sync byte and the checksum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// Receiver address (1..=255; 0 is reserved).
    pub address: u8,
    /// Command 1: sense, auto/manual scan, camera on/off, iris, focus near.
    pub command1: u8,
    /// Command 2: focus far, zoom, tilt, pan bits; or an extended opcode.
    pub command2: u8,
    /// Data 1 (pan speed, or high byte).
    pub data1: u8,
    /// Data 2 (tilt speed, or low byte).
    pub data2: u8,
}

impl Frame {
    /// Sum of bytes 2-6 modulo 256.
    pub fn checksum(&self) -> u8 {
        self.address
            .wrapping_add(self.command1)
            .wrapping_add(self.command2)
            .wrapping_add(self.data1)
            .wrapping_add(self.data2)
    }

    /// The seven wire bytes.
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        [
            SYNC,
            self.address,
            self.command1,
            self.command2,
            self.data1,
            self.data2,
            self.checksum(),
        ]
    }

    /// Decode seven wire bytes.
    pub fn decode(bytes: &[u8; FRAME_LEN]) -> Result<Self, PelcoError> {
        if bytes[0] != SYNC {
            return Err(PelcoError::NoSync);
        }
        let f = Self {
            address: bytes[1],
            command1: bytes[2],
            command2: bytes[3],
            data1: bytes[4],
            data2: bytes[5],
        };
        let computed = f.checksum();
        if computed != bytes[6] {
            return Err(PelcoError::Checksum {
                computed,
                received: bytes[6],
            });
        }
        Ok(f)
    }

    /// The 16-bit value in data1 (MSB) and data2 (LSB).
    pub fn value(&self) -> u16 {
        u16::from_be_bytes([self.data1, self.data2])
    }
}

/// Motion bits of command 2 in a standard frame.
pub mod bits {
    /// Pan right.
    pub const PAN_RIGHT: u8 = 0x02;
    /// Pan left.
    pub const PAN_LEFT: u8 = 0x04;
    /// Tilt up.
    pub const TILT_UP: u8 = 0x08;
    /// Tilt down.
    pub const TILT_DOWN: u8 = 0x10;
}

/// Extended opcodes (command 2 with bit 0 set or a known value).
pub mod opcode {
    /// Set preset.
    pub const SET_PRESET: u8 = 0x03;
    /// Clear preset.
    pub const CLEAR_PRESET: u8 = 0x05;
    /// Go to preset.
    pub const GO_TO_PRESET: u8 = 0x07;
    /// Set pan position.
    pub const SET_PAN: u8 = 0x4B;
    /// Set tilt position.
    pub const SET_TILT: u8 = 0x4D;
    /// Query pan position.
    pub const QUERY_PAN: u8 = 0x51;
    /// Query tilt position.
    pub const QUERY_TILT: u8 = 0x53;
    /// Pan position response.
    pub const PAN_RESPONSE: u8 = 0x59;
    /// Tilt position response.
    pub const TILT_RESPONSE: u8 = 0x5B;
}

/// The typed commands this crate uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Stop all motion (all bits zero).
    Stop,
    /// Continuous motion: `pan` < 0 left, > 0 right; `tilt` < 0 down, > 0
    /// up; speeds 0..=0x3F (0xFF on pan is "turbo").
    Drive {
        /// Pan direction: −1, 0 or 1.
        pan: i8,
        /// Tilt direction: −1, 0 or 1.
        tilt: i8,
        /// Pan speed byte.
        pan_speed: u8,
        /// Tilt speed byte.
        tilt_speed: u8,
    },
    /// Store the current position as preset `n`.
    SetPreset(u8),
    /// Forget preset `n`.
    ClearPreset(u8),
    /// Go to preset `n`.
    GoToPreset(u8),
    /// Absolute pan, 1/100° in 0..=35999.
    SetPan(u16),
    /// Absolute tilt, 1/100° in 0..=35999.
    SetTilt(u16),
    /// Ask for the pan position.
    QueryPan,
    /// Ask for the tilt position.
    QueryTilt,
    /// The pan position, 1/100°.
    PanResponse(u16),
    /// The tilt position, 1/100°.
    TiltResponse(u16),
}

impl Command {
    /// The frame for receiver `address`.
    pub fn frame(&self, address: u8) -> Frame {
        let (command2, value) = match *self {
            Command::Stop => (0, 0),
            Command::Drive {
                pan,
                tilt,
                pan_speed,
                tilt_speed,
            } => {
                let mut c2 = 0;
                if pan > 0 {
                    c2 |= bits::PAN_RIGHT;
                } else if pan < 0 {
                    c2 |= bits::PAN_LEFT;
                }
                if tilt > 0 {
                    c2 |= bits::TILT_UP;
                } else if tilt < 0 {
                    c2 |= bits::TILT_DOWN;
                }
                (c2, u16::from_be_bytes([pan_speed, tilt_speed]))
            }
            Command::SetPreset(n) => (opcode::SET_PRESET, u16::from(n)),
            Command::ClearPreset(n) => (opcode::CLEAR_PRESET, u16::from(n)),
            Command::GoToPreset(n) => (opcode::GO_TO_PRESET, u16::from(n)),
            Command::SetPan(v) => (opcode::SET_PAN, v),
            Command::SetTilt(v) => (opcode::SET_TILT, v),
            Command::QueryPan => (opcode::QUERY_PAN, 0),
            Command::QueryTilt => (opcode::QUERY_TILT, 0),
            Command::PanResponse(v) => (opcode::PAN_RESPONSE, v),
            Command::TiltResponse(v) => (opcode::TILT_RESPONSE, v),
        };
        let [data1, data2] = value.to_be_bytes();
        Frame {
            address,
            command1: 0,
            command2,
            data1,
            data2,
        }
    }

    /// The typed command in a frame, if it is one of ours.
    pub fn from_frame(f: &Frame) -> Option<Self> {
        if f.command1 != 0 {
            return None;
        }
        let v = f.value();
        Some(match f.command2 {
            0 if v == 0 => Command::Stop,
            opcode::SET_PRESET if f.data1 == 0 => Command::SetPreset(f.data2),
            opcode::CLEAR_PRESET if f.data1 == 0 => Command::ClearPreset(f.data2),
            opcode::GO_TO_PRESET if f.data1 == 0 => Command::GoToPreset(f.data2),
            opcode::SET_PAN => Command::SetPan(v),
            opcode::SET_TILT => Command::SetTilt(v),
            opcode::QUERY_PAN => Command::QueryPan,
            opcode::QUERY_TILT => Command::QueryTilt,
            opcode::PAN_RESPONSE => Command::PanResponse(v),
            opcode::TILT_RESPONSE => Command::TiltResponse(v),
            c2 if c2 & 0xE1 == 0 => {
                let pan = match c2 & (bits::PAN_LEFT | bits::PAN_RIGHT) {
                    bits::PAN_RIGHT => 1,
                    bits::PAN_LEFT => -1,
                    0 => 0,
                    _ => return None,
                };
                let tilt = match c2 & (bits::TILT_UP | bits::TILT_DOWN) {
                    bits::TILT_UP => 1,
                    bits::TILT_DOWN => -1,
                    0 => 0,
                    _ => return None,
                };
                Command::Drive {
                    pan,
                    tilt,
                    pan_speed: f.data1,
                    tilt_speed: f.data2,
                }
            }
            _ => return None,
        })
    }
}

/// A signed angle in 1/100° as the wire's 0..=35999.
pub fn to_wire(centideg: i32) -> u16 {
    centideg.rem_euclid(FULL_TURN) as u16
}

/// A wire angle (0..=35999) as a signed angle in −18000..18000.
pub fn from_wire(v: u16) -> i32 {
    let v = i32::from(v) % FULL_TURN;
    if v >= FULL_TURN / 2 { v - FULL_TURN } else { v }
}

/// Finds frames in a byte stream: waits for `FF`, collects seven bytes, and
/// on a bad checksum resynchronizes at the next `FF` already received.
#[derive(Debug, Clone, Default)]
pub struct Deframer {
    buf: [u8; FRAME_LEN],
    len: usize,
}

impl Deframer {
    /// Push one byte; returns a frame or an error when seven bytes are in.
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, PelcoError>> {
        if self.len == 0 && byte != SYNC {
            return None;
        }
        self.buf[self.len] = byte;
        self.len += 1;
        if self.len < FRAME_LEN {
            return None;
        }
        match Frame::decode(&self.buf) {
            Ok(f) => {
                self.len = 0;
                Some(Ok(f))
            }
            Err(e) => {
                // Keep the bytes from the next FF on: it may start a frame.
                match self.buf[1..].iter().position(|&b| b == SYNC) {
                    Some(i) => {
                        let start = i + 1;
                        self.buf.copy_within(start.., 0);
                        self.len = FRAME_LEN - start;
                    }
                    None => self.len = 0,
                }
                Some(Err(e))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The example frame widely published with the protocol description:
    /// camera 10, "sense" + camera on, focus far + tilt down, tilt speed 0x20.
    #[test]
    fn published_example_frame() {
        let f = Frame {
            address: 0x0A,
            command1: 0x88,
            command2: 0x90,
            data1: 0x00,
            data2: 0x20,
        };
        assert_eq!(f.encode(), [0xFF, 0x0A, 0x88, 0x90, 0x00, 0x20, 0x42]);
        assert_eq!(Frame::decode(&[0xFF, 0x0A, 0x88, 0x90, 0x00, 0x20, 0x42]), Ok(f));
    }

    /// Frames from the Pelco-D command tables in PTZ camera manuals.
    #[test]
    fn published_command_table_frames() {
        assert_eq!(
            Command::Stop.frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x00, 0x00, 0x00, 0x01]
        );
        // Right at pan speed 0x20: sum 01+00+02+20+00 = 0x23.
        let right = Command::Drive {
            pan: 1,
            tilt: 0,
            pan_speed: 0x20,
            tilt_speed: 0,
        };
        assert_eq!(right.frame(1).encode(), [0xFF, 0x01, 0x00, 0x02, 0x20, 0x00, 0x23]);
        assert_eq!(
            Command::SetPreset(1).frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x03, 0x00, 0x01, 0x05]
        );
        assert_eq!(
            Command::GoToPreset(1).frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x07, 0x00, 0x01, 0x09]
        );
        assert_eq!(
            Command::QueryPan.frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x51, 0x00, 0x00, 0x52]
        );
        assert_eq!(
            Command::QueryTilt.frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x53, 0x00, 0x00, 0x54]
        );
        // Pan to 90.00° = 9000 = 0x2328: sum 01+00+4B+23+28 = 0x97.
        assert_eq!(
            Command::SetPan(9000).frame(1).encode(),
            [0xFF, 0x01, 0x00, 0x4B, 0x23, 0x28, 0x97]
        );
        // A 59 response with 180.00° = 18000 = 0x4650.
        let resp = Frame::decode(&[0xFF, 0x01, 0x00, 0x59, 0x46, 0x50, 0xF0]).unwrap();
        assert_eq!(Command::from_frame(&resp), Some(Command::PanResponse(18000)));
    }

    #[test]
    fn angles_wrap_modulo_a_turn() {
        assert_eq!(to_wire(-1000), 35_000);
        assert_eq!(from_wire(35_000), -1000);
        assert_eq!(from_wire(to_wire(17_999)), 17_999);
    }

    #[test]
    fn deframer_resyncs() {
        let mut d = Deframer::default();
        // Garbage, a frame with a bad checksum that contains an FF, then a good frame.
        let good = Command::QueryPan.frame(2).encode();
        let mut stream = vec![0x12, 0x34, 0xFF, 0x01, 0x00, 0xFF];
        stream.extend_from_slice(&good);
        let got: Vec<_> = stream.iter().filter_map(|&b| d.push(b)).collect();
        assert!(got.iter().any(|r| r == &Ok(Frame::decode(&good).unwrap())), "{got:?}");
    }

    proptest! {
        #[test]
        fn command_round_trip(addr in 1u8.., v in 0u16..36000, n: u8, which in 0usize..8) {
            let c = [
                Command::Stop, Command::SetPreset(n), Command::ClearPreset(n), Command::GoToPreset(n),
                Command::SetPan(v), Command::SetTilt(v), Command::PanResponse(v), Command::TiltResponse(v),
            ][which];
            let f = c.frame(addr);
            prop_assert_eq!(Frame::decode(&f.encode()), Ok(f));
            prop_assert_eq!(Command::from_frame(&f), Some(c));
        }

        #[test]
        fn deframer_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
            let mut d = Deframer::default();
            for b in bytes { let _ = d.push(b); }
        }
    }
}
