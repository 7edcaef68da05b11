//! The unattended run: every occurrence of a plan's days, one day session
//! directory per plan day, until the days end or a stop is asked for.
//!
//! Per occurrence, in start order:
//! 1. Open its day's session (create, or resume after a restart) under the
//!    store: [`super::day_rollover`].
//! 2. Skip it if settled (every promised shot journaled, as a frame or
//!    missed, in this or an earlier run; unlike `capture --resume`, shots
//!    missed earlier are not retaken: the sky has moved on).
//! 3. Wait for its start, probing the devices ([`StationOptions::health_interval`];
//!    a down one with backoff), beating, and returning at once on a stop.
//! 4. If a device it needs is down, journal its open shots missed with
//!    the outage as the reason; otherwise run it through the controller
//!    under the [`StationSupervisor`] (stop between shots, damped
//!    exposures, device failures).
//! 5. Journal ended outages (`outage` lines), run the [`ScanHook`], and
//!    enforce the [`StorageBudget`] (`pruned` lines).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use campanile_config::Station;
use campanile_config::plan::Plan;
use chrono::{DateTime, NaiveDate, TimeDelta, Utc};

use super::day_rollover::{DayError, Opened, day_dir, existing_days, open_day, plan_day};
use super::exposure_plan::{ExposureChoice, ExposureDamping, ExposurePlan};
use super::heartbeat::{Beat, FrameBeat, Heartbeat, StationState};
use super::outage::EndedOutage;
use super::scan_hook::ScanHook;
use super::stop::StopHandle;
use super::storage_budget::{StorageBudget, deletable, occurrence_of, oldest_first, session_bytes};
use super::supervision::StationSupervisor;
use crate::clock::Clock;
use crate::controller::{self, DeviceKind, Progress, Rig, RunOptions};
use crate::device::{DeviceError, FilterWheel, PanTilt};
use crate::driver::backoff::Backoff;
use crate::schedule::{Occurrence, Timeline};
use crate::store::{FsStorage, ProcessedProducts, SessionStore, Snapshot, StoreError};

/// How the station behaves.
#[derive(Debug, Clone, PartialEq)]
pub struct StationOptions {
    /// The storage budget, if any.
    pub budget: Option<StorageBudget>,
    /// How often an idle device that is up is probed (head status, wheel
    /// position; lights and camera have no harmless query and are judged
    /// by their calls during scans).
    pub health_interval: Duration,
    /// How a down device is probed again: reconnect, then query, waiting
    /// `first`, doubling, at most `cap` (its `attempts` are not limited:
    /// a down device is probed until it is back).
    pub probe_backoff: Backoff,
    /// Exposure damping.
    pub exposure: ExposureDamping,
    /// The controller's options for each scan.
    pub run: RunOptions,
}

impl Default for StationOptions {
    /// No budget; probes every 60 s, a down device after 1, 2, 4 … 60 s;
    /// default damping; the controller's defaults except 2 reconnects per
    /// failed call (a device that stays down is the station's to probe).
    fn default() -> Self {
        Self {
            budget: None,
            health_interval: Duration::from_secs(60),
            probe_backoff: Backoff {
                attempts: u32::MAX,
                first: Duration::from_secs(1),
                cap: Duration::from_secs(60),
            },
            exposure: ExposureDamping::default(),
            run: RunOptions {
                reconnect_attempts: 2,
                ..RunOptions::default()
            },
        }
    }
}

/// What the station runs: the plan's timeline over its days.
#[derive(Debug, Clone, Copy)]
pub struct StationInputs<'a> {
    /// Every occurrence of the plan's days.
    pub timeline: &'a Timeline,
    /// The plan.
    pub plan: &'a Plan,
    /// The station.
    pub station: &'a Station,
    /// What each day session snapshots (plan, station, scene, provenance).
    pub snapshot: &'a Snapshot,
}

