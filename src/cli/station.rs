//! `campanile station run|status|serve|calibrate-mount`: the unattended
//! station, its heartbeat, its live page, and its head's mount calibrated
//! from targets.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use campanile_capture::unattended::{StationOptions, StorageBudget, parse_bytes};
use campanile_sim::faults::Device;
use chrono::{DateTime, Utc};
use clap::{Args, Subcommand};

use super::{EXIT_FAILURE, EXIT_OK};
use campanile_session::capture_inputs::Inputs;
use campanile_session::station_run::{StationRun, TimedOutage, run_station};
use campanile_session::{station_page, station_status};

#[derive(Debug, Subcommand)]
pub enum StationCommand {
    // The variants take their help from their arguments' doc comments.
    Run(RunArgs),
    Status(StatusArgs),
    Serve(ServeArgs),
    CalibrateMount(CalibrateMountArgs),
}

/// Calibrate the head's mount and find the tripod from registered photographs.
///
/// Photographs taken from the head at several pans (and tilts), each
/// registered from surveyed targets by `campanile register`, give the
/// camera's world orientation and place. This fits the mount calibration
/// that the station file's `head.mount` holds (the azimuth at pan 0, the
/// tilt reading at the horizon, the base's roll and pitch) to all of them
/// at once, each view weighted by its registration's stated uncertainty,
/// and places the head at the registered centres' weighted mean: after a
/// tripod was set up anywhere, `campanile process --camera-calibration
/// OUT` takes the views from where the head really stood.
///
/// READINGS is a CSV with the columns photo (the photograph's file stem,
/// as the poses file names it), pan_deg and tilt_deg (the head's reading
/// when it was taken). Photographs whose registration failed are skipped
/// and named.
///
/// OUT gets a `CameraCalibration(...)` (the station's camera intrinsics,
/// the fitted mount, `head_position_m`); the verdict (ok, poor or failed:
/// an angle σ over 0.025°, a view more than 0.1° from the mount's
/// prediction, registered centres spread over 2 cm: a moved tripod or a
/// camera off the head's axes; failed at four times those, or when the
/// views do not fix the four angles, e.g. all at one pan) goes to OUT's
/// stem + .quality.json; a failed calibration exits 3.
///
/// With --session instead, the photographs come from a captured session
/// whose plan took them as a calibration step: brackets aimed at head
/// angles (`Bracket(aim: PanTilt(pan_deg: -55.0, tilt_deg: 8.0), ...)`, at
/// three or more pans, facing the surveyed targets). Each bracket's
/// best-exposed frame is registered from --targets, with the head's reading
/// as the journal recorded it reached; the photographs, head.csv, the
/// session's station.ron and poses.ron are left in OUT's stem + -photos/.
///
/// Examples:
///   campanile register head/*.png --targets targets.ron \
///       --station examples/sim-station.ron --out poses.ron
///   campanile station calibrate-mount poses.ron --readings head.csv \
///       --station examples/sim-station.ron --out camera.ron
///   campanile station calibrate-mount --session mount-session \
///       --targets examples/campanile-targets.ron --out camera.ron
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct CalibrateMountArgs {
    /// `campanile register`'s poses file.
    #[arg(value_name = "POSES.ron", required_unless_present = "session", requires_all = ["readings", "station"])]
    poses: Option<PathBuf>,
    /// The head's reading at each photograph (CSV: photo, pan_deg, tilt_deg).
    #[arg(long, value_name = "READINGS.csv", requires = "poses")]
    readings: Option<PathBuf>,
    /// The station file whose camera and head took the photographs.
    #[arg(long, value_name = "STATION.ron", requires = "poses")]
    station: Option<PathBuf>,
    /// A captured session whose plan took the photographs as brackets aimed
    /// at head angles (`Bracket(aim: PanTilt(...))`): each bracket's
    /// best-exposed frame is registered from --targets, with the head's
    /// reached reading and the session's station. The photographs, their
    /// readings and poses are left in OUT's stem + `-photos/`.
    #[arg(long, value_name = "SESSION", conflicts_with_all = ["poses", "readings", "station"], requires = "targets")]
    session: Option<PathBuf>,
    /// With --session: the surveyed targets file (`campanile register --targets`).
    #[arg(long, value_name = "TARGETS.ron", requires = "session")]
    targets: Option<PathBuf>,
    /// Where to write the calibration.
    #[arg(long, value_name = "CAMERA.ron")]
    out: PathBuf,
}

