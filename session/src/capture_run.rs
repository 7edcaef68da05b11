//! Running a capture's timeline on a station into a session: the
//! simulated station under paused time (with injected faults), or the
//! real devices on the wall clock; and what the session holds afterwards.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use campanile_capture::clock::SystemClock;
use campanile_capture::controller::{self, Progress, RunError, RunOptions, RunReport};
use campanile_capture::station::{
    SerialOpener, StationOptions, StationRig, check_ports, driver_built, open_camera, open_station_camera,
};
use campanile_capture::store::fault::QuotaStorage;
use campanile_capture::store::{FsStorage, JournalEntry, SessionStore, Storage};
use campanile_sim::camera::CameraOptions;
use campanile_sim::faults::{CameraFaultPlan, FaultPlan, LinkFaults, Outage};
use campanile_sim::station::{SimOptions, SimStation};
use chrono::TimeDelta;

use crate::capture_inputs::{Inputs, SimulatedWorld, simulated_world};
use crate::progress::CaptureBars;
use crate::{Error, Result};

/// The simulated station's rendering and the faults to inject.
#[derive(Debug, Clone, Default)]
pub struct SimFaults {
    /// Paths per pixel of the simulated photographs.
    pub samples: u32,
    /// Scattering events per path.
    pub bounces: u32,
    /// Chance that a serial frame is dropped.
    pub drop_chance: Option<f64>,
    /// Chance that a serial frame is corrupted.
    pub corrupt_chance: Option<f64>,
    /// Chance that a camera capture times out.
    pub camera_timeout_chance: Option<f64>,
    /// Chance that a camera capture fails.
    pub camera_error_chance: Option<f64>,
    /// Device outages.
    pub outages: Vec<Outage>,
}

/// How a run ended: its report, or the error that stopped it (with the
/// report so far).
pub type RunResult = std::result::Result<RunReport, RunError>;

/// The simulated station under paused time: the day passes as fast as the
/// frames render.
pub fn run_simulated<S: Storage>(
    sim: &SimFaults,
    inputs: &Inputs,
    store: &mut SessionStore<S>,
    resumed: bool,
    progress: &mut dyn Progress,
) -> Result<RunResult> {
    let first = &inputs.timeline.occurrences[0];
    // The simulated calendar begins a minute before the first occurrence,
    // or, on resume, a second after the last journaled shot.
    let last = store.entries().iter().map(JournalEntry::time);
    let origin = match (resumed, last.max()) {
        (true, Some(t)) => t + TimeDelta::seconds(1),
        _ => first.start - TimeDelta::seconds(60),
    };
    let SimulatedWorld { world, home, seed } = simulated_world(inputs, sim.samples, sim.bounces)?;
    let faults = FaultPlan {
        link: (sim.drop_chance.is_some() || sim.corrupt_chance.is_some()).then(|| LinkFaults {
            drop_chance: sim.drop_chance.unwrap_or(0.0),
            corrupt_chance: sim.corrupt_chance.unwrap_or(0.0),
        }),
        outages: sim.outages.clone(),
        ..FaultPlan::default()
    };
    let camera = CameraOptions {
        faults: CameraFaultPlan {
            seed,
            timeout_chance: sim.camera_timeout_chance.unwrap_or(0.0),
            error_chance: sim.camera_error_chance.unwrap_or(0.0),
            ..CameraFaultPlan::none()
        },
        ..CameraOptions::default()
    };
    let options = SimOptions {
        origin,
        position_m: home,
        faults,
        camera,
        ..SimOptions::default()
    };
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let mut sim = SimStation::start(&inputs.station, world, options)
            .await
            .context("starting the simulated station")?;
        let clock = sim.clock();
        Ok(controller::run(
            &inputs.timeline,
            &inputs.plan.plan.value,
            &inputs.station,
            store,
            &mut sim,
            &clock,
            &RunOptions::default(),
            progress,
        )
        .await)
    })
}

