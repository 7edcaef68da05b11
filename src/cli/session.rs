//! `campanile session`: sessions from hand-taken photographs (`import`),
//! and checking a session's frames (`verify`).

use std::path::PathBuf;

use anyhow::Result;
use campanile_capture::import::ImportOptions;
use campanile_capture::import::clock::ClockSettings;
use campanile_capture::import::station_estimate::SiteGiven;
use campanile_session::photo_import;
use clap::{Args, Subcommand};

#[derive(Debug, Subcommand)]
pub enum SessionCommand {
    Import(Box<ImportArgs>),
    Verify(VerifyArgs),
}

/// Turn a folder of hand-taken JPEG brackets into a session that `campanile process` takes.
///
/// Every file of FOLDER must be a JPEG with EXIF (hidden files are passed
/// over). The photographs are put in time order (DateTimeOriginal,
/// SubSecTimeOriginal, then name) and grouped into brackets: consecutive
/// frames at one focal length and aperture, each starting within
/// --bracket-gap-s of the previous frame's end, no exposure twice (the same
/// exposure again starts the next bracket). The grouping is printed as a
/// table. A lone frame is refused (one JPEG cannot calibrate the response,
/// and its clipped highlights would pass for radiance) unless --skip-single
/// leaves it out.
///
///   time       DateTimeOriginal at OffsetTimeOriginal (or --utc-offset), less
///              --clock-offset-s (camera clock minus true time); both must be
///              stated: a wrong time is a wrong sun
///   exposure   ExposureTime (or --times), and the effective time
///              t·(ISO/ISO₀)·(N₀/N)² that the journal's exposure_actual_s holds
///   poses      --poses POSES.ron, per bracket (first file name or pattern):
///              a pose of --scene (`campanile register` writes them from
///              targets in the photographs), or azimuth/elevation (and
///              position, roll). A view is taken off the head: it journals
///              no head reading, and `process` turns it by its pose as it
///              is, roll included
///   sky        brackets marked sky: true in the poses, or by --sky PATTERN:
///              processed as a sky scan
///   camera     --station STATION.ron (calibrated), or estimated from EXIF
///              (focal length and pixel pitch) at --site LAT,LON[,ELEV_M]
///   zoom       the camera is the lens at the focal length most files were
///              taken at; brackets at another (EXIF FocalLength, needed on
///              every file then) are zoom photographs: they need --scene,
///              journal their focal length in pixels (the camera's scaled
///              by the FocalLength ratio, an undistorted lens) and get
///              eq. (5.16) pseudo-albedos per pixel from `process`. A sky
///              bracket must be at the camera's focal length
///
/// The frames are copied byte for byte into SESSION/frames and journaled
/// with their CRCs; SESSION/import.json records where every value came from
/// and what was estimated, which `process` repeats in its verdicts.
///
/// POSES.ron:
///   ImportPoses(brackets: [
///       (files: "IMG_6955.JPG", pose: "view-se"),
///       (files: "IMG_70*.JPG", position_m: (12.0, -30.0, 1.6), azimuth_deg: 20.0, elevation_deg: 8.0),
///       (files: "IMG_71*.JPG", position_m: (9.0, -25.0, 1.5), azimuth_deg: 35.0, elevation_deg: 12.0,
///        roll_deg: -4.5),
///       (files: "SKY_*.JPG", sky: true, azimuth_deg: 0.0, elevation_deg: 90.0),
///   ])
///
/// Exit status: 0 imported; 1 failure while working; 2 bad input (a file
/// that is not a JPEG or has no EXIF, a missing tag or option, mixed
/// cameras, a lone frame, an output directory that exists or cannot be made).
///
/// Example:
///   campanile session import photos/ --out tower-session --clock-offset-s 0 --utc-offset +02:00 \
///       --poses poses.ron --scene tower-scene.ron --site 45.4371,12.3326,5
///   campanile process tower-session --out tower-processed
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ImportArgs {
    /// The folder of camera files.
    #[arg(value_name = "FOLDER")]
    folder: PathBuf,
    /// The session directory to make (absent or empty).
    #[arg(long, value_name = "SESSION")]
    out: PathBuf,
    /// The camera's clock minus the true time, seconds (0 if checked right). Required.
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    clock_offset_s: Option<f64>,
    /// The camera clock's offset from UTC, for files without OffsetTimeOriginal (e.g. +02:00).
    #[arg(long, value_name = "+HH:MM", allow_hyphen_values = true, value_parser = utc_offset)]
    utc_offset: Option<chrono::FixedOffset>,
    /// Largest gap from one frame's end to the next frame's start within a bracket, seconds.
    #[arg(long, value_name = "S", default_value_t = 10.0)]
    bracket_gap_s: f64,
    /// Largest gap between brackets taken under one light (one occurrence), minutes.
    #[arg(long, value_name = "MIN", default_value_t = 15.0)]
    occurrence_gap_min: f64,
    /// Exposure times for files without ExposureTime (CSV `file,time`, or `NAME TIME` lines).
    #[arg(long, value_name = "FILE")]
    times: Option<PathBuf>,
    /// The poses of the brackets (see above).
    #[arg(long, value_name = "POSES.ron")]
    poses: Option<PathBuf>,
    /// The scene (its named poses, its geometry for the outdoor stages).
    #[arg(long, value_name = "SCENE.ron")]
    scene: Option<PathBuf>,
    /// The station: a calibrated camera and the site. Default: estimated from EXIF at --site.
    #[arg(long, value_name = "STATION.ron")]
    station: Option<PathBuf>,
    /// The site when no --station is given: latitude, longitude (degrees), elevation (m).
    #[arg(long, value_name = "LAT,LON[,ELEV_M]", allow_hyphen_values = true)]
    site: Option<SiteGiven>,
    /// Brackets of the sky, by their first file's name (`*` and `?`); repeatable.
    #[arg(long, value_name = "PATTERN")]
    sky: Vec<String>,
    /// Leave lone frames out (listed) instead of refusing them.
    #[arg(long)]
    skip_single: bool,
}

/// Check every frame of a session: present, its journaled size and CRC-32C, decodable at its journaled size.
///
/// Exit status: 0 every frame intact; 2 a frame missing or damaged (listed), or not a session.
///
/// Example:
///   campanile session verify tower-session
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct VerifyArgs {
    /// The session directory.
    #[arg(value_name = "SESSION")]
    session: PathBuf,
}

fn utc_offset(s: &str) -> Result<chrono::FixedOffset, String> {
    campanile_capture::import::camera_file::parse_utc_offset(s)
        .ok_or_else(|| format!("{s:?}: expected an offset from UTC, +HH:MM or -HH:MM (e.g. +02:00)"))
}

pub fn run(command: SessionCommand) -> Result<()> {
    let out = &mut std::io::stdout().lock();
    match command {
        SessionCommand::Import(args) => {
            let opts = ImportOptions {
                folder: args.folder,
                bracket_gap_s: args.bracket_gap_s,
                occurrence_gap_s: args.occurrence_gap_min * 60.0,
                clock: ClockSettings {
                    clock_offset_s: args.clock_offset_s,
                    utc_offset: args.utc_offset,
                },
                times: args.times,
                poses: args.poses,
                scene: args.scene,
                station: args.station,
                site: args.site,
                sky: args.sky,
                skip_single: args.skip_single,
            };
            Ok(photo_import::import(&opts, &args.out, out)?)
        }
        SessionCommand::Verify(args) => Ok(photo_import::verify(&args.session, out)?),
    }
}
