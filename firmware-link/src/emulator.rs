//! Runs any device-side state machine ([`Firmware`]) over a byte stream
//! under tokio: the emulated device behind a pty, an in-memory duplex or a
//! fault injector. Time comes from tokio's clock, so it runs under paused
//! time in tests.

use crate::firmware::{CollectingOutput, Firmware};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncReadExt, AsyncWrite, AsyncWriteExt};
use tokio::task::JoinHandle;
use tokio::time::{Instant, MissedTickBehavior};

/// A running emulator.
#[derive(Debug)]
pub struct Emulator<F: Firmware> {
    firmware: Arc<Mutex<F>>,
    effects: Arc<Mutex<Vec<F::Effect>>>,
    task: JoinHandle<std::io::Result<()>>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl<F> Emulator<F>
where
    F: Firmware + Send + 'static,
    F::Effect: Send + 'static,
{
    /// Spawn `firmware` on `io`; it is advanced every `tick` and whenever
    /// bytes arrive. The task ends when `io` reaches end of file or fails.
    pub fn spawn<T>(firmware: F, io: T, tick: Duration) -> Self
    where
        T: AsyncRead + AsyncWrite + Unpin + Send + 'static,
    {
        let firmware = Arc::new(Mutex::new(firmware));
        let effects = Arc::new(Mutex::new(Vec::new()));
        let task = tokio::spawn(run(firmware.clone(), effects.clone(), io, tick));
        Self {
            firmware,
            effects,
            task,
        }
    }

    /// Inspect or drive the firmware (ground truth, fault injection).
    pub fn firmware(&self) -> MutexGuard<'_, F> {
        lock(&self.firmware)
    }

    /// Every effect so far, in order.
    pub fn effects(&self) -> MutexGuard<'_, Vec<F::Effect>> {
        lock(&self.effects)
    }

    /// Stop the emulator task.
    pub fn stop(&self) {
        self.task.abort();
    }

    /// Whether the emulator task has ended (link closed or failed).
    pub fn finished(&self) -> bool {
        self.task.is_finished()
    }
}

impl<F: Firmware> Drop for Emulator<F> {
    fn drop(&mut self) {
        self.task.abort();
    }
}

async fn run<F, T>(
    firmware: Arc<Mutex<F>>,
    effects: Arc<Mutex<Vec<F::Effect>>>,
    mut io: T,
    tick: Duration,
) -> std::io::Result<()>
where
    F: Firmware,
    T: AsyncRead + AsyncWrite + Unpin,
{
    let start = Instant::now();
    let mut ticker = tokio::time::interval(tick.max(Duration::from_millis(1)));
    ticker.set_missed_tick_behavior(MissedTickBehavior::Skip);
    let mut buf = [0u8; 512];
    loop {
        let mut out = CollectingOutput::default();
        tokio::select! {
            r = io.read(&mut buf) => {
                let n = r?;
                if n == 0 {
                    return Ok(());
                }
                let now = start.elapsed().as_millis() as u64;
                let mut fw = lock(&firmware);
                fw.advance(now, &mut out);
                fw.receive(&buf[..n], &mut out);
            }
            _ = ticker.tick() => {
                let now = start.elapsed().as_millis() as u64;
                lock(&firmware).advance(now, &mut out);
            }
        }
        if !out.effects.is_empty() {
            lock(&effects).extend(out.effects);
        }
        if !out.bytes.is_empty() {
            io.write_all(&out.bytes).await?;
            io.flush().await?;
        }
    }
}