/// The station's real devices on the wall clock: the camera its driver
/// names, the serial devices on their ports, reopened with backoff when a
/// link drops.
pub fn run_real<S: Storage>(
    inputs: &Inputs,
    store: &mut SessionStore<S>,
    progress: &mut dyn Progress,
) -> Result<RunResult> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let camera = open_station_camera(&inputs.station.camera)
            .await
            .with_context(|| format!("opening the camera of station {}", inputs.station_label))?;
        // Sequence numbers from the clock, so that a restarted program does
        // not reuse numbers a campanile-link device still remembers.
        let link_seq = (chrono::Utc::now().timestamp_subsec_micros() % 4096) as u16 + 1;
        let options = StationOptions {
            link_seq,
            ..StationOptions::default()
        };
        let mut rig = StationRig::connect(&inputs.station, SerialOpener, camera, options)
            .await
            .with_context(|| {
                format!(
                    "connecting the devices of station {} (check the cables, the baud rates and the devices' power)",
                    inputs.station_label
                )
            })?;
        Ok(controller::run(
            &inputs.timeline,
            &inputs.plan.plan.value,
            &inputs.station,
            store,
            &mut rig,
            &SystemClock,
            &RunOptions::default(),
            progress,
        )
        .await)
    })
}

/// What a session holds of its timeline's promised frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tally {
    /// Promised frames stored (late ones included).
    pub stored: usize,
    /// Of those, taken late.
    pub late: usize,
    /// Frames beyond the promised ones (auto-bracket extras).
    pub extra: usize,
    /// Shots missed and never completed.
    pub missed: usize,
}

/// Counts the journal of `store` against the promised shots of `inputs`.
pub fn tally<S: Storage>(inputs: &Inputs, store: &SessionStore<S>) -> Tally {
    let promised_keys: std::collections::HashSet<&str> = inputs
        .timeline
        .occurrences
        .iter()
        .flat_map(|o| o.shots.iter())
        .filter(|s| s.promised)
        .map(|s| s.key.as_str())
        .collect();
    let (mut stored, mut late, mut extra) = (0, 0, 0);
    // Shots, not lines: a journal from before one-line-per-shot may hold several.
    let mut missed_keys = std::collections::HashSet::new();
    for e in store.entries() {
        let promised = promised_keys.contains(e.key());
        match e {
            JournalEntry::Done(_) if promised => stored += 1,
            JournalEntry::Late(_) if promised => {
                stored += 1;
                late += 1;
            }
            JournalEntry::Missed(_) if !store.completed(e.key()) => {
                missed_keys.insert(e.key());
            }
            JournalEntry::Missed(_) => {}
            JournalEntry::Pruned(_) | JournalEntry::Outage(_) => {}
            _ => extra += 1,
        }
    }
    Tally {
        stored,
        late,
        extra,
        missed: missed_keys.len(),
    }
}

/// Where a capture goes, and the simulated station's faults.
#[derive(Debug, Clone, Default)]
pub struct CaptureRequest {
    /// A new session directory (must not exist or be empty).
    pub out: Option<PathBuf>,
    /// A session to resume instead.
    pub resume: Option<PathBuf>,
    /// The simulated station's rendering and injected faults.
    pub sim: SimFaults,
    /// Simulation: the session directory may hold at most this many bytes.
    pub disk_quota: Option<u64>,
}

impl CaptureRequest {
    /// Whether any fault is asked for (only simulated stations take them).
    pub fn injects_faults(&self) -> bool {
        let s = &self.sim;
        s.drop_chance.is_some()
            || s.corrupt_chance.is_some()
            || s.camera_timeout_chance.is_some()
            || s.camera_error_chance.is_some()
            || !s.outages.is_empty()
            || self.disk_quota.is_some()
    }
}

/// Runs a capture: checks a real station's ports and camera driver before
/// any session directory is made, opens the session (new or resumed; what
/// a resume repaired goes to `err`), runs the timeline with progress bars,
/// and prints the tally to `out`. `Ok(true)` when every promised frame is
/// stored and none missed; `Ok(false)` when some were missed or the run
/// stopped (the error and how to resume are written to `err`).
pub fn capture(req: &CaptureRequest, inputs: &Inputs, out: &mut dyn Write, err: &mut dyn Write) -> Result<bool> {
    if !inputs.station.uses_simulation() && req.injects_faults() {
        return Err(Error::input(format!(
            "the --sim-* fault flags are for simulated stations; station {:?} ({}) has real devices",
            inputs.station.name, inputs.station_label
        )));
    }
    let dir = req
        .out
        .as_ref()
        .or(req.resume.as_ref())
        .ok_or_else(|| Error::input("give --out DIR or --resume DIR"))?;
    if !inputs.station.uses_simulation() {
        // Before any session directory is made: the ports are real and
        // distinct, and this build has the camera's driver.
        check_ports(&inputs.station).with_context(|| format!("station {}", inputs.station_label))?;
        if !driver_built(inputs.station.camera.driver) {
            let why = open_camera(&inputs.station.camera)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            bail!("opening the camera of station {}: {why}", inputs.station_label);
        }
    }
    match req.disk_quota {
        Some(quota) => {
            // The quota counts what is already in the directory (none if
            // absent: the session store creates it).
            let storage = QuotaStorage::open(FsStorage, dir, quota)
                .with_context(|| format!("measuring {} for the disk quota", dir.display()))?;
            capture_into(req, inputs, storage, out, err)
        }
        None => capture_into(req, inputs, FsStorage, out, err),
    }
}

