//! campanile-link messages: requests, replies and unsolicited events, and
//! their payload encodings (all integers little-endian).
//!
//! Units on the wire: angles in microradians (`i32`), angular speed in
//! µrad/s and acceleration in µrad/s² (`u32`), light levels as a fraction of
//! full scale in 1/65535 (`u16`), time in milliseconds.

use super::frame::MAX_PAYLOAD;
use thiserror::Error;

/// Largest number of light channels a reply carries.
pub const MAX_LIGHT_CHANNELS: usize = 8;

/// Why a payload could not be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum MessageError {
    /// The kind byte names no message.
    #[error("unknown message kind {0:#04x}")]
    UnknownKind(u8),
    /// The payload length does not fit the kind.
    #[error("payload of {len} bytes does not fit kind {kind:#04x}")]
    BadLength {
        /// The kind byte.
        kind: u8,
        /// The payload length received.
        len: usize,
    },
    /// A field holds a value that the kind does not allow.
    #[error("invalid field value in kind {0:#04x}")]
    BadField(u8),
}

/// A request from the host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Request {
    /// Move to an absolute pose, µrad.
    MoveTo {
        /// Pan, µrad.
        pan: i32,
        /// Tilt, µrad.
        tilt: i32,
    },
    /// Move the target by an offset, µrad.
    MoveBy {
        /// Pan offset, µrad.
        pan: i32,
        /// Tilt offset, µrad.
        tilt: i32,
    },
    /// Go to the home pose.
    Home,
    /// Halt both axes where they are.
    Stop,
    /// Set slew speed and acceleration for both axes.
    SetMotion {
        /// µrad/s.
        speed: u32,
        /// µrad/s².
        accel: u32,
    },
    /// Report the head's position and status.
    QueryHead,
    /// Select a filter slot (0-based).
    SelectFilter(u8),
    /// Report the filter wheel.
    QueryFilter,
    /// Set one light channel's level.
    SetLight {
        /// Channel, 0-based.
        channel: u8,
        /// Level, 0..=65535 of full scale.
        level: u16,
    },
    /// Turn every light channel off.
    AllLightsOff,
    /// Report every light channel.
    QueryLights,
    /// Report the device's identity and limits.
    DeviceInfo,
    /// Liveness check.
    Heartbeat,
}

/// Head position and status.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct HeadState {
    /// Current pan, µrad.
    pub pan: i32,
    /// Current tilt, µrad.
    pub tilt: i32,
    /// Commanded pan, µrad.
    pub target_pan: i32,
    /// Commanded tilt, µrad.
    pub target_tilt: i32,
    /// Status bits: [`HeadState::MOVING`], [`HeadState::HOMED`], [`HeadState::FAULT`].
    pub flags: u8,
}

impl HeadState {
    /// An axis is travelling.
    pub const MOVING: u8 = 1;
    /// The head has been homed since power-on.
    pub const HOMED: u8 = 2;
    /// A fault is latched.
    pub const FAULT: u8 = 4;

    /// Whether an axis is travelling.
    pub fn moving(&self) -> bool {
        self.flags & Self::MOVING != 0
    }
}

/// Filter wheel state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FilterState {
    /// Selected slot, 0-based.
    pub slot: u8,
    /// Number of slots.
    pub slots: u8,
}

/// Light levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightsState {
    /// Number of channels in use (≤ [`MAX_LIGHT_CHANNELS`]).
    pub count: u8,
    /// Levels, 0..=65535; entries past `count` are zero.
    pub levels: [u16; MAX_LIGHT_CHANNELS],
}

/// The device's identity and limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceInfo {
    /// Protocol version the device speaks.
    pub protocol: u8,
    /// Firmware version, major.minor.patch.
    pub firmware: [u8; 3],
    /// Lowest pan, µrad.
    pub pan_min: i32,
    /// Highest pan, µrad.
    pub pan_max: i32,
    /// Lowest tilt, µrad.
    pub tilt_min: i32,
    /// Highest tilt, µrad.
    pub tilt_max: i32,
    /// Filter slots (0 if none).
    pub filter_slots: u8,
    /// Light channels (0 if none).
    pub light_channels: u8,
}

/// Why the device refused a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum NackCode {
    /// A target lies outside the soft limits.
    OutOfRange = 1,
    /// The payload does not fit the request kind.
    BadPayload = 2,
    /// The kind is not a request this device knows.
    UnknownKind = 3,
    /// The device has no such subsystem (e.g. no filter wheel).
    Unsupported = 4,
    /// The frame's protocol version differs from the device's.
    VersionMismatch = 5,
    /// A fault is latched; home to clear it.
    Fault = 6,
}