/// How the run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StationEnd {
    /// Every occurrence is settled.
    Finished,
    /// Stopped on request; the same command continues.
    Stopped,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct StationReport {
    /// How it ended.
    pub end: StationEnd,
    /// Frames journaled by this run.
    pub frames: usize,
    /// Shots journaled missed by the controller (device failures, late starts).
    pub missed: usize,
    /// Shots journaled missed because a device they need was down.
    pub missed_in_outages: usize,
    /// Occurrences run (wholly or in part).
    pub occurrences_run: usize,
    /// Occurrences settled by an earlier run, skipped.
    pub occurrences_skipped: usize,
    /// The day sessions opened.
    pub days: Vec<NaiveDate>,
    /// Frames pruned by the storage budget, and their bytes.
    pub pruned_frames: usize,
    /// Bytes pruned.
    pub pruned_bytes: u64,
    /// Outages journaled by this run.
    pub outages: Vec<EndedOutage>,
    /// Exposures chosen by this run.
    pub exposures: Vec<ExposureChoice>,
    /// Test captures taken to meter.
    pub metering_captures: usize,
}

/// Why the station stopped on an error.
#[derive(Debug, thiserror::Error)]
pub enum StationError {
    /// A day's session could not be opened.
    #[error(transparent)]
    Day(#[from] DayError),
    /// The store failed (e.g. the disk is full); the journal is valid up
    /// to the last frame, and the same command continues.
    #[error("the session {}: {source}", dir.display())]
    Store {
        /// The day session.
        dir: PathBuf,
        /// What failed.
        #[source]
        source: StoreError,
    },
    /// The store directory could not be made or read.
    #[error("the store {}: {source}", dir.display())]
    Io {
        /// The store directory.
        dir: PathBuf,
        /// What failed.
        #[source]
        source: std::io::Error,
    },
    /// An occurrence key has no plan day (`{session}@{YYYY-MM-DD}`).
    #[error("occurrence {0:?} has no plan day in its key")]
    NoDay(String),
}

/// A run stopped by an error, with what it did before.
#[derive(Debug, thiserror::Error)]
#[error("{error}")]
pub struct StationFailure {
    /// The error.
    #[source]
    pub error: StationError,
    /// What the run did.
    pub report: Box<StationReport>,
}

/// Run the station (see the module documentation) into the store
/// directory `root`.
#[allow(clippy::too_many_arguments)]
pub async fn run<R: Rig, C: Clock>(
    inputs: &StationInputs<'_>,
    root: &Path,
    rig: &mut R,
    clock: &C,
    options: &StationOptions,
    hook: &mut dyn ScanHook,
    stop: &StopHandle,
    progress: &mut dyn Progress,
) -> Result<StationReport, StationFailure> {
    let mut devices = vec![DeviceKind::Camera];
    devices.extend(probed(inputs.station));
    let beat = Beat::new(
        root,
        &devices,
        Heartbeat::starting(clock.now(), options.budget.map(|b| b.max_bytes)),
    );
    let mut station = Unattended {
        inputs: *inputs,
        root: root.to_path_buf(),
        rig,
        clock,
        options,
        stop,
        beat,
        days: BTreeMap::new(),
        exposure: ExposurePlan::new(options.exposure),
        last_probe: Vec::new(),
        report: StationReport {
            end: StationEnd::Stopped,
            frames: 0,
            missed: 0,
            missed_in_outages: 0,
            occurrences_run: 0,
            occurrences_skipped: 0,
            days: Vec::new(),
            pruned_frames: 0,
            pruned_bytes: 0,
            outages: Vec::new(),
            exposures: Vec::new(),
            metering_captures: 0,
        },
        budget_warned: false,
    };
    let result = station.all(hook, progress).await;
    station.report.exposures = station.exposure.choices().to_vec();
    let now = clock.now();
    // Outages still open when the run ends are journaled as such.
    let flushed = station.journal_outages(true);
    match flushed.and(result) {
        Ok(end) => {
            station.report.end = end;
            let (state, detail) = match end {
                StationEnd::Finished => (StationState::Finished, "every occurrence of the plan's days is settled"),
                StationEnd::Stopped => (
                    StationState::Stopped,
                    "stopped on request; run the same command to continue",
                ),
            };
            station.beat.update(now, |b, _| {
                b.state = state;
                b.detail = detail.to_owned();
            });
            Ok(station.report)
        }
        Err(error) => {
            let detail = format!("{error}; run the same command to continue once it is fixed");
            station.beat.update(now, |b, _| {
                b.state = StationState::Failed;
                b.detail = detail;
            });
            Err(StationFailure {
                error,
                report: Box::new(station.report),
            })
        }
    }
}

struct Unattended<'a, R, C> {
    inputs: StationInputs<'a>,
    root: PathBuf,
    rig: &'a mut R,
    clock: &'a C,
    options: &'a StationOptions,
    stop: &'a StopHandle,
    beat: Beat,
    days: BTreeMap<NaiveDate, SessionStore<FsStorage>>,
    exposure: ExposurePlan,
    /// When each probed device was last probed.
    last_probe: Vec<(DeviceKind, DateTime<Utc>)>,
    report: StationReport,
    budget_warned: bool,
}

