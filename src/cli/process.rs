//! `campanile process`: a captured session to radiance, light and
//! reflectance, with a machine-readable summary of every figure (the work
//! is `campanile_session`'s; this parses the arguments and prints).

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::hdr::debevec::DebevecOptions;
use campanile_session::process::room::RoomOptions;
use campanile_session::run::{self, ProcessOptions, SessionKind};
use clap::Args;

use crate::cli::verdicts;

/// Process a captured session: response and HDR, then sun, sky and environment.
///
/// Reads the session directory that `campanile capture` wrote (its journal,
/// frames and the plan, station and scene snapshots) and runs:
///   1. the camera response (Debevec–Malik) from the session's own brackets,
///      and the HDR merge of every bracket (filters and lens falloff undone);
///   2. per occurrence: the sun's irradiance from its filtered frames
///      (triplet agreement checked), the sky model per channel fitted to the
///      sky scan (model choice by BIC, reason given), the environment map.
///
/// Outputs, in OUT (default SESSION/processed):
///   response.csv, response.svg     the curve with its uncertainty
///   radiance/<group>.exr           HDR views (RGB, variance, mask)
///   light/<occurrence>.ron         the sky per channel (eq. 5.9 parameters, model and why)
///   light/<occurrence>-environment.exr   the environment's lat-long region map
///   summary.json                   every figure and diagnostic, with stage times
///   quality.json                   every product's verdict (ok, poor, failed), its figures and thresholds
///   report.html                    the same as a page with plots (self-contained), the verdicts in a banner
/// and, with a scene: the pseudo-albedos (albedo/), the held-out views
/// re-rendered (held-out/), outdoor.json, and for each zoom photograph (a
/// view whose frames journal their own focal length, `focal_px`, as
/// `session import` writes photographs taken at another focal length) its
/// pixels' pseudo-albedos by eq. (5.16), kept out of the fit:
///   zoom/<group>-albedo-sun.exr, -albedo-se.exr   per pixel of the photograph
///   zoom/<group>-grid-albedo-se.exr               the grid's, interpolated there
///   zoom/<group>-used.png                         pixels given eq. (5.16) (white)
///   zoom/<group>-render.exr                       re-rendered with them at its own time
///
/// A sky-only session (only sun shots, sky scans and brackets aimed at head
/// angles) is processed as a sky time series instead: per scan the sun's
/// irradiance, the sky per channel (model and why, residuals), a profile
/// and quality flags; per day the extinction β per channel, a CSV, plots
/// and a keogram. It is incremental (scans with products are skipped;
/// scans still being captured wait) and shardable:
///   scans/<occurrence>.ron         one scan's products (the source of every per-day product)
///   sky-series.csv                 one row per scan, every column documented in its header
///   sky-series.parquet             the same rows, typed columns, each column's unit in its metadata
///   extinction.csv                 β and E₀ per day and channel (Langley)
///   plots/*.svg, keogram.png, keogram-residual.png, report.html
///   response.csv                   the response used (given, or from the calibration bracket)
/// and, when OUT is SESSION/processed and no --shard is given, each scan's
/// occurrence is added to SESSION/processed/products.ron once its file is
/// on disk (the station may then delete its raw frames).
///
/// Exit status: 0 every product ok or poor; 1 failure while working; 2 bad
/// input (no such session, a bad option or thresholds file); 3 finished,
/// but a product failed its quality gate (quality.json and the summary
/// line name it; products made from it inherit its verdict).
///
/// Examples:
///   campanile process campanile-day-session --scene examples/campanile-scene.ron
///   campanile process sky-day --response other-day/processed/response.csv
///   campanile process sky-day --shard 2/8 --out shard-2     (one of 8 array jobs)
///   campanile process sky-day --merge-shards shard-1 shard-2 … shard-8
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ProcessArgs {
    /// The session directory.
    #[arg(value_name = "SESSION")]
    session: PathBuf,
    /// Output directory (created; existing files in it are replaced).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// The scene file, when the session's scene snapshot cannot find its OBJ geometry.
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    /// Response recovery: smoothness weight λ (Debevec–Malik; unit-free, see `hdr calibrate --help`).
    #[arg(long, value_name = "λ", default_value_t = campanile_process::hdr::debevec::DEFAULT_LAMBDA)]
    lambda: f64,
    /// Response recovery: pixels sampled per channel.
    #[arg(long, value_name = "N", default_value_t = 4000)]
    samples: usize,
    /// Environment map elevation bands (−90° to 90°).
    #[arg(long, value_name = "N", default_value_t = 18)]
    env_rows: usize,
    /// Environment map azimuth sectors.
    #[arg(long, value_name = "N", default_value_t = 36)]
    env_cols: usize,
    /// Sky-only sessions: the response curve (CSV from `campanile hdr
    /// calibrate` or a session's processed/response.csv), for a day without
    /// a calibration bracket. Default: OUT/response.csv of an earlier run,
    /// else the session's own calibration bracket.
    #[arg(long, value_name = "FILE.csv")]
    response: Option<PathBuf>,
    /// A calibrated camera (CameraCalibration RON from `campanile sky
    /// calibrate` or `campanile station calibrate-mount`) whose intrinsics
    /// and mount replace the station's: a mis-set sky camera's frames are
    /// sampled through it, and a scene's views are taken from the head's
    /// measured place when the file gives one (a moved tripod).
    #[arg(long, value_name = "FILE.ron")]
    camera_calibration: Option<PathBuf>,
    /// Sky-only sessions: process only share K of N of the scans, chosen by
    /// a stable hash of the occurrence id (1 ≤ K ≤ N). Shards do not write
    /// the products list; merge them with --merge-shards.
    #[arg(long, value_name = "K/N")]
    shard: Option<campanile_process::sky_series::Shard>,
    /// Sky-only sessions: copy the per-scan files of these shard output
    /// directories into OUT (none: use what OUT holds), list them in the
    /// products list (if OUT is SESSION/processed) and recompute the day.
    /// No scan is processed.
    #[arg(long, value_name = "DIR", num_args = 0.., conflicts_with = "shard")]
    merge_shards: Option<Vec<PathBuf>>,
    /// Sky-only sessions: process this one occurrence (e.g. sky@2026-08-28#3)
    /// again or for the first time, whether or not it has products, then
    /// recompute the day (what the station does after each scan).
    #[arg(long, value_name = "ID", conflicts_with_all = ["shard", "merge_shards"])]
    occurrence: Option<String>,
    /// Room sessions: size of the rectified views handed to inverse global
    /// illumination, relative to the camera's frames (box-filtered
    /// radiance; 1 keeps every pixel, smaller is faster).
    #[arg(long, value_name = "S", default_value_t = 0.5, value_parser = room_scale)]
    room_scale: f64,
    /// Room sessions: the solver's faster, coarser settings (fewer
    /// radiosity cells, rays and ΔS iterations).
    #[arg(long)]
    quick: bool,
    /// Outdoor sessions: the side of the pseudo-albedo grid's cells on the
    /// scene's surfaces, metres (thesis §5.4). Finer cells see fewer pixels
    /// of each photo (noisier); coarser ones average light that varies
    /// over the cell. BENCHMARKS.md sweeps it.
    #[arg(long, value_name = "M", default_value_t = campanile_process::outdoor::ReflectanceSettings::default().spacing_m, value_parser = grid_spacing)]
    grid_spacing: f64,
    /// Quality thresholds (a `Quality(...)` RON file; any subset of the
    /// gates, the rest keep the plan's or the defaults). Every product
    /// gets a verdict, ok, poor or failed, in OUT/quality.json and the
    /// report's banner; a failed one makes the command exit 3.
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
}