/// Run a plan unattended, day after day, until its days end or it is stopped.
///
/// The plan's daily-repeating triggers (e.g. a sun triplet and a sky scan
/// every 10 minutes while the sun is above 5°) run for all its days.
///
/// Each plan day (the site's mean solar day, centred on local mean noon)
/// is one session directory, STORE/YYYY-MM-DD/. SIGTERM or SIGINT stops at
/// the next frame boundary with the journal consistent (at once while
/// waiting for a scan); running the same command again continues where it
/// stopped: completed shots are kept, shots missed earlier are not retaken.
///
/// STORE/heartbeat.json says what the station is doing (state, last
/// frame, device status, free disk, frames today, current session); see
/// `campanile station status`. Devices are probed between scans, every
/// 60 s, and a device that is down every 1, 2, 4 … 60 s (reconnecting);
/// an outage is journaled with its start and end, and scans due while it
/// lasts are journaled missed with the outage as the reason.
///
/// --budget: when the store holds more (frames and journals), the oldest
/// raw frames of scans whose processed products exist (listed in their
/// day's processed/products.ron) are deleted, journaled `pruned` and
/// logged. With --process the station processes each scan as it finishes
/// (the sky time series of `campanile process`: per-scan sun, sky fits and
/// flags into the day's processed/, the day's CSV, extinction and plots
/// recomputed), so its frames become deletable; without it only scans
/// listed by a separate `campanile process` are. With nothing deletable, a
/// warning is logged and capture goes on until the disk is full (then the
/// run stops cleanly, exit 1; rerun once there is room).
///
/// Exposures of the sky tiles are planned across the day from a clear-sky
/// model and damped from scan to scan (at most 0.5 stop per scan).
///
/// Simulated stations (a `Sim` camera) run under simulated time: days pass
/// as fast as the frames render.
///
/// Exit status: 0 when the plan's days are done or the run was stopped by
/// a signal; 1 when an error stopped it (e.g. the disk is full); 2 for bad
/// input.
///
/// Example:
///   campanile station run examples/sky-station.ron --station examples/sky-sim-station.ron --store sky --budget 50MB
///
/// Example with sky conditions and an alert (simulated broken clouds):
///   campanile station run examples/sky-station.ron \
///     --station examples/sky-sim-station.ron --store sky --days 1 \
///     --process --response response.csv --sim-broken-clouds 7 \
///     --on-condition-change 'echo "sky $2 -> $1 at $3" >> conditions.log'
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct RunArgs {
    /// The plan (RON); its scene is read from the plan's `scene` field.
    #[arg(value_name = "PLAN")]
    plan: PathBuf,
    /// The station (RON).
    #[arg(long, value_name = "STATION")]
    station: PathBuf,
    /// The store: one session directory per plan day, and heartbeat.json.
    #[arg(long, value_name = "DIR")]
    store: PathBuf,
    /// Storage budget, e.g. 2GB, 500MiB (see above).
    #[arg(long, value_name = "SIZE", value_parser = parse_bytes)]
    budget: Option<u64>,
    /// Process each scan as it finishes, into its day's processed/ (see
    /// above). Needs --response.
    #[arg(long, requires = "response")]
    process: bool,
    /// The camera's response curve for --process: a CSV from `campanile hdr
    /// calibrate`, or a session's processed/response.csv.
    #[arg(long, value_name = "CSV")]
    response: Option<PathBuf>,
    /// Run only the first N days of the plan.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    days: Option<u32>,
    /// Simulation: render samples per pixel.
    #[arg(long, value_name = "N", default_value_t = 2)]
    sim_samples: u32,
    /// Simulation: render bounces (three keep the light the ground and the
    /// walls reflect, which processing's models include; see `campanile
    /// capture --help`).
    #[arg(long, value_name = "N", default_value_t = 3)]
    sim_bounces: u32,
    /// Simulation: DEVICE (head, wheel or lights) disconnects at START (UTC,
    /// RFC 3339, e.g. 2026-06-22T18:03:00Z) for DURATION seconds, e.g.
    /// head:2026-06-22T18:03:00Z:1800. Repeatable. Absolute times, so a
    /// restarted run keeps them.
    #[arg(long, value_name = "DEVICE:START:DURATION")]
    sim_outage: Vec<StationOutageArg>,
    /// Simulation: a broken-cloud day, seeded: cloud patches drifting over
    /// the clear sky (clear spells, scattered, broken and near-overcast
    /// hours), for the sky-condition index.
    #[arg(long, value_name = "SEED")]
    sim_broken_clouds: Option<u64>,
    /// With --process: run CMD (through `sh -c`) when a scan's sky
    /// condition differs from the previous scan's of the day. Arguments
    /// $1..$8 (and environment variables): the new condition
    /// (CAMPANILE_SKY_CONDITION: clear, partly-cloudy, cloudy, overcast),
    /// the previous one or `unknown` (CAMPANILE_PREVIOUS_SKY_CONDITION),
    /// the scan time UTC (CAMPANILE_SCAN_TIME_UTC), the occurrence
    /// (CAMPANILE_OCCURRENCE), cloud cover 0-1 (CAMPANILE_CLOUD_COVER),
    /// the clear-sky index (CAMPANILE_CLEAR_SKY_INDEX), the direct one
    /// (CAMPANILE_DIRECT_CLEAR_SKY_INDEX), clouds near the sun 1/0
    /// (CAMPANILE_CLOUDS_NEAR_SUN_REGION). A failing or hanging command
    /// (killed after 30 s) is logged; the station goes on.
    #[arg(long, value_name = "CMD", requires = "process")]
    on_condition_change: Option<String>,
}