/// Opens the session (new or resumed) on `storage`, runs the timeline on
/// the station's devices, and reports.
fn capture_into<S: Storage>(
    req: &CaptureRequest,
    inputs: &Inputs,
    storage: S,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<bool> {
    let (mut store, resumed) = match (&req.out, &req.resume) {
        (Some(dir), _) => (
            SessionStore::create_with(storage, dir, inputs.snapshot.clone())
                .with_context(|| format!("creating the session in {}", dir.display()))?,
            false,
        ),
        (None, Some(dir)) => {
            let (store, report) = SessionStore::resume_with(storage, dir)
                .with_context(|| format!("resuming the session in {}", dir.display()))?;
            if store.snapshot().plan_ron != inputs.snapshot.plan_ron
                || store.snapshot().station_ron != inputs.snapshot.station_ron
            {
                bail!(
                    "{} began with another plan or station than {} and {}; resume with `campanile capture --resume {}` alone to use its own plan.ron and station.ron",
                    dir.display(),
                    inputs.plan_label,
                    inputs.station_label,
                    dir.display()
                );
            }
            // The repairs themselves, not "see the log": -q hides the log.
            let repairs: String = report.repairs().iter().map(|r| format!("\n  repaired: {r}")).collect();
            writeln!(
                err,
                "resuming {}{}: {} frames and {} missed shots journaled{repairs}",
                dir.display(),
                if inputs.from_session {
                    " with its own plan.ron and station.ron"
                } else {
                    ""
                },
                report.frames,
                report.missed,
            )?;
            tracing::info!(%report, "resumed");
            (store, true)
        }
        (None, None) => return Err(Error::input("give --out DIR or --resume DIR")),
    };
    if inputs.timeline.occurrences.is_empty() {
        writeln!(out, "the plan has no occurrences: nothing to capture")?;
        return Ok(true);
    }
    let promised = inputs.timeline.frames_promised();
    let mut bars = CaptureBars::new(promised);
    let wall = Instant::now();
    let started = if inputs.station.uses_simulation() {
        run_simulated(&req.sim, inputs, &mut store, resumed, &mut bars)
    } else {
        run_real(inputs, &mut store, &mut bars)
    };
    let result = match started {
        Ok(r) => r,
        Err(e) => {
            // A run that could not start leaves no new session behind.
            let dir = store.dir().to_path_buf();
            if let Err(d) = store.discard_unused() {
                tracing::warn!(dir = %dir.display(), error = %d, "could not remove the unused session");
            }
            return Err(e);
        }
    };
    bars.finish();
    let elapsed = wall.elapsed();
    let (report, stopped) = match result {
        Ok(r) => (r, None),
        Err(e) => (*e.report.clone(), Some(e)),
    };
    let Tally {
        stored,
        late,
        extra,
        missed,
    } = tally(inputs, &store);
    writeln!(out, "session {}", store.dir().display())?;
    writeln!(out, "  frames promised      {promised}")?;
    writeln!(out, "  frames stored        {stored} (of which late: {late})")?;
    writeln!(out, "  auto-bracket extras  {extra}")?;
    writeln!(out, "  shots missed         {missed}")?;
    writeln!(
        out,
        "  this run             {} frames, {} missed, {} retries, {} reconnects, {} metering captures, {} sun retakes",
        report.frames,
        report.missed,
        report.retries,
        report.reconnects,
        report.metering_captures,
        report.saturation_retakes
    )?;
    writeln!(out, "  wall time            {:.1} s", elapsed.as_secs_f64())?;
    if let Some(e) = stopped {
        writeln!(err, "error: {e:#}")?;
        writeln!(err, "resume with: campanile capture --resume {}", store.dir().display())?;
        return Ok(false);
    }
    Ok(stored == promised && missed == 0)
}