fn grid_spacing(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if (0.1..=50.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} m: expected a cell side in [0.1, 50] m"))
    }
}

fn room_scale(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if (0.05..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v}: expected a scale in [0.05, 1]"))
    }
}

/// The options of the run `args` ask for.
fn options(args: ProcessArgs) -> ProcessOptions {
    let mut debevec = DebevecOptions {
        lambda: args.lambda,
        ..DebevecOptions::default()
    };
    debevec.sampling.samples = args.samples;
    ProcessOptions {
        out: args.out.unwrap_or_else(|| args.session.join("processed")),
        session: args.session,
        scene: args.scene,
        debevec,
        env: (args.env_rows, args.env_cols),
        thresholds: args.thresholds,
        room: RoomOptions {
            scale: args.room_scale,
            quick: args.quick,
        },
        grid_spacing_m: args.grid_spacing,
        response: args.response,
        camera_calibration: args.camera_calibration,
        shard: args.shard,
        merge_shards: args.merge_shards,
        occurrence: args.occurrence,
    }
}

pub fn run(args: ProcessArgs) -> Result<()> {
    let opts = options(args);
    let (out, err) = (&mut std::io::stdout(), &mut std::io::stderr());
    let quality = match run::kind(&opts)? {
        SessionKind::SkyOnly(q) => {
            let r = run::sky_only(&opts, &q)?;
            r.write_lines(&opts, out, err)?;
            if let Some(failure) = r.failure() {
                return Err(failure.into());
            }
            r.quality
        }
        SessionKind::Room => {
            let r = run::room(&opts)?;
            r.write_lines(&opts, out, err)?;
            r.quality
        }
        SessionKind::Outdoor => {
            let r = run::outdoor(&opts)?;
            r.write_lines(&opts, out)?;
            r.quality
        }
    };
    verdicts::finish(&quality, &opts.out.join("quality.json"))
}