/// `--sim-outage DEVICE:START:DURATION`.
#[derive(Debug, Clone, Copy)]
pub struct StationOutageArg {
    device: Device,
    start: DateTime<Utc>,
    duration: Duration,
}

impl std::str::FromStr for StationOutageArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "found {s:?}; expected DEVICE:START:DURATION_S with DEVICE head, wheel or lights and START a UTC time, e.g. head:2026-06-22T18:03:00Z:1800"
            )
        };
        let (device, rest) = s.split_once(':').ok_or_else(bad)?;
        let (start, duration) = rest.rsplit_once(':').ok_or_else(bad)?;
        let device = match device {
            "head" => Device::Head,
            "wheel" => Device::Wheel,
            "lights" => Device::Lights,
            _ => return Err(bad()),
        };
        let start = DateTime::parse_from_rfc3339(start)
            .map_err(|_| bad())?
            .with_timezone(&Utc);
        let duration = duration
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && *x > 0.0 && *x < 1e9)
            .map(Duration::from_secs_f64)
            .ok_or_else(bad)?;
        Ok(Self {
            device,
            start,
            duration,
        })
    }
}

/// Print a station's heartbeat (exit 1 when it is stale).
///
/// Exit status: 0 when the heartbeat was written less than --max-age
/// seconds ago (wall clock); 1 when it is older (stale: the station is not
/// running, or stuck; a stopped or finished station is stale too) or
/// cannot be read, and 1 at once when it says the station runs but its
/// process does not (same host, and the PID is gone or is another process
/// now: "not running (killed?)"). A heartbeat written on another host, or
/// by an older version without host and start time, is judged by its age
/// only. A running station rewrites it at every frame and at
/// least every 60 s while it waits.
#[derive(Debug, Args)]
///
/// Example:
///   campanile station status sky --max-age 600
#[command(verbatim_doc_comment)]
pub struct StatusArgs {
    /// The store directory (`station run --store DIR`).
    #[arg(value_name = "DIR")]
    store: PathBuf,
    /// Stale beyond this many seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 300.0, allow_negative_numbers = true)]
    max_age: f64,
}

/// Serve a live web page of a running station (read-only).
///
/// The page shows the heartbeat (state, devices, free disk, frames today,
/// last frame), the latest sky frame, today's keogram as it builds up,
/// the sky series plots (sun irradiance, the Langley plot of the
/// extinction, sky parameters, and the sky-condition columns when the
/// series has them), and the day's outages and missed shots. Updates are
/// pushed to the browser (server-sent events): no reload. The same data
/// is a JSON API: /api/state, /api/days, /api/day/YYYY-MM-DD, and
/// /day/YYYY-MM-DD/keogram.png and latest.png; /events is the event
/// stream.
///
/// Only the files the station writes are read (polled every --poll-ms),
/// so any number of browsers cannot slow the station.
///
/// It listens on loopback (127.0.0.1:8080) unless --listen says
/// otherwise; on any other address a token is required (--token or
/// --token-file, 16 or more printable characters), and every request
/// must carry it (open the page as /?token=TOKEN, or send
/// `Authorization: Bearer TOKEN`); others get 401.
///
/// Runs until SIGINT or SIGTERM (exit 0); exit 2 for bad input (no such
/// store, a network address without a token), 1 when the address cannot
/// be used.
///
/// Examples:
///   campanile station serve sky
///   campanile station serve sky --listen 0.0.0.0:8080 --token-file /etc/campanile/page-token
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ServeArgs {
    /// The store directory (`station run --store DIR`).
    #[arg(value_name = "DIR")]
    store: PathBuf,
    /// Address and port to listen on.
    #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8080")]
    listen: std::net::SocketAddr,
    /// The token requests must carry (needed off loopback). Visible to
    /// other users in the process list: prefer --token-file.
    #[arg(long, value_name = "TOKEN", conflicts_with = "token_file")]
    token: Option<String>,
    /// A file whose first line is the token.
    #[arg(long, value_name = "FILE")]
    token_file: Option<PathBuf>,
    /// How often the store's files are looked at, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 500)]
    poll_ms: u64,
}

