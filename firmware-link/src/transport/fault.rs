//! A seeded fault injector that wraps any transport, in the manner of
//! smoltcp's `--drop-chance`/`--corrupt-chance` example flags.
//!
//! Faults apply independently to each direction: bytes written through the
//! wrapper (outgoing) and bytes read through it (incoming). Per byte: drop,
//! corrupt (replaced by a different random byte), duplicate. Per
//! read/write call: a short delay, or a long stall. After a set number of
//! bytes in total the link disconnects: writes fail with `BrokenPipe` and
//! reads see end of file. The same seed gives the same faults for the same
//! traffic.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::task::{Context, Poll, ready};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::time::Sleep;

/// Fault chances and sizes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultConfig {
    /// Seed of the fault generator.
    pub seed: u64,
    /// Chance that a byte is dropped.
    pub drop_chance: f64,
    /// Chance that a byte is replaced by a different random byte.
    pub corrupt_chance: f64,
    /// Chance that a byte is delivered twice.
    pub duplicate_chance: f64,
    /// Chance that a read or write call is delayed by up to `max_delay`.
    pub delay_chance: f64,
    /// Longest delay.
    pub max_delay: Duration,
    /// Chance that a read or write call stalls for `stall`.
    pub stall_chance: f64,
    /// Length of a stall.
    pub stall: Duration,
    /// Disconnect once this many bytes have passed (both directions).
    pub disconnect_after: Option<u64>,
}

impl FaultConfig {
    /// No faults at all, with this seed.
    pub fn none(seed: u64) -> Self {
        Self {
            seed,
            drop_chance: 0.0,
            corrupt_chance: 0.0,
            duplicate_chance: 0.0,
            delay_chance: 0.0,
            max_delay: Duration::ZERO,
            stall_chance: 0.0,
            stall: Duration::ZERO,
            disconnect_after: None,
        }
    }
}

/// Counts of injected faults, shared with the caller.
#[derive(Debug, Default)]
pub struct FaultStats {
    /// Bytes that passed the wrapper (before faults).
    pub bytes: AtomicU64,
    /// Bytes dropped.
    pub dropped: AtomicU64,
    /// Bytes corrupted.
    pub corrupted: AtomicU64,
    /// Bytes duplicated.
    pub duplicated: AtomicU64,
    /// Calls delayed.
    pub delays: AtomicU64,
    /// Calls stalled.
    pub stalls: AtomicU64,
}

impl FaultStats {
    fn add(counter: &AtomicU64, n: u64) {
        counter.fetch_add(n, Ordering::Relaxed);
    }

    /// A plain snapshot: (bytes, dropped, corrupted, duplicated, delays, stalls).
    pub fn snapshot(&self) -> [u64; 6] {
        [
            self.bytes.load(Ordering::Relaxed),
            self.dropped.load(Ordering::Relaxed),
            self.corrupted.load(Ordering::Relaxed),
            self.duplicated.load(Ordering::Relaxed),
            self.delays.load(Ordering::Relaxed),
            self.stalls.load(Ordering::Relaxed),
        ]
    }
}

/// A transport with injected faults.
#[derive(Debug)]
pub struct FaultyStream<T> {
    inner: T,
    config: FaultConfig,
    rng: ChaCha8Rng,
    stats: Arc<FaultStats>,
    total: u64,
    read_ready: Vec<u8>,
    write_pending: Vec<u8>,
    read_sleep: Option<Pin<Box<Sleep>>>,
    write_sleep: Option<Pin<Box<Sleep>>>,
}

impl<T> FaultyStream<T> {
    /// Wrap `inner`.
    pub fn new(inner: T, config: FaultConfig) -> Self {
        Self {
            inner,
            rng: ChaCha8Rng::seed_from_u64(config.seed),
            config,
            stats: Arc::new(FaultStats::default()),
            total: 0,
            read_ready: Vec::new(),
            write_pending: Vec::new(),
            read_sleep: None,
            write_sleep: None,
        }
    }

    /// The fault counters (shared; read them while the stream is in use).
    pub fn stats(&self) -> Arc<FaultStats> {
        self.stats.clone()
    }

    fn disconnected(&self) -> bool {
        self.config.disconnect_after.is_some_and(|n| self.total >= n)
    }

