//! A FLIR PTU emulator speaking the ASCII protocol: a pure state machine in
//! the unit's native position steps.

use super::{format_i32, parse_i64};
use crate::firmware::{Firmware, Output};
use crate::line::{LineBuffer, LineEvent};
use crate::motion::{Axis, Head};

/// Static description of the emulated unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PtuConfig {
    /// Pan limits, steps (`PN`, `PX`).
    pub pan_range: (i32, i32),
    /// Tilt limits, steps (`TN`, `TX`).
    pub tilt_range: (i32, i32),
    /// Resolution of both axes, 1/10000 arc-second per step (`PR`, `TR`).
    pub resolution_e4_arcsec: u32,
    /// Power-on speed, steps/s.
    pub speed: u32,
}

impl Default for PtuConfig {
    /// The limits and resolution of the manual's PTU-D300 example:
    /// pan ±3090, tilt −907..604 steps, 185.1428″ per step; 1000 steps/s.
    fn default() -> Self {
        Self {
            pan_range: (-3090, 3090),
            tilt_range: (-907, 604),
            resolution_e4_arcsec: 1_851_428,
            speed: 1000,
        }
    }
}

/// What the emulated unit does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PtuEffect {
    /// New targets, steps.
    Target {
        /// Pan.
        pan: i32,
        /// Tilt.
        tilt: i32,
    },
    /// Axes halted.
    Halt,
    /// Speed changed, steps/s.
    Speed {
        /// Pan.
        pan: u32,
        /// Tilt.
        tilt: u32,
    },
}

/// The emulated unit.
#[derive(Debug, Clone)]
pub struct PtuDevice {
    config: PtuConfig,
    head: Head,
    accel: (i32, i32),
    echo: bool,
    terse: bool,
    limits_enforced: bool,
    awaiting: bool,
    limit_pending: [bool; 2],
    line: LineBuffer<32>,
}

impl PtuDevice {
    /// A unit at power-on: at (0, 0), echo on, verbose, limits enforced.
    pub fn new(config: PtuConfig) -> Self {
        let pan = Axis::new(0, config.pan_range.0, config.pan_range.1, config.speed);
        let tilt = Axis::new(0, config.tilt_range.0, config.tilt_range.1, config.speed);
        Self {
            config,
            head: Head::new(pan, tilt, (0, 0)),
            accel: (2000, 2000),
            echo: true,
            terse: false,
            limits_enforced: true,
            awaiting: false,
            limit_pending: [false; 2],
            line: LineBuffer::default(),
        }
    }

    /// (pan, tilt) position, steps (ground truth).
    pub fn position(&self) -> (i32, i32) {
        (self.head.pan.position, self.head.tilt.position)
    }

    /// The head's motion model (ground truth: exact and mechanical
    /// positions, dynamics).
    pub fn head(&self) -> &Head {
        &self.head
    }

    /// The head's motion model, to set dynamics, encoder noise and limits.
    pub fn head_mut(&mut self) -> &mut Head {
        &mut self.head
    }

    /// Simulate a limit switch on `axis` (0 pan, 1 tilt): halt, send `!P`/`!T`.
    pub fn trip_limit<O: Output<PtuEffect>>(&mut self, axis: u8, out: &mut O) {
        self.head.stop();
        out.effect(PtuEffect::Halt);
        out.send(if axis == 0 { b"!P\r\n" } else { b"!T\r\n" });
    }

    fn ack<O: Output<PtuEffect>>(out: &mut O) {
        out.send(b"*\r\n");
    }

    fn value<O: Output<PtuEffect>>(&self, words: &[u8], v: i32, out: &mut O) {
        out.send(b"* ");
        if !self.terse {
            out.send(words);
            out.send(b" ");
        }
        let mut d = [0u8; 11];
        let n = format_i32(v, &mut d);
        out.send(&d[..n]);
        out.send(b"\r\n");
    }

    fn error<O: Output<PtuEffect>>(out: &mut O, msg: &[u8]) {
        out.send(b"! ");
        out.send(msg);
        out.send(b"\r\n");
    }

    fn axis_mut(&mut self, tilt: bool) -> &mut Axis {
        if tilt { &mut self.head.tilt } else { &mut self.head.pan }
    }

    fn set_position<O: Output<PtuEffect>>(&mut self, tilt: bool, p: i64, out: &mut O) {
        let enforced = self.limits_enforced;
        let ax = self.axis_mut(tilt);
        let (min, max) = (i64::from(ax.min), i64::from(ax.max));
        if enforced && p > max {
            return Self::error(
                out,
                if tilt {
                    b"Maximum allowable Tilt position exceeded"
                } else {
                    b"Maximum allowable Pan position exceeded"
                },
            );
        }
        if enforced && p < min {
            return Self::error(
                out,
                if tilt {
                    b"Minimum allowable Tilt position exceeded"
                } else {
                    b"Minimum allowable Pan position exceeded"
                },
            );
        }
        // Unenforced: the axis travels to its hard stop and reports the hit.
        ax.target = p.clamp(min, max) as i32;
        let hit = p < min || p > max;
        self.limit_pending[usize::from(tilt)] = hit;
        out.effect(PtuEffect::Target {
            pan: self.head.pan.target,
            tilt: self.head.tilt.target,
        });
        Self::ack(out);
    }

