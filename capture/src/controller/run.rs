//! The run: every occurrence of a timeline in order, every planned shot
//! of it not yet in the store, through a [`Rig`], on a [`Clock`].
//!
//! Per occurrence: wait for its start; if it cannot start within
//! [`RunOptions::start_window`], journal its shots missed; if it starts
//! later than [`RunOptions::late_tolerance`], journal `late` each frame
//! taken more than that after its planned time (the trigger plus the
//! shot's estimated start in the occurrence, [`duration::start_offsets`]),
//! with `late_by_s` against that time: a resumed run that reaches a shot
//! no later than a clean run would does not call it late.
//! Per shot: aim, filter, lights, exposure, capture, journal. A device
//! failure is retried per the step's [`ErrorPolicy`] (a dropped link is
//! reconnected first, with doubling waits), then the step's fallback
//! applies: `Continue` journals the shot missed, `Skip` the rest of the
//! step too, `Abort` the rest of the occurrence. A shot the head cannot
//! reach is journaled missed at once.
//!
//! The store is synchronous: its writes (a small PNG, a journal line and
//! their fsyncs) block the controller's task for their duration. The
//! controller takes one shot at a time, so nothing else waits on them.

use std::collections::{HashMap, HashSet};
use std::time::Duration;

use campanile_config::Station;
use campanile_config::plan::{ErrorPolicy, Fallback, Plan, Step};
use campanile_process::camera::image::CodeImage;
use campanile_process::pose::HeadPose;
use campanile_process::sky::{Atmosphere, Daylight};
use campanile_process::sun::{Observer, sun_position};
use chrono::{DateTime, Utc};
use tracing::Instrument;

use super::auto_bracket;
use super::metering::{self, Codes};
use super::options::{AutoBracketUse, Progress, RunOptions, RunReport, ShotOutcome};
use super::rig::{DeviceKind, Rig};
use super::sun_shot::{self, FilterCandidate};
use super::supervisor::{Metering, Supervisor, Unsupervised};
use super::{aim, error::RunError};
use crate::clock::Clock;
use crate::device::{
    Camera, CaptureSettings, DeviceError, ExposureTime, FilterWheel, Frame, Gain, Level, Lights, PanTilt, Pose,
};
use crate::schedule::{
    FilterChoice, Occurrence, PlannedAim, PlannedExposure, PlannedShot, ShotKind, Timeline, duration,
};
use crate::store::{self, FrameMeta, LightLevel, PoseDeg, SessionStore, Storage, StoreError};
use crate::unattended::outage::{DeviceHealth, WATCHED};

/// Frame numbers reserved per shot (see [`Rig::number_frames_from`]):
/// attempts from 0, saturation retakes from 16, metering from 32.
const FRAMES_PER_SHOT: u64 = 64;

/// Run `timeline` (built from `plan` on `station`) into `store`.
///
/// Returns what this run did; a store failure (disk full, a crash in a
/// test, an I/O error) stops the run at once and is returned with the
/// report so far. Everything journaled before it stays valid.
#[allow(clippy::too_many_arguments)]
pub async fn run<R: Rig, C: Clock, S: Storage>(
    timeline: &Timeline,
    plan: &Plan,
    station: &Station,
    store: &mut SessionStore<S>,
    rig: &mut R,
    clock: &C,
    options: &RunOptions,
    progress: &mut dyn Progress,
) -> Result<RunReport, RunError> {
    run_supervised(
        timeline,
        plan,
        station,
        store,
        rig,
        clock,
        options,
        progress,
        &mut Unsupervised,
        0,
    )
    .await
}

/// [`run()`] under a [`Supervisor`]: when it asks to stop, the run ends
/// before the next shot with `report.stopped` set and `Ok`. The frames of
/// the timeline's shots are numbered (see [`Rig::number_frames_from`]) from
/// `first_ordinal` on, so that a timeline cut into parts (one occurrence
/// at a time) numbers them as the whole one would.
#[allow(clippy::too_many_arguments)]
pub async fn run_supervised<R: Rig, C: Clock, S: Storage>(
    timeline: &Timeline,
    plan: &Plan,
    station: &Station,
    store: &mut SessionStore<S>,
    rig: &mut R,
    clock: &C,
    options: &RunOptions,
    progress: &mut dyn Progress,
    supervisor: &mut dyn Supervisor,
    first_ordinal: u64,
) -> Result<RunReport, RunError> {
    let mut ordinals = HashMap::new();
    for (i, shot) in timeline.occurrences.iter().flat_map(|o| o.shots.iter()).enumerate() {
        ordinals.insert(shot.key.clone(), first_ordinal + i as u64);
    }
    let s = &station.site;
    let mut c = Controller {
        plan,
        station,
        store,
        rig,
        clock,
        options,
        progress,
        supervisor,
        stopping: false,
        ordinals,
        observer: Observer::from_degrees(
            s.latitude_deg,
            s.longitude_deg,
            s.elevation_m,
            s.pressure_mbar,
            s.temperature_c,
        ),
        report: RunReport::default(),
        last_pose: None,
        last_slot: None,
        health: DeviceHealth::default(),
        linear_camera: false,
    };
    c.linear_camera = c.rig.camera().info().linear;
    for occ in &timeline.occurrences {
        if c.stopping || c.supervisor.stop_requested() {
            c.report.stopped = Some(STOPPED_ON_REQUEST.to_owned());
            tracing::info!("the run stops on request, between shots");
            if let Err(e) = c.journal_open_outages() {
                tracing::error!(error = %e, "the open outages could not be journaled");
            }
            return Ok(c.report);
        }
        let span = tracing::info_span!("occurrence", key = %occ.key);
        if let Err(error) = c.occurrence(occ).instrument(span).await {
            if let Err(e) = c.journal_open_outages() {
                tracing::error!(error = %e, "the open outages could not be journaled");
            }
            c.report.stopped = Some(error.to_string());
            tracing::error!(%error, "the session stops");
            return Err(RunError {
                error,
                report: Box::new(c.report),
            });
        }
    }
    if let Err(error) = c.journal_open_outages() {
        c.report.stopped = Some(error.to_string());
        return Err(RunError {
            error,
            report: Box::new(c.report),
        });
    }
    if c.stopping {
        c.report.stopped = Some(STOPPED_ON_REQUEST.to_owned());
        tracing::info!("the run stops on request, between shots");
    }
    Ok(c.report)
}

