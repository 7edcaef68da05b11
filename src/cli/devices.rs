//! `campanile devices`: list serial ports and cameras; `devices test`
//! runs the conformance suites against a station's devices.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{Context, Result};
use campanile_capture::conformance::{self, Report};
use campanile_capture::device::LightChannel;
use campanile_capture::driver::backoff::Backoff;
use campanile_capture::station::camera::list_cameras;
use campanile_capture::station::{
    SerialOpener, check_ports, connect_head, connect_lights, connect_wheel, light_channel, open_camera,
};
use campanile_config::camera::CameraDriver;
use campanile_config::{Station, load_station};
use campanile_firmware_link::link::host::RetryPolicy;
use campanile_firmware_link::transport::serial;
use campanile_sim::camera::UniformSource;
use campanile_sim::station::{SimOptions, SimStation};
use clap::{Args, Subcommand};

use super::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};

/// List serial ports and cameras, or test a station's devices.
///
/// Without a subcommand: the serial ports the system lists (through /sys)
/// and the cameras (through V4L2 when built with the `v4l` feature,
/// otherwise the /dev/video* nodes named from /sys).
///
/// Examples:
///   campanile devices
///   campanile devices test --station examples/real-station.ron
#[derive(Debug, Args)]
#[command(verbatim_doc_comment, args_conflicts_with_subcommands = true)]
pub struct DevicesArgs {
    #[command(subcommand)]
    action: Option<DevicesCommand>,
}

#[derive(Debug, Subcommand)]
enum DevicesCommand {
    /// Run the conformance suites against a station's devices.
    ///
    /// Connects each device of the station on its configured port (the
    /// camera through its driver) and runs the suite for its kind: the
    /// head (query, moves, every corner of its limits, an out-of-range
    /// move, home, stop), the filter wheel (every slot, an out-of-range
    /// slot), the lights (each lamp at half then off, all off, an
    /// out-of-range channel) and the camera (frame size and depth, the
    /// applied exposure at two exposures, an out-of-range exposure). The
    /// head moves over its whole range: clear its path first. A
    /// simulated station's devices are tested under simulated time.
    ///
    /// Exit status: 0 when every check passed, 1 when one failed or a
    /// device could not be connected, 2 for a bad station file.
    ///
    /// Example:
    ///   campanile devices test --station examples/sim-station.ron
    ///   campanile devices test --station my-head.ron --move-limit-s 20
    #[command(verbatim_doc_comment)]
    Test(TestArgs),
}

#[derive(Debug, Args)]
struct TestArgs {
    /// The station (RON).
    #[arg(long, value_name = "STATION")]
    station: PathBuf,
    /// Longest a single head move may take, seconds.
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    move_limit_s: f64,
}

pub fn run(args: DevicesArgs) -> Result<u8> {
    match args.action {
        None => list().map(|()| EXIT_OK),
        Some(DevicesCommand::Test(t)) => test(&t),
    }
}

fn list() -> Result<()> {
    let ports = serial::list().context("listing serial ports")?;
    outln!("serial ports:")?;
    if ports.is_empty() {
        outln!("  (none found)")?;
    }
    for p in &ports {
        outln!("  {p}")?;
    }
    let cameras = list_cameras().context("listing cameras")?;
    outln!("cameras:")?;
    if cameras.is_empty() {
        outln!("  (none found)")?;
    }
    for c in &cameras {
        match &c.name {
            Some(n) => outln!("  {}  {n}", c.path.display())?,
            None => outln!("  {}", c.path.display())?,
        }
    }
    if !cfg!(feature = "v4l") {
        outln!(
            "note: built without the `v4l` feature: cameras are the /dev/video* nodes, named from /sys; \
             rebuild with `--features v4l` to open them"
        )?;
    }
    Ok(())
}

/// One device's outcome.
enum Outcome {
    Tested(Report),
    /// Could not be connected or opened.
    Failed(String),
    /// Not testable in this build.
    Skipped(String),
}

fn test(args: &TestArgs) -> Result<u8> {
    let station = match load_station(&args.station) {
        Ok(s) => s.value,
        Err(e) => {
            eprintln!("error: {e}");
            return Ok(EXIT_USAGE);
        }
    };
    if !(args.move_limit_s.is_finite() && args.move_limit_s > 0.0) {
        eprintln!(
            "error: --move-limit-s: found {}; expected a positive number of seconds",
            args.move_limit_s
        );
        return Ok(EXIT_USAGE);
    }
    let head_options = conformance::pan_tilt::Options {
        move_limit: Duration::from_secs_f64(args.move_limit_s),
        ..conformance::pan_tilt::Options::default()
    };
    let result = if station.uses_simulation() {
        test_simulated(&station, head_options)
    } else {
        if let Err(e) = check_ports(&station) {
            eprintln!("error: {}: {e}", args.station.display());
            return Ok(EXIT_USAGE);
        }
        test_real(&station, head_options)
    };
    let outcomes = match result {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e:#}");
            return Ok(EXIT_FAILURE);
        }
    };
    let (mut checks, mut failed) = (0, 0);
    for (device, outcome) in &outcomes {
        outln!("{device}:")?;
        match outcome {
            Outcome::Tested(report) => {
                for line in report.to_string().lines() {
                    outln!("  {line}")?;
                }
                checks += report.checks.len();
                failed += report.failures().len();
            }
            Outcome::Failed(why) => {
                outln!("  FAIL  connect: {why}")?;
                checks += 1;
                failed += 1;
            }
            Outcome::Skipped(why) => outln!("  skipped: {why}")?,
        }
    }
    outln!("{checks} checks, {failed} failed")?;
    Ok(if failed == 0 { EXIT_OK } else { EXIT_FAILURE })
}

