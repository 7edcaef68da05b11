//! `campanile capture`: run a plan on a station into a session directory,
//! or resume one after a crash.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use campanile_capture::controller::{Progress, ShotOutcome};
use campanile_capture::schedule::{Occurrence, PlannedShot};
use campanile_capture::station::{check_ports, open_camera};
use campanile_capture::store::SessionStore;
use campanile_capture::store::fault::QuotaStorage;
use campanile_capture::store::{FsStorage, Storage};
use campanile_config::camera::CameraDriver;
use campanile_firmware_link::link::soak::PROVEN_FAULT_CHANCE;
use campanile_sim::faults::{Device, Outage};
use clap::Args;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};
use campanile_session::capture_inputs::Inputs;
use campanile_session::capture_run::{SimFaults, Tally, run_real, run_simulated, tally};

/// Run a plan on a station and store every frame in a session directory.
///
/// Executes exactly the shots `campanile plan check` lists, occurrence by
/// occurrence, and writes each frame (16-bit PNG, checksummed) and a journal
/// line before the next shot. Shots that cannot be taken (a device down
/// after its retries, the head unable to reach, a session that starts too
/// late) are journaled as missed with the reason.
///
/// Simulated stations (a `Sim` camera or `sim:` ports) photograph the plan's
/// scene under simulated time: the day passes as fast as the frames render;
/// the --sim-* flags inject faults. Real stations run on the wall clock:
/// the camera through its driver (V4L2 or nokhwa, cargo features `v4l` and
/// `nokhwa`), the head, filter wheel and lights on their serial ports, each
/// reopened with exponential backoff when its link drops.
///
/// Exit status: 0 when every promised frame is stored; 1 when a shot was
/// missed or the session stopped (e.g. the disk is full; resume it with
/// --resume); 2 for bad input.
///
/// Examples:
///   campanile capture examples/campanile-day.ron --station examples/sim-station.ron --out day
///   campanile capture --resume day
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct CaptureArgs {
    /// The plan (RON); its scene is read from the plan's `scene` field.
    /// Optional with --resume: the session's own plan.ron is used.
    #[arg(value_name = "PLAN", required_unless_present = "resume")]
    plan: Option<PathBuf>,
    /// The station (RON) that runs it. Optional with --resume: the
    /// session's own station.ron is used.
    #[arg(long, value_name = "STATION", required_unless_present = "resume")]
    station: Option<PathBuf>,
    /// A new session directory (must not exist or be empty).
    #[arg(
        long,
        value_name = "DIR",
        required_unless_present = "resume",
        conflicts_with = "resume"
    )]
    out: Option<PathBuf>,
    /// Resume the session in DIR after a crash or a stop: complete shots are
    /// kept, the rest are taken. Without PLAN and STATION the session's
    /// snapshots (DIR/plan.ron, station.ron, scene.ron) are used; given
    /// ones must be the ones it began with.
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
    /// Run only the first N days of the plan.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    days: Option<u32>,
    /// Simulation: render samples per pixel (indoor scenes: paths per pixel
    /// for the interreflected light; the lamps' direct light is exact).
    #[arg(long, value_name = "N", default_value_t = 2)]
    sim_samples: u32,
    /// Simulation: render bounces (scattering events per path, the first included).
    #[arg(long, value_name = "N", default_value_t = 1)]
    sim_bounces: u32,
    /// Simulation: chance that a byte is dropped on every serial link,
    /// 0–0.05 (the link soak proves 10⁴ commands exactly once up to 5 % drop
    /// + 5 % corruption; at 10 % + 10 % a command needs about 18 000 attempts).
    #[arg(long, value_name = "P", value_parser = link_chance)]
    sim_drop_chance: Option<f64>,
    /// Simulation: chance that a byte is corrupted on every serial link,
    /// 0–0.05 (as for --sim-drop-chance).
    #[arg(long, value_name = "P", value_parser = link_chance)]
    sim_corrupt_chance: Option<f64>,
    /// Simulation: chance that any one frame never arrives (the camera times out), 0–1.
    #[arg(long, value_name = "P", value_parser = chance)]
    sim_camera_timeout_chance: Option<f64>,
    /// Simulation: chance that any one frame fails with a camera error, 0–1.
    #[arg(long, value_name = "P", value_parser = chance)]
    sim_camera_error_chance: Option<f64>,
    /// Simulation: DEVICE (head, wheel or lights) disconnects AFTER seconds
    /// into the run for DURATION seconds, e.g. head:600:20. Repeatable.
    #[arg(long, value_name = "DEVICE:AFTER:DURATION")]
    sim_outage: Vec<OutageArg>,
    /// Simulation: the session directory may hold at most BYTES (what it
    /// already holds counts), as if the disk filled up there.
    #[arg(long, value_name = "BYTES")]
    sim_disk_quota: Option<u64>,
}

