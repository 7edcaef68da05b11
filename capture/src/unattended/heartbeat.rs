//! The heartbeat file, `STORE/heartbeat.json`: what the station is doing,
//! for outside monitoring. Rewritten atomically (temporary file, rename;
//! not fsynced: a crash may lose the last beat, never tear it) at every
//! frame, every state change and every device probe while waiting (at
//! least every [`super::StationOptions::health_interval`] of station
//! time), so a reader always sees a whole JSON object.
//!
//! ```json
//! {
//!   "written_utc": "2026-06-22T18:03:10Z",   station (simulated or real) time
//!   "wall_utc": "2026-11-22T12:01:02Z",      the computer's clock, for staleness
//!   "pid": 4242,
//!   "state": "capturing",                    starting | waiting | capturing | processing | stopped | finished | failed
//!   "detail": "sky@2026-06-22#29",
//!   "last_frame_utc": "2026-06-22T18:03:10Z",
//!   "last_frame_key": "sky@2026-06-22#29/s1/t2/f1",
//!   "devices": [{"device": "head", "status": "down", "since": "…", "error": "…", "probes": 3}, …],
//!   "free_disk_bytes": 40123456789,
//!   "store_bytes": 1234567,
//!   "budget_bytes": 2000000,
//!   "frames_today": 812,
//!   "day": "2026-06-22",
//!   "session_dir": "/data/sky/2026-06-22",
//!   "host": "station-1",                      who wrote it (see `super::liveness`);
//!   "boot_id": "0c2f…",                       absent in older heartbeats
//!   "start_ticks": 987654
//! }
//! ```
//!
//! A heartbeat is *stale* when its `wall_utc` is older than a threshold
//! (`campanile station status --max-age`, 300 s by default: five device
//! probes of a waiting station).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use chrono::{DateTime, NaiveDate, Utc};
use serde::{Deserialize, Serialize};

use super::liveness::{Liveness, ProcessIdentity, liveness};
use super::outage::{DeviceHealth, DeviceState};
use crate::clock::Clock;
use crate::controller::{Progress, ShotOutcome};
use crate::schedule::{Occurrence, PlannedShot};

/// File name of the heartbeat, in the store directory.
pub const HEARTBEAT_FILE: &str = "heartbeat.json";

/// What the station is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StationState {
    /// Opening the store and the devices.
    Starting,
    /// Waiting for the next scan (probing the devices).
    Waiting,
    /// Taking a scan.
    Capturing,
    /// Running the processing hook on a finished scan.
    Processing,
    /// Stopped on request (a signal); the same command continues.
    Stopped,
    /// Every occurrence of the plan's days is settled.
    Finished,
    /// Stopped by an error (e.g. the disk is full); see `detail`.
    Failed,
}

impl StationState {
    /// Whether a heartbeat in this state says that its writer runs
    /// (starting, waiting, capturing or processing).
    pub fn claims_running(self) -> bool {
        matches!(
            self,
            Self::Starting | Self::Waiting | Self::Capturing | Self::Processing
        )
    }
}

/// One device's line in the heartbeat.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DeviceLine {
    /// `camera`, `head`, `filter wheel` or `lights`.
    pub device: String,
    /// Its state.
    #[serde(flatten)]
    pub state: DeviceState,
}

/// The heartbeat's contents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Heartbeat {
    /// Station time of writing (simulated for a simulated station).
    pub written_utc: DateTime<Utc>,
    /// The computer's clock at writing, for staleness.
    pub wall_utc: DateTime<Utc>,
    /// The station's process id.
    pub pid: u32,
    /// What it is doing.
    pub state: StationState,
    /// More: the occurrence, what is awaited, or the error.
    pub detail: String,
    /// Station time of the last frame stored by this run.
    pub last_frame_utc: Option<DateTime<Utc>>,
    /// Its shot key.
    pub last_frame_key: Option<String>,
    /// Every device's state.
    pub devices: Vec<DeviceLine>,
    /// Free bytes on the store's file system (for unprivileged users).
    pub free_disk_bytes: Option<u64>,
    /// Bytes the storage budget counts.
    pub store_bytes: u64,
    /// The storage budget, if any.
    pub budget_bytes: Option<u64>,
    /// Frames journaled in the current day's session.
    pub frames_today: u64,
    /// The current plan day.
    pub day: Option<NaiveDate>,
    /// The current day's session directory.
    pub session_dir: Option<PathBuf>,
    /// The writer's host name (absent in heartbeats of older versions).
    #[serde(default)]
    pub host: Option<String>,
    /// The writer's host's boot id (absent when unknown).
    #[serde(default)]
    pub boot_id: Option<String>,
    /// The writer's start time, clock ticks after boot (absent when unknown).
    #[serde(default)]
    pub start_ticks: Option<u64>,
}