/// [`RunReport::stopped`] of a run its supervisor stopped.
pub const STOPPED_ON_REQUEST: &str = "stopped on request";

/// Why a shot was not taken.
enum ShotError {
    /// A device failed (after the watchdog, if it hung).
    Device(DeviceKind, DeviceError),
    /// The aim is out of the head's reach, or the sun is down.
    Unreachable(String),
    /// The store failed: the run stops.
    Store(StoreError),
}

impl From<StoreError> for ShotError {
    fn from(e: StoreError) -> Self {
        ShotError::Store(e)
    }
}

/// A shot's result.
enum Taken {
    /// A frame and its metadata, to journal.
    Frame(Box<Frame>, Box<FrameMeta>),
    /// An auto-bracket frame the range did not need.
    NotNeeded,
}

/// How an auto-bracket data frame is exposed.
enum AutoExposure {
    /// At this many seconds.
    At(f64),
    /// At the metered exposure.
    Metered,
    /// Not taken: the frames so far cover the target.
    NotNeeded,
}

/// What a sun shot learned from its centering frame.
#[derive(Debug, Clone, Copy)]
struct SunFix {
    /// Azimuth and elevation to add to the ephemeris sun, degrees.
    correction: (f64, f64),
    /// Index of the filter in the step's list.
    filter: usize,
    /// Exposure of the data frames, seconds.
    exposure_s: f64,
}

#[derive(Default)]
struct OccurrenceState {
    metered: HashMap<String, f64>,
    sun: HashMap<usize, SunFix>,
    auto_targets: Vec<(String, usize)>,
}

struct Controller<'a, R, C, S: Storage> {
    plan: &'a Plan,
    station: &'a Station,
    store: &'a mut SessionStore<S>,
    rig: &'a mut R,
    clock: &'a C,
    options: &'a RunOptions,
    progress: &'a mut dyn Progress,
    supervisor: &'a mut dyn Supervisor,
    /// The supervisor asked to stop: no further shot is taken.
    stopping: bool,
    ordinals: HashMap<String, u64>,
    observer: Observer,
    report: RunReport,
    /// The head's last pose asked for and reached, while nothing failed since.
    last_pose: Option<(Pose, PoseDeg)>,
    /// The wheel's last slot, while nothing failed since.
    last_slot: Option<u8>,
    /// Which devices are down since when, for the journal's `outage` lines
    /// (kept only when the supervisor leaves those to the controller).
    health: DeviceHealth,
    /// The camera's codes are linear ([`crate::device::CameraInfo::linear`]).
    linear_camera: bool,
}

/// `"{occurrence}/s{step}/t{target}"` of a shot key.
fn target_of(key: &str) -> &str {
    key.rsplit_once("/f").map_or(key, |(t, _)| t)
}

/// The frame index `f` of a shot key.
fn frame_index(key: &str) -> usize {
    key.rsplit_once("/f").and_then(|(_, f)| f.parse().ok()).unwrap_or(0)
}

/// Await a device call under the watchdog.
async fn guarded<T>(
    kind: DeviceKind,
    limit: Duration,
    call: impl Future<Output = Result<T, DeviceError>>,
) -> Result<T, ShotError> {
    match tokio::time::timeout(limit, call).await {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(ShotError::Device(kind, e)),
        Err(_) => Err(ShotError::Device(
            kind,
            DeviceError::Timeout(format!("watchdog: no answer from the {kind} within {limit:?}")),
        )),
    }
}