impl NackCode {
    /// Decode a code byte.
    pub fn from_u8(b: u8) -> Option<Self> {
        Some(match b {
            1 => Self::OutOfRange,
            2 => Self::BadPayload,
            3 => Self::UnknownKind,
            4 => Self::Unsupported,
            5 => Self::VersionMismatch,
            6 => Self::Fault,
            _ => return None,
        })
    }
}

/// A reply from the device, carrying the request's sequence number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply {
    /// Ack with the head's new state.
    Head(HeadState),
    /// Ack with the filter wheel's new state.
    Filter(FilterState),
    /// Ack with the lights' new state.
    Lights(LightsState),
    /// Ack with the device info.
    Info(DeviceInfo),
    /// Ack of a heartbeat: milliseconds since power-on (wrapping).
    Heartbeat(u32),
    /// Refusal of the request `kind`.
    Nack {
        /// The refused request's kind byte.
        kind: u8,
        /// Why.
        code: NackCode,
    },
}

/// An unsolicited event from the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// An axis hit a hard limit (0 = pan, 1 = tilt); the head stopped.
    LimitHit {
        /// 0 = pan, 1 = tilt.
        axis: u8,
        /// State after stopping.
        state: HeadState,
    },
    /// The head came to rest at its target.
    MotionDone(HeadState),
    /// A fault was latched (device-specific code).
    Fault(u8),
    /// The device has just powered on or reset; its replay cache is empty.
    PowerOnReset,
}

/// Any campanile-link message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Message {
    /// Host to device.
    Request(Request),
    /// Device to host, answering a request.
    Reply(Reply),
    /// Device to host, unsolicited.
    Event(Event),
}

/// Kind bytes.
pub mod kind {
    /// [`super::Request::MoveTo`].
    pub const MOVE_TO: u8 = 0x01;
    /// [`super::Request::MoveBy`].
    pub const MOVE_BY: u8 = 0x02;
    /// [`super::Request::Home`].
    pub const HOME: u8 = 0x03;
    /// [`super::Request::Stop`].
    pub const STOP: u8 = 0x04;
    /// [`super::Request::SetMotion`].
    pub const SET_MOTION: u8 = 0x05;
    /// [`super::Request::QueryHead`].
    pub const QUERY_HEAD: u8 = 0x06;
    /// [`super::Request::SelectFilter`].
    pub const SELECT_FILTER: u8 = 0x10;
    /// [`super::Request::QueryFilter`].
    pub const QUERY_FILTER: u8 = 0x11;
    /// [`super::Request::SetLight`].
    pub const SET_LIGHT: u8 = 0x20;
    /// [`super::Request::AllLightsOff`].
    pub const ALL_LIGHTS_OFF: u8 = 0x21;
    /// [`super::Request::QueryLights`].
    pub const QUERY_LIGHTS: u8 = 0x22;
    /// [`super::Request::DeviceInfo`].
    pub const DEVICE_INFO: u8 = 0x30;
    /// [`super::Request::Heartbeat`].
    pub const HEARTBEAT: u8 = 0x31;
    /// [`super::Reply::Head`].
    pub const ACK_HEAD: u8 = 0x81;
    /// [`super::Reply::Filter`].
    pub const ACK_FILTER: u8 = 0x82;
    /// [`super::Reply::Lights`].
    pub const ACK_LIGHTS: u8 = 0x83;
    /// [`super::Reply::Info`].
    pub const ACK_INFO: u8 = 0x84;
    /// [`super::Reply::Heartbeat`].
    pub const ACK_HEARTBEAT: u8 = 0x85;
    /// [`super::Reply::Nack`].
    pub const NACK: u8 = 0x8F;
    /// [`super::Event::LimitHit`].
    pub const EV_LIMIT_HIT: u8 = 0xC0;
    /// [`super::Event::MotionDone`].
    pub const EV_MOTION_DONE: u8 = 0xC1;
    /// [`super::Event::Fault`].
    pub const EV_FAULT: u8 = 0xC2;
    /// [`super::Event::PowerOnReset`].
    pub const EV_POWER_ON_RESET: u8 = 0xC3;
}

/// A payload under construction.
struct Writer {
    buf: [u8; MAX_PAYLOAD],
    len: usize,
}

