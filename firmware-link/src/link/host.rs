//! The host side of campanile-link: one request at a time, retried with
//! the same sequence number until the matching reply arrives.

use super::frame::{Deframer, Frame, MAX_WIRE};
use super::message::{DeviceInfo, Event, FilterState, HeadState, LightsState, Message, NackCode, Reply, Request};
use crate::driver_error::DriverError;
use std::collections::VecDeque;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::time::Instant;

/// Retry policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RetryPolicy {
    /// How long to wait for a reply before resending.
    pub timeout: Duration,
    /// Attempts per request (the first send included).
    pub max_attempts: u32,
}

impl Default for RetryPolicy {
    /// 100 ms per attempt, 20 attempts.
    fn default() -> Self {
        Self {
            timeout: Duration::from_millis(100),
            max_attempts: 20,
        }
    }
}

/// Counters kept by the client.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Requests completed with a reply.
    pub requests: u64,
    /// Resends after a timeout.
    pub retries: u64,
    /// Frames received that failed COBS, length or CRC checks.
    pub bad_frames: u64,
    /// Valid replies to an earlier sequence number (late or duplicated).
    pub stale_replies: u64,
    /// Unsolicited events received.
    pub events: u64,
}

/// A campanile-link client over any byte transport.
#[derive(Debug)]
pub struct LinkClient<T> {
    io: T,
    seq: u16,
    policy: RetryPolicy,
    deframer: Deframer,
    events: VecDeque<Event>,
    stats: LinkStats,
}

/// Most events kept before the oldest are dropped.
const EVENT_QUEUE: usize = 256;

impl<T: AsyncRead + AsyncWrite + Unpin> LinkClient<T> {
    /// A client whose first sequence number is `initial_seq` (pick it at
    /// random, e.g. from the clock, so that a restarted host does not reuse
    /// sequence numbers the device still has in its replay cache).
    pub fn new(io: T, policy: RetryPolicy, initial_seq: u16) -> Self {
        Self {
            io,
            seq: initial_seq,
            policy,
            deframer: Deframer::default(),
            events: VecDeque::new(),
            stats: LinkStats::default(),
        }
    }

    /// Counters so far.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Take the unsolicited events received so far.
    pub fn take_events(&mut self) -> Vec<Event> {
        self.events.drain(..).collect()
    }

    /// Send `req` and wait for its reply, retrying on timeout. A
    /// [`Reply::Nack`] is returned as a reply, not as an error.
    pub async fn request(&mut self, req: Request) -> Result<Reply, DriverError> {
        let seq = self.seq;
        self.seq = self.seq.wrapping_add(1);
        let (k, p, n) = Message::Request(req).encode();
        let frame = Frame::new(seq, k, &p[..n]).map_err(|e| DriverError::Protocol(e.to_string()))?;
        let mut wire = [0u8; MAX_WIRE];
        let len = frame.encode(&mut wire);
        let mut buf = [0u8; 256];
        for attempt in 0..self.policy.max_attempts {
            if attempt > 0 {
                self.stats.retries += 1;
            }
            // A leading delimiter ends any partial frame the device holds.
            self.io.write_all(&[0]).await?;
            self.io.write_all(&wire[..len]).await?;
            self.io.flush().await?;
            let deadline = Instant::now() + self.policy.timeout;
            loop {
                let n = match tokio::time::timeout_at(deadline, self.io.read(&mut buf)).await {
                    Err(_) => break,
                    Ok(r) => r?,
                };
                if n == 0 {
                    return Err(DriverError::Disconnected);
                }
                let mut found = None;
                for &b in &buf[..n] {
                    match self.deframer.push(b) {
                        None => {}
                        Some(Err(_)) => self.stats.bad_frames += 1,
                        Some(Ok(f)) => match Message::decode(f.kind, f.payload()) {
                            Ok(Message::Event(e)) => {
                                self.stats.events += 1;
                                if self.events.len() == EVENT_QUEUE {
                                    self.events.pop_front();
                                }
                                self.events.push_back(e);
                            }
                            Ok(Message::Reply(r)) if f.seq == seq && found.is_none() => found = Some(r),
                            Ok(Message::Reply(_)) => self.stats.stale_replies += 1,
                            Ok(Message::Request(_)) | Err(_) => self.stats.bad_frames += 1,
                        },
                    }
                }
                if let Some(r) = found {
                    self.stats.requests += 1;
                    return Ok(r);
                }
            }
        }
        Err(DriverError::Timeout {
            attempts: self.policy.max_attempts,
        })
    }

    fn rejected(code: NackCode) -> DriverError {
        DriverError::Rejected(format!("{code:?}"))
    }

