//! Stopping an unattended run from outside: a signal handler (SIGTERM,
//! SIGINT) or a test asks, and the run stops at the next frame boundary,
//! or at once while it waits for the next scan.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use tokio::sync::Notify;

/// A shared request to stop; clones share it.
#[derive(Debug, Clone, Default)]
pub struct StopHandle {
    inner: Arc<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    requested: AtomicBool,
    notify: Notify,
}

impl StopHandle {
    /// A handle nobody has asked to stop yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Ask the run to stop (idempotent).
    pub fn request(&self) {
        self.inner.requested.store(true, Ordering::SeqCst);
        self.inner.notify.notify_waiters();
    }

    /// Whether a stop was asked for.
    pub fn is_requested(&self) -> bool {
        self.inner.requested.load(Ordering::SeqCst)
    }

    /// Resolves once a stop is asked for (at once if it already was).
    pub async fn requested(&self) {
        loop {
            let notified = self.inner.notify.notified();
            tokio::pin!(notified);
            notified.as_mut().enable();
            if self.is_requested() {
                return;
            }
            notified.await;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[tokio::test(start_paused = true)]
    async fn a_request_wakes_a_waiter_and_stays_set() {
        let stop = StopHandle::new();
        assert!(!stop.is_requested());
        let other = stop.clone();
        let waiter = tokio::spawn(async move {
            other.requested().await;
            tokio::time::Instant::now()
        });
        let t0 = tokio::time::Instant::now();
        tokio::time::sleep(Duration::from_secs(5)).await;
        stop.request();
        let woke = waiter.await.expect("the waiter ends");
        assert_eq!(woke - t0, Duration::from_secs(5));
        assert!(stop.is_requested());
        // Already requested: resolves at once.
        tokio::time::timeout(Duration::from_millis(1), stop.requested())
            .await
            .expect("resolves at once");
    }
}