impl Heartbeat {
    /// A first heartbeat: starting, nothing known.
    pub fn starting(now: DateTime<Utc>, budget_bytes: Option<u64>) -> Self {
        let me = ProcessIdentity::of_self();
        Self {
            written_utc: now,
            wall_utc: Utc::now(),
            pid: std::process::id(),
            state: StationState::Starting,
            detail: String::new(),
            last_frame_utc: None,
            last_frame_key: None,
            devices: Vec::new(),
            free_disk_bytes: None,
            store_bytes: 0,
            budget_bytes,
            frames_today: 0,
            day: None,
            session_dir: None,
            host: me.as_ref().map(|m| m.host.clone()),
            boot_id: me.as_ref().and_then(|m| m.boot_id.clone()),
            start_ticks: me.map(|m| m.start_ticks),
        }
    }

    /// Who wrote it, when the heartbeat says.
    pub fn writer(&self) -> Option<ProcessIdentity> {
        Some(ProcessIdentity {
            host: self.host.clone()?,
            boot_id: self.boot_id.clone(),
            start_ticks: self.start_ticks?,
        })
    }

    /// Whether its writer still runs (see [`super::liveness`]).
    pub fn liveness(&self) -> Liveness {
        liveness(self.pid, self.writer().as_ref())
    }

    /// Seconds between `wall_utc` and `now`.
    pub fn age_s(&self, now: DateTime<Utc>) -> f64 {
        (now - self.wall_utc).num_milliseconds() as f64 / 1000.0
    }

    /// Read `store/heartbeat.json`.
    pub fn read(store: &Path) -> Result<Heartbeat, String> {
        let path = store.join(HEARTBEAT_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            format!(
                "{}: {e} (is {} the --store of a `campanile station run`?)",
                path.display(),
                store.display()
            )
        })?;
        serde_json::from_str(&text).map_err(|e| format!("{}: not a heartbeat: {e}", path.display()))
    }

    /// Write it to `store/heartbeat.json` atomically (temporary file, rename).
    pub fn write(&self, store: &Path) -> std::io::Result<()> {
        let path = store.join(HEARTBEAT_FILE);
        let tmp = store.join(format!(".{HEARTBEAT_FILE}.tmp"));
        let text = serde_json::to_vec_pretty(self).map_err(std::io::Error::other)?;
        std::fs::write(&tmp, text)?;
        std::fs::rename(&tmp, &path)
    }
}

/// Free bytes for unprivileged users on the file system holding `path`.
pub fn free_disk_bytes(path: &Path) -> Option<u64> {
    let s = rustix::fs::statvfs(path).ok()?;
    Some(s.f_bavail.saturating_mul(s.f_frsize))
}

/// The heartbeat as the run keeps it, shared between the run loop and its
/// progress and supervisor; every update rewrites the file.
#[derive(Debug, Clone)]
pub struct Beat {
    store: PathBuf,
    devices: Vec<crate::controller::DeviceKind>,
    shared: Arc<Mutex<(Heartbeat, DeviceHealth)>>,
}

impl Beat {
    /// Start beating into `store`, listing `devices` (those the station has).
    pub fn new(store: &Path, devices: &[crate::controller::DeviceKind], first: Heartbeat) -> Self {
        Self {
            store: store.to_path_buf(),
            devices: devices.to_vec(),
            shared: Arc::new(Mutex::new((first, DeviceHealth::default()))),
        }
    }

