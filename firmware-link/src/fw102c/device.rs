//! An FW102C filter wheel emulator.

use super::PROMPT;
use crate::firmware::{Firmware, Output};
use crate::flir_ptu::{format_i32, parse_i64};
use crate::line::{LineBuffer, LineEvent};

/// What the wheel does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WheelEffect {
    /// The wheel turned to this position (1-based).
    Position(u8),
}

/// The emulated wheel.
#[derive(Debug, Clone)]
pub struct WheelDevice {
    count: u8,
    position: u8,
    line: LineBuffer<24>,
}

impl WheelDevice {
    /// A wheel with `count` positions (6 or 12; anything else becomes 6), at
    /// position 1.
    pub fn new(count: u8) -> Self {
        Self {
            count: if count == 12 { 12 } else { 6 },
            position: 1,
            line: LineBuffer::default(),
        }
    }

    /// The current position, 1-based (ground truth).
    pub fn position(&self) -> u8 {
        self.position
    }

    fn number<O: Output<WheelEffect>>(out: &mut O, v: i32) {
        let mut d = [0u8; 11];
        let n = format_i32(v, &mut d);
        out.send(&d[..n]);
        out.send(b"\r");
    }

    fn execute<O: Output<WheelEffect>>(&mut self, cmd: &[u8], out: &mut O) {
        match cmd {
            b"pos?" => Self::number(out, i32::from(self.position)),
            b"pcount?" => Self::number(out, i32::from(self.count)),
            b"*idn?" => out.send(b"THORLABS FW102C/FW212C Filter Wheel version 1.07\r"),
            _ => {
                if let Some(arg) = cmd.strip_prefix(b"pos=") {
                    match parse_i64(arg) {
                        Some(p) if p >= 1 && p <= i64::from(self.count) => {
                            self.position = p as u8;
                            out.effect(WheelEffect::Position(self.position));
                        }
                        _ => out.send(b"Command error CMD_ARG_INVALID\r"),
                    }
                } else {
                    out.send(b"Command error CMD_NOT_DEFINED\r");
                }
            }
        }
    }
}

impl Firmware for WheelDevice {
    type Effect = WheelEffect;

    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<WheelEffect>) {
        for &b in bytes {
            if b == b'\n' {
                continue;
            }
            match self.line.push(b, |c| c == b'\r') {
                LineEvent::Pending => {}
                LineEvent::Overflowed => {
                    out.send(b"Command error CMD_NOT_DEFINED\r");
                    out.send(&[PROMPT]);
                }
                LineEvent::Complete => {
                    let mut cmd = [0u8; 24];
                    let n = self.line.line().len();
                    cmd[..n].copy_from_slice(self.line.line());
                    self.line.clear();
                    out.send(&cmd[..n]);
                    out.send(b"\r");
                    self.execute(&cmd[..n], out);
                    out.send(&[PROMPT]);
                }
            }
        }
    }

    fn advance(&mut self, _now_ms: u64, _out: &mut impl Output<WheelEffect>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware::CollectingOutput;

    #[test]
    fn select_and_query() {
        let mut d = WheelDevice::new(6);
        let mut out = CollectingOutput::default();
        d.receive(b"pos=4\rpos?\rpos=7\rfoo\r", &mut out);
        assert_eq!(
            String::from_utf8(out.bytes).unwrap(),
            "pos=4\r>pos?\r4\r>pos=7\rCommand error CMD_ARG_INVALID\r>foo\rCommand error CMD_NOT_DEFINED\r>"
        );
        assert_eq!(out.effects, [WheelEffect::Position(4)]);
        assert_eq!(d.position(), 4);
    }

    proptest::proptest! {
        /// Any bytes: no panic, position stays in 1..=count.
        #[test]
        fn never_panics_on_any_bytes(bytes in proptest::collection::vec(proptest::prop_oneof![
            proptest::prelude::any::<u8>(),
            proptest::sample::select(b"pos=?count*idn0123456789\r".to_vec()),
        ], 0..300)) {
            let mut d = WheelDevice::new(6);
            let mut out = crate::firmware::CountingOutput::default();
            d.receive(&bytes, &mut out);
            proptest::prop_assert!((1..=6).contains(&d.position()));
        }
    }
}