    async fn head_request(&mut self, req: Request) -> Result<HeadState, DriverError> {
        match self.request(req).await? {
            Reply::Head(s) => Ok(s),
            Reply::Nack { code, .. } => Err(Self::rejected(code)),
            other => Err(DriverError::Protocol(format!("{other:?} in answer to {req:?}"))),
        }
    }

    /// Move to an absolute pose, µrad; returns the state with the new target.
    pub async fn move_to(&mut self, pan: i32, tilt: i32) -> Result<HeadState, DriverError> {
        self.head_request(Request::MoveTo { pan, tilt }).await
    }

    /// Move the target by an offset, µrad (applied exactly once).
    pub async fn move_by(&mut self, pan: i32, tilt: i32) -> Result<HeadState, DriverError> {
        self.head_request(Request::MoveBy { pan, tilt }).await
    }

    /// Start homing.
    pub async fn home(&mut self) -> Result<HeadState, DriverError> {
        self.head_request(Request::Home).await
    }

    /// Halt the head.
    pub async fn stop(&mut self) -> Result<HeadState, DriverError> {
        self.head_request(Request::Stop).await
    }

    /// Set slew speed (µrad/s) and acceleration (µrad/s²).
    pub async fn set_motion(&mut self, speed: u32, accel: u32) -> Result<HeadState, DriverError> {
        self.head_request(Request::SetMotion { speed, accel }).await
    }

    /// The head's position and status.
    pub async fn head(&mut self) -> Result<HeadState, DriverError> {
        self.head_request(Request::QueryHead).await
    }

    /// Poll until the head is at rest, every `poll`; gives up after `limit`.
    pub async fn wait_idle(&mut self, poll: Duration, limit: Duration) -> Result<HeadState, DriverError> {
        let end = Instant::now() + limit;
        loop {
            let s = self.head().await?;
            if !s.moving() {
                return Ok(s);
            }
            if Instant::now() >= end {
                return Err(DriverError::Timeout { attempts: 1 });
            }
            tokio::time::sleep(poll).await;
        }
    }

    async fn filter_request(&mut self, req: Request) -> Result<FilterState, DriverError> {
        match self.request(req).await? {
            Reply::Filter(s) => Ok(s),
            Reply::Nack { code, .. } => Err(Self::rejected(code)),
            other => Err(DriverError::Protocol(format!("{other:?} in answer to {req:?}"))),
        }
    }

    /// Select a filter slot (0-based).
    pub async fn select_filter(&mut self, slot: u8) -> Result<FilterState, DriverError> {
        self.filter_request(Request::SelectFilter(slot)).await
    }

    /// The filter wheel's state.
    pub async fn filter(&mut self) -> Result<FilterState, DriverError> {
        self.filter_request(Request::QueryFilter).await
    }

    async fn lights_request(&mut self, req: Request) -> Result<LightsState, DriverError> {
        match self.request(req).await? {
            Reply::Lights(s) => Ok(s),
            Reply::Nack { code, .. } => Err(Self::rejected(code)),
            other => Err(DriverError::Protocol(format!("{other:?} in answer to {req:?}"))),
        }
    }

    /// Set one channel's level (0..=65535 of full scale).
    pub async fn set_light(&mut self, channel: u8, level: u16) -> Result<LightsState, DriverError> {
        self.lights_request(Request::SetLight { channel, level }).await
    }

    /// Turn every channel off.
    pub async fn all_lights_off(&mut self) -> Result<LightsState, DriverError> {
        self.lights_request(Request::AllLightsOff).await
    }

    /// Every channel's level.
    pub async fn lights(&mut self) -> Result<LightsState, DriverError> {
        self.lights_request(Request::QueryLights).await
    }

    /// The device's identity and limits.
    pub async fn info(&mut self) -> Result<DeviceInfo, DriverError> {
        match self.request(Request::DeviceInfo).await? {
            Reply::Info(i) => Ok(i),
            other => Err(DriverError::Protocol(format!("{other:?} in answer to DeviceInfo"))),
        }
    }

