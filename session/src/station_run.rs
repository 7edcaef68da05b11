//! The unattended station's run (`campanile station run`): day after day
//! of a plan into a store, on the simulated hardware under paused time
//! (with device outages injected) or on the real devices, each settled
//! scan handed to a [`ScanHook`].

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use campanile_capture::clock::SystemClock;
use campanile_capture::controller::NoProgress;
use campanile_capture::station::{SerialOpener, StationOptions as RigOptions, StationRig, check_ports, open_camera};
use campanile_capture::store::{JournalEntry, SessionReader};
use campanile_capture::unattended::day_rollover::existing_days;
use campanile_capture::unattended::{self, ScanHook, StationInputs, StationOptions, StationReport, StopHandle};
use campanile_sim::faults::{Device, FaultPlan, Outage};
use campanile_sim::station::{SimOptions, SimStation};
use chrono::{DateTime, TimeDelta, Utc};

use crate::Result;
use crate::capture_inputs::{Inputs, SimulatedWorld, simulated_world};

/// A device outage at a station time.
#[derive(Debug, Clone, Copy)]
pub struct TimedOutage {
    /// The device down.
    pub device: Device,
    /// When it goes down (station time).
    pub start: DateTime<Utc>,
    /// For how long.
    pub duration: Duration,
}

/// Where and how the station runs.
#[derive(Debug, Clone)]
pub struct StationRun {
    /// The store: one day session per plan day, the heartbeat.
    pub store: PathBuf,
    /// The station's options (storage budget, …).
    pub options: StationOptions,
    /// Simulated stations: paths per pixel of the photographs.
    pub samples: u32,
    /// Simulated stations: scattering events per path.
    pub bounces: u32,
    /// Simulated stations: device outages.
    pub outages: Vec<TimedOutage>,
}

/// How the station's run ended: its report, or the failure that stopped it.
pub type StationResult = std::result::Result<StationReport, unattended::StationFailure>;

/// The station time of the last line journaled in any day session of `store`.
fn last_journaled(store: &Path) -> Result<Option<DateTime<Utc>>> {
    let mut last = None;
    for day in existing_days(store).with_context(|| format!("reading {}", store.display()))? {
        let dir = unattended::day_rollover::day_dir(store, day);
        let reader = SessionReader::open(&dir).with_context(|| format!("reading {}", dir.display()))?;
        last = last.max(reader.entries().iter().map(JournalEntry::time).max());
    }
    Ok(last)
}

/// The unattended station on the simulated hardware under paused time,
/// into `run.store`: from a minute before the first occurrence, or a
/// second after the last line journaled; `listen` is called on the stop
/// handle inside the runtime (the command line stops on SIGTERM and SIGINT).
pub fn run_simulated(
    run: &StationRun,
    inputs: &Inputs,
    hook: &mut dyn ScanHook,
    listen: &dyn Fn(&StopHandle) -> anyhow::Result<()>,
) -> Result<StationResult> {
    let Some(first) = inputs.timeline.occurrences.first() else {
        bail!("the plan has no occurrences: nothing to run");
    };
    // The simulated calendar begins a minute before the first occurrence,
    // or, after a stop, a second after the last journaled line.
    let origin = match last_journaled(&run.store)? {
        Some(t) => t + TimeDelta::seconds(1),
        None => first.start - TimeDelta::seconds(60),
    };
    let SimulatedWorld { world, home, seed: _ } = simulated_world(inputs, run.samples, run.bounces)?;
    let outages = run
        .outages
        .iter()
        .filter_map(|o| {
            let end = o.start + TimeDelta::from_std(o.duration).ok()?;
            if end <= origin {
                return None;
            }
            let start = o.start.max(origin);
            Some(Outage {
                device: o.device,
                after: (start - origin).to_std().ok()?,
                duration: (end - start).to_std().ok()?,
            })
        })
        .collect();
    let sim_options = SimOptions {
        origin,
        position_m: home,
        faults: FaultPlan {
            outages,
            ..FaultPlan::default()
        },
        ..SimOptions::default()
    };
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let stop = StopHandle::new();
        listen(&stop)?;
        let mut sim = SimStation::start(&inputs.station, world, sim_options)
            .await
            .context("starting the simulated station")?;
        let clock = sim.clock();
        Ok(unattended::run(
            &station_inputs(inputs),
            &run.store,
            &mut sim,
            &clock,
            &run.options,
            hook,
            &stop,
            &mut NoProgress,
        )
        .await)
    })
}

fn station_inputs(inputs: &Inputs) -> StationInputs<'_> {
    StationInputs {
        timeline: &inputs.timeline,
        plan: &inputs.plan.plan.value,
        station: &inputs.station,
        snapshot: &inputs.snapshot,
    }
}

/// The unattended station on its real devices on the wall clock, into
/// `run.store`; `listen` as for [`run_simulated`].
pub fn run_real(
    run: &StationRun,
    inputs: &Inputs,
    hook: &mut dyn ScanHook,
    listen: &dyn Fn(&StopHandle) -> anyhow::Result<()>,
) -> Result<StationResult> {
    check_ports(&inputs.station).with_context(|| format!("station {}", inputs.station_label))?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let stop = StopHandle::new();
        listen(&stop)?;
        let camera = open_camera(&inputs.station.camera)
            .with_context(|| format!("opening the camera of station {}", inputs.station_label))?;
        let link_seq = (Utc::now().timestamp_subsec_micros() % 4096) as u16 + 1;
        let rig_options = RigOptions {
            link_seq,
            ..RigOptions::default()
        };
        let mut rig = StationRig::connect(&inputs.station, SerialOpener, camera, rig_options)
            .await
            .with_context(|| format!("connecting the devices of station {}", inputs.station_label))?;
        Ok(unattended::run(
            &station_inputs(inputs),
            &run.store,
            &mut rig,
            &SystemClock,
            &run.options,
            hook,
            &stop,
            &mut NoProgress,
        )
        .await)
    })
}
