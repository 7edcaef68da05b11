//! Reopening a device link that dropped: exponential backoff, capped, with
//! every attempt logged through `tracing`.
//!
//! A serial device that is unplugged, power-cycled or reset by a USB hub
//! comes back after a while; hammering its port meanwhile only fills the
//! log. [`Backoff`] waits `first`, then twice as long each time up to
//! `cap`, for at most `attempts` tries; [`reopen`] runs any connect
//! function (open the port, handshake with the driver) under it. Waits use
//! tokio's clock, so tests run under paused time.

use crate::device::DeviceError;
use std::future::Future;
use std::time::Duration;

/// When to try again after a failed reopen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Backoff {
    /// Tries in all (at least one).
    pub attempts: u32,
    /// The wait before the second try (the first is made at once).
    pub first: Duration,
    /// The longest wait between tries.
    pub cap: Duration,
}

impl Default for Backoff {
    /// 6 tries, waiting 0.5, 1, 2, 4 and 8 s between them (15.5 s in all),
    /// capped at 8 s.
    fn default() -> Self {
        Self {
            attempts: 6,
            first: Duration::from_millis(500),
            cap: Duration::from_secs(8),
        }
    }
}

impl Backoff {
    /// The wait before try `n` (0-based): zero for the first, then
    /// `first · 2^(n−1)`, never above `cap`.
    pub fn wait_before(&self, n: u32) -> Duration {
        if n == 0 {
            return Duration::ZERO;
        }
        let factor = 1u32.checked_shl(n - 1).unwrap_or(u32::MAX);
        self.first.checked_mul(factor).unwrap_or(self.cap).min(self.cap)
    }

    /// The total time spent waiting if every try fails.
    pub fn total_wait(&self) -> Duration {
        (0..self.attempts.max(1)).map(|n| self.wait_before(n)).sum()
    }
}

/// Connect `what` with `connect`, retrying under `backoff`; returns the
/// first success, or the last error once every try has failed. Each
/// failure is logged at `warn` with the wait before the next try, a
/// success after a failure at `info`, and giving up at `error`.
pub async fn reopen<T, F, Fut>(what: &str, backoff: Backoff, mut connect: F) -> Result<T, DeviceError>
where
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<T, DeviceError>>,
{
    let attempts = backoff.attempts.max(1);
    let mut n = 0;
    loop {
        tokio::time::sleep(backoff.wait_before(n)).await;
        match connect().await {
            Ok(v) => {
                if n > 0 {
                    tracing::info!(device = what, attempt = n + 1, "link reopened");
                }
                return Ok(v);
            }
            Err(e) if n + 1 < attempts => {
                let wait = backoff.wait_before(n + 1);
                tracing::warn!(device = what, attempt = n + 1, of = attempts, error = %e, retry_in_s = wait.as_secs_f64(), "reopening the link failed");
            }
            Err(e) => {
                tracing::error!(device = what, attempts, error = %e, "could not reopen the link; giving up");
                return Err(e);
            }
        }
        n += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_firmware_link::driver_error::DriverError;
    use tokio::time::Instant;

    #[test]
    fn waits_double_up_to_the_cap() {
        let b = Backoff {
            attempts: 7,
            first: Duration::from_millis(250),
            cap: Duration::from_secs(3),
        };
        let waits: Vec<u64> = (0..7).map(|n| b.wait_before(n).as_millis() as u64).collect();
        assert_eq!(waits, [0, 250, 500, 1000, 2000, 3000, 3000]);
        assert_eq!(b.total_wait(), Duration::from_millis(9750));
        // No overflow far out.
        assert_eq!(b.wait_before(200), Duration::from_secs(3));
        assert_eq!(Backoff::default().total_wait(), Duration::from_millis(15_500));
    }

    /// Fails three times, then connects: 0.5 + 1 + 2 s of waiting.
    #[tokio::test(start_paused = true)]
    async fn reopens_after_three_failures_with_doubling_waits() {
        let start = Instant::now();
        let mut tries = Vec::new();
        let got = reopen("head", Backoff::default(), || {
            tries.push(start.elapsed());
            let n = tries.len();
            async move {
                if n <= 3 {
                    Err(DeviceError::Link(DriverError::Disconnected))
                } else {
                    Ok(n)
                }
            }
        })
        .await
        .unwrap();
        assert_eq!(got, 4);
        let ms: Vec<u128> = tries.iter().map(Duration::as_millis).collect();
        assert_eq!(ms, [0, 500, 1500, 3500]);
    }

    /// Never connects: every try is made, then the last error is returned.
    #[tokio::test(start_paused = true)]
    async fn gives_up_after_every_attempt_with_the_last_error() {
        let start = Instant::now();
        let mut n = 0;
        let b = Backoff {
            attempts: 4,
            first: Duration::from_secs(1),
            cap: Duration::from_secs(2),
        };
        let r: Result<(), _> = reopen("wheel", b, || {
            n += 1;
            let k = n;
            async move { Err(DeviceError::Timeout(format!("try {k}"))) }
        })
        .await;
        assert!(matches!(r, Err(DeviceError::Timeout(ref m)) if m == "try 4"), "{r:?}");
        assert_eq!(n, 4);
        // 1 + 2 + 2 s.
        assert_eq!(start.elapsed(), Duration::from_secs(5));
    }
}
