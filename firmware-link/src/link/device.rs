//! The device side of campanile-link: a pure state machine with fixed-size
//! buffers (no allocator, no tokio) that a microcontroller or `sim` can run.
//!
//! It owns an emulated head ([`crate::motion::Head`], µrad), a filter wheel
//! and up to [`MAX_LIGHT_CHANNELS`] dimmers, and reports what it does to them
//! as [`Effect`]s.

use super::frame::{Deframer, Frame, MAX_WIRE, VERSION};
use super::message::{
    DeviceInfo, Event, FilterState, HeadState, LightsState, MAX_LIGHT_CHANNELS, Message, NackCode, Reply, Request, kind,
};
use crate::firmware::{Firmware, Output};
use crate::motion::{Axis, Head};

/// How many replies the device keeps for replay.
pub const REPLAY_SLOTS: usize = 8;

/// Static description of the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceConfig {
    /// Pan soft limits, µrad.
    pub pan_range: (i32, i32),
    /// Tilt soft limits, µrad.
    pub tilt_range: (i32, i32),
    /// Home pose, µrad.
    pub home: (i32, i32),
    /// Initial slew speed, µrad/s.
    pub speed: u32,
    /// Initial acceleration, µrad/s² (stored and reported, not simulated).
    pub accel: u32,
    /// Filter slots (0: no wheel).
    pub filter_slots: u8,
    /// Light channels (0: no lights), at most [`MAX_LIGHT_CHANNELS`].
    pub light_channels: u8,
    /// Firmware version reported by [`Request::DeviceInfo`].
    pub firmware: [u8; 3],
}

impl Default for DeviceConfig {
    /// A head with ±π pan, −π/2..π/2 tilt, 1 rad/s, a 6-slot wheel and 4
    /// dimmers.
    fn default() -> Self {
        Self {
            pan_range: (-3_141_593, 3_141_593),
            tilt_range: (-1_570_796, 1_570_796),
            home: (0, 0),
            speed: 1_000_000,
            accel: 2_000_000,
            filter_slots: 6,
            light_channels: 4,
            firmware: [1, 0, 0],
        }
    }
}

/// What the firmware does to its hardware.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    /// A move was accepted; the axes now head for this target (µrad).
    HeadMove {
        /// New pan target.
        pan: i32,
        /// New tilt target.
        tilt: i32,
        /// Whether the request was an offset move.
        relative: bool,
    },
    /// The head was halted.
    HeadStop,
    /// Homing started.
    HeadHome,
    /// Speed and acceleration changed.
    HeadMotion {
        /// µrad/s.
        speed: u32,
        /// µrad/s².
        accel: u32,
    },
    /// A filter slot was selected.
    FilterSelect(u8),
    /// A dimmer changed.
    LightLevel {
        /// Channel.
        channel: u8,
        /// Level, 0..=65535.
        level: u16,
    },
    /// Every dimmer was turned off.
    LightsAllOff,
}

#[derive(Debug, Clone, Copy)]
struct ReplayEntry {
    used: bool,
    seq: u16,
    request_crc: u32,
    wire: [u8; MAX_WIRE],
    len: usize,
}

const EMPTY_ENTRY: ReplayEntry = ReplayEntry {
    used: false,
    seq: 0,
    request_crc: 0,
    wire: [0; MAX_WIRE],
    len: 0,
};

/// Counters kept by the device.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DeviceStats {
    /// Frames that failed COBS, length or CRC checks.
    pub bad_frames: u32,
    /// Requests answered from the replay cache.
    pub replays: u32,
    /// Requests executed.
    pub executed: u32,
}

/// The campanile-link firmware.
#[derive(Debug, Clone)]
pub struct LinkDevice {
    config: DeviceConfig,
    head: Head,
    accel: u32,
    homed: bool,
    fault: bool,
    filter_slot: u8,
    lights: [u16; MAX_LIGHT_CHANNELS],
    deframer: Deframer,
    replay: [ReplayEntry; REPLAY_SLOTS],
    replay_next: usize,
    event_seq: u16,
    announced: bool,
    now_ms: u64,
    stats: DeviceStats,
}

