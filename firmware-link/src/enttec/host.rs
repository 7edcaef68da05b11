//! Host driver for an Enttec DMX USB Pro.

use super::{Deframer, MIN_CHANNELS, UNIVERSE, encode, encode_dmx, label};
use crate::driver_error::DriverError;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::time::Instant;

/// Widget parameters (label 3 reply).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WidgetParameters {
    /// Firmware version.
    pub firmware: u16,
    /// DMX break time, units of 10.67 µs.
    pub break_time: u8,
    /// Mark-after-break time, units of 10.67 µs.
    pub mab_time: u8,
    /// Output rate, packets per second.
    pub rate: u8,
}

/// A DMX USB Pro on a byte transport, driving `channels` dimmers.
#[derive(Debug)]
pub struct DmxUsbPro<T> {
    io: T,
    levels: Vec<u8>,
    timeout: Duration,
    deframer: Deframer,
}

impl<T: AsyncRead + AsyncWrite + Unpin> DmxUsbPro<T> {
    /// A driver for `channels` DMX channels (1..=512); frames carry at least
    /// 24 channels, as the widget requires.
    pub fn new(io: T, channels: usize, timeout: Duration) -> Self {
        Self {
            io,
            levels: vec![0; channels.clamp(MIN_CHANNELS, UNIVERSE)],
            timeout,
            deframer: Deframer::default(),
        }
    }

    /// The levels last sent, channel 1 first.
    pub fn levels(&self) -> &[u8] {
        &self.levels
    }

    /// Set channel `channel` (1-based) to `level` and send the universe.
    pub async fn set_level(&mut self, channel: u16, level: u8) -> Result<(), DriverError> {
        let i = usize::from(channel);
        if i == 0 || i > self.levels.len() {
            return Err(DriverError::OutOfRange {
                what: "DMX channel",
                value: i64::from(channel),
                min: 1,
                max: self.levels.len() as i64,
            });
        }
        self.levels[i - 1] = level;
        self.send().await
    }

    /// Set every channel to zero and send.
    pub async fn blackout(&mut self) -> Result<(), DriverError> {
        self.levels.iter_mut().for_each(|l| *l = 0);
        self.send().await
    }

    /// Send the current universe (label 6, start code 0).
    pub async fn send(&mut self) -> Result<(), DriverError> {
        let mut buf = [0u8; UNIVERSE + 6];
        let n = encode_dmx(&self.levels, &mut buf).map_err(|e| DriverError::Protocol(e.to_string()))?;
        self.io.write_all(&buf[..n]).await?;
        self.io.flush().await?;
        Ok(())
    }

    async fn ask(&mut self, lab: u8, data: &[u8]) -> Result<Vec<u8>, DriverError> {
        let mut buf = [0u8; 16];
        let n = encode(lab, data, &mut buf).map_err(|e| DriverError::Protocol(e.to_string()))?;
        self.io.write_all(&buf[..n]).await?;
        self.io.flush().await?;
        let deadline = Instant::now() + self.timeout;
        let mut rx = [0u8; 256];
        loop {
            let n = match tokio::time::timeout_at(deadline, self.io.read(&mut rx)).await {
                Err(_) => return Err(DriverError::Timeout { attempts: 1 }),
                Ok(r) => r?,
            };
            if n == 0 {
                return Err(DriverError::Disconnected);
            }
            for &b in &rx[..n] {
                if let Some(Ok(l)) = self.deframer.push(b)
                    && l == lab
                {
                    return Ok(self.deframer.data().to_vec());
                }
            }
        }
    }

    /// The widget's serial number (label 10; BCD decoded).
    pub async fn serial_number(&mut self) -> Result<u32, DriverError> {
        let d = self.ask(label::GET_SERIAL, &[]).await?;
        if d.len() != 4 {
            return Err(DriverError::Protocol(format!("serial number of {} bytes", d.len())));
        }
        let mut v = 0u32;
        for &b in d.iter().rev() {
            let (hi, lo) = (b >> 4, b & 0x0F);
            if hi > 9 || lo > 9 {
                return Err(DriverError::Protocol(format!("serial number byte {b:#04x} is not BCD")));
            }
            v = v * 100 + u32::from(hi) * 10 + u32::from(lo);
        }
        Ok(v)
    }

    /// The widget's parameters (label 3).
    pub async fn parameters(&mut self) -> Result<WidgetParameters, DriverError> {
        let d = self.ask(label::GET_PARAMETERS, &[0, 0]).await?;
        if d.len() < 5 {
            return Err(DriverError::Protocol(format!("parameters of {} bytes", d.len())));
        }
        Ok(WidgetParameters {
            firmware: u16::from_le_bytes([d[0], d[1]]),
            break_time: d[2],
            mab_time: d[3],
            rate: d[4],
        })
    }
}