    /// Apply byte faults to `src`, appending the result to `dst`. Stops at
    /// the disconnect point.
    fn mangle(&mut self, src: &[u8], into_read: bool) {
        let c = self.config;
        let mut passed = 0u64;
        for &b in src {
            if c.disconnect_after.is_some_and(|n| self.total + passed >= n) {
                break;
            }
            passed += 1;
            let dst = if into_read {
                &mut self.read_ready
            } else {
                &mut self.write_pending
            };
            if self.rng.random_bool(c.drop_chance) {
                FaultStats::add(&self.stats.dropped, 1);
                continue;
            }
            let mut out = b;
            if self.rng.random_bool(c.corrupt_chance) {
                out = b ^ self.rng.random_range(1..=255u8);
                FaultStats::add(&self.stats.corrupted, 1);
            }
            dst.push(out);
            if self.rng.random_bool(c.duplicate_chance) {
                dst.push(out);
                FaultStats::add(&self.stats.duplicated, 1);
            }
        }
        self.total += passed;
        FaultStats::add(&self.stats.bytes, passed);
    }

    /// Maybe start a delay or a stall for the next call in one direction.
    fn maybe_pause(&mut self) -> Option<Pin<Box<Sleep>>> {
        let c = self.config;
        if self.rng.random_bool(c.stall_chance) {
            FaultStats::add(&self.stats.stalls, 1);
            return Some(Box::pin(tokio::time::sleep(c.stall)));
        }
        if self.rng.random_bool(c.delay_chance) && !c.max_delay.is_zero() {
            FaultStats::add(&self.stats.delays, 1);
            let d = self.rng.random_range(Duration::ZERO..=c.max_delay);
            return Some(Box::pin(tokio::time::sleep(d)));
        }
        None
    }
}

fn broken_pipe() -> io::Error {
    io::Error::new(io::ErrorKind::BrokenPipe, "fault injector: link disconnected")
}

impl<T: AsyncRead + Unpin> AsyncRead for FaultyStream<T> {
    fn poll_read(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        let this = &mut *self;
        loop {
            // A delay or stall holds back the chunk that was just read.
            if let Some(s) = this.read_sleep.as_mut() {
                ready!(s.as_mut().poll(cx));
                this.read_sleep = None;
            }
            if !this.read_ready.is_empty() {
                let n = this.read_ready.len().min(buf.remaining());
                buf.put_slice(&this.read_ready[..n]);
                this.read_ready.drain(..n);
                return Poll::Ready(Ok(()));
            }
            if this.disconnected() {
                return Poll::Ready(Ok(()));
            }
            let mut tmp = [0u8; 256];
            let mut rb = ReadBuf::new(&mut tmp);
            ready!(Pin::new(&mut this.inner).poll_read(cx, &mut rb))?;
            let got = rb.filled();
            if got.is_empty() {
                return Poll::Ready(Ok(()));
            }
            let got = got.to_vec();
            this.mangle(&got, true);
            this.read_sleep = this.maybe_pause();
        }
    }
}

impl<T: AsyncWrite + Unpin> FaultyStream<T> {
    fn poll_drain(&mut self, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        if let Some(s) = self.write_sleep.as_mut() {
            ready!(s.as_mut().poll(cx));
            self.write_sleep = None;
        }
        while !self.write_pending.is_empty() {
            let n = ready!(Pin::new(&mut self.inner).poll_write(cx, &self.write_pending))?;
            if n == 0 {
                return Poll::Ready(Err(io::ErrorKind::WriteZero.into()));
            }
            self.write_pending.drain(..n);
        }
        Poll::Ready(Ok(()))
    }
}

