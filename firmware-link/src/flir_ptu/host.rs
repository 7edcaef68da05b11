//! Host driver for a FLIR PTU over its ASCII protocol.
//!
//! [`Ptu::init`] turns echo off (`ED`) and selects terse feedback (`FT`).
//! Each command then waits for its status line; `!P`/`!T`/`!D` lines that
//! arrive first are set aside as [`Unsolicited`] events.

use super::{Axis, Command, MAX_COMMAND, Query, Reply, Setting, Unsolicited, is_reply_terminator};
use crate::driver_error::DriverError;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::time::Instant;

/// A reply line, owned.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Answer {
    /// `*`.
    Ack,
    /// `* <value>`.
    Value(String),
}

/// A PTU on a byte transport.
#[derive(Debug)]
pub struct Ptu<T> {
    io: T,
    timeout: Duration,
    line: Vec<u8>,
    pending: std::collections::VecDeque<u8>,
    events: Vec<Unsolicited>,
}

/// Longest reply line kept.
const MAX_LINE: usize = 256;

impl<T: AsyncRead + AsyncWrite + Unpin> Ptu<T> {
    /// A driver whose commands wait up to `timeout` for their status line.
    pub fn new(io: T, timeout: Duration) -> Self {
        Self {
            io,
            timeout,
            line: Vec::new(),
            pending: Default::default(),
            events: Vec::new(),
        }
    }

    /// Echo off, terse feedback.
    pub async fn init(&mut self) -> Result<(), DriverError> {
        self.command(Command::EchoOff).await?;
        self.command(Command::Terse).await?;
        Ok(())
    }

    /// Take the unsolicited lines received so far.
    pub fn take_events(&mut self) -> Vec<Unsolicited> {
        std::mem::take(&mut self.events)
    }

    /// Send a command and wait (up to `timeout`) for its status line.
    pub async fn command_within(&mut self, cmd: Command, timeout: Duration) -> Result<Answer, DriverError> {
        let mut b = [0u8; MAX_COMMAND];
        let n = cmd.encode(&mut b);
        self.io.write_all(&b[..n]).await?;
        self.io.flush().await?;
        let deadline = Instant::now() + timeout;
        let mut buf = [0u8; 128];
        loop {
            while let Some(byte) = self.pending.pop_front() {
                if !is_reply_terminator(byte) {
                    if self.line.len() < MAX_LINE {
                        self.line.push(byte);
                    }
                    continue;
                }
                let line = std::mem::take(&mut self.line);
                match Reply::parse(&line) {
                    Reply::Ack => return Ok(Answer::Ack),
                    Reply::Value(v) => return Ok(Answer::Value(String::from_utf8_lossy(v).into_owned())),
                    Reply::Error(e) => return Err(DriverError::Rejected(String::from_utf8_lossy(e).into_owned())),
                    Reply::Unsolicited(u) => self.events.push(u),
                    Reply::Unrecognized(_) => {}
                }
            }
            let n = match tokio::time::timeout_at(deadline, self.io.read(&mut buf)).await {
                Err(_) => return Err(DriverError::Timeout { attempts: 1 }),
                Ok(r) => r?,
            };
            if n == 0 {
                return Err(DriverError::Disconnected);
            }
            self.pending.extend(&buf[..n]);
        }
    }

    /// Send a command with the default timeout.
    pub async fn command(&mut self, cmd: Command) -> Result<Answer, DriverError> {
        self.command_within(cmd, self.timeout).await
    }

    /// Set an axis parameter (steps, steps/s, steps/s²).
    pub async fn set(&mut self, axis: Axis, what: Setting, value: i32) -> Result<(), DriverError> {
        self.command(Command::Set(axis, what, value)).await.map(|_| ())
    }

    /// Query an axis value (integer).
    pub async fn get(&mut self, axis: Axis, what: Query) -> Result<i64, DriverError> {
        match self.command(Command::Get(axis, what)).await? {
            Answer::Value(v) => Reply::Value(v.as_bytes())
                .integer()
                .ok_or_else(|| DriverError::Protocol(format!("not an integer: {v:?}"))),
            Answer::Ack => Err(DriverError::Protocol("query answered with a bare *".into())),
        }
    }

    /// Resolution of `axis`, arc-seconds per step × 1000.
    pub async fn resolution_milli_arcsec(&mut self, axis: Axis) -> Result<i64, DriverError> {
        match self.command(Command::Get(axis, Query::Resolution)).await? {
            Answer::Value(v) => Reply::Value(v.as_bytes())
                .milli()
                .ok_or_else(|| DriverError::Protocol(format!("not a resolution: {v:?}"))),
            Answer::Ack => Err(DriverError::Protocol("query answered with a bare *".into())),
        }
    }

    /// Wait for the last position commands to complete (`A`), up to `limit`.
    pub async fn await_motion(&mut self, limit: Duration) -> Result<(), DriverError> {
        self.command_within(Command::Await, limit).await.map(|_| ())
    }

    /// Halt both axes.
    pub async fn halt(&mut self) -> Result<(), DriverError> {
        self.command(Command::Halt).await.map(|_| ())
    }
}