/// A chance in [0, 1].
fn chance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..=1.0).contains(&p) => Ok(p),
        _ => Err(format!("found {s:?}; expected a chance between 0 and 1")),
    }
}

/// A byte-fault chance in [0, PROVEN_FAULT_CHANCE], what the link soak proves.
fn link_chance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..=PROVEN_FAULT_CHANCE).contains(&p) => Ok(p),
        _ => Err(format!(
            "found {s:?}; expected a chance between 0 and {PROVEN_FAULT_CHANCE} (the link is proven to hold up to {PROVEN_FAULT_CHANCE} drop and {PROVEN_FAULT_CHANCE} corruption)"
        )),
    }
}

/// `--sim-outage DEVICE:AFTER:DURATION`.
#[derive(Debug, Clone, Copy)]
struct OutageArg(Outage);

impl std::str::FromStr for OutageArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "found {s:?}; expected DEVICE:AFTER_S:DURATION_S with DEVICE head, wheel or lights, e.g. head:600:20"
            )
        };
        let mut parts = s.split(':');
        let (Some(d), Some(a), Some(l), None) = (parts.next(), parts.next(), parts.next(), parts.next()) else {
            return Err(bad());
        };
        let device = match d {
            "head" => Device::Head,
            "wheel" => Device::Wheel,
            "lights" => Device::Lights,
            _ => return Err(bad()),
        };
        let secs = |v: &str| {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x >= 0.0 && *x < 1e9)
                .map(Duration::from_secs_f64)
                .ok_or_else(bad)
        };
        Ok(Self(Outage {
            device,
            after: secs(a)?,
            duration: secs(l)?,
        }))
    }
}

pub fn run(args: CaptureArgs) -> Result<u8> {
    let inputs = match Inputs::load(
        args.resume.as_deref(),
        args.plan.as_deref(),
        args.station.as_deref(),
        args.days,
    ) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("error: {e:#}");
            return Ok(EXIT_USAGE);
        }
    };
    let sim_flags = args.sim_drop_chance.is_some()
        || args.sim_corrupt_chance.is_some()
        || args.sim_camera_timeout_chance.is_some()
        || args.sim_camera_error_chance.is_some()
        || !args.sim_outage.is_empty()
        || args.sim_disk_quota.is_some();
    if !inputs.station.uses_simulation() && sim_flags {
        eprintln!(
            "error: the --sim-* fault flags are for simulated stations; station {:?} ({}) has real devices",
            inputs.station.name, inputs.station_label
        );
        return Ok(EXIT_USAGE);
    }
    Ok(if capture(&args, &inputs)? {
        EXIT_OK
    } else {
        EXIT_FAILURE
    })
}

/// Progress bars: the session, and the current occurrence's step.
struct Bars {
    session: ProgressBar,
    step: ProgressBar,
    _multi: MultiProgress,
}

impl Bars {
    fn new(promised: usize) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let multi = MultiProgress::with_draw_target(target);
        let style = ProgressStyle::with_template("{prefix:>24} [{bar:40}] {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let session = multi.add(ProgressBar::new(promised as u64).with_style(style.clone()));
        session.set_prefix("session");
        let step = multi.add(ProgressBar::new(0).with_style(style));
        Self {
            session,
            step,
            _multi: multi,
        }
    }
}

impl Progress for Bars {
    fn occurrence(&mut self, occurrence: &Occurrence) {
        self.session.set_message(occurrence.key.clone());
    }

    fn step(&mut self, occurrence: &Occurrence, step: usize, kind: &str, shots: usize) {
        self.step.reset();
        self.step.set_length(shots as u64);
        self.step.set_prefix(format!("{} s{step} {kind}", occurrence.name));
    }