    fn execute<O: Output<PtuEffect>>(&mut self, cmd: &[u8], out: &mut O) {
        let mut up = [0u8; 32];
        let n = cmd.len().min(32);
        for (d, s) in up.iter_mut().zip(cmd) {
            *d = s.to_ascii_uppercase();
        }
        let c = &up[..n];
        let (name, arg) = if c.len() >= 2 && c[0].is_ascii_alphabetic() && c[1].is_ascii_alphabetic() {
            (&c[..2], &c[2..])
        } else {
            (&c[..c.len().min(1)], &c[c.len().min(1)..])
        };
        let num = if arg.is_empty() { None } else { Some(parse_i64(arg)) };
        if num == Some(None) {
            return Self::error(out, b"Illegal argument");
        }
        let num = num.flatten();
        let res = self.config.resolution_e4_arcsec;
        match (name, num) {
            (b"FT", None) => {
                self.terse = true;
                Self::ack(out)
            }
            (b"FV", None) => {
                self.terse = false;
                Self::ack(out)
            }
            (b"ED", None) => {
                self.echo = false;
                Self::ack(out)
            }
            (b"EE", None) => {
                self.echo = true;
                Self::ack(out)
            }
            (b"LE", None) => {
                self.limits_enforced = true;
                Self::ack(out)
            }
            (b"LD", None) => {
                self.limits_enforced = false;
                Self::ack(out)
            }
            (b"A", None) => {
                if self.head.moving() {
                    self.awaiting = true;
                } else {
                    Self::ack(out)
                }
            }
            (b"H", None) => {
                self.head.stop();
                out.effect(PtuEffect::Halt);
                Self::ack(out)
            }
            (b"R", None) => {
                self.head.pan.target = 0;
                self.head.tilt.target = 0;
                out.effect(PtuEffect::Target { pan: 0, tilt: 0 });
                Self::ack(out)
            }
            (b"PP", None) => {
                let p = self.head.read_pan();
                self.value(b"Current Pan position is", p, out)
            }
            (b"TP", None) => {
                let t = self.head.read_tilt();
                self.value(b"Current Tilt position is", t, out)
            }
            (b"PP", Some(v)) => self.set_position(false, v, out),
            (b"TP", Some(v)) => self.set_position(true, v, out),
            (b"PO", Some(v)) => {
                let p = i64::from(self.head.pan.target) + v;
                self.set_position(false, p, out)
            }
            (b"TO", Some(v)) => {
                let p = i64::from(self.head.tilt.target) + v;
                self.set_position(true, p, out)
            }
            (b"PS", None) => self.value(b"Target Pan speed is", self.head.pan.speed as i32, out),
            (b"TS", None) => self.value(b"Target Tilt speed is", self.head.tilt.speed as i32, out),
            (b"PS" | b"TS", Some(v)) => {
                if !(1..=100_000).contains(&v) {
                    return Self::error(out, b"Illegal speed");
                }
                self.axis_mut(name == b"TS").speed = v as u32;
                out.effect(PtuEffect::Speed {
                    pan: self.head.pan.speed,
                    tilt: self.head.tilt.speed,
                });
                Self::ack(out)
            }
            (b"PA", None) => self.value(b"Pan acceleration is", self.accel.0, out),
            (b"TA", None) => self.value(b"Tilt acceleration is", self.accel.1, out),
            (b"PA" | b"TA", Some(v)) => {
                if !(1..=1_000_000).contains(&v) {
                    return Self::error(out, b"Illegal acceleration");
                }
                if name == b"PA" {
                    self.accel.0 = v as i32;
                } else {
                    self.accel.1 = v as i32;
                }
                Self::ack(out)
            }
            (b"PR" | b"TR", None) => {
                // e.g. "* 185.1428 seconds arc per position"
                out.send(b"* ");
                let mut d = [0u8; 11];
                let k = format_i32((res / 10_000) as i32, &mut d);
                out.send(&d[..k]);
                out.send(b".");
                let frac = res % 10_000;
                let digits = [
                    b'0' + (frac / 1000) as u8,
                    b'0' + (frac / 100 % 10) as u8,
                    b'0' + (frac / 10 % 10) as u8,
                    b'0' + (frac % 10) as u8,
                ];
                out.send(&digits);
                if !self.terse {
                    out.send(b" seconds arc per position");
                }
                out.send(b"\r\n");
            }
            (b"PN", None) => self.value(b"Minimum Pan position is", self.head.pan.min, out),
            (b"PX", None) => self.value(b"Maximum Pan position is", self.head.pan.max, out),
            (b"TN", None) => self.value(b"Minimum Tilt position is", self.head.tilt.min, out),
            (b"TX", None) => self.value(b"Maximum Tilt position is", self.head.tilt.max, out),
            _ => Self::error(out, b"Illegal Command"),
        }
    }
}