fn label(kind: &str, protocol: impl std::fmt::Debug, port: &str) -> String {
    format!("{kind} ({protocol:?} on {port})")
}

/// The station's real devices, one at a time, on the wall clock.
fn test_real(station: &Station, head_options: conformance::pan_tilt::Options) -> Result<Vec<(String, Outcome)>> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the runtime")?;
    // A device that is not there is reported after a few tries, not 15 s.
    let backoff = Backoff {
        attempts: 3,
        first: Duration::from_millis(250),
        cap: Duration::from_secs(1),
    };
    let retry = RetryPolicy::default();
    let seq = (chrono::Utc::now().timestamp_subsec_micros() % 4096) as u16 + 1;
    let opener = SerialOpener;
    runtime.block_on(async {
        let mut out = Vec::new();
        let h = &station.head;
        let head =
            campanile_capture::driver::backoff::reopen("head", backoff, || connect_head(h, &opener, retry, seq)).await;
        out.push((
            label("head", h.protocol, &h.link.port),
            match head {
                Ok(mut head) => Outcome::Tested(conformance::pan_tilt::run(&mut head, head_options).await),
                Err(e) => Outcome::Failed(e.to_string()),
            },
        ));
        if let Some(w) = &station.filter_wheel {
            let wheel = campanile_capture::driver::backoff::reopen("filter wheel", backoff, || {
                connect_wheel(w, &opener, retry, seq.wrapping_add(4096))
            })
            .await;
            out.push((
                label("filter wheel", w.protocol, &w.link.port),
                match wheel {
                    Ok(mut wheel) => Outcome::Tested(conformance::filter_wheel::run(&mut wheel).await),
                    Err(e) => Outcome::Failed(e.to_string()),
                },
            ));
        }
        if let Some(l) = &station.lights {
            let lights = campanile_capture::driver::backoff::reopen("lights", backoff, || {
                connect_lights(l, &opener, retry, seq.wrapping_add(8192))
            })
            .await;
            let channels: Vec<LightChannel> = (0..l.channels.len()).filter_map(|i| light_channel(l, i)).collect();
            out.push((
                label("lights", l.protocol, &l.link.port),
                match lights {
                    Ok(mut lights) => Outcome::Tested(conformance::lights::run(&mut lights, &channels).await),
                    Err(e) => Outcome::Failed(e.to_string()),
                },
            ));
        }
        let cam = &station.camera;
        // "camera (V4l on /dev/video0)", like the serial devices' labels.
        let camera_label = match &cam.device {
            Some(campanile_config::camera::DeviceRef::Path(p)) => format!("camera ({:?} on {p})", cam.driver),
            Some(campanile_config::camera::DeviceRef::Index(i)) => format!("camera ({:?} number {i})", cam.driver),
            None => format!("camera ({:?}, its first device)", cam.driver),
        };
        let built = match cam.driver {
            CameraDriver::V4l => cfg!(feature = "v4l"),
            CameraDriver::Nokhwa => cfg!(feature = "nokhwa"),
            CameraDriver::Sim => false,
        };
        let outcome = if built {
            match open_camera(cam) {
                Ok(mut camera) => Outcome::Tested(conformance::camera::run(&mut camera).await),
                Err(e) => Outcome::Failed(e.to_string()),
            }
        } else {
            Outcome::Skipped(
                open_camera(cam)
                    .err()
                    .map_or_else(|| "no driver".to_owned(), |e| e.to_string()),
            )
        };
        out.push((camera_label, outcome));
        Ok(out)
    })
}

/// A simulated station's devices: the emulators behind the same drivers,
/// under paused time, and the simulated camera on a uniform scene.
fn test_simulated(station: &Station, head_options: conformance::pan_tilt::Options) -> Result<Vec<(String, Outcome)>> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let source = Arc::new(UniformSource {
            radiance: [0.2, 0.2, 0.2],
        });
        let mut sim = SimStation::start(station, source, SimOptions::default())
            .await
            .context("starting the simulated station")?;
        let mut out = Vec::new();
        let h = &station.head;
        out.push((
            label("head", h.protocol, &h.link.port),
            Outcome::Tested(conformance::pan_tilt::run(&mut sim.head, head_options).await),
        ));
        if let (Some(w), Some(wheel)) = (&station.filter_wheel, sim.wheel.as_mut()) {
            out.push((
                label("filter wheel", w.protocol, &w.link.port),
                Outcome::Tested(conformance::filter_wheel::run(wheel).await),
            ));
        }
        let channels: Vec<LightChannel> = station
            .lights
            .as_ref()
            .map(|l| (0..l.channels.len()).filter_map(|i| sim.light_channel(i)).collect())
            .unwrap_or_default();
        if let (Some(l), Some(lights)) = (&station.lights, sim.lights.as_mut()) {
            out.push((
                label("lights", l.protocol, &l.link.port),
                Outcome::Tested(conformance::lights::run(lights, &channels).await),
            ));
        }
        out.push((
            "camera (Sim)".to_owned(),
            Outcome::Tested(conformance::camera::run(&mut sim.camera).await),
        ));
        Ok(out)
    })
}