pub fn run(command: StationCommand) -> Result<u8> {
    let out = &mut std::io::stdout();
    let ok = match command {
        StationCommand::Run(args) => {
            let inputs = Inputs::from_files(&args.plan, &args.station, args.days)
                .map_err(|e| campanile_session::Error::input(format!("{e:#}")))?;
            let run = StationRun {
                store: args.store.clone(),
                options: StationOptions {
                    budget: args.budget.map(|max_bytes| StorageBudget { max_bytes }),
                    ..StationOptions::default()
                },
                samples: args.sim_samples,
                bounces: args.sim_bounces,
                outages: args
                    .sim_outage
                    .iter()
                    .map(|o| TimedOutage {
                        device: o.device,
                        start: o.start,
                        duration: o.duration,
                    })
                    .collect(),
                broken_clouds: args.sim_broken_clouds,
                on_condition_change: args.on_condition_change.clone(),
            };
            let response = args.response.as_deref().filter(|_| args.process);
            run_station(&run, &inputs, response, out, &mut std::io::stderr())?
        }
        StationCommand::Status(args) => station_status::status(&args.store, args.max_age, out)?,
        StationCommand::Serve(args) => {
            let token = match (args.token, &args.token_file) {
                (_, Some(file)) => Some(station_page::access::token_from_file(file)?),
                (token, None) => token,
            };
            let options = station_page::ServeOptions {
                store: args.store,
                listen: args.listen,
                token,
                poll: Duration::from_millis(args.poll_ms),
            };
            station_page::serve(options, out)?;
            true
        }
        StationCommand::CalibrateMount(args) => {
            let limits = campanile_process::registration::mount::MountLimits::default();
            let cal = match (&args.session, &args.targets, &args.poses, &args.readings, &args.station) {
                (Some(session), Some(targets), ..) => {
                    let stem = args.out.file_stem().map(|s| s.to_string_lossy().into_owned());
                    let dir = args
                        .out
                        .with_file_name(format!("{}-photos", stem.as_deref().unwrap_or("camera")));
                    let bar = campanile_session::progress::bar(0, "reading the session's calibration frames");
                    let photos = campanile_session::mount_session::session_photos(session, &dir, &bar)?;
                    bar.finish_and_clear();
                    let poses = dir.join("poses.ron");
                    let written = campanile_session::register_files::register_photos(
                        &campanile_session::register_files::RegisterRequest {
                            photos: photos.photos,
                            targets: targets.clone(),
                            station: photos.station.clone(),
                            out: poses.clone(),
                            settings: Default::default(),
                        },
                    )?;
                    for p in &written.photos {
                        eprintln!("{}: {}", p.file.display(), p.quality.verdict);
                    }
                    campanile_session::mount_files::calibrate_mount_files(
                        &poses,
                        &photos.readings,
                        &photos.station,
                        &limits,
                    )?
                }
                (None, None, Some(poses), Some(readings), Some(station)) => {
                    campanile_session::mount_files::calibrate_mount_files(poses, readings, station, &limits)?
                }
                _ => {
                    return Err(super::exit::bad_input(
                        "calibrate-mount takes POSES.ron --readings --station, or --session --targets",
                    ));
                }
            };
            eprint!("{}", cal.report);
            let text = campanile_session::sky_camera_files::calibration_ron(&cal.file)?;
            campanile_session::partial_file::write(&args.out, text.as_bytes())?;
            super::verdicts::finish(&cal.quality, &super::verdicts::beside(&args.out))?;
            true
        }
    };
    Ok(if ok { EXIT_OK } else { EXIT_FAILURE })
}