impl Writer {
    fn new() -> Self {
        Self {
            buf: [0; MAX_PAYLOAD],
            len: 0,
        }
    }
    fn put(&mut self, bytes: &[u8]) {
        // Every message below fits MAX_PAYLOAD (checked by tests); never panic.
        let end = (self.len + bytes.len()).min(MAX_PAYLOAD);
        let n = end - self.len;
        self.buf[self.len..end].copy_from_slice(&bytes[..n]);
        self.len = end;
    }
    fn u8(&mut self, v: u8) {
        self.put(&[v]);
    }
    fn u16(&mut self, v: u16) {
        self.put(&v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.put(&v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.put(&v.to_le_bytes());
    }
    fn head(&mut self, s: &HeadState) {
        self.i32(s.pan);
        self.i32(s.tilt);
        self.i32(s.target_pan);
        self.i32(s.target_tilt);
        self.u8(s.flags);
    }
}

/// A payload being read; every read checks length first.
struct Reader<'a> {
    buf: &'a [u8],
    kind: u8,
    total: usize,
}

impl<'a> Reader<'a> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], MessageError> {
        if self.buf.len() < N {
            return Err(MessageError::BadLength {
                kind: self.kind,
                len: self.total,
            });
        }
        let mut out = [0u8; N];
        out.copy_from_slice(&self.buf[..N]);
        self.buf = &self.buf[N..];
        Ok(out)
    }
    fn u8(&mut self) -> Result<u8, MessageError> {
        Ok(self.take::<1>()?[0])
    }
    fn u16(&mut self) -> Result<u16, MessageError> {
        Ok(u16::from_le_bytes(self.take()?))
    }
    fn u32(&mut self) -> Result<u32, MessageError> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    fn i32(&mut self) -> Result<i32, MessageError> {
        Ok(i32::from_le_bytes(self.take()?))
    }
    fn head(&mut self) -> Result<HeadState, MessageError> {
        Ok(HeadState {
            pan: self.i32()?,
            tilt: self.i32()?,
            target_pan: self.i32()?,
            target_tilt: self.i32()?,
            flags: self.u8()?,
        })
    }
    fn end(self) -> Result<(), MessageError> {
        if self.buf.is_empty() {
            Ok(())
        } else {
            Err(MessageError::BadLength {
                kind: self.kind,
                len: self.total,
            })
        }
    }
}

impl Message {
    /// The kind byte and payload of this message.
    pub fn encode(&self) -> (u8, [u8; MAX_PAYLOAD], usize) {
        let mut w = Writer::new();
        let k = match self {
            Message::Request(r) => match *r {
                Request::MoveTo { pan, tilt } => {
                    w.i32(pan);
                    w.i32(tilt);
                    kind::MOVE_TO
                }
                Request::MoveBy { pan, tilt } => {
                    w.i32(pan);
                    w.i32(tilt);
                    kind::MOVE_BY
                }
                Request::Home => kind::HOME,
                Request::Stop => kind::STOP,
                Request::SetMotion { speed, accel } => {
                    w.u32(speed);
                    w.u32(accel);
                    kind::SET_MOTION
                }
                Request::QueryHead => kind::QUERY_HEAD,
                Request::SelectFilter(s) => {
                    w.u8(s);
                    kind::SELECT_FILTER
                }
                Request::QueryFilter => kind::QUERY_FILTER,
                Request::SetLight { channel, level } => {
                    w.u8(channel);
                    w.u16(level);
                    kind::SET_LIGHT
                }
                Request::AllLightsOff => kind::ALL_LIGHTS_OFF,
                Request::QueryLights => kind::QUERY_LIGHTS,
                Request::DeviceInfo => kind::DEVICE_INFO,
                Request::Heartbeat => kind::HEARTBEAT,
            },
            Message::Reply(r) => match r {
                Reply::Head(s) => {
                    w.head(s);
                    kind::ACK_HEAD
                }
                Reply::Filter(f) => {
                    w.u8(f.slot);
                    w.u8(f.slots);
                    kind::ACK_FILTER
                }
                Reply::Lights(l) => {
                    let count = l.count.min(MAX_LIGHT_CHANNELS as u8);
                    w.u8(count);
                    for &lv in &l.levels[..usize::from(count)] {
                        w.u16(lv);
                    }
                    kind::ACK_LIGHTS
                }
                Reply::Info(i) => {
                    w.u8(i.protocol);
                    w.put(&i.firmware);
                    w.i32(i.pan_min);
                    w.i32(i.pan_max);
                    w.i32(i.tilt_min);
                    w.i32(i.tilt_max);
                    w.u8(i.filter_slots);
                    w.u8(i.light_channels);
                    kind::ACK_INFO
                }
                Reply::Heartbeat(t) => {
                    w.u32(*t);
                    kind::ACK_HEARTBEAT
                }
                Reply::Nack { kind: k, code } => {
                    w.u8(*k);
                    w.u8(*code as u8);
                    kind::NACK
                }
            },
            Message::Event(e) => match e {
                Event::LimitHit { axis, state } => {
                    w.u8(*axis);
                    w.head(state);
                    kind::EV_LIMIT_HIT
                }
                Event::MotionDone(s) => {
                    w.head(s);
                    kind::EV_MOTION_DONE
                }
                Event::Fault(c) => {
                    w.u8(*c);
                    kind::EV_FAULT
                }
                Event::PowerOnReset => kind::EV_POWER_ON_RESET,
            },
        };
        (k, w.buf, w.len)
    }