impl LinkDevice {
    /// A device at power-on, head at home.
    pub fn new(config: DeviceConfig) -> Self {
        let pan = Axis::new(config.home.0, config.pan_range.0, config.pan_range.1, config.speed);
        let tilt = Axis::new(config.home.1, config.tilt_range.0, config.tilt_range.1, config.speed);
        let mut config = config;
        config.light_channels = config.light_channels.min(MAX_LIGHT_CHANNELS as u8);
        Self {
            config,
            head: Head::new(pan, tilt, config.home),
            accel: config.accel,
            homed: false,
            fault: false,
            filter_slot: 0,
            lights: [0; MAX_LIGHT_CHANNELS],
            deframer: Deframer::default(),
            replay: [EMPTY_ENTRY; REPLAY_SLOTS],
            replay_next: 0,
            event_seq: 0,
            announced: false,
            now_ms: 0,
            stats: DeviceStats::default(),
        }
    }

    /// The head's state (ground truth for tests and `sim`).
    pub fn head_state(&self) -> HeadState {
        let mut flags = 0;
        if self.head.moving() {
            flags |= HeadState::MOVING;
        }
        if self.homed {
            flags |= HeadState::HOMED;
        }
        if self.fault {
            flags |= HeadState::FAULT;
        }
        HeadState {
            pan: self.head.pan.position,
            tilt: self.head.tilt.position,
            target_pan: self.head.pan.target,
            target_tilt: self.head.tilt.target,
            flags,
        }
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

    /// The head's state as the encoders report it (with noise, if the head
    /// has any); what the device sends to the host.
    fn reported_head_state(&mut self) -> HeadState {
        let mut s = self.head_state();
        s.pan = self.head.read_pan();
        s.tilt = self.head.read_tilt();
        s
    }

    /// The selected filter slot.
    pub fn filter_slot(&self) -> u8 {
        self.filter_slot
    }

    /// Light levels, one per configured channel.
    pub fn light_levels(&self) -> &[u16] {
        &self.lights[..usize::from(self.config.light_channels)]
    }

    /// Counters.
    pub fn stats(&self) -> DeviceStats {
        self.stats
    }

    /// Simulate a hard limit switch on `axis` (0 pan, 1 tilt): the head
    /// stops and a [`Event::LimitHit`] is sent.
    pub fn trip_limit<O: Output<Effect>>(&mut self, axis: u8, out: &mut O) {
        self.head.stop();
        out.effect(Effect::HeadStop);
        let state = self.head_state();
        self.send_event(
            Event::LimitHit {
                axis: axis.min(1),
                state,
            },
            out,
        );
    }

    /// Latch a fault with a device-specific code and send [`Event::Fault`];
    /// moves are refused until the head is homed.
    pub fn latch_fault<O: Output<Effect>>(&mut self, code: u8, out: &mut O) {
        self.fault = true;
        self.head.stop();
        out.effect(Effect::HeadStop);
        self.send_event(Event::Fault(code), out);
    }

    fn send_event<O: Output<Effect>>(&mut self, event: Event, out: &mut O) {
        let (k, p, n) = Message::Event(event).encode();
        if let Ok(frame) = Frame::new(self.event_seq, k, &p[..n]) {
            let mut wire = [0u8; MAX_WIRE];
            let len = frame.encode(&mut wire);
            out.send(&wire[..len]);
        }
        self.event_seq = self.event_seq.wrapping_add(1);
    }

    fn handle_frame<O: Output<Effect>>(&mut self, frame: &Frame, out: &mut O) {
        let request_crc = frame.crc();
        if let Some(entry) = self
            .replay
            .iter()
            .find(|e| e.used && e.seq == frame.seq && e.request_crc == request_crc)
        {
            self.stats.replays += 1;
            out.send(&entry.wire[..entry.len]);
            return;
        }
        let reply = if frame.version != VERSION {
            Reply::Nack {
                kind: frame.kind,
                code: NackCode::VersionMismatch,
            }
        } else {
            match Message::decode(frame.kind, frame.payload()) {
                Ok(Message::Request(req)) => {
                    self.stats.executed += 1;
                    self.execute(frame.kind, req, out)
                }
                Ok(_) | Err(super::message::MessageError::UnknownKind(_)) => Reply::Nack {
                    kind: frame.kind,
                    code: NackCode::UnknownKind,
                },
                Err(_) => Reply::Nack {
                    kind: frame.kind,
                    code: NackCode::BadPayload,
                },
            }
        };
        let (k, p, n) = Message::Reply(reply).encode();
        let Ok(reply_frame) = Frame::new(frame.seq, k, &p[..n]) else {
            return;
        };
        let entry = &mut self.replay[self.replay_next];
        entry.len = reply_frame.encode(&mut entry.wire);
        entry.seq = frame.seq;
        entry.request_crc = request_crc;
        entry.used = true;
        self.replay_next = (self.replay_next + 1) % REPLAY_SLOTS;
        out.send(&entry.wire[..entry.len]);
    }

    fn nack(kind: u8, code: NackCode) -> Reply {
        Reply::Nack { kind, code }
    }

    fn execute<O: Output<Effect>>(&mut self, k: u8, req: Request, out: &mut O) -> Reply {
        match req {
            Request::MoveTo { pan, tilt } | Request::MoveBy { pan, tilt } => {
                if self.fault {
                    return Self::nack(k, NackCode::Fault);
                }
                let relative = matches!(req, Request::MoveBy { .. });
                let (tp, tt) = if relative {
                    (
                        i64::from(self.head.pan.target) + i64::from(pan),
                        i64::from(self.head.tilt.target) + i64::from(tilt),
                    )
                } else {
                    (i64::from(pan), i64::from(tilt))
                };
                let (Ok(tp), Ok(tt)) = (i32::try_from(tp), i32::try_from(tt)) else {
                    return Self::nack(k, NackCode::OutOfRange);
                };
                if !self.head.pan.in_range(tp) || !self.head.tilt.in_range(tt) {
                    return Self::nack(k, NackCode::OutOfRange);
                }
                self.head.pan.target = tp;
                self.head.tilt.target = tt;
                out.effect(Effect::HeadMove {
                    pan: tp,
                    tilt: tt,
                    relative,
                });
                Reply::Head(self.reported_head_state())
            }
            Request::Home => {
                self.fault = false;
                self.homed = true;
                self.head.pan.target = self.head.home.0;
                self.head.tilt.target = self.head.home.1;
                out.effect(Effect::HeadHome);
                Reply::Head(self.reported_head_state())
            }
            Request::Stop => {
                self.head.stop();
                out.effect(Effect::HeadStop);
                Reply::Head(self.reported_head_state())
            }
            Request::SetMotion { speed, accel } => {
                if speed == 0 {
                    return Self::nack(k, NackCode::OutOfRange);
                }
                self.head.pan.speed = speed;
                self.head.tilt.speed = speed;
                self.accel = accel;
                // Acceleration is simulated only on heads given dynamics.
                for axis in [&mut self.head.pan, &mut self.head.tilt] {
                    if axis.dynamics.accel != 0 && accel != 0 {
                        axis.dynamics.accel = accel;
                    }
                }
                out.effect(Effect::HeadMotion { speed, accel });
                Reply::Head(self.reported_head_state())
            }
            Request::QueryHead => Reply::Head(self.reported_head_state()),
            Request::SelectFilter(slot) => {
                if self.config.filter_slots == 0 {
                    return Self::nack(k, NackCode::Unsupported);
                }
                if slot >= self.config.filter_slots {
                    return Self::nack(k, NackCode::OutOfRange);
                }
                self.filter_slot = slot;
                out.effect(Effect::FilterSelect(slot));
                Reply::Filter(self.filter_state())
            }
            Request::QueryFilter => {
                if self.config.filter_slots == 0 {
                    return Self::nack(k, NackCode::Unsupported);
                }
                Reply::Filter(self.filter_state())
            }
            Request::SetLight { channel, level } => {
                if self.config.light_channels == 0 {
                    return Self::nack(k, NackCode::Unsupported);
                }
                if channel >= self.config.light_channels {
                    return Self::nack(k, NackCode::OutOfRange);
                }
                self.lights[usize::from(channel)] = level;
                out.effect(Effect::LightLevel { channel, level });
                Reply::Lights(self.lights_state())
            }
            Request::AllLightsOff => {
                if self.config.light_channels == 0 {
                    return Self::nack(k, NackCode::Unsupported);
                }
                self.lights = [0; MAX_LIGHT_CHANNELS];
                out.effect(Effect::LightsAllOff);
                Reply::Lights(self.lights_state())
            }
            Request::QueryLights => {
                if self.config.light_channels == 0 {
                    return Self::nack(k, NackCode::Unsupported);
                }
                Reply::Lights(self.lights_state())
            }
            Request::DeviceInfo => Reply::Info(DeviceInfo {
                protocol: VERSION,
                firmware: self.config.firmware,
                pan_min: self.config.pan_range.0,
                pan_max: self.config.pan_range.1,
                tilt_min: self.config.tilt_range.0,
                tilt_max: self.config.tilt_range.1,
                filter_slots: self.config.filter_slots,
                light_channels: self.config.light_channels,
            }),
            Request::Heartbeat => Reply::Heartbeat(self.now_ms as u32),
        }
    }

    fn filter_state(&self) -> FilterState {
        FilterState {
            slot: self.filter_slot,
            slots: self.config.filter_slots,
        }
    }

    fn lights_state(&self) -> LightsState {
        LightsState {
            count: self.config.light_channels,
            levels: self.lights,
        }
    }
}

impl Firmware for LinkDevice {
    type Effect = Effect;

    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<Effect>) {
        for &b in bytes {
            match self.deframer.push(b) {
                None => {}
                Some(Err(_)) => self.stats.bad_frames += 1,
                Some(Ok(frame)) => {
                    if frame.kind < kind::ACK_HEAD {
                        self.handle_frame(&frame, out);
                    } else {
                        // A reply or event sent to the device: not a request.
                        self.stats.bad_frames += 1;
                    }
                }
            }
        }
    }

