//! `campanile capture`: run a plan on a station into a session directory,
//! or resume one after a crash.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use campanile_firmware_link::link::soak::PROVEN_FAULT_CHANCE;
use campanile_sim::faults::{Device, Outage};
use clap::Args;

use super::{EXIT_FAILURE, EXIT_OK};
use campanile_session::capture_inputs::Inputs;
use campanile_session::capture_run::{self, CaptureRequest, SimFaults};

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
    /// Simulation: render bounces (scattering events per path, the first
    /// included). Three keep the light the ground and the walls reflect onto
    /// each other, which processing's models include: with one, that light
    /// is missing from the frames and the tower's pseudo-albedos come out
    /// at 0.45× the truth (`tests/cli_moved_tripod.rs`); use 1 only for
    /// frames whose values do not matter (a test of the capture itself).
    #[arg(long, value_name = "N", default_value_t = 3)]
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

/// Runs `capture`: 0 when every promised frame is stored, 1 when some
/// were missed or the run stopped, 2 for bad input.
pub fn run(args: CaptureArgs) -> Result<u8> {
    let inputs = Inputs::load(
        args.resume.as_deref(),
        args.plan.as_deref(),
        args.station.as_deref(),
        args.days,
    )
    .map_err(|e| campanile_session::Error::input(format!("{e:#}")))?;
    let request = CaptureRequest {
        out: args.out,
        resume: args.resume,
        sim: SimFaults {
            samples: args.sim_samples,
            bounces: args.sim_bounces,
            drop_chance: args.sim_drop_chance,
            corrupt_chance: args.sim_corrupt_chance,
            camera_timeout_chance: args.sim_camera_timeout_chance,
            camera_error_chance: args.sim_camera_error_chance,
            outages: args.sim_outage.iter().map(|o| o.0).collect(),
        },
        disk_quota: args.sim_disk_quota,
    };
    let complete = capture_run::capture(&request, &inputs, &mut std::io::stdout(), &mut std::io::stderr())?;
    Ok(if complete { EXIT_OK } else { EXIT_FAILURE })
}
