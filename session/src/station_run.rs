//! The unattended station's run (`campanile station run`): day after day
//! of a plan into a store, on the simulated hardware under paused time
//! (with device outages injected) or on the real devices, each settled
//! scan handed to a [`ScanHook`].

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use campanile_capture::clock::SystemClock;
use campanile_capture::controller::NoProgress;
use campanile_capture::station::{
    SerialOpener, StationOptions as RigOptions, StationRig, check_ports, open_station_camera,
};
use campanile_capture::store::{JournalEntry, SessionReader};
use campanile_capture::unattended::day_rollover::existing_days;
use campanile_capture::unattended::{
    self, NoProcessing, ScanHook, StationEnd, StationInputs, StationOptions, StationReport, StopHandle,
};
use campanile_process::quality::Quality;
use campanile_sim::faults::{Device, FaultPlan, Outage};
use campanile_sim::station::{SimOptions, SimStation};
use campanile_sim::world::broken_clouds::BrokenClouds;
use chrono::{DateTime, TimeDelta, Utc};

use crate::capture_inputs::{Inputs, SimulatedWorld, simulated_world};
use crate::condition_hook::ConditionHook;
use crate::scan_processor::{SkySeriesProcessor, StationHook};
use crate::{Error, Result};

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
    /// Simulated stations: a seeded drifting broken-cloud layer over the
    /// clear sky (`sim::world::broken_clouds`), from an hour before the
    /// plan's first occurrence.
    pub broken_clouds: Option<u64>,
    /// A command run when a processed scan changes the sky condition
    /// (see [`crate::condition_hook`]).
    pub on_condition_change: Option<String>,
}

/// How the station's run ended: its report, or the failure that stopped it.
pub type StationResult = std::result::Result<StationReport, unattended::StationFailure>;

/// The seeded broken-cloud layer `--sim-broken-clouds SEED` puts over
/// the plan of `inputs`: from an hour before its first occurrence to an
/// hour after its last (`None` without occurrences).
pub fn broken_clouds_for(inputs: &Inputs, seed: u64) -> Option<BrokenClouds> {
    let first = inputs.timeline.occurrences.first()?;
    let last = inputs.timeline.occurrences.last()?;
    let start = first.start - TimeDelta::hours(1);
    let hours = ((last.start - start).num_hours() + 2).max(1) as usize;
    Some(BrokenClouds::seeded(seed, start, hours))
}

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
    let SimulatedWorld {
        mut world,
        home,
        seed: _,
    } = simulated_world(inputs, run.samples, run.bounces)?;
    if let Some(seed) = run.broken_clouds {
        std::sync::Arc::make_mut(&mut world).broken_clouds = broken_clouds_for(inputs, seed);
    }
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
        let camera = open_station_camera(&inputs.station.camera)
            .await
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

/// The station's run as `campanile station run` makes it: on the simulated
/// station or the real one, stopping at the next frame boundary on SIGTERM
/// or SIGINT, each scan processed into the sky series when `response` is
/// given (with the plan's thresholds). The summary goes to `out`; a run
/// that stopped on a failure writes it and how to go on to `err` and
/// returns `Ok(false)`.
pub fn run_station(
    run: &StationRun,
    inputs: &Inputs,
    response: Option<&Path>,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<bool> {
    if !inputs.station.uses_simulation() && !run.outages.is_empty() {
        return Err(Error::input(format!(
            "--sim-outage is for simulated stations; station {:?} ({}) has real devices",
            inputs.station.name, inputs.station_label
        )));
    }
    let wall = Instant::now();
    let thresholds: Quality = inputs.plan.plan.value.quality.clone().unwrap_or_default();
    let mut hook: Box<dyn ScanHook> = match response {
        Some(response) => Box::new(StationHook(SkySeriesProcessor {
            response: response.to_path_buf(),
            thresholds,
            camera_calibration: None,
            on_condition_change: run.on_condition_change.clone().map(ConditionHook::new),
        })),
        None => Box::new(NoProcessing),
    };
    let result = if inputs.station.uses_simulation() {
        run_simulated(run, inputs, hook.as_mut(), &stop_on_signals)
    } else {
        run_real(run, inputs, hook.as_mut(), &stop_on_signals)
    }?;
    match result {
        Ok(report) => {
            write_summary(&run.store, &report, wall.elapsed(), out)?;
            Ok(true)
        }
        Err(failure) => {
            write_summary(&run.store, &failure.report, wall.elapsed(), out)?;
            writeln!(err, "error: {:#}", anyhow::Error::new(failure.error))?;
            writeln!(err, "continue with the same command once it is fixed")?;
            Ok(false)
        }
    }
}

/// Requests a stop at the next frame boundary on SIGTERM or SIGINT.
fn stop_on_signals(stop: &StopHandle) -> anyhow::Result<()> {
    use tokio::signal::unix::{SignalKind, signal};
    let mut term = signal(SignalKind::terminate()).context("listening for SIGTERM")?;
    let mut int = signal(SignalKind::interrupt()).context("listening for SIGINT")?;
    let stop = stop.clone();
    tokio::spawn(async move {
        tokio::select! {
            _ = term.recv() => tracing::warn!("SIGTERM: stopping at the next frame boundary"),
            _ = int.recv() => tracing::warn!("SIGINT: stopping at the next frame boundary"),
        }
        stop.request();
    });
    Ok(())
}

/// The run's summary: how it ended, its day sessions, scans, frames,
/// outages, pruning and wall time.
pub fn write_summary(store: &Path, r: &StationReport, wall: Duration, out: &mut dyn Write) -> Result<()> {
    writeln!(out, "store {}", store.display())?;
    let ended = match r.end {
        StationEnd::Finished => "every occurrence of the plan's days is settled",
        StationEnd::Stopped => "stopped on request (run the same command to continue)",
    };
    writeln!(out, "  ended                {ended}")?;
    let days: Vec<String> = r.days.iter().map(|d| d.to_string()).collect();
    writeln!(out, "  day sessions         {}", days.join(", "))?;
    writeln!(
        out,
        "  scans                {} run, {} settled earlier",
        r.occurrences_run, r.occurrences_skipped
    )?;
    writeln!(
        out,
        "  this run             {} frames, {} missed, {} missed in outages, {} metering captures",
        r.frames, r.missed, r.missed_in_outages, r.metering_captures
    )?;
    for o in &r.outages {
        writeln!(
            out,
            "  outage               {} from {} to {} ({:.1} min)",
            o.device,
            o.start.format("%Y-%m-%d %H:%M:%S UTC"),
            o.end.format("%Y-%m-%d %H:%M:%S UTC"),
            (o.end - o.start).num_seconds() as f64 / 60.0
        )?;
    }
    writeln!(
        out,
        "  pruned               {} frames, {} bytes",
        r.pruned_frames, r.pruned_bytes
    )?;
    writeln!(out, "  wall time            {:.1} s", wall.as_secs_f64())?;
    Ok(())
}