    fn shot(&mut self, shot: &PlannedShot, outcome: ShotOutcome) {
        self.step.inc(1);
        if shot.promised && outcome != ShotOutcome::NotNeeded {
            self.session.inc(1);
        }
    }
}

fn capture(args: &CaptureArgs, inputs: &Inputs) -> Result<bool> {
    let dir = args
        .out
        .as_ref()
        .or(args.resume.as_ref())
        .context("give --out DIR or --resume DIR")?;
    if !inputs.station.uses_simulation() {
        // Before any session directory is made: the ports are real and
        // distinct, and this build has the camera's driver.
        check_ports(&inputs.station).with_context(|| format!("station {}", inputs.station_label))?;
        let driver = inputs.station.camera.driver;
        let built = match driver {
            CameraDriver::V4l => cfg!(feature = "v4l"),
            CameraDriver::Nokhwa => cfg!(feature = "nokhwa"),
            CameraDriver::Sim => true,
        };
        if !built {
            let why = open_camera(&inputs.station.camera)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            bail!("opening the camera of station {}: {why}", inputs.station_label);
        }
    }
    match args.sim_disk_quota {
        Some(quota) => {
            if inputs.station.uses_simulation() {
                // The quota counts what is already in the directory (none
                // if absent: the session store creates it).
                let storage = QuotaStorage::open(FsStorage, dir, quota)
                    .with_context(|| format!("measuring {} for the disk quota", dir.display()))?;
                capture_into(args, inputs, storage)
            } else {
                bail!("--sim-disk-quota is for simulated stations")
            }
        }
        None => capture_into(args, inputs, FsStorage),
    }
}

/// The `--sim-*` options of `args`.
fn sim_faults(args: &CaptureArgs) -> SimFaults {
    SimFaults {
        samples: args.sim_samples,
        bounces: args.sim_bounces,
        drop_chance: args.sim_drop_chance,
        corrupt_chance: args.sim_corrupt_chance,
        camera_timeout_chance: args.sim_camera_timeout_chance,
        camera_error_chance: args.sim_camera_error_chance,
        outages: args.sim_outage.iter().map(|o| o.0).collect(),
    }
}

/// Open the session (new or resumed) on `storage`, run the timeline on
/// the station's devices, and report.
fn capture_into<S: Storage>(args: &CaptureArgs, inputs: &Inputs, storage: S) -> Result<bool> {
    let (mut store, resumed) = match (&args.out, &args.resume) {
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
            eprintln!(
                "resuming {}{}: {} frames and {} missed shots journaled{repairs}",
                dir.display(),
                if inputs.from_session {
                    " with its own plan.ron and station.ron"
                } else {
                    ""
                },
                report.frames,
                report.missed,
            );
            tracing::info!(%report, "resumed");
            (store, true)
        }
        (None, None) => bail!("give --out DIR or --resume DIR"),
    };
    if inputs.timeline.occurrences.is_empty() {
        outln!("the plan has no occurrences: nothing to capture")?;
        return Ok(true);
    }
    let promised = inputs.timeline.frames_promised();
    let mut bars = Bars::new(promised);
    let wall = Instant::now();
    let started = if inputs.station.uses_simulation() {
        run_simulated(&sim_faults(args), inputs, &mut store, resumed, &mut bars)
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
            return Err(e.into());
        }
    };
    bars.session.finish_and_clear();
    bars.step.finish_and_clear();
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
    outln!("session {}", store.dir().display())?;
    outln!("  frames promised      {promised}")?;
    outln!("  frames stored        {stored} (of which late: {late})")?;
    outln!("  auto-bracket extras  {extra}")?;
    outln!("  shots missed         {missed}")?;
    outln!(
        "  this run             {} frames, {} missed, {} retries, {} reconnects, {} metering captures, {} sun retakes",
        report.frames,
        report.missed,
        report.retries,
        report.reconnects,
        report.metering_captures,
        report.saturation_retakes
    )?;
    outln!("  wall time            {}", seconds(elapsed))?;
    if let Some(e) = stopped {
        eprintln!("error: {e:#}");
        eprintln!("resume with: campanile capture --resume {}", store.dir().display());
        return Ok(false);
    }
    Ok(stored == promised && missed == 0)
}

fn seconds(d: Duration) -> String {
    format!("{:.1} s", d.as_secs_f64())
}
