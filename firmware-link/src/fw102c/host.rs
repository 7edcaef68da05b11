//! Host driver for a Thorlabs FW102C filter wheel.

use super::{Command, MAX_COMMAND, PROMPT, Response};
use crate::driver_error::DriverError;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::time::Instant;

/// An FW102C on a byte transport.
#[derive(Debug)]
pub struct Fw102c<T> {
    io: T,
    timeout: Duration,
    rx: Vec<u8>,
}

/// Longest answer kept.
const MAX_ANSWER: usize = 256;

impl<T: AsyncRead + AsyncWrite + Unpin> Fw102c<T> {
    /// A driver whose commands wait up to `timeout` for the prompt.
    pub fn new(io: T, timeout: Duration) -> Self {
        Self {
            io,
            timeout,
            rx: Vec::new(),
        }
    }

    /// Send a command and return the answer's value line, if any.
    pub async fn command(&mut self, cmd: Command) -> Result<Option<String>, DriverError> {
        let mut b = [0u8; MAX_COMMAND];
        let n = cmd.encode(&mut b);
        self.io.write_all(&b[..n]).await?;
        self.io.flush().await?;
        let deadline = Instant::now() + self.timeout;
        let mut buf = [0u8; 128];
        loop {
            if let Some(end) = self.rx.iter().position(|&c| c == PROMPT) {
                let answer: Vec<u8> = self.rx.drain(..=end).collect();
                let r = Response::parse(&answer[..answer.len() - 1]);
                if let Some(e) = r.error {
                    return Err(DriverError::Rejected(String::from_utf8_lossy(e).into_owned()));
                }
                return Ok(r.value.map(|v| String::from_utf8_lossy(v).into_owned()));
            }
            let n = match tokio::time::timeout_at(deadline, self.io.read(&mut buf)).await {
                Err(_) => return Err(DriverError::Timeout { attempts: 1 }),
                Ok(r) => r?,
            };
            if n == 0 {
                return Err(DriverError::Disconnected);
            }
            self.rx.extend_from_slice(&buf[..n]);
            if self.rx.len() > MAX_ANSWER && !self.rx.contains(&PROMPT) {
                self.rx.clear();
                return Err(DriverError::Protocol("answer without a prompt".into()));
            }
        }
    }

    async fn integer(&mut self, cmd: Command) -> Result<u8, DriverError> {
        let v = self.command(cmd).await?;
        v.as_deref()
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| DriverError::Protocol(format!("expected a number, got {v:?}")))
    }

    /// Turn to filter `n` (1-based).
    pub async fn set_position(&mut self, n: u8) -> Result<(), DriverError> {
        self.command(Command::SetPosition(n)).await.map(|_| ())
    }

    /// The current filter (1-based).
    pub async fn position(&mut self) -> Result<u8, DriverError> {
        self.integer(Command::GetPosition).await
    }

    /// Number of positions (6 or 12).
    pub async fn count(&mut self) -> Result<u8, DriverError> {
        self.integer(Command::GetCount).await
    }

    /// The identity string.
    pub async fn identify(&mut self) -> Result<String, DriverError> {
        Ok(self.command(Command::Identify).await?.unwrap_or_default())
    }
}
