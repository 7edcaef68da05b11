//! The controller's clock: UTC now, and an async sleep until a UTC
//! instant. The controller reads time only through [`Clock`], so the same
//! code runs on the wall clock ([`SystemClock`]) and on the simulator's
//! calendar over tokio's pausable clock (`campanile_sim::clock::SimClock`),
//! where a whole day passes in moments.

use chrono::{DateTime, Utc};
use std::future::Future;

/// A source of UTC time that can wait.
pub trait Clock: Send + Sync {
    /// The time now, UTC.
    fn now(&self) -> DateTime<Utc>;
    /// Return once the clock reads `t` or later (at once if it already does).
    fn sleep_until(&self, t: DateTime<Utc>) -> impl Future<Output = ()> + Send;
}

/// The system's wall clock, waiting with tokio's timer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SystemClock;

impl Clock for SystemClock {
    fn now(&self) -> DateTime<Utc> {
        Utc::now()
    }

    async fn sleep_until(&self, t: DateTime<Utc>) {
        // Sleep in slices of at most a minute, so that a wall clock stepped
        // by NTP during a long wait is noticed.
        loop {
            let left = t - Utc::now();
            let Ok(left) = left.to_std() else { return };
            if left.is_zero() {
                return;
            }
            tokio::time::sleep(left.min(std::time::Duration::from_secs(60))).await;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn system_clock_returns_at_once_for_a_past_instant() {
        let c = SystemClock;
        let before = c.now();
        c.sleep_until(before - chrono::TimeDelta::seconds(5)).await;
        assert!(c.now() >= before);
    }
}
