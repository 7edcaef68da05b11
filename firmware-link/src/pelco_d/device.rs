//! A Pelco-D pan-tilt head emulator: a pure state machine in 1/100°.

use super::{Command, Deframer, Frame, from_wire, to_wire};
use crate::firmware::{Firmware, Output};
use crate::motion::{Axis, Head};

/// Presets the emulator stores.
pub const PRESETS: usize = 64;

/// Static description of the emulated head.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PelcoConfig {
    /// Address it answers to.
    pub address: u8,
    /// Pan limits, 1/100° (within −18000..=17999).
    pub pan_range: (i32, i32),
    /// Tilt limits, 1/100°.
    pub tilt_range: (i32, i32),
    /// Slew speed for absolute moves and presets, 1/100° per second.
    pub speed: u32,
}

impl Default for PelcoConfig {
    /// Address 1, pan ±179.99°, tilt ±90°, 60°/s.
    fn default() -> Self {
        Self {
            address: 1,
            pan_range: (-17_999, 17_999),
            tilt_range: (-9_000, 9_000),
            speed: 6_000,
        }
    }
}

/// What the emulated head does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PelcoEffect {
    /// New target, 1/100°.
    Target {
        /// Pan.
        pan: i32,
        /// Tilt.
        tilt: i32,
    },
    /// Motion stopped.
    Stop,
    /// Preset stored.
    PresetStored(u8),
}

/// The emulated head.
#[derive(Debug, Clone)]
pub struct PelcoDevice {
    config: PelcoConfig,
    head: Head,
    presets: [Option<(i32, i32)>; PRESETS],
    deframer: Deframer,
    /// Frames with a bad checksum.
    pub bad_frames: u32,
}

impl PelcoDevice {
    /// A head at (0, 0).
    pub fn new(config: PelcoConfig) -> Self {
        let pan = Axis::new(0, config.pan_range.0, config.pan_range.1, config.speed);
        let tilt = Axis::new(0, config.tilt_range.0, config.tilt_range.1, config.speed);
        Self {
            config,
            head: Head::new(pan, tilt, (0, 0)),
            presets: [None; PRESETS],
            deframer: Deframer::default(),
            bad_frames: 0,
        }
    }

    /// (pan, tilt) position, 1/100° (ground truth).
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

    /// Whether the head is moving.
    pub fn moving(&self) -> bool {
        self.head.moving()
    }

    fn set_targets<O: Output<PelcoEffect>>(&mut self, pan: i32, tilt: i32, speed: u32, out: &mut O) {
        self.head.pan.speed = speed;
        self.head.tilt.speed = speed;
        self.head.pan.target = pan.clamp(self.head.pan.min, self.head.pan.max);
        self.head.tilt.target = tilt.clamp(self.head.tilt.min, self.head.tilt.max);
        out.effect(PelcoEffect::Target {
            pan: self.head.pan.target,
            tilt: self.head.tilt.target,
        });
    }

    fn handle<O: Output<PelcoEffect>>(&mut self, f: &Frame, out: &mut O) {
        if f.address != self.config.address {
            return;
        }
        let Some(cmd) = Command::from_frame(f) else {
            return;
        };
        let speed = self.config.speed;
        match cmd {
            Command::Stop => {
                self.head.stop();
                out.effect(PelcoEffect::Stop);
            }
            Command::Drive {
                pan,
                tilt,
                pan_speed,
                tilt_speed,
            } => {
                // Continuous motion: head for the limit in that direction.
                let p = match pan {
                    1 => self.head.pan.max,
                    -1 => self.head.pan.min,
                    _ => self.head.pan.position,
                };
                let t = match tilt {
                    1 => self.head.tilt.max,
                    -1 => self.head.tilt.min,
                    _ => self.head.tilt.position,
                };
                let s = u32::from(pan_speed.max(tilt_speed).min(0x40)) * 100 + 100;
                self.set_targets(p, t, s, out);
            }
            Command::SetPreset(n) => {
                if let Some(slot) = self.presets.get_mut(usize::from(n)) {
                    *slot = Some((self.head.pan.position, self.head.tilt.position));
                    out.effect(PelcoEffect::PresetStored(n));
                }
            }
            Command::ClearPreset(n) => {
                if let Some(slot) = self.presets.get_mut(usize::from(n)) {
                    *slot = None;
                }
            }
            Command::GoToPreset(n) => {
                if let Some(Some((p, t))) = self.presets.get(usize::from(n)).copied() {
                    self.set_targets(p, t, speed, out);
                }
            }
            Command::SetPan(v) if v < 36_000 => {
                let t = self.head.tilt.target;
                self.set_targets(from_wire(v), t, speed, out);
            }
            Command::SetTilt(v) if v < 36_000 => {
                let p = self.head.pan.target;
                self.set_targets(p, from_wire(v), speed, out);
            }
            Command::QueryPan => {
                let r = Command::PanResponse(to_wire(self.head.read_pan()));
                out.send(&r.frame(self.config.address).encode());
            }
            Command::QueryTilt => {
                let r = Command::TiltResponse(to_wire(self.head.read_tilt()));
                out.send(&r.frame(self.config.address).encode());
            }
            _ => {}
        }
    }
}