impl Firmware for PtuDevice {
    type Effect = PtuEffect;

    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<PtuEffect>) {
        for &b in bytes {
            if self.echo {
                out.send(&[b]);
            }
            match self.line.push(b, |c| c == b' ' || c == b'\r' || c == b'\n') {
                LineEvent::Pending => {}
                LineEvent::Overflowed => Self::error(out, b"Command too long"),
                LineEvent::Complete => {
                    let mut cmd = [0u8; 32];
                    let line = self.line.line();
                    let n = line.len();
                    cmd[..n].copy_from_slice(line);
                    self.line.clear();
                    if n > 0 {
                        self.execute(&cmd[..n], out);
                    }
                }
            }
        }
    }

    fn advance(&mut self, now_ms: u64, out: &mut impl Output<PtuEffect>) {
        self.head.advance(now_ms);
        for (i, tilt) in [false, true].into_iter().enumerate() {
            let ax = if tilt { &self.head.tilt } else { &self.head.pan };
            if self.limit_pending[i] && !ax.moving() {
                self.limit_pending[i] = false;
                out.send(if tilt { b"!T\r\n" } else { b"!P\r\n" });
            }
        }
        if self.awaiting && !self.head.moving() {
            self.awaiting = false;
            Self::ack(out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware::CollectingOutput;

    fn run(d: &mut PtuDevice, input: &[u8]) -> String {
        let mut out = CollectingOutput::default();
        d.receive(input, &mut out);
        String::from_utf8(out.bytes).unwrap()
    }

    #[test]
    fn manual_session_with_echo_then_terse() {
        let mut d = PtuDevice::new(PtuConfig::default());
        let mut out = CollectingOutput::default();
        d.advance(0, &mut out);
        // Echo on, verbose: the manual's "PP * Current pan position is 0" shape.
        assert_eq!(run(&mut d, b"PP "), "PP * Current Pan position is 0\r\n");
        assert_eq!(run(&mut d, b"ED "), "ED *\r\n");
        assert_eq!(run(&mut d, b"FT "), "*\r\n");
        assert_eq!(run(&mut d, b"PP-2500 "), "*\r\n");
        assert_eq!(run(&mut d, b"A "), "");
        let mut out = CollectingOutput::default();
        d.advance(3000, &mut out);
        assert_eq!(out.bytes, b"*\r\n");
        assert_eq!(run(&mut d, b"PP "), "* -2500\r\n");
        assert_eq!(run(&mut d, b"PX "), "* 3090\r\n");
        assert_eq!(run(&mut d, b"TN "), "* -907\r\n");
        assert_eq!(run(&mut d, b"PR "), "* 185.1428\r\n");
        assert!(run(&mut d, b"PP3200 ").starts_with("! Maximum allowable Pan position"));
        assert_eq!(d.position(), (-2500, 0));
        assert!(run(&mut d, b"XYZ ").starts_with("! "));
    }

    #[test]
    fn unenforced_limit_hit_is_reported_asynchronously() {
        let mut d = PtuDevice::new(PtuConfig::default());
        let mut out = CollectingOutput::default();
        d.advance(0, &mut out);
        run(&mut d, b"ED FT LD ");
        assert_eq!(run(&mut d, b"TP5000 "), "*\r\n");
        let mut out = CollectingOutput::default();
        d.advance(2000, &mut out);
        assert_eq!(out.bytes, b"!T\r\n");
        assert_eq!(d.position(), (0, 604));
    }

    proptest::proptest! {
        /// Any bytes (biased towards command letters): no panic, head within its limits.
        #[test]
        fn never_panics_on_any_bytes(bytes in proptest::collection::vec(proptest::prop_oneof![
            proptest::prelude::any::<u8>(),
            proptest::sample::select(b"PTOSANXRHLDEFV0123456789- \r".to_vec()),
        ], 0..300)) {
            let cfg = PtuConfig::default();
            let mut d = PtuDevice::new(cfg);
            let mut out = crate::firmware::CountingOutput::default();
            for (i, c) in bytes.chunks(9).enumerate() {
                d.receive(c, &mut out);
                d.advance(i as u64 * 50, &mut out);
                let (p, t) = d.position();
                proptest::prop_assert!(p >= cfg.pan_range.0 && p <= cfg.pan_range.1);
                proptest::prop_assert!(t >= cfg.tilt_range.0 && t <= cfg.tilt_range.1);
            }
        }
    }
}