    /// Decode a payload of kind `k`. Never panics.
    pub fn decode(k: u8, payload: &[u8]) -> Result<Self, MessageError> {
        let mut r = Reader {
            buf: payload,
            kind: k,
            total: payload.len(),
        };
        let m = match k {
            kind::MOVE_TO => Message::Request(Request::MoveTo {
                pan: r.i32()?,
                tilt: r.i32()?,
            }),
            kind::MOVE_BY => Message::Request(Request::MoveBy {
                pan: r.i32()?,
                tilt: r.i32()?,
            }),
            kind::HOME => Message::Request(Request::Home),
            kind::STOP => Message::Request(Request::Stop),
            kind::SET_MOTION => Message::Request(Request::SetMotion {
                speed: r.u32()?,
                accel: r.u32()?,
            }),
            kind::QUERY_HEAD => Message::Request(Request::QueryHead),
            kind::SELECT_FILTER => Message::Request(Request::SelectFilter(r.u8()?)),
            kind::QUERY_FILTER => Message::Request(Request::QueryFilter),
            kind::SET_LIGHT => Message::Request(Request::SetLight {
                channel: r.u8()?,
                level: r.u16()?,
            }),
            kind::ALL_LIGHTS_OFF => Message::Request(Request::AllLightsOff),
            kind::QUERY_LIGHTS => Message::Request(Request::QueryLights),
            kind::DEVICE_INFO => Message::Request(Request::DeviceInfo),
            kind::HEARTBEAT => Message::Request(Request::Heartbeat),
            kind::ACK_HEAD => Message::Reply(Reply::Head(r.head()?)),
            kind::ACK_FILTER => Message::Reply(Reply::Filter(FilterState {
                slot: r.u8()?,
                slots: r.u8()?,
            })),
            kind::ACK_LIGHTS => {
                let count = r.u8()?;
                if usize::from(count) > MAX_LIGHT_CHANNELS {
                    return Err(MessageError::BadField(k));
                }
                let mut levels = [0u16; MAX_LIGHT_CHANNELS];
                for lv in levels.iter_mut().take(usize::from(count)) {
                    *lv = r.u16()?;
                }
                Message::Reply(Reply::Lights(LightsState { count, levels }))
            }
            kind::ACK_INFO => {
                let protocol = r.u8()?;
                let firmware = r.take::<3>()?;
                Message::Reply(Reply::Info(DeviceInfo {
                    protocol,
                    firmware,
                    pan_min: r.i32()?,
                    pan_max: r.i32()?,
                    tilt_min: r.i32()?,
                    tilt_max: r.i32()?,
                    filter_slots: r.u8()?,
                    light_channels: r.u8()?,
                }))
            }
            kind::ACK_HEARTBEAT => Message::Reply(Reply::Heartbeat(r.u32()?)),
            kind::NACK => {
                let refused = r.u8()?;
                let code = NackCode::from_u8(r.u8()?).ok_or(MessageError::BadField(k))?;
                Message::Reply(Reply::Nack { kind: refused, code })
            }
            kind::EV_LIMIT_HIT => {
                let axis = r.u8()?;
                if axis > 1 {
                    return Err(MessageError::BadField(k));
                }
                Message::Event(Event::LimitHit { axis, state: r.head()? })
            }
            kind::EV_MOTION_DONE => Message::Event(Event::MotionDone(r.head()?)),
            kind::EV_FAULT => Message::Event(Event::Fault(r.u8()?)),
            kind::EV_POWER_ON_RESET => Message::Event(Event::PowerOnReset),
            other => return Err(MessageError::UnknownKind(other)),
        };
        r.end()?;
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn head() -> impl Strategy<Value = HeadState> {
        (any::<i32>(), any::<i32>(), any::<i32>(), any::<i32>(), any::<u8>()).prop_map(
            |(pan, tilt, target_pan, target_tilt, flags)| HeadState {
                pan,
                tilt,
                target_pan,
                target_tilt,
                flags,
            },
        )
    }

    fn message() -> impl Strategy<Value = Message> {
        prop_oneof![
            (any::<i32>(), any::<i32>()).prop_map(|(pan, tilt)| Message::Request(Request::MoveTo { pan, tilt })),
            (any::<i32>(), any::<i32>()).prop_map(|(pan, tilt)| Message::Request(Request::MoveBy { pan, tilt })),
            Just(Message::Request(Request::Home)),
            Just(Message::Request(Request::Stop)),
            (any::<u32>(), any::<u32>())
                .prop_map(|(speed, accel)| Message::Request(Request::SetMotion { speed, accel })),
            Just(Message::Request(Request::QueryHead)),
            any::<u8>().prop_map(|s| Message::Request(Request::SelectFilter(s))),
            Just(Message::Request(Request::QueryFilter)),
            (any::<u8>(), any::<u16>())
                .prop_map(|(channel, level)| Message::Request(Request::SetLight { channel, level })),
            Just(Message::Request(Request::AllLightsOff)),
            Just(Message::Request(Request::QueryLights)),
            Just(Message::Request(Request::DeviceInfo)),
            Just(Message::Request(Request::Heartbeat)),
            head().prop_map(|s| Message::Reply(Reply::Head(s))),
            (any::<u8>(), any::<u8>())
                .prop_map(|(slot, slots)| Message::Reply(Reply::Filter(FilterState { slot, slots }))),
            (0u8..=8, any::<[u16; 8]>()).prop_map(|(count, mut levels)| {
                for l in levels.iter_mut().skip(usize::from(count)) {
                    *l = 0;
                }
                Message::Reply(Reply::Lights(LightsState { count, levels }))
            }),
            (
                any::<u8>(),
                any::<[u8; 3]>(),
                any::<[i32; 4]>(),
                any::<u8>(),
                any::<u8>()
            )
                .prop_map(|(protocol, firmware, l, filter_slots, light_channels)| Message::Reply(
                    Reply::Info(DeviceInfo {
                        protocol,
                        firmware,
                        pan_min: l[0],
                        pan_max: l[1],
                        tilt_min: l[2],
                        tilt_max: l[3],
                        filter_slots,
                        light_channels,
                    })
                )),
            any::<u32>().prop_map(|t| Message::Reply(Reply::Heartbeat(t))),
            (any::<u8>(), 1u8..=6).prop_map(|(kind, c)| Message::Reply(Reply::Nack {
                kind,
                code: NackCode::from_u8(c).unwrap()
            })),
            (0u8..=1, head()).prop_map(|(axis, state)| Message::Event(Event::LimitHit { axis, state })),
            head().prop_map(|s| Message::Event(Event::MotionDone(s))),
            any::<u8>().prop_map(|c| Message::Event(Event::Fault(c))),
            Just(Message::Event(Event::PowerOnReset)),
        ]
    }

    #[test]
    fn move_to_payload_layout() {
        // MoveTo pan = 1 rad (1_000_000 µrad = 0x000F4240), tilt = -1 µrad.
        let (k, p, n) = Message::Request(Request::MoveTo {
            pan: 1_000_000,
            tilt: -1,
        })
        .encode();
        assert_eq!(k, 0x01);
        assert_eq!(&p[..n], &[0x40, 0x42, 0x0F, 0x00, 0xFF, 0xFF, 0xFF, 0xFF]);
    }

    #[test]
    fn rejects_wrong_lengths() {
        assert_eq!(
            Message::decode(kind::MOVE_TO, &[0; 7]),
            Err(MessageError::BadLength {
                kind: kind::MOVE_TO,
                len: 7
            })
        );
        assert_eq!(
            Message::decode(kind::HOME, &[0]),
            Err(MessageError::BadLength {
                kind: kind::HOME,
                len: 1
            })
        );
        assert_eq!(Message::decode(0x7F, &[]), Err(MessageError::UnknownKind(0x7F)));
    }

    proptest! {
        #[test]
        fn round_trip(m in message()) {
            let (k, p, n) = m.encode();
            prop_assert!(n <= MAX_PAYLOAD);
            prop_assert_eq!(Message::decode(k, &p[..n]), Ok(m));
        }

        #[test]
        fn decode_never_panics(k: u8, p in proptest::collection::vec(any::<u8>(), 0..=MAX_PAYLOAD)) {
            let _ = Message::decode(k, &p);
        }
    }
}