impl Firmware for PelcoDevice {
    type Effect = PelcoEffect;

    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<PelcoEffect>) {
        for &b in bytes {
            match self.deframer.push(b) {
                Some(Ok(f)) => self.handle(&f, out),
                Some(Err(_)) => self.bad_frames += 1,
                None => {}
            }
        }
    }

    fn advance(&mut self, now_ms: u64, _out: &mut impl Output<PelcoEffect>) {
        self.head.advance(now_ms);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware::CollectingOutput;

    #[test]
    fn absolute_move_then_query_answers_59_and_5b() {
        let mut d = PelcoDevice::new(PelcoConfig::default());
        let mut out = CollectingOutput::default();
        d.advance(0, &mut out);
        d.receive(&Command::SetPan(9000).frame(1).encode(), &mut out);
        d.receive(&Command::SetTilt(to_wire(-1000)).frame(1).encode(), &mut out);
        d.advance(2000, &mut out);
        assert_eq!(d.position(), (9000, -1000));
        d.receive(&Command::QueryPan.frame(1).encode(), &mut out);
        d.receive(&Command::QueryTilt.frame(1).encode(), &mut out);
        // 9000 = 0x2328; 35000 = 0x88B8.
        assert_eq!(
            out.bytes,
            [
                0xFF, 0x01, 0x00, 0x59, 0x23, 0x28, 0xA5, //
                0xFF, 0x01, 0x00, 0x5B, 0x88, 0xB8, 0x9C
            ]
        );
    }

    #[test]
    fn ignores_other_addresses_and_bad_checksums() {
        let mut d = PelcoDevice::new(PelcoConfig::default());
        let mut out = CollectingOutput::default();
        d.receive(&Command::QueryPan.frame(2).encode(), &mut out);
        d.receive(&[0xFF, 0x01, 0x00, 0x51, 0x00, 0x00, 0x53], &mut out);
        assert!(out.bytes.is_empty());
        assert_eq!(d.bad_frames, 1);
    }

    #[test]
    fn presets_store_and_recall() {
        let mut d = PelcoDevice::new(PelcoConfig::default());
        let mut out = CollectingOutput::default();
        d.advance(0, &mut out);
        d.receive(&Command::SetPan(4500).frame(1).encode(), &mut out);
        d.advance(5000, &mut out);
        d.receive(&Command::SetPreset(3).frame(1).encode(), &mut out);
        d.receive(&Command::SetPan(0).frame(1).encode(), &mut out);
        d.advance(10_000, &mut out);
        assert_eq!(d.position(), (0, 0));
        d.receive(&Command::GoToPreset(3).frame(1).encode(), &mut out);
        d.advance(15_000, &mut out);
        assert_eq!(d.position(), (4500, 0));
    }

    proptest::proptest! {
        /// Any bytes: no panic, head within its limits.
        #[test]
        fn never_panics_on_any_bytes(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..400)) {
            let cfg = PelcoConfig::default();
            let mut d = PelcoDevice::new(cfg);
            let mut out = crate::firmware::CountingOutput::default();
            for (i, c) in bytes.chunks(7).enumerate() {
                d.receive(c, &mut out);
                d.advance(i as u64 * 50, &mut out);
                let (p, t) = d.position();
                proptest::prop_assert!(p >= cfg.pan_range.0 && p <= cfg.pan_range.1);
                proptest::prop_assert!(t >= cfg.tilt_range.0 && t <= cfg.tilt_range.1);
            }
        }
    }
}
