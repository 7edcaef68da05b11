//! Running a capture's timeline on a station into a session: the
//! simulated station under paused time (with injected faults), or the
//! real devices on the wall clock; and what the session holds afterwards.

use anyhow::Context;
use campanile_capture::clock::SystemClock;
use campanile_capture::controller::{self, Progress, RunError, RunOptions, RunReport};
use campanile_capture::station::{SerialOpener, StationOptions, StationRig, open_camera};
use campanile_capture::store::{JournalEntry, SessionStore, Storage};
use campanile_sim::camera::CameraOptions;
use campanile_sim::faults::{CameraFaultPlan, FaultPlan, LinkFaults, Outage};
use campanile_sim::station::{SimOptions, SimStation};
use chrono::TimeDelta;

use crate::Result;
use crate::capture_inputs::{Inputs, SimulatedWorld, simulated_world};

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
        let camera = open_camera(&inputs.station.camera)
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