    /// Liveness check; returns the device's uptime, ms (wrapping).
    pub async fn heartbeat(&mut self) -> Result<u32, DriverError> {
        match self.request(Request::Heartbeat).await? {
            Reply::Heartbeat(t) => Ok(t),
            other => Err(DriverError::Protocol(format!("{other:?} in answer to Heartbeat"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emulator::Emulator;
    use crate::link::device::{DeviceConfig, Effect, LinkDevice};
    use crate::transport::memory::duplex;

    #[tokio::test(start_paused = true)]
    async fn full_command_set_in_memory() {
        let (host, dev) = duplex(4096);
        let emu = Emulator::spawn(LinkDevice::new(DeviceConfig::default()), dev, Duration::from_millis(5));
        let mut c = LinkClient::new(host, RetryPolicy::default(), 1000);
        let info = c.info().await.unwrap();
        assert_eq!((info.protocol, info.filter_slots, info.light_channels), (1, 6, 4));
        assert_eq!(info.pan_max, 3_141_593);
        let s = c.move_to(500_000, -250_000).await.unwrap();
        assert_eq!((s.target_pan, s.target_tilt), (500_000, -250_000));
        let s = c
            .wait_idle(Duration::from_millis(20), Duration::from_secs(5))
            .await
            .unwrap();
        assert_eq!((s.pan, s.tilt), (500_000, -250_000));
        let s = c.move_by(-100_000, 50_000).await.unwrap();
        assert_eq!((s.target_pan, s.target_tilt), (400_000, -200_000));
        assert!(matches!(c.move_to(9_000_000, 0).await, Err(DriverError::Rejected(_))));
        c.set_motion(10_000, 1000).await.unwrap();
        c.move_to(0, 0).await.unwrap();
        tokio::time::sleep(Duration::from_millis(100)).await;
        // 10 mrad/s for ~100 ms from (0.5, -0.25) rad towards (0, 0): about 1 mrad of travel.
        let s = c.stop().await.unwrap();
        assert!(s.pan < 500_000 && s.pan > 498_000, "{s:?}");
        assert_eq!((s.target_pan, s.target_tilt, s.moving()), (s.pan, s.tilt, false));
        assert_eq!(c.select_filter(3).await.unwrap().slot, 3);
        assert_eq!(c.filter().await.unwrap(), FilterState { slot: 3, slots: 6 });
        assert_eq!(c.set_light(2, 40_000).await.unwrap().levels[2], 40_000);
        assert_eq!(c.lights().await.unwrap().levels[..4], [0, 0, 40_000, 0]);
        assert_eq!(c.all_lights_off().await.unwrap().levels, [0; 8]);
        let t = c.heartbeat().await.unwrap();
        assert!(t >= 100, "uptime {t}");
        c.home().await.unwrap();
        c.set_motion(1_000_000, 1000).await.unwrap();
        let s = c
            .wait_idle(Duration::from_millis(20), Duration::from_secs(5))
            .await
            .unwrap();
        assert_eq!((s.pan, s.tilt, s.flags & HeadState::HOMED), (0, 0, HeadState::HOMED));
        let events = c.take_events();
        assert!(events.contains(&Event::PowerOnReset), "{events:?}");
        assert!(events.iter().any(|e| matches!(e, Event::MotionDone(_))));
        let fx = emu.effects();
        assert_eq!(fx.iter().filter(|e| matches!(e, Effect::HeadMove { .. })).count(), 3);
        assert_eq!(c.stats().retries, 0);
    }

    #[tokio::test(start_paused = true)]
    async fn times_out_against_a_silent_device() {
        let (host, _dev) = duplex(4096);
        let policy = RetryPolicy {
            timeout: Duration::from_millis(50),
            max_attempts: 3,
        };
        let mut c = LinkClient::new(host, policy, 0);
        let t0 = Instant::now();
        assert!(matches!(c.heartbeat().await, Err(DriverError::Timeout { attempts: 3 })));
        assert_eq!(t0.elapsed(), Duration::from_millis(150));
        assert_eq!(c.stats().retries, 2);
    }

    #[tokio::test(start_paused = true)]
    async fn disconnect_is_reported_not_retried_forever() {
        use crate::transport::fault::{FaultConfig, FaultyStream};
        let (host, dev) = duplex(4096);
        let _emu = Emulator::spawn(LinkDevice::new(DeviceConfig::default()), dev, Duration::from_millis(5));
        let mut cfg = FaultConfig::none(1);
        cfg.disconnect_after = Some(200);
        let mut c = LinkClient::new(FaultyStream::new(host, cfg), RetryPolicy::default(), 0);
        let mut completed = 0;
        let err = loop {
            match c.heartbeat().await {
                Ok(_) => completed += 1,
                Err(e) => break e,
            }
        };
        // Each heartbeat exchange is about 25 bytes; the link dies within 200.
        assert!((3..=8).contains(&completed), "{completed}");
        assert!(
            matches!(err, DriverError::Disconnected)
                || matches!(&err, DriverError::Io(e) if e.kind() == std::io::ErrorKind::BrokenPipe),
            "{err:?}"
        );
    }
}
