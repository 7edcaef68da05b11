//! A simulated serial port: a device-side firmware that outlives its
//! connections, reached by the host through an in-memory duplex, optionally
//! through firmware-link's seeded fault injector.
//!
//! The firmware is advanced on tokio's clock from one origin, so its time
//! runs on across reconnections. It is ticked only while it is busy (a head
//! travelling or settling) and otherwise brought up to date whenever bytes
//! arrive, so an idle station costs nothing under paused time; ground truth
//! read from an idle firmware is exact, and from a busy one at most one
//! tick old.

use crate::seed::{Purpose, derive};
use campanile_firmware_link::enttec::device::DmxDevice;
use campanile_firmware_link::firmware::{CollectingOutput, Firmware};
use campanile_firmware_link::flir_ptu::device::PtuDevice;
use campanile_firmware_link::fw102c::device::WheelDevice;
use campanile_firmware_link::link::device::LinkDevice;
use campanile_firmware_link::pelco_d::device::PelcoDevice;
use campanile_firmware_link::transport::fault::{FaultConfig, FaultStats, FaultyStream};
use campanile_firmware_link::transport::memory::duplex;
use std::io;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt, DuplexStream};
use tokio::task::JoinHandle;
use tokio::time::Instant;

/// The host end of a simulated serial link.
pub type HostStream = FaultyStream<DuplexStream>;

/// A firmware that can say whether time matters to it right now.
pub trait Powered: Firmware<Effect: Send> + Send + 'static {
    /// Whether the firmware must be advanced on every tick (something is
    /// moving); when not, it is advanced only when bytes arrive.
    fn busy(&self) -> bool;
}

impl Powered for LinkDevice {
    fn busy(&self) -> bool {
        self.head().moving()
    }
}

impl Powered for PelcoDevice {
    fn busy(&self) -> bool {
        self.head().moving()
    }
}

impl Powered for PtuDevice {
    fn busy(&self) -> bool {
        self.head().moving()
    }
}

impl Powered for WheelDevice {
    fn busy(&self) -> bool {
        false
    }
}

impl Powered for DmxDevice {
    fn busy(&self) -> bool {
        false
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

#[derive(Debug, Default)]
struct PortState {
    task: Option<JoinHandle<()>>,
    down_until: Option<Instant>,
    opened: u64,
    stats: Vec<Arc<FaultStats>>,
}

#[derive(Debug)]
struct Inner<F> {
    name: String,
    firmware: Arc<Mutex<F>>,
    origin: Instant,
    tick: Duration,
    faults: FaultConfig,
    purpose: Purpose,
    state: Mutex<PortState>,
}

/// A simulated device behind a port such as `sim:head`. Cloning shares the
/// device.
#[derive(Debug)]
pub struct DevicePort<F> {
    inner: Arc<Inner<F>>,
}

impl<F> Clone for DevicePort<F> {
    fn clone(&self) -> Self {
        Self {
            inner: self.inner.clone(),
        }
    }
}

impl<F: Powered> DevicePort<F> {
    /// A device powered on now. `faults` applies to every connection, each
    /// with a seed derived from `faults.seed`, `purpose` and the connection
    /// count. The firmware is advanced every `tick` while busy.
    pub fn new(name: &str, firmware: F, tick: Duration, faults: FaultConfig, purpose: Purpose) -> Self {
        Self {
            inner: Arc::new(Inner {
                name: name.to_string(),
                firmware: Arc::new(Mutex::new(firmware)),
                origin: Instant::now(),
                tick: tick.max(Duration::from_millis(1)),
                faults,
                purpose,
                state: Mutex::new(PortState::default()),
            }),
        }
    }

    /// The port name.
    pub fn name(&self) -> &str {
        &self.inner.name
    }

    /// The firmware (ground truth; fault injection).
    pub fn firmware(&self) -> MutexGuard<'_, F> {
        lock(&self.inner.firmware)
    }

    /// The shared firmware.
    pub fn shared(&self) -> Arc<Mutex<F>> {
        self.inner.firmware.clone()
    }

    /// Open the port: a fresh link to the firmware (any earlier link is cut).
    /// Fails with `NotFound` while the device is disconnected.
    pub fn open(&self) -> io::Result<HostStream> {
        let mut st = lock(&self.inner.state);
        if let Some(until) = st.down_until {
            if Instant::now() < until {
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("{} is disconnected", self.inner.name),
                ));
            }
            st.down_until = None;
        }
        if let Some(task) = st.task.take() {
            task.abort();
        }
        let (host, device) = duplex(8192);
        let seed = derive(self.inner.faults.seed, self.inner.purpose, st.opened);
        st.opened += 1;
        let stream = FaultyStream::new(
            host,
            FaultConfig {
                seed,
                ..self.inner.faults
            },
        );
        st.stats.push(stream.stats());
        st.task = Some(tokio::spawn(run(
            self.inner.firmware.clone(),
            self.inner.origin,
            device,
            self.inner.tick,
        )));
        Ok(stream)
    }

    /// Disconnect the device now for `duration`: its current link sees end
    /// of file (writes fail), and [`DevicePort::open`] fails until then.
    pub fn disconnect(&self, duration: Duration) {
        let mut st = lock(&self.inner.state);
        if let Some(task) = st.task.take() {
            task.abort();
        }
        st.down_until = Some(Instant::now() + duration);
    }

    /// Whether the device is disconnected now.
    pub fn is_disconnected(&self) -> bool {
        lock(&self.inner.state).down_until.is_some_and(|t| Instant::now() < t)
    }

    /// Bytes seen, dropped and corrupted on every link so far (the
    /// [`FaultStats::snapshot`] order, summed).
    pub fn fault_counts(&self) -> [u64; 6] {
        let st = lock(&self.inner.state);
        let mut sum = [0u64; 6];
        for s in &st.stats {
            for (a, b) in sum.iter_mut().zip(s.snapshot()) {
                *a += b;
            }
        }
        sum
    }
}

impl<F> Drop for Inner<F> {
    fn drop(&mut self) {
        if let Some(task) = lock(&self.state).task.take() {
            task.abort();
        }
    }
}

async fn run<F: Powered>(firmware: Arc<Mutex<F>>, origin: Instant, mut io: DuplexStream, tick: Duration) {
    let now_ms = || Instant::now().saturating_duration_since(origin).as_millis() as u64;
    let mut buf = [0u8; 512];
    loop {
        let busy = lock(&firmware).busy();
        let mut out = CollectingOutput::default();
        tokio::select! {
            r = io.read(&mut buf) => {
                let n = match r {
                    Ok(0) | Err(_) => return,
                    Ok(n) => n,
                };
                let mut fw = lock(&firmware);
                fw.advance(now_ms(), &mut out);
                fw.receive(&buf[..n], &mut out);
            }
            _ = tokio::time::sleep(tick), if busy => {
                lock(&firmware).advance(now_ms(), &mut out);
            }
        }
        if !out.bytes.is_empty() && (io.write_all(&out.bytes).await.is_err() || io.flush().await.is_err()) {
            return;
        }
    }
}
