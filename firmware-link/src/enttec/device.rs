//! A DMX USB Pro widget emulator: keeps the universe it was last sent and
//! answers the parameter and serial-number requests.

use super::{Deframer, UNIVERSE, encode, label};
use crate::firmware::{Firmware, Output};

/// What the widget does on its DMX output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DmxEffect {
    /// A channel (1-based) changed level.
    Channel {
        /// DMX channel, 1..=512.
        channel: u16,
        /// Level, 0..=255.
        level: u8,
    },
}

/// The emulated widget.
#[derive(Debug, Clone)]
pub struct DmxDevice {
    deframer: Deframer,
    universe: [u8; UNIVERSE],
    serial: u32,
    firmware: u16,
    /// Label 6 messages applied.
    pub frames: u32,
    /// Messages rejected (framing errors, wrong start code).
    pub rejected: u32,
}

impl DmxDevice {
    /// A widget with this serial number (decimal digits, sent as BCD).
    pub fn new(serial: u32) -> Self {
        Self {
            deframer: Deframer::default(),
            universe: [0; UNIVERSE],
            serial,
            firmware: 0x0144,
            frames: 0,
            rejected: 0,
        }
    }

    /// The DMX levels, channel 1 at index 0 (ground truth).
    pub fn universe(&self) -> &[u8; UNIVERSE] {
        &self.universe
    }

    fn serial_bcd(&self) -> [u8; 4] {
        let mut s = self.serial;
        let mut out = [0u8; 4];
        for o in &mut out {
            let lo = (s % 10) as u8;
            s /= 10;
            let hi = (s % 10) as u8;
            s /= 10;
            *o = hi << 4 | lo;
        }
        out
    }
}

impl Firmware for DmxDevice {
    type Effect = DmxEffect;

    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<DmxEffect>) {
        for &b in bytes {
            match self.deframer.push(b) {
                None => {}
                Some(Err(_)) => self.rejected += 1,
                Some(Ok(label::SEND_DMX)) => {
                    let data = self.deframer.data();
                    if data.first() != Some(&0) || data.len() > UNIVERSE + 1 {
                        self.rejected += 1;
                        continue;
                    }
                    self.frames += 1;
                    for (i, &level) in data[1..].iter().enumerate() {
                        if self.universe[i] != level {
                            self.universe[i] = level;
                            out.effect(DmxEffect::Channel {
                                channel: i as u16 + 1,
                                level,
                            });
                        }
                    }
                }
                Some(Ok(label::GET_SERIAL)) => {
                    let mut buf = [0u8; 9];
                    if let Ok(n) = encode(label::GET_SERIAL, &self.serial_bcd(), &mut buf) {
                        out.send(&buf[..n]);
                    }
                }
                Some(Ok(label::GET_PARAMETERS)) => {
                    let [lo, hi] = self.firmware.to_le_bytes();
                    // Break 9 × 10.67 µs, MAB 1 × 10.67 µs, 40 packets/s.
                    let mut buf = [0u8; 10];
                    if let Ok(n) = encode(label::GET_PARAMETERS, &[lo, hi, 9, 1, 40], &mut buf) {
                        out.send(&buf[..n]);
                    }
                }
                Some(Ok(_)) => self.rejected += 1,
            }
        }
    }

    fn advance(&mut self, _now_ms: u64, _out: &mut impl Output<DmxEffect>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::enttec::encode_dmx;
    use crate::firmware::CollectingOutput;

    #[test]
    fn applies_universe_and_answers_serial() {
        let mut d = DmxDevice::new(12_345_678);
        let mut out = CollectingOutput::default();
        let mut buf = [0u8; 600];
        let n = encode_dmx(&[0, 200, 0, 17], &mut buf).unwrap();
        d.receive(&buf[..n], &mut out);
        assert_eq!(&d.universe()[..5], &[0, 200, 0, 17, 0]);
        assert_eq!(
            out.effects,
            [
                DmxEffect::Channel { channel: 2, level: 200 },
                DmxEffect::Channel { channel: 4, level: 17 }
            ]
        );
        d.receive(&[0x7E, 0x0A, 0x00, 0x00, 0xE7], &mut out);
        assert_eq!(out.bytes, [0x7E, 0x0A, 0x04, 0x00, 0x78, 0x56, 0x34, 0x12, 0xE7]);
    }

    proptest::proptest! {
        /// Any bytes: no panic.
        #[test]
        fn never_panics_on_any_bytes(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..2000)) {
            let mut d = DmxDevice::new(7);
            let mut out = crate::firmware::CountingOutput::default();
            d.receive(&bytes, &mut out);
        }
    }
}
