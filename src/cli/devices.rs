//! `campanile devices`: list serial ports and cameras; `devices test`
//! runs the conformance suites against a station's devices.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use campanile_capture::conformance;
use campanile_capture::station::check_ports;
use campanile_config::load_station;
use campanile_session::device_checks;
use clap::{Args, Subcommand};

use super::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};

/// List serial ports and cameras, or test a station's devices.
///
/// Without a subcommand: the serial ports the system lists (through /sys),
/// the cameras (through V4L2 when built with the `v4l` feature,
/// otherwise the /dev/video* nodes named from /sys) and, when built with
/// the `aravis` feature, the GenICam cameras Aravis finds, each with the id
/// a station's `driver: Aravis, device: Aravis(id: …)` takes; with --indi, the
/// devices an INDI server offers (a CCD is a station camera, a filter wheel
/// a station wheel: `driver: Indi, device: Indi(server: …, device: …)`).
///
/// Examples:
///   campanile devices
///   campanile devices --indi 127.0.0.1:7624
///   campanile devices test --station examples/real-station.ron
#[derive(Debug, Args)]
#[command(verbatim_doc_comment, args_conflicts_with_subcommands = true)]
pub struct DevicesArgs {
    #[command(subcommand)]
    action: Option<DevicesCommand>,
    /// List the devices of the INDI server at HOST:PORT instead.
    #[arg(long, value_name = "HOST:PORT")]
    indi: Option<String>,
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
    let out = &mut std::io::stdout();
    let Some(DevicesCommand::Test(args)) = args.action else {
        match &args.indi {
            Some(server) => device_checks::list_indi(server, out)?,
            None => device_checks::list(out)?,
        }
        return Ok(EXIT_OK);
    };
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
    if !station.uses_simulation()
        && let Err(e) = check_ports(&station)
    {
        eprintln!("error: {}: {e}", args.station.display());
        return Ok(EXIT_USAGE);
    }
    let head_options = conformance::pan_tilt::Options {
        move_limit: Duration::from_secs_f64(args.move_limit_s),
        ..conformance::pan_tilt::Options::default()
    };
    let outcomes = match device_checks::run_suites(&station, head_options) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e:#}");
            return Ok(EXIT_FAILURE);
        }
    };
    let (_, failed) = device_checks::write_outcomes(&outcomes, out)?;
    Ok(if failed == 0 { EXIT_OK } else { EXIT_FAILURE })
}