    /// Change the heartbeat and the device health, then rewrite the file
    /// at station time `now`. A failed write is logged, not fatal.
    pub fn update<T>(&self, now: DateTime<Utc>, f: impl FnOnce(&mut Heartbeat, &mut DeviceHealth) -> T) -> T {
        let mut guard = self.shared.lock().unwrap_or_else(PoisonError::into_inner);
        let (beat, health) = &mut *guard;
        let out = f(beat, health);
        beat.written_utc = now;
        beat.wall_utc = Utc::now();
        beat.devices = health
            .states()
            .filter(|(k, _)| self.devices.contains(k))
            .map(|(k, s)| DeviceLine {
                device: k.to_string(),
                state: s.clone(),
            })
            .collect();
        beat.free_disk_bytes = free_disk_bytes(&self.store);
        if let Err(e) = beat.write(&self.store) {
            tracing::warn!(store = %self.store.display(), error = %e, "could not write the heartbeat");
        }
        out
    }

    /// Read the device health without writing.
    pub fn health<T>(&self, f: impl FnOnce(&mut DeviceHealth) -> T) -> T {
        let mut guard = self.shared.lock().unwrap_or_else(PoisonError::into_inner);
        f(&mut guard.1)
    }

    /// A copy of the current heartbeat.
    pub fn snapshot(&self) -> Heartbeat {
        self.shared.lock().unwrap_or_else(PoisonError::into_inner).0.clone()
    }
}

/// Progress that beats at every stored frame, with the time from `clock`.
pub struct FrameBeat<'a, C> {
    /// The heartbeat.
    pub beat: &'a Beat,
    /// The station's clock.
    pub clock: &'a C,
    /// Also report to this.
    pub inner: &'a mut dyn Progress,
}

impl<C: Clock> Progress for FrameBeat<'_, C> {
    fn occurrence(&mut self, occurrence: &Occurrence) {
        self.beat.update(self.clock.now(), |b, _| {
            b.state = StationState::Capturing;
            b.detail = occurrence.key.clone();
        });
        self.inner.occurrence(occurrence);
    }

    fn step(&mut self, occurrence: &Occurrence, step: usize, kind: &str, shots: usize) {
        self.inner.step(occurrence, step, kind, shots);
    }

    fn shot(&mut self, shot: &PlannedShot, outcome: ShotOutcome) {
        if matches!(outcome, ShotOutcome::Stored | ShotOutcome::Late) {
            let now = self.clock.now();
            self.beat.update(now, |b, _| {
                b.last_frame_utc = Some(now);
                b.last_frame_key = Some(shot.key.clone());
                b.frames_today += 1;
            });
        }
        self.inner.shot(shot, outcome);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::DeviceKind;
    use chrono::TimeZone;

    #[test]
    fn a_beat_round_trips_with_devices_and_free_disk() {
        let dir = tempfile::tempdir().unwrap();
        let t = Utc.with_ymd_and_hms(2026, 6, 22, 18, 0, 0).unwrap();
        let beat = Beat::new(
            dir.path(),
            &crate::unattended::outage::WATCHED,
            Heartbeat::starting(t, Some(2_000_000)),
        );
        beat.update(t, |b, h| {
            b.state = StationState::Waiting;
            b.frames_today = 12;
            h.failed(DeviceKind::Head, t, "link closed");
            h.answered(DeviceKind::Camera, t);
        });
        let back = Heartbeat::read(dir.path()).unwrap();
        assert_eq!(back.state, StationState::Waiting);
        assert_eq!(back.frames_today, 12);
        assert_eq!(back.budget_bytes, Some(2_000_000));
        assert_eq!(back.devices.len(), 4);
        assert_eq!(back.devices[1].device, "head");
        assert!(matches!(back.devices[1].state, DeviceState::Down { since, .. } if since == t));
        assert!(back.free_disk_bytes.is_some_and(|b| b > 0));
        assert!(back.age_s(Utc::now()) < 60.0);
        let text = std::fs::read_to_string(dir.path().join(HEARTBEAT_FILE)).unwrap();
        assert!(text.contains("\"status\": \"down\""), "{text}");
        let e = Heartbeat::read(&dir.path().join("nowhere")).unwrap_err();
        assert!(e.contains("heartbeat.json") && e.contains("--store"), "{e}");
    }
}