impl<T: AsyncWrite + Unpin> AsyncWrite for FaultyStream<T> {
    fn poll_write(mut self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        let this = &mut *self;
        ready!(this.poll_drain(cx))?;
        if this.disconnected() {
            return Poll::Ready(Err(broken_pipe()));
        }
        this.mangle(buf, false);
        this.write_sleep = this.maybe_pause();
        // Start sending now; what does not fit goes out on the next call or flush.
        if let Poll::Ready(Err(e)) = this.poll_drain(cx) {
            return Poll::Ready(Err(e));
        }
        Poll::Ready(Ok(buf.len()))
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let this = &mut *self;
        ready!(this.poll_drain(cx))?;
        Pin::new(&mut this.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let this = &mut *self;
        ready!(this.poll_drain(cx))?;
        Pin::new(&mut this.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::memory::duplex;
    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    async fn pass(config: FaultConfig, data: &[u8]) -> (Vec<u8>, [u64; 6]) {
        let (a, mut b) = duplex(1 << 20);
        let mut f = FaultyStream::new(a, config);
        let stats = f.stats();
        let _ = f.write_all(data).await;
        let _ = f.flush().await;
        drop(f);
        let mut got = Vec::new();
        b.read_to_end(&mut got).await.unwrap();
        (got, stats.snapshot())
    }

    #[tokio::test(start_paused = true)]
    async fn drop_rate_matches_the_chance() {
        let data = vec![0x55u8; 100_000];
        let mut cfg = FaultConfig::none(7);
        cfg.drop_chance = 0.02;
        let (got, s) = pass(cfg, &data).await;
        // Binomial(100000, 0.02): mean 2000, sd 44; ±5 sd.
        assert!((1780..=2220).contains(&s[1]), "dropped {}", s[1]);
        assert_eq!(got.len() as u64, 100_000 - s[1]);
        assert!(got.iter().all(|&b| b == 0x55));
    }

    #[tokio::test(start_paused = true)]
    async fn corruption_and_duplication_are_counted_exactly() {
        let data: Vec<u8> = (0..50_000u32).map(|i| i as u8).collect();
        let mut cfg = FaultConfig::none(11);
        cfg.corrupt_chance = 0.02;
        cfg.duplicate_chance = 0.01;
        let (got, s) = pass(cfg, &data).await;
        assert_eq!(got.len() as u64, 50_000 + s[3]);
        assert!((800..=1200).contains(&s[2]), "corrupted {}", s[2]);
        assert!((380..=620).contains(&s[3]), "duplicated {}", s[3]);
    }

    #[tokio::test(start_paused = true)]
    async fn same_seed_same_faults() {
        let data = vec![1u8; 5000];
        let mut cfg = FaultConfig::none(3);
        cfg.drop_chance = 0.05;
        cfg.corrupt_chance = 0.05;
        assert_eq!(pass(cfg, &data).await, pass(cfg, &data).await);
    }

    #[tokio::test(start_paused = true)]
    async fn disconnects_after_n_bytes() {
        let (a, mut b) = duplex(1024);
        let mut cfg = FaultConfig::none(1);
        cfg.disconnect_after = Some(10);
        let mut f = FaultyStream::new(a, cfg);
        f.write_all(&[9u8; 6]).await.unwrap();
        f.write_all(&[9u8; 6]).await.unwrap(); // 4 of these pass
        f.flush().await.unwrap();
        let e = f.write_all(&[9u8; 1]).await.unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::BrokenPipe);
        let mut buf = [0u8; 32];
        let n = b.read(&mut buf).await.unwrap();
        assert_eq!(n, 10);
        let mut r = [0u8; 1];
        assert_eq!(f.read(&mut r).await.unwrap(), 0);
    }

    #[tokio::test(start_paused = true)]
    async fn stalls_take_virtual_time() {
        let (a, _b) = duplex(1024);
        let mut cfg = FaultConfig::none(1);
        cfg.stall_chance = 1.0;
        cfg.stall = Duration::from_secs(3);
        let mut f = FaultyStream::new(a, cfg);
        let t0 = tokio::time::Instant::now();
        f.write_all(b"x").await.unwrap();
        f.flush().await.unwrap();
        assert_eq!(t0.elapsed(), Duration::from_secs(3));
        assert_eq!(f.stats().snapshot()[5], 1);
    }

    #[tokio::test(start_paused = true)]
    async fn read_side_stall_holds_back_the_chunk() {
        let (a, mut b) = duplex(1024);
        let mut cfg = FaultConfig::none(1);
        cfg.stall_chance = 1.0;
        cfg.stall = Duration::from_secs(2);
        let mut f = FaultyStream::new(a, cfg);
        b.write_all(b"abc").await.unwrap();
        let t0 = tokio::time::Instant::now();
        let mut buf = [0u8; 3];
        f.read_exact(&mut buf).await.unwrap();
        assert_eq!(&buf, b"abc");
        assert_eq!(t0.elapsed(), Duration::from_secs(2));
    }
}
