//! The simulated calendar: tokio's clock (paused in tests, so a whole day
//! passes in moments) mapped to UTC from an injected origin. The camera
//! stamps frames and the world is rendered at [`SimClock::now`].

use chrono::{DateTime, TimeDelta, Utc};
use std::time::Duration;
use tokio::time::Instant;

/// Maps tokio's [`Instant`] to UTC: the origin instant is the origin date.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SimClock {
    origin_utc: DateTime<Utc>,
    origin: Instant,
}

impl SimClock {
    /// A clock that reads `origin_utc` now (call inside a tokio runtime).
    pub fn start(origin_utc: DateTime<Utc>) -> Self {
        Self::with_origin(origin_utc, Instant::now())
    }

    /// A clock that reads `origin_utc` at `origin`.
    pub fn with_origin(origin_utc: DateTime<Utc>, origin: Instant) -> Self {
        Self { origin_utc, origin }
    }

    /// The tokio instant of the origin.
    pub fn origin(&self) -> Instant {
        self.origin
    }

    /// The calendar time at `instant` (instants before the origin read the
    /// origin).
    pub fn at(&self, instant: Instant) -> DateTime<Utc> {
        let d = instant.saturating_duration_since(self.origin);
        self.origin_utc + TimeDelta::from_std(d).unwrap_or(TimeDelta::MAX)
    }

    /// The calendar time now.
    pub fn now(&self) -> DateTime<Utc> {
        self.at(Instant::now())
    }

    /// The tokio instant at which the calendar reads `t` (the origin for
    /// times before it).
    pub fn instant_of(&self, t: DateTime<Utc>) -> Instant {
        let d = (t - self.origin_utc).to_std().unwrap_or(Duration::ZERO);
        self.origin + d
    }

    /// Sleep until the calendar reads `t`.
    pub async fn sleep_until(&self, t: DateTime<Utc>) {
        tokio::time::sleep_until(self.instant_of(t)).await;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test(start_paused = true)]
    async fn follows_paused_tokio_time_exactly() {
        let origin: DateTime<Utc> = "2024-06-21T12:00:00Z".parse().unwrap();
        let clock = SimClock::start(origin);
        tokio::time::sleep(Duration::from_millis(90_061_500)).await;
        // 1 d 1 h 1 min 1.5 s later.
        let expected: DateTime<Utc> = "2024-06-22T13:01:01.5Z".parse().unwrap();
        assert_eq!(clock.now(), expected);
        let later: DateTime<Utc> = "2024-06-23T00:00:00Z".parse().unwrap();
        clock.sleep_until(later).await;
        assert_eq!(clock.now(), later);
        assert_eq!(clock.at(clock.origin() - Duration::from_secs(5)), origin);
    }
}