/// The devices a station probes: the head, and the wheel and lights it has.
fn probed(station: &Station) -> Vec<DeviceKind> {
    let mut kinds = vec![DeviceKind::Head];
    if station.filter_wheel.is_some() {
        kinds.push(DeviceKind::Wheel);
    }
    if station.lights.is_some() {
        kinds.push(DeviceKind::Lights);
    }
    kinds
}

/// The devices `occurrence` cannot do without: the camera and head
/// (every shot aims), the wheel if the station has one (every shot sets a
/// filter), the lights if a shot sets them.
fn needed(occurrence: &Occurrence, station: &Station) -> Vec<DeviceKind> {
    let mut kinds = vec![DeviceKind::Camera, DeviceKind::Head];
    if station.filter_wheel.is_some() {
        kinds.push(DeviceKind::Wheel);
    }
    if occurrence.shots.iter().any(|s| s.lights.is_some()) {
        kinds.push(DeviceKind::Lights);
    }
    kinds
}

impl<R: Rig, C: Clock> Unattended<'_, R, C> {
    fn store_error(&self, day: NaiveDate, source: StoreError) -> StationError {
        StationError::Store {
            dir: day_dir(&self.root, day),
            source,
        }
    }

    async fn all(&mut self, hook: &mut dyn ScanHook, progress: &mut dyn Progress) -> Result<StationEnd, StationError> {
        std::fs::create_dir_all(&self.root).map_err(|source| StationError::Io {
            dir: self.root.clone(),
            source,
        })?;
        let existing = existing_days(&self.root).map_err(|source| StationError::Io {
            dir: self.root.clone(),
            source,
        })?;
        for day in existing {
            self.open(day)?;
        }
        self.enforce_budget()?;
        let timeline = self.inputs.timeline;
        let mut ordinal = 0u64;
        for occ in &timeline.occurrences {
            let first_ordinal = ordinal;
            ordinal += occ.shots.len() as u64;
            if self.stop.is_requested() {
                return Ok(StationEnd::Stopped);
            }
            let day = plan_day(occ).ok_or_else(|| StationError::NoDay(occ.key.clone()))?;
            self.enter_day(day)?;
            if self.settled(day, occ) {
                self.report.occurrences_skipped += 1;
                if let Some(store) = self.days.get(&day) {
                    self.exposure.recall(occ, store);
                    let listed = ProcessedProducts::read(store.dir()).is_ok_and(|p| p.contains(&occ.key));
                    let has_frames = occ.shots.iter().any(|s| store.frame_entry(&s.key).is_some());
                    if has_frames && !listed {
                        self.process(hook, day, occ);
                    }
                }
                continue;
            }
            if !self.wait_until(occ.start, &occ.key).await {
                return Ok(StationEnd::Stopped);
            }
            self.journal_outages(false)?;
            let down = needed(occ, self.inputs.station)
                .into_iter()
                .find_map(|k| self.beat.health(|h| h.down_since(k)).map(|since| (k, since)));
            if let Some((kind, since)) = down {
                self.miss_in_outage(day, occ, kind, since)?;
                continue;
            }
            self.report.occurrences_run += 1;
            let stopped = self.scan(day, occ, first_ordinal, progress).await?;
            self.journal_outages(false)?;
            if stopped {
                return Ok(StationEnd::Stopped);
            }
            self.process(hook, day, occ);
            self.enforce_budget()?;
        }
        Ok(StationEnd::Finished)
    }

    /// Open (create or resume) the session of `day`.
    fn open(&mut self, day: NaiveDate) -> Result<(), StationError> {
        let (store, opened) = open_day(&self.root, day, self.inputs.snapshot)?;
        match opened {
            Opened::Created => tracing::info!(dir = %store.dir().display(), "day session created"),
            Opened::Resumed(r) => tracing::info!(dir = %store.dir().display(), report = %r, "day session resumed"),
        }
        self.report.days.push(day);
        self.days.insert(day, store);
        Ok(())
    }

    /// Make `day` the current one (opening its session), and say so in the heartbeat.
    fn enter_day(&mut self, day: NaiveDate) -> Result<(), StationError> {
        if !self.days.contains_key(&day) {
            self.open(day)?;
        }
        if self.beat.snapshot().day == Some(day) {
            return Ok(());
        }
        let store = &self.days[&day];
        let frames = store.entries().iter().filter(|e| e.frame().is_some()).count() as u64;
        let dir = store.dir().to_path_buf();
        tracing::info!(%day, dir = %dir.display(), "the day rolls over");
        let bytes = self.store_bytes();
        self.beat.update(self.clock.now(), |b, _| {
            b.day = Some(day);
            b.session_dir = Some(dir);
            b.frames_today = frames;
            b.store_bytes = bytes;
        });
        Ok(())
    }

    fn store_bytes(&self) -> u64 {
        self.days.values().map(session_bytes).sum()
    }

    /// Every promised shot of `occ` journaled (a frame or missed).
    fn settled(&self, day: NaiveDate, occ: &Occurrence) -> bool {
        let Some(store) = self.days.get(&day) else {
            return false;
        };
        occ.shots
            .iter()
            .filter(|s| s.promised)
            .all(|s| store.completed(&s.key) || store.missed(&s.key))
    }

    /// Wait until `t`, probing devices; `false` if a stop was asked for.
    async fn wait_until(&mut self, t: DateTime<Utc>, next: &str) -> bool {
        let detail = format!("next: {next} at {}", t.format("%Y-%m-%d %H:%M:%S UTC"));
        self.beat.update(self.clock.now(), |b, _| {
            b.state = StationState::Waiting;
            b.detail = detail.clone();
        });
        loop {
            if self.stop.is_requested() {
                return false;
            }
            let now = self.clock.now();
            self.probe_due(now).await;
            if self.stop.is_requested() {
                return false;
            }
            let now = self.clock.now();
            if now >= t {
                return true;
            }
            let wake = self.next_probe().map_or(t, |p| p.min(t)).max(now);
            let stop = self.stop.clone();
            tokio::select! {
                () = self.clock.sleep_until(wake) => {}
                () = stop.requested() => return false,
            }
        }
    }

    /// When the next device probe is due.
    fn next_probe(&self) -> Option<DateTime<Utc>> {
        probed(self.inputs.station)
            .into_iter()
            .map(|k| self.probe_due_at(k))
            .min()
    }

    fn probe_due_at(&self, kind: DeviceKind) -> DateTime<Utc> {
        let last = self.last_probe.iter().find(|(k, _)| *k == kind).map(|(_, t)| *t);
        let Some(last) = last else {
            return DateTime::<Utc>::MIN_UTC;
        };
        let wait = match self.beat.health(|h| h.down_since(kind).map(|_| h.failed_probes(kind))) {
            Some(probes) => self.options.probe_backoff.wait_before(probes.saturating_add(1)),
            None => self.options.health_interval,
        };
        last + TimeDelta::from_std(wait).unwrap_or(TimeDelta::MAX)
    }

    /// Probe every device whose probe is due at `now`.
    async fn probe_due(&mut self, now: DateTime<Utc>) {
        for kind in probed(self.inputs.station) {
            if self.probe_due_at(kind) > now {
                continue;
            }
            // Lights have no harmless query: they are probed only when
            // down (by reconnecting), else judged by their calls in scans.
            if kind == DeviceKind::Lights && self.beat.health(|h| h.down_since(kind).is_none()) {
                self.last_probe.retain(|(k, _)| *k != kind);
                self.last_probe.push((kind, now));
                continue;
            }
            let result = self.probe(kind).await;
            let t = self.clock.now();
            self.last_probe.retain(|(k, _)| *k != kind);
            self.last_probe.push((kind, t));
            let changed = self.beat.health(|h| {
                let was_down = h.down_since(kind).is_some();
                match &result {
                    Ok(()) => h.answered(kind, t),
                    Err(e) => h.failed(kind, t, &e.to_string()),
                }
                was_down != h.down_since(kind).is_some() || result.is_err()
            });
            if changed {
                self.beat.update(t, |_, _| ());
            }
        }
        let now = self.clock.now();
        self.beat.update(now, |_, _| ());
    }

    /// One probe: reconnect a down device first, then ask it something harmless.
    async fn probe(&mut self, kind: DeviceKind) -> Result<(), DeviceError> {
        let down = self.beat.health(|h| h.down_since(kind).is_some());
        let limit = self.options.run.watchdog;
        let call = async {
            if down {
                self.rig.reconnect(kind).await?;
            }
            match kind {
                DeviceKind::Head => self.rig.head().status().await.map(|_| ()),
                DeviceKind::Wheel => match self.rig.wheel() {
                    Some(w) => w.current().await.map(|_| ()),
                    None => Ok(()),
                },
                DeviceKind::Lights | DeviceKind::Camera => Ok(()),
            }
        };
        match tokio::time::timeout(limit, call).await {
            Ok(r) => r,
            Err(_) => Err(DeviceError::Timeout(format!(
                "watchdog: no answer from the {kind} probe within {limit:?}"
            ))),
        }
    }

    /// Journal every outage that ended (and, with `all`, those still open,
    /// as open) in the current day's session.
    fn journal_outages(&mut self, all: bool) -> Result<(), StationError> {
        let now = self.clock.now();
        let mut ended = self.beat.health(|h| h.take_ended());
        let mut open = Vec::new();
        if all {
            for kind in crate::unattended::outage::WATCHED {
                if let Some(since) = self.beat.health(|h| h.down_since(kind)) {
                    open.push(EndedOutage {
                        device: kind,
                        start: since,
                        end: now,
                    });
                }
            }
        }
        if ended.is_empty() && open.is_empty() {
            return Ok(());
        }
        let Some(day) = self
            .beat
            .snapshot()
            .day
            .or_else(|| self.days.keys().next_back().copied())
        else {
            return Ok(());
        };
        let Some(store) = self.days.get_mut(&day) else {
            return Ok(());
        };
        for (o, is_open) in ended.iter().map(|o| (o, false)).chain(open.iter().map(|o| (o, true))) {
            store
                .record_outage(&o.device.to_string(), o.start, o.end, is_open)
                .map_err(|source| StationError::Store {
                    dir: store.dir().to_path_buf(),
                    source,
                })?;
            tracing::warn!(
                device = %o.device,
                start = %o.start,
                end = %o.end,
                minutes = (o.end - o.start).num_seconds() as f64 / 60.0,
                still_down = is_open,
                "outage journaled"
            );
        }
        self.report.outages.append(&mut ended);
        self.report.outages.extend(open);
        Ok(())
    }

    /// Journal the open promised shots of `occ` missed: `kind` is down.
    fn miss_in_outage(
        &mut self,
        day: NaiveDate,
        occ: &Occurrence,
        kind: DeviceKind,
        since: DateTime<Utc>,
    ) -> Result<(), StationError> {
        let now = self.clock.now();
        let reason = format!(
            "outage: the {kind} has been down since {}; the scan is not taken",
            since.format("%Y-%m-%d %H:%M:%S UTC")
        );
        tracing::warn!(occurrence = %occ.key, %reason, "scan missed");
        let Some(store) = self.days.get_mut(&day) else {
            return Ok(());
        };
        for shot in occ.shots.iter().filter(|s| s.promised) {
            if store.completed(&shot.key) || store.missed(&shot.key) {
                continue;
            }
            store
                .record_missed(&shot.key, &reason, now)
                .map_err(|source| StationError::Store {
                    dir: store.dir().to_path_buf(),
                    source,
                })?;
            self.report.missed_in_outages += 1;
        }
        Ok(())
    }

    /// Run `occ` through the controller; whether it stopped on request.
    async fn scan(
        &mut self,
        day: NaiveDate,
        occ: &Occurrence,
        first_ordinal: u64,
        progress: &mut dyn Progress,
    ) -> Result<bool, StationError> {
        let one = Timeline {
            occurrences: vec![occ.clone()],
            uncovered: Vec::new(),
        };
        let Some(store) = self.days.get_mut(&day) else {
            return Ok(false);
        };
        let mut supervisor = StationSupervisor {
            stop: self.stop,
            exposure: &mut self.exposure,
            beat: &self.beat,
        };
        let mut beats = FrameBeat {
            beat: &self.beat,
            clock: self.clock,
            inner: progress,
        };
        let result = controller::run_supervised(
            &one,
            self.inputs.plan,
            self.inputs.station,
            store,
            self.rig,
            self.clock,
            &self.options.run,
            &mut beats,
            &mut supervisor,
            first_ordinal,
        )
        .await;
        match result {
            Ok(r) => {
                self.report.frames += r.frames;
                self.report.missed += r.missed;
                self.report.metering_captures += r.metering_captures;
                Ok(r.stopped.is_some())
            }
            Err(e) => {
                self.report.frames += e.report.frames;
                self.report.missed += e.report.missed;
                Err(self.store_error(day, e.error))
            }
        }
    }

    /// Run the hook on a settled occurrence; its error is logged.
    fn process(&mut self, hook: &mut dyn ScanHook, day: NaiveDate, occ: &Occurrence) {
        let Some(dir) = self.days.get(&day).map(|s| s.dir().to_path_buf()) else {
            return;
        };
        self.beat.update(self.clock.now(), |b, _| {
            b.state = StationState::Processing;
            b.detail = occ.key.clone();
        });
        if let Err(e) = hook.on_occurrence_done(&dir, occ) {
            tracing::warn!(occurrence = %occ.key, error = %e, "processing the scan failed; its frames stay");
        }
    }

    /// Delete the oldest processed frames while the store is over budget.
    fn enforce_budget(&mut self) -> Result<(), StationError> {
        let total = self.store_bytes();
        let now = self.clock.now();
        self.beat.update(now, |b, _| b.store_bytes = total);
        let Some(budget) = self.options.budget else {
            return Ok(());
        };
        if total <= budget.max_bytes {
            self.budget_warned = false;
            return Ok(());
        }
        let excess = total - budget.max_bytes;
        let mut candidates = Vec::new();
        for (day, store) in &self.days {
            let products = ProcessedProducts::read(store.dir()).unwrap_or_else(|e| {
                tracing::warn!(error = %e, "unreadable products list: none of its frames is deleted");
                ProcessedProducts::default()
            });
            candidates.extend(deletable(*day, store, &products));
        }
        let chosen = oldest_first(candidates, excess);
        let freed: u64 = chosen.iter().map(|c| c.bytes).sum();
        if freed < excess && !self.budget_warned {
            tracing::warn!(
                store_bytes = total,
                budget_bytes = budget.max_bytes,
                deletable_bytes = freed,
                "the storage budget is exceeded and no more processed frames can be deleted: capture goes on until the disk is full (the run then stops cleanly; run the same command once there is room)"
            );
            self.budget_warned = true;
        }
        let mut by_day: BTreeMap<NaiveDate, Vec<String>> = BTreeMap::new();
        for c in &chosen {
            by_day.entry(c.day).or_default().push(c.key.clone());
        }
        let reason = format!(
            "storage budget of {} bytes exceeded by {excess} bytes; the scans' processed products exist",
            budget.max_bytes
        );
        for (day, keys) in by_day {
            let Some(store) = self.days.get_mut(&day) else { continue };
            let entry = store
                .record_pruned(&keys, &reason, now)
                .map_err(|source| StationError::Store {
                    dir: store.dir().to_path_buf(),
                    source,
                })?;
            let bytes = match &entry {
                crate::store::JournalEntry::Pruned(p) => p.bytes,
                _ => 0,
            };
            let mut occurrences: Vec<&str> = keys.iter().map(|k| occurrence_of(k)).collect();
            occurrences.dedup();
            tracing::info!(
                "storage budget: deleted {} raw frames ({bytes} bytes) of the processed scans {} from {} (the store held {total} bytes, budget {})",
                keys.len(),
                occurrences.join(", "),
                store.dir().display(),
                budget.max_bytes
            );
            self.report.pruned_frames += keys.len();
            self.report.pruned_bytes += bytes;
        }
        let total = self.store_bytes();
        self.beat.update(now, |b, _| b.store_bytes = total);
        Ok(())
    }
}