    fn advance(&mut self, now_ms: u64, out: &mut impl Output<Effect>) {
        self.now_ms = now_ms;
        if !self.announced {
            self.announced = true;
            self.head.advance(now_ms);
            self.send_event(Event::PowerOnReset, out);
        }
        if self.head.advance(now_ms) {
            let state = self.head_state();
            self.send_event(Event::MotionDone(state), out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware::CollectingOutput;

    fn request(seq: u16, req: Request) -> Vec<u8> {
        let (k, p, n) = Message::Request(req).encode();
        let mut w = [0u8; MAX_WIRE];
        let len = Frame::new(seq, k, &p[..n]).unwrap().encode(&mut w);
        w[..len].to_vec()
    }

    fn replies(bytes: &[u8]) -> Vec<(u16, Message)> {
        let mut d = Deframer::default();
        bytes
            .iter()
            .filter_map(|&b| d.push(b))
            .map(|f| {
                let f = f.unwrap();
                (f.seq, Message::decode(f.kind, f.payload()).unwrap())
            })
            .collect()
    }

    #[test]
    fn relative_move_retried_applies_once() {
        let mut dev = LinkDevice::new(DeviceConfig::default());
        let mut out = CollectingOutput::default();
        let req = request(5, Request::MoveBy { pan: 1000, tilt: -200 });
        dev.receive(&req, &mut out);
        dev.receive(&req, &mut out);
        dev.receive(&req, &mut out);
        assert_eq!(
            out.effects,
            [Effect::HeadMove {
                pan: 1000,
                tilt: -200,
                relative: true
            }]
        );
        let r = replies(&out.bytes);
        assert_eq!(r.len(), 3);
        assert!(r.iter().all(|x| x == &r[0]));
        assert_eq!(dev.head_state().target_pan, 1000);
        assert_eq!(dev.stats().replays, 2);
        // A new sequence number is a new request.
        dev.receive(&request(6, Request::MoveBy { pan: 1000, tilt: -200 }), &mut out);
        assert_eq!(dev.head_state().target_pan, 2000);
        // Same seq but different content is not a retry.
        dev.receive(&request(6, Request::MoveBy { pan: 1, tilt: 0 }), &mut out);
        assert_eq!(dev.head_state().target_pan, 2001);
    }

    #[test]
    fn out_of_range_is_refused_without_effect() {
        let mut dev = LinkDevice::new(DeviceConfig::default());
        let mut out = CollectingOutput::default();
        dev.receive(
            &request(
                1,
                Request::MoveTo {
                    pan: 4_000_000,
                    tilt: 0,
                },
            ),
            &mut out,
        );
        assert!(out.effects.is_empty());
        assert_eq!(
            replies(&out.bytes),
            [(
                1,
                Message::Reply(Reply::Nack {
                    kind: kind::MOVE_TO,
                    code: NackCode::OutOfRange
                })
            )]
        );
    }

    #[test]
    fn motion_done_event_after_travel() {
        let mut dev = LinkDevice::new(DeviceConfig::default());
        let mut out = CollectingOutput::default();
        dev.advance(0, &mut out);
        dev.receive(&request(1, Request::MoveTo { pan: 500_000, tilt: 0 }), &mut out);
        dev.advance(400, &mut out); // 1 rad/s: 0.4 rad so far
        assert_eq!(dev.head_state().pan, 400_000);
        dev.advance(500, &mut out);
        let msgs: Vec<_> = replies(&out.bytes).into_iter().map(|(_, m)| m).collect();
        assert_eq!(msgs[0], Message::Event(Event::PowerOnReset));
        assert!(matches!(msgs[1], Message::Reply(Reply::Head(_))));
        match msgs[2] {
            Message::Event(Event::MotionDone(s)) => {
                assert_eq!((s.pan, s.tilt, s.moving()), (500_000, 0, false))
            }
            ref m => panic!("expected MotionDone, got {m:?}"),
        }
    }

    #[test]
    fn wrong_version_is_nacked() {
        let mut dev = LinkDevice::new(DeviceConfig::default());
        let mut out = CollectingOutput::default();
        let mut f = Frame::new(3, kind::HEARTBEAT, &[]).unwrap();
        f.version = 9;
        let mut w = [0u8; MAX_WIRE];
        let n = f.encode(&mut w);
        dev.receive(&w[..n], &mut out);
        assert_eq!(
            replies(&out.bytes),
            [(
                3,
                Message::Reply(Reply::Nack {
                    kind: kind::HEARTBEAT,
                    code: NackCode::VersionMismatch
                })
            )]
        );
    }

    proptest::proptest! {
        /// Any bytes, any clock steps: no panic, head within its limits.
        #[test]
        fn never_panics_on_any_bytes(chunks in proptest::collection::vec(proptest::collection::vec(proptest::prelude::any::<u8>(), 0..40), 0..30)) {
            let cfg = DeviceConfig::default();
            let mut dev = LinkDevice::new(cfg);
            let mut out = crate::firmware::CountingOutput::default();
            for (i, c) in chunks.iter().enumerate() {
                dev.receive(c, &mut out);
                dev.advance(i as u64 * 37, &mut out);
                let s = dev.head_state();
                proptest::prop_assert!(s.pan >= cfg.pan_range.0 && s.pan <= cfg.pan_range.1);
                proptest::prop_assert!(s.tilt >= cfg.tilt_range.0 && s.tilt <= cfg.tilt_range.1);
            }
        }
    }
}