impl<R: Rig, C: Clock, S: Storage> Controller<'_, R, C, S> {
    fn step(&self, occ: &Occurrence, index: usize) -> Option<&Step> {
        self.plan.sessions.get(occ.session).and_then(|s| s.steps.get(index))
    }

    fn open(&self, shot: &PlannedShot) -> bool {
        !self.store.completed(&shot.key) && !self.store.missed_in_this_run(&shot.key)
    }

    fn missed(&mut self, shot: &PlannedShot, reason: &str) -> Result<(), StoreError> {
        if !self.open(shot) {
            return Ok(());
        }
        tracing::warn!(key = %shot.key, reason, "shot missed");
        self.store.record_missed(&shot.key, reason, self.clock.now())?;
        self.report.missed += 1;
        self.progress.shot(shot, ShotOutcome::Missed);
        Ok(())
    }

    async fn occurrence(&mut self, occ: &Occurrence) -> Result<(), StoreError> {
        let open = occ.shots.iter().filter(|s| self.open(s)).count();
        self.report.already_done += occ.shots.iter().filter(|s| self.store.completed(&s.key)).count();
        if open == 0 {
            return Ok(());
        }
        self.clock.sleep_until(occ.start).await;
        let now = self.clock.now();
        let late = (now - occ.start).to_std().unwrap_or(Duration::ZERO);
        if late > self.options.start_window {
            let reason = format!(
                "the occurrence could not start until {now}, {:.0} s after its trigger at {} (window {:.0} s)",
                late.as_secs_f64(),
                occ.start,
                self.options.start_window.as_secs_f64()
            );
            for shot in occ.shots.iter().filter(|s| s.promised) {
                self.missed(shot, &reason)?;
            }
            return Ok(());
        }
        let started_late = late > self.options.late_tolerance;
        if started_late {
            tracing::warn!(late_by_s = late.as_secs_f64(), "the occurrence starts late");
        }
        let offsets = duration::start_offsets(&occ.shots, self.station, occ.sun);
        tracing::info!(shots = occ.shots.len(), open, "occurrence starts");
        self.progress.occurrence(occ);
        let mut state = OccurrenceState::default();
        let mut current = None;
        let mut skipped: HashMap<usize, String> = HashMap::new();
        let mut aborted: Option<String> = None;
        for (i, shot) in occ.shots.iter().enumerate() {
            // When the plan has the shot begin, if the occurrence started late.
            let planned = started_late.then(|| {
                let offset = offsets.get(i).copied().unwrap_or_default();
                occ.start + chrono::TimeDelta::from_std(offset).unwrap_or_default()
            });
            if current != Some(shot.step) {
                current = Some(shot.step);
                let kind = self.step(occ, shot.step).map_or("step", Step::kind);
                let n = occ.shots.iter().filter(|s| s.step == shot.step).count();
                self.progress.step(occ, shot.step, kind, n);
                tracing::info!(step = shot.step, kind, shots = n, "step");
                if let Some(Step::AutoBracket { .. }) = self.step(occ, shot.step) {
                    let mut targets: Vec<String> = occ
                        .shots
                        .iter()
                        .filter(|s| s.step == shot.step)
                        .map(|s| target_of(&s.key).to_owned())
                        .collect();
                    targets.dedup();
                    state.auto_targets.extend(targets.into_iter().map(|t| (t, shot.step)));
                }
            }
            if self.store.completed(&shot.key) {
                self.progress.shot(shot, ShotOutcome::AlreadyDone);
                continue;
            }
            if self.supervisor.stop_requested() {
                self.stopping = true;
                return Ok(());
            }
            if !self.open(shot) {
                continue;
            }
            if let Some(reason) = aborted.clone().or_else(|| skipped.get(&shot.step).cloned()) {
                if shot.promised {
                    self.missed(shot, &reason)?;
                }
                continue;
            }
            let policy = self.step(occ, shot.step).map(Step::on_error).unwrap_or_default();
            let span = tracing::info_span!("shot", key = %shot.key);
            if let Some(reason) = self
                .shot_with_policy(occ, shot, &mut state, planned, policy)
                .instrument(span)
                .await?
            {
                match policy.then {
                    Fallback::Continue => {}
                    Fallback::Skip => {
                        skipped.insert(shot.step, format!("step {} skipped: {reason}", shot.step));
                    }
                    Fallback::Abort => aborted = Some(format!("occurrence aborted at step {}: {reason}", shot.step)),
                }
            }
        }
        for (target, step) in std::mem::take(&mut state.auto_targets) {
            self.summarize_auto_bracket(occ, &target, step)?;
        }
        Ok(())
    }

    /// Take one shot with retries; `Some(reason)` if it was journaled
    /// missed after a device failure (the step's fallback then applies).
    async fn shot_with_policy(
        &mut self,
        occ: &Occurrence,
        shot: &PlannedShot,
        state: &mut OccurrenceState,
        planned: Option<DateTime<Utc>>,
        policy: ErrorPolicy,
    ) -> Result<Option<String>, StoreError> {
        let mut attempt = 0u32;
        loop {
            match self.shot(occ, shot, state, planned, attempt).await {
                Ok(Taken::Frame(frame, meta)) => {
                    self.store.record_frame(&shot.key, &meta, &frame)?;
                    self.report.frames += 1;
                    let outcome = if meta.late_by_s.is_some() {
                        self.report.late += 1;
                        ShotOutcome::Late
                    } else {
                        ShotOutcome::Stored
                    };
                    tracing::debug!(
                        exposure_s = meta.exposure_actual_s,
                        filter = meta.filter.as_deref().unwrap_or("none"),
                        "frame stored"
                    );
                    self.progress.shot(shot, outcome);
                    return Ok(None);
                }
                Ok(Taken::NotNeeded) => {
                    self.progress.shot(shot, ShotOutcome::NotNeeded);
                    return Ok(None);
                }
                Err(ShotError::Store(e)) => return Err(e),
                Err(ShotError::Unreachable(reason)) => {
                    self.missed(shot, &reason)?;
                    return Ok(None);
                }
                Err(ShotError::Device(kind, e)) => {
                    self.last_pose = None;
                    self.last_slot = None;
                    tracing::warn!(device = %kind, error = %e, attempt, "device call failed");
                    if attempt < policy.retries {
                        attempt += 1;
                        self.report.retries += 1;
                        if matches!(e, DeviceError::Link(_)) {
                            self.reconnect(kind).await;
                        }
                        tracing::info!(attempt, of = policy.retries, "retrying the shot");
                        continue;
                    }
                    let reason = format!("the {kind} failed after {} attempt(s): {e}", attempt + 1);
                    self.missed(shot, &reason)?;
                    return Ok(Some(reason));
                }
            }
        }
    }

    /// Reconnect `kind` with doubling waits; logs each attempt.
    async fn reconnect(&mut self, kind: DeviceKind) {
        let mut wait = self.options.reconnect_backoff;
        for attempt in 1..=self.options.reconnect_attempts {
            tokio::time::sleep(wait).await;
            match self.rig.reconnect(kind).await {
                Ok(()) => {
                    self.report.reconnects += 1;
                    tracing::info!(device = %kind, attempt, "reconnected");
                    return;
                }
                Err(e) => tracing::warn!(device = %kind, attempt, error = %e, "reconnect failed"),
            }
            wait = (wait * 2).min(Duration::from_secs(60));
        }
        tracing::error!(device = %kind, "could not reconnect");
    }

    fn exposure_range(&mut self) -> (f64, f64) {
        let info = self.rig.camera().info();
        (info.exposure.min.seconds(), info.exposure.max.seconds())
    }

    fn clamp_exposure(&mut self, t: f64) -> f64 {
        let (lo, hi) = self.exposure_range();
        if t.is_finite() { t.clamp(lo, hi) } else { lo }
    }

    /// One attempt at a shot; its frame is `late` if taken more than the
    /// late tolerance after `planned`.
    async fn shot(
        &mut self,
        occ: &Occurrence,
        shot: &PlannedShot,
        state: &mut OccurrenceState,
        planned: Option<DateTime<Utc>>,
        attempt: u32,
    ) -> Result<Taken, ShotError> {
        let ordinal = self.ordinals.get(&shot.key).copied().unwrap_or(0);
        let step = self.step(occ, shot.step).cloned();
        let auto_data = matches!(step, Some(Step::AutoBracket { .. })) && shot.kind == ShotKind::Data;
        let mut notes = Vec::new();
        // An auto-bracket frame is taken only if the frames so far leave pixels uncovered.
        let auto_exposure = if auto_data {
            match self.auto_bracket_exposure(shot)? {
                AutoExposure::At(t) => Some(t),
                AutoExposure::Metered => None,
                AutoExposure::NotNeeded => return Ok(Taken::NotNeeded),
            }
        } else {
            None
        };
        if shot.kind == ShotKind::Data
            && let Some(Step::SunShot { .. }) = step
            && !state.sun.contains_key(&shot.step)
        {
            let fix = self.sun_fix(occ, shot)?;
            state.sun.insert(shot.step, fix);
        }
        let (requested, reached) = self.aim(shot, state).await?;
        let filter = self.filter(shot, state).await?;
        let lights = self.lights(shot).await?;
        let exposure_s = match shot.exposure {
            PlannedExposure::Fixed { seconds } => self.clamp_exposure(seconds),
            PlannedExposure::Metered { stops } => {
                let t = self.metered(occ, shot, state).await?;
                self.clamp_exposure(t * 2f64.powf(stops))
            }
            PlannedExposure::Auto => match (shot.kind, &step) {
                (ShotKind::Data, Some(Step::SunShot { .. })) => state.sun.get(&shot.step).map_or(
                    self.clamp_exposure(crate::schedule::expand::SUN_CENTERING_EXPOSURE_S),
                    |f| f.exposure_s,
                ),
                _ => match auto_exposure {
                    Some(t) => self.clamp_exposure(t),
                    None => self.metered(occ, shot, state).await?,
                },
            },
        };
        self.rig
            .number_frames_from(ordinal * FRAMES_PER_SHOT + u64::from(attempt));
        let mut frame = self.capture(exposure_s).await?;
        let mut filter = filter;
        if shot.kind == ShotKind::Data
            && let Some(Step::SunShot { filters, triplet, .. }) = &step
        {
            let mut retake = 0;
            loop {
                let disc = sun_shot::find_disc(Codes::from(&self.as_metered(Codes::from(&frame))));
                let Some(d) = disc else {
                    notes.push("no sun disc found in the frame".to_owned());
                    break;
                };
                let Some(fix) = state.sun.get_mut(&shot.step) else {
                    break;
                };
                if !d.saturated() {
                    if *triplet && frame_index(&shot.key) == 3 {
                        notes.extend(self.triplet_note(shot, d.sum)?);
                    }
                    break;
                }
                let candidates = self.filter_candidates(filters);
                if fix.filter + 1 >= candidates.len() {
                    notes.push("the disc saturates even through the densest filter".to_owned());
                    break;
                }
                let from = candidates[fix.filter].name.clone();
                fix.filter += 1;
                let to = candidates[fix.filter].clone();
                tracing::warn!(from = %from, to = %to.name, "the sun's disc saturated: retaking through a denser filter");
                notes.push(format!(
                    "retaken through {}: the disc saturated through {from}",
                    to.name
                ));
                self.report.saturation_retakes += 1;
                self.select(to.slot).await?;
                filter = Some(to.name);
                retake += 1;
                self.rig.number_frames_from(ordinal * FRAMES_PER_SHOT + 16 + retake);
                frame = self.capture(exposure_s).await?;
            }
        }
        let kind = match shot.kind {
            ShotKind::Data => store::ShotKind::Data,
            ShotKind::Metering => store::ShotKind::Metering,
            ShotKind::Centering => store::ShotKind::Centering,
        };
        let mut meta = FrameMeta::from_frame(&frame, kind);
        meta.pose_requested = Some(requested);
        meta.pose_reached = Some(reached);
        meta.filter = filter;
        meta.lights = lights;
        meta.late_by_s = planned
            .map(|p| (meta.time - p).as_seconds_f64())
            .filter(|&by| by > self.options.late_tolerance.as_secs_f64());
        meta.notes = notes;
        if shot.kind == ShotKind::Centering {
            let codes = self.as_metered(Codes::from(&frame));
            let fix = self.fix_from_centering(occ, shot, Codes::from(&codes), reached, frame.timestamp, exposure_s);
            meta.notes.push(format!(
                "sun centring: {:+.3}° azimuth, {:+.3}° elevation from the ephemeris",
                fix.correction.0, fix.correction.1
            ));
            state.sun.insert(shot.step, fix);
        }
        Ok(Taken::Frame(Box::new(frame), Box::new(meta)))
    }

    async fn capture(&mut self, exposure_s: f64) -> Result<Frame, ShotError> {
        let exposure = ExposureTime::from_seconds(exposure_s)
            .ok_or_else(|| ShotError::Unreachable(format!("exposure {exposure_s} s is not a positive time")))?;
        let limit = self.options.watchdog + exposure.duration();
        let r = guarded(
            DeviceKind::Camera,
            limit,
            self.rig.camera().capture(CaptureSettings {
                exposure,
                gain: Gain::UNITY,
            }),
        )
        .await;
        self.noted(DeviceKind::Camera, r)
    }

    /// `codes` as the controller reads them: a linear camera's through
    /// the assumed gamma ([`metering::gamma_equivalent`]), others as they are.
    fn as_metered(&self, codes: Codes<'_>) -> CodeImage {
        if self.linear_camera {
            metering::gamma_equivalent(codes)
        } else {
            CodeImage {
                width: codes.width,
                height: codes.height,
                bits: codes.bits,
                data: codes.data.to_vec(),
                label: String::new(),
            }
        }
    }

    /// Tell the supervisor how a device call went, and journal an outage
    /// it ends (unless the supervisor journals outages itself); pass the
    /// result on.
    fn noted<T>(&mut self, kind: DeviceKind, r: Result<T, ShotError>) -> Result<T, ShotError> {
        let now = self.clock.now();
        let journals = self.supervisor.journals_outages();
        match &r {
            Ok(_) => {
                self.supervisor.device_answered(kind, now);
                if journals {
                    self.health.answered(kind, now);
                }
            }
            Err(ShotError::Device(k, e)) => {
                self.supervisor.device_failed(*k, now, e);
                if journals {
                    self.health.failed(*k, now, &e.to_string());
                }
            }
            Err(_) => {}
        }
        for o in self.health.take_ended() {
            self.store
                .record_outage(&o.device.to_string(), o.start, o.end, false)
                .map_err(ShotError::Store)?;
        }
        r
    }

    /// Journal the outages of devices still down as the run ends (`open`:
    /// their end is the run's, not the device's return).
    fn journal_open_outages(&mut self) -> Result<(), StoreError> {
        let now = self.clock.now();
        for kind in WATCHED {
            if let Some(since) = self.health.down_since(kind) {
                self.store.record_outage(&kind.to_string(), since, now, true)?;
            }
        }
        Ok(())
    }

    /// Aim the head (and, for a pose, the tripod); the pose asked for and reached.
    async fn aim(&mut self, shot: &PlannedShot, state: &OccurrenceState) -> Result<(PoseDeg, PoseDeg), ShotError> {
        let angles = match &shot.aim {
            PlannedAim::Head { pan_deg, tilt_deg } => {
                self.rig.place(None);
                self.station
                    .head
                    .limits
                    .contains(*pan_deg, *tilt_deg)
                    .then_some((*pan_deg, *tilt_deg))
            }
            PlannedAim::Sky {
                azimuth_deg,
                elevation_deg,
            } => {
                self.rig.place(None);
                aim::head_angles(self.station, *azimuth_deg, *elevation_deg)
            }
            PlannedAim::Pose {
                position_m,
                azimuth_deg,
                elevation_deg,
                ..
            } => {
                self.rig.place(Some([position_m.0, position_m.1, position_m.2]));
                aim::head_angles(self.station, *azimuth_deg, *elevation_deg)
            }
            PlannedAim::Sun => {
                self.rig.place(None);
                let (az, el) = self.ephemeris_sun(self.clock.now())?;
                if el < 0.0 {
                    return Err(ShotError::Unreachable(format!(
                        "the sun is below the horizon ({el:.1}°)"
                    )));
                }
                let (daz, del) = if shot.kind == ShotKind::Centering {
                    (0.0, 0.0)
                } else {
                    state.sun.get(&shot.step).map_or((0.0, 0.0), |f| f.correction)
                };
                aim::head_angles(self.station, az + daz, el + del)
            }
        };
        let Some((pan, tilt)) = angles else {
            return Err(ShotError::Unreachable(format!(
                "the head cannot reach {}",
                shot.aim.describe()
            )));
        };
        let pose = Pose::from_degrees(pan, tilt);
        // Consecutive frames of a target share their aim: the head stays.
        if let Some((last, reached)) = self.last_pose
            && last == pose
        {
            return Ok((PoseDeg::from(pose), reached));
        }
        self.last_pose = None;
        let limit = self.options.watchdog;
        let r = guarded(DeviceKind::Head, limit, self.rig.head().move_to(pose)).await;
        self.noted(DeviceKind::Head, r)?;
        let settle = self.options.settle_limit;
        let r = guarded(DeviceKind::Head, limit + settle, self.rig.head().wait_idle(settle)).await;
        let reached = self.noted(DeviceKind::Head, r)?;
        self.last_pose = Some((pose, PoseDeg::from(reached)));
        Ok((PoseDeg::from(pose), PoseDeg::from(reached)))
    }

    fn ephemeris_sun(&self, t: DateTime<Utc>) -> Result<(f64, f64), ShotError> {
        let p = sun_position(t, &self.observer, self.station.site.delta_t_s)
            .map_err(|e| ShotError::Unreachable(format!("no solar position at {t}: {e}")))?;
        Ok((p.azimuth_rad.to_degrees(), p.elevation_rad().to_degrees()))
    }

    fn filter_candidates(&self, names: &[String]) -> Vec<FilterCandidate> {
        let Some(wheel) = &self.station.filter_wheel else {
            return Vec::new();
        };
        names
            .iter()
            .filter_map(|n| {
                let slot = wheel.slots.iter().position(|s| &s.name == n)?;
                Some(FilterCandidate {
                    name: n.clone(),
                    slot: u8::try_from(slot).ok()?,
                    transmittance: wheel.slots[slot].transmittance(),
                })
            })
            .collect()
    }

    async fn select(&mut self, slot: u8) -> Result<(), ShotError> {
        if self.last_slot == Some(slot) {
            return Ok(());
        }
        self.last_slot = None;
        let limit = self.options.watchdog;
        if let Some(w) = self.rig.wheel() {
            let r = guarded(DeviceKind::Wheel, limit, w.select(slot)).await;
            self.noted(DeviceKind::Wheel, r)?;
        }
        self.last_slot = Some(slot);
        Ok(())
    }

    /// Put the shot's filter in place; its name.
    async fn filter(&mut self, shot: &PlannedShot, state: &OccurrenceState) -> Result<Option<String>, ShotError> {
        let Some(wheel) = &self.station.filter_wheel else {
            return Ok(None);
        };
        let name = match &shot.filter {
            FilterChoice::None => wheel
                .slots
                .iter()
                .find(|s| s.transmittance().iter().all(|&t| t >= 1.0))
                .map(|s| s.name.clone()),
            FilterChoice::Slot(name) => Some(name.clone()),
            FilterChoice::LightestUnsaturated(names) => {
                let candidates = self.filter_candidates(names);
                let i = state
                    .sun
                    .get(&shot.step)
                    .map_or(candidates.len().saturating_sub(1), |f| f.filter);
                candidates.get(i).map(|c| c.name.clone())
            }
        };
        let Some(name) = name else { return Ok(None) };
        let Some(slot) = wheel
            .slots
            .iter()
            .position(|s| s.name == name)
            .and_then(|s| u8::try_from(s).ok())
        else {
            return Err(ShotError::Unreachable(format!("the wheel has no filter {name:?}")));
        };
        self.select(slot).await?;
        Ok(Some(name))
    }

    /// Set the shot's light levels; the levels journaled.
    async fn lights(&mut self, shot: &PlannedShot) -> Result<Option<Vec<LightLevel>>, ShotError> {
        let Some(levels) = &shot.lights else { return Ok(None) };
        let limit = self.options.watchdog;
        let mut journaled = Vec::new();
        for (i, &l) in levels.iter().enumerate() {
            let (Some(channel), Some(level)) = (self.rig.light_channel(i), Level::new(l)) else {
                continue;
            };
            if let Some(lights) = self.rig.lights() {
                let r = guarded(DeviceKind::Lights, limit, lights.set_level(channel, level)).await;
                self.noted(DeviceKind::Lights, r)?;
            }
            journaled.push(LightLevel {
                channel: channel.0,
                level: l,
            });
        }
        Ok(Some(journaled))
    }

    /// The metered exposure of the shot's target (once per target per
    /// occurrence): unstored test captures until the median is mid-range.
    async fn metered(
        &mut self,
        occ: &Occurrence,
        shot: &PlannedShot,
        state: &mut OccurrenceState,
    ) -> Result<f64, ShotError> {
        let target = target_of(&shot.key).to_owned();
        if let Some(&t) = state.metered.get(&target) {
            return Ok(t);
        }
        // An auto-bracket's metering frame, journaled by an earlier run, holds the answer.
        if let Some(e) = self.store.frame_entry(&format!("{target}/f0"))
            && e.meta.kind == store::ShotKind::Metering
        {
            state.metered.insert(target, e.meta.exposure_requested_s);
            return Ok(e.meta.exposure_requested_s);
        }
        let first = self
            .ordinals
            .iter()
            .filter(|(k, _)| target_of(k) == target)
            .map(|(_, &o)| o)
            .min()
            .unwrap_or(0);
        let start = self
            .supervisor
            .metering_start(occ, &target)
            .filter(|s| s.is_finite() && *s > 0.0)
            .unwrap_or(self.options.meter_start_s);
        let mut t = self.clamp_exposure(start);
        let mut ideal = t;
        let mut captures = 0;
        for i in 0..metering::MAX_CAPTURES as u64 {
            self.rig.number_frames_from(first * FRAMES_PER_SHOT + 32 + i);
            let frame = self.capture(t).await?;
            self.report.metering_captures += 1;
            captures += 1;
            let median = metering::median_fraction(Codes::from(&self.as_metered(Codes::from(&frame))));
            ideal = if median > 0.01 && median < 0.97 {
                t * (metering::TARGET_FRACTION / median).powf(metering::ASSUMED_GAMMA)
            } else {
                t
            };
            match metering::next_exposure(t, median) {
                None => break,
                Some(next) => {
                    let next = self.clamp_exposure(next);
                    if (next - t).abs() <= t * 1e-9 {
                        break;
                    }
                    t = next;
                }
            }
        }
        let chosen = self.supervisor.metered_exposure(
            occ,
            &target,
            Metering {
                accepted_s: t,
                ideal_s: ideal,
                captures,
            },
        );
        let t = self.clamp_exposure(chosen);
        tracing::debug!(target = %target, exposure_s = t, ideal_s = ideal, "metered");
        state.metered.insert(target, t);
        Ok(t)
    }

    /// The data frames of an auto-bracket journaled so far: (exposure, codes).
    fn auto_bracket_frames(&self, target: &str, before: usize) -> Result<Vec<(f64, CodeImage)>, StoreError> {
        let mut frames = Vec::new();
        for f in 1..before {
            if let Some(e) = self.store.frame_entry(&format!("{target}/f{f}")) {
                let e = e.clone();
                let codes = self.store.read_frame(&e)?;
                frames.push((e.meta.exposure_actual_s, self.as_metered(Codes::from(&codes))));
            }
        }
        Ok(frames)
    }

    /// The exposure of an auto-bracket data frame.
    fn auto_bracket_exposure(&mut self, shot: &PlannedShot) -> Result<AutoExposure, ShotError> {
        let target = target_of(&shot.key).to_owned();
        let f = frame_index(&shot.key);
        if f <= 1 {
            // The first data frame is promised: at the metered exposure
            // (metered anew if the metering frame was missed).
            return Ok(self
                .store
                .frame_entry(&format!("{target}/f0"))
                .map_or(AutoExposure::Metered, |e| AutoExposure::At(e.meta.exposure_requested_s)));
        }
        let frames = self.auto_bracket_frames(&target, f)?;
        if frames.is_empty() {
            return Ok(AutoExposure::NotNeeded);
        }
        let codes: Vec<(f64, Codes<'_>)> = frames.iter().map(|(t, c)| (*t, Codes::from(c))).collect();
        let range = self.exposure_range();
        Ok(auto_bracket::next_exposure(&codes, range).map_or(AutoExposure::NotNeeded, AutoExposure::At))
    }

    fn summarize_auto_bracket(&mut self, occ: &Occurrence, target: &str, step: usize) -> Result<(), StoreError> {
        let max_frames = occ
            .shots
            .iter()
            .filter(|s| s.step == step && target_of(&s.key) == target && s.kind == ShotKind::Data)
            .count();
        let frames = self.auto_bracket_frames(target, max_frames + 1)?;
        let codes: Vec<(f64, Codes<'_>)> = frames.iter().map(|(t, c)| (*t, Codes::from(c))).collect();
        let uncovered = auto_bracket::coverage(&codes).uncovered();
        tracing::info!(target, frames = frames.len(), max_frames, uncovered, "auto-bracket");
        self.report.auto_brackets.push(AutoBracketUse {
            target: target.to_owned(),
            frames: frames.len(),
            max_frames,
            uncovered_pixels: uncovered,
        });
        Ok(())
    }

    /// The sun fix of a step from its journaled centering frame (a
    /// resumed session), or the ephemeris alone if it was missed.
    fn sun_fix(&mut self, occ: &Occurrence, shot: &PlannedShot) -> Result<SunFix, ShotError> {
        let key = format!("{}/t0/f0", shot.key.rsplit_once("/t").map_or("", |(s, _)| s));
        if let Some(e) = self.store.frame_entry(&key).cloned() {
            let codes = self.store.read_frame(&e)?;
            let codes = self.as_metered(Codes::from(&codes));
            let reached = e.meta.pose_reached.unwrap_or(PoseDeg {
                pan_deg: 0.0,
                tilt_deg: 0.0,
            });
            return Ok(self.fix_from_centering(
                occ,
                shot,
                Codes::from(&codes),
                reached,
                e.meta.time,
                e.meta.exposure_actual_s,
            ));
        }
        let filters = match self.step(occ, shot.step) {
            Some(Step::SunShot { filters, .. }) => filters.clone(),
            _ => Vec::new(),
        };
        Ok(SunFix {
            correction: (0.0, 0.0),
            filter: self.filter_candidates(&filters).len().saturating_sub(1),
            exposure_s: self.clamp_exposure(crate::schedule::expand::SUN_CENTERING_EXPOSURE_S),
        })
    }

    /// What a centering frame says: the disc's offset from the ephemeris
    /// sun, and the filter and exposure of the data frames.
    fn fix_from_centering(
        &mut self,
        occ: &Occurrence,
        shot: &PlannedShot,
        frame: Codes<'_>,
        reached: PoseDeg,
        time: DateTime<Utc>,
        exposure_s: f64,
    ) -> SunFix {
        let filters = match self.step(occ, shot.step) {
            Some(Step::SunShot { filters, .. }) => filters.clone(),
            _ => Vec::new(),
        };
        let candidates = self.filter_candidates(&filters);
        let densest = candidates.len().saturating_sub(1);
        let range = self.exposure_range();
        let disc = sun_shot::find_disc(frame);
        let ephemeris = self.ephemeris_sun(time).ok();
        let mut correction = (0.0, 0.0);
        if let (Some(d), Some((az, el))) = (disc, ephemeris) {
            let pinhole = aim::pinhole(self.station, frame.width, frame.height);
            let pose = HeadPose {
                pan_rad: reached.pan_deg.to_radians(),
                tilt_rad: reached.tilt_deg.to_radians(),
            };
            if let Some(w) = aim::pixel_direction(self.station, &pinhole, pose, d.centroid_px.0, d.centroid_px.1) {
                let (oaz, oel) = aim::azimuth_elevation_deg(w);
                correction = ((oaz - az + 540.0).rem_euclid(360.0) - 180.0, oel - el);
            }
        } else {
            tracing::warn!("no sun disc in the centering frame: aiming by the ephemeris alone");
        }
        let radiance = ephemeris.map_or([0.0; 3], |(az, el)| {
            Daylight::clear(aim::direction_deg(az, el), &Atmosphere::clear()).sun_radiance
        });
        let k = match (disc, candidates.get(densest)) {
            (Some(d), Some(f)) => sun_shot::sensitivity(&d, radiance, f.transmittance, exposure_s),
            _ => None,
        };
        let (filter, exposure_s) = sun_shot::choose(k, radiance, &candidates, range, exposure_s);
        tracing::info!(
            azimuth_deg = correction.0,
            elevation_deg = correction.1,
            filter = candidates.get(filter).map_or("none", |c| c.name.as_str()),
            exposure_s,
            "sun centred"
        );
        SunFix {
            correction,
            filter,
            exposure_s,
        }
    }

    /// A note if the triplet's disc sums disagree by more than the tolerance.
    fn triplet_note(&mut self, shot: &PlannedShot, third: f64) -> Result<Option<String>, ShotError> {
        let target = target_of(&shot.key);
        let mut sums = Vec::new();
        let mut filters = HashSet::new();
        for f in 1..=2 {
            if let Some(e) = self.store.frame_entry(&format!("{target}/f{f}")).cloned() {
                let codes = self.store.read_frame(&e)?;
                let codes = self.as_metered(Codes::from(&codes));
                filters.insert(e.meta.filter.clone());
                if let Some(d) = sun_shot::find_disc(Codes::from(&codes)) {
                    sums.push(d.sum);
                }
            }
        }
        sums.push(third);
        if sums.len() < 3 {
            return Ok(Some("triplet incomplete: agreement not checked".to_owned()));
        }
        let spread = sun_shot::spread(&sums);
        Ok((spread > sun_shot::TRIPLET_TOLERANCE || filters.len() > 1).then(|| {
            format!(
                "triplet disagrees: disc sums spread {:.1}% (tolerance {:.0}%)",
                spread * 100.0,
                sun_shot::TRIPLET_TOLERANCE * 100.0
            )
        }))
    }
}
