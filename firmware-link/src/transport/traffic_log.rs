//! A traffic log: every chunk read or written, as a line of timestamped hex
//! with its direction, appended to a file.
//!
//! ```text
//! # campanile traffic log, started 1763780000.123456 s since the Unix epoch
//! 0.000000 > 7e 06 04 00 00 ff 80 00 e7
//! 0.002310 < 2a 0d 0a
//! ```
//!
//! `>` is host to device (written through the wrapper), `<` device to host
//! (read through it). Times are seconds since the log started, on tokio's
//! clock (so they follow paused time in tests).

use std::fs::File;
use std::io::{self, LineWriter, Write};
use std::path::Path;
use std::pin::Pin;
use std::task::{Context, Poll, ready};
use std::time::SystemTime;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::time::Instant;

/// A transport whose traffic is logged.
#[derive(Debug)]
pub struct TrafficLog<T> {
    inner: T,
    log: LineWriter<File>,
    start: Instant,
}

impl<T> TrafficLog<T> {
    /// Wrap `inner`, appending to the file at `path` (created if missing).
    pub fn create(inner: T, path: &Path) -> io::Result<Self> {
        let file = std::fs::OpenOptions::new().create(true).append(true).open(path)?;
        let mut log = LineWriter::new(file);
        let epoch = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .unwrap_or_default();
        writeln!(
            log,
            "# campanile traffic log, started {}.{:06} s since the Unix epoch",
            epoch.as_secs(),
            epoch.subsec_micros()
        )?;
        Ok(Self {
            inner,
            log,
            start: Instant::now(),
        })
    }

    fn record(&mut self, direction: char, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        let t = self.start.elapsed();
        let mut line = format!("{}.{:06} {direction}", t.as_secs(), t.subsec_micros());
        for b in bytes {
            line.push_str(&format!(" {b:02x}"));
        }
        // A failing log must not break the link; the error is dropped.
        let _ = writeln!(self.log, "{line}");
    }
}

impl<T: AsyncRead + Unpin> AsyncRead for TrafficLog<T> {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        let before = buf.filled().len();
        ready!(Pin::new(&mut self.inner).poll_read(cx, buf))?;
        let got = buf.filled()[before..].to_vec();
        self.record('<', &got);
        Poll::Ready(Ok(()))
    }
}

impl<T: AsyncWrite + Unpin> AsyncWrite for TrafficLog<T> {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        let n = ready!(Pin::new(&mut self.inner).poll_write(cx, buf))?;
        self.record('>', &buf[..n]);
        Poll::Ready(Ok(n))
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::memory::duplex;
    use std::time::Duration;
    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    #[tokio::test(start_paused = true)]
    async fn logs_direction_time_and_hex() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("traffic.log");
        let (a, mut b) = duplex(64);
        let mut t = TrafficLog::create(a, &path).unwrap();
        t.write_all(&[0x7E, 0x0A, 0x00, 0x00, 0xE7]).await.unwrap();
        tokio::time::sleep(Duration::from_millis(1500)).await;
        b.write_all(b"*\r\n").await.unwrap();
        let mut buf = [0u8; 3];
        t.read_exact(&mut buf).await.unwrap();
        drop(t);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].starts_with("# campanile traffic log"));
        assert_eq!(lines[1], "0.000000 > 7e 0a 00 00 e7");
        assert_eq!(lines[2], "1.500000 < 2a 0d 0a");
    }
}
