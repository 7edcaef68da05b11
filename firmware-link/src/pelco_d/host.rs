//! Host driver for a Pelco-D head.
//!
//! Pelco-D acknowledges nothing but the position queries, so motion commands
//! are sent once and checked by querying; queries are retried on timeout.

use super::{Command, Deframer, FULL_TURN, from_wire, to_wire};
use crate::driver_error::DriverError;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::time::Instant;

/// A Pelco-D head on a byte transport.
#[derive(Debug)]
pub struct PelcoD<T> {
    io: T,
    address: u8,
    timeout: Duration,
    attempts: u32,
    deframer: Deframer,
}

impl<T: AsyncRead + AsyncWrite + Unpin> PelcoD<T> {
    /// A driver for the head at `address`; queries wait `timeout` and are
    /// tried up to `attempts` times.
    pub fn new(io: T, address: u8, timeout: Duration, attempts: u32) -> Self {
        Self {
            io,
            address,
            timeout,
            attempts: attempts.max(1),
            deframer: Deframer::default(),
        }
    }

    /// Send one command.
    pub async fn send(&mut self, cmd: Command) -> Result<(), DriverError> {
        self.io.write_all(&cmd.frame(self.address).encode()).await?;
        self.io.flush().await?;
        Ok(())
    }

    /// Start an absolute move, 1/100° (signed; sent modulo 360°).
    pub async fn goto(&mut self, pan: i32, tilt: i32) -> Result<(), DriverError> {
        for (what, v) in [("pan (1/100 deg)", pan), ("tilt (1/100 deg)", tilt)] {
            if v.abs() >= FULL_TURN {
                return Err(DriverError::OutOfRange {
                    what,
                    value: i64::from(v),
                    min: -i64::from(FULL_TURN - 1),
                    max: i64::from(FULL_TURN - 1),
                });
            }
        }
        self.send(Command::SetPan(to_wire(pan))).await?;
        self.send(Command::SetTilt(to_wire(tilt))).await
    }

    /// Stop all motion.
    pub async fn stop(&mut self) -> Result<(), DriverError> {
        self.send(Command::Stop).await
    }

    /// Store the current position as preset `n`.
    pub async fn set_preset(&mut self, n: u8) -> Result<(), DriverError> {
        self.send(Command::SetPreset(n)).await
    }

    /// Go to preset `n`.
    pub async fn go_to_preset(&mut self, n: u8) -> Result<(), DriverError> {
        self.send(Command::GoToPreset(n)).await
    }

    async fn query(&mut self, q: Command) -> Result<i32, DriverError> {
        let mut buf = [0u8; 64];
        for _ in 0..self.attempts {
            self.send(q).await?;
            let deadline = Instant::now() + self.timeout;
            loop {
                let n = match tokio::time::timeout_at(deadline, self.io.read(&mut buf)).await {
                    Err(_) => break,
                    Ok(r) => r?,
                };
                if n == 0 {
                    return Err(DriverError::Disconnected);
                }
                let mut answer = None;
                for &b in &buf[..n] {
                    if let Some(Ok(f)) = self.deframer.push(b) {
                        if f.address != self.address {
                            continue;
                        }
                        match (q, Command::from_frame(&f)) {
                            (Command::QueryPan, Some(Command::PanResponse(v)))
                            | (Command::QueryTilt, Some(Command::TiltResponse(v))) => answer = Some(from_wire(v)),
                            _ => {}
                        }
                    }
                }
                if let Some(v) = answer {
                    return Ok(v);
                }
            }
        }
        Err(DriverError::Timeout {
            attempts: self.attempts,
        })
    }

    /// The pan position, 1/100° in −18000..18000 (query `51`, answer `59`).
    pub async fn pan(&mut self) -> Result<i32, DriverError> {
        self.query(Command::QueryPan).await
    }

    /// The tilt position, 1/100° in −18000..18000 (query `53`, answer `5B`).
    pub async fn tilt(&mut self) -> Result<i32, DriverError> {
        self.query(Command::QueryTilt).await
    }
}
