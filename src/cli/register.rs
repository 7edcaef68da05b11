//! `campanile register`: camera poses from photographs of surveyed targets
//! (coded AprilTags, or the thesis's white circles).

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::registration::RegistrationSettings;
use campanile_session::register_files::{RegisterRequest, failed_photos, register_photos};
use clap::Args;

use super::exit::{EXIT_OK, EXIT_QUALITY};

/// Camera poses from photographs of surveyed targets (thesis §3.3).
///
/// The targets file's kind decides. Coded targets (the default): finds the
/// tag36h11 tags in each photograph and pairs their corners with the
/// surveyed ones by id. Circle targets (`kind: Circle(radius_m)`, the
/// thesis's own): finds white circles on dark plates (template sweep at
/// several scales, ellipse fit) and pairs them with the survey by search
/// (pairs of ellipses give a pose, the other targets confirm it, §3.3.2);
/// `photos[].circles` reports what was found, matched and tried. Then
/// solves the pose (three-point solver inside
/// RANSAC, then Levenberg–Marquardt through the station camera's lens
/// distortion), and judges it: ok, poor (nearly collinear targets, a
/// reprojection error or an uncertainty over its limit) or failed (fewer
/// than three targets, or none agreeing). Photos taken at a reduced size
/// are fine: the intrinsics scale with the image.
///
/// --out gets a `RegisteredPoses(...)` file: `poses` in the form a scene
/// file's `poses` take (name = the photo's file stem), then each photo's
/// verdict, reasons, roll and figures (targets used and rejected,
/// reprojection error, one-sigma position and angle uncertainty).
///
/// Exit status: 0 when every photo has a pose (ok or poor), 3 when one
/// failed (the file is still written), 2 for bad input.
///
/// Example:
///   campanile register photos/*.png --targets targets.ron \
///       --station examples/sim-station.ron --out poses.ron
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct RegisterArgs {
    /// The photographs (PNG, JPEG or TIFF).
    #[arg(required = true, value_name = "PHOTOS")]
    photos: Vec<PathBuf>,
    /// The surveyed targets file (`Targets(...)`; see docs/reference/files.md).
    #[arg(long, value_name = "TARGETS.ron")]
    targets: PathBuf,
    /// The station file whose camera took the photographs.
    #[arg(long, value_name = "STATION.ron")]
    station: PathBuf,
    /// Where to write the poses.
    #[arg(long, value_name = "POSES.ron")]
    out: PathBuf,
    /// A target agrees with a pose when its corners reproject within this many pixels.
    #[arg(long, default_value_t = RegistrationSettings::default().inlier_threshold_px)]
    inlier_threshold_px: f64,
}

pub fn run(args: RegisterArgs) -> Result<u8> {
    if !(args.inlier_threshold_px.is_finite() && args.inlier_threshold_px > 0.0) {
        return Err(super::exit::bad_input(format!(
            "--inlier-threshold-px {}: expected a positive number of pixels",
            args.inlier_threshold_px
        )));
    }
    let request = RegisterRequest {
        photos: args.photos,
        targets: args.targets,
        station: args.station,
        out: args.out,
        settings: RegistrationSettings {
            inlier_threshold_px: args.inlier_threshold_px,
            ..RegistrationSettings::default()
        },
    };
    let written = register_photos(&request)?;
    for p in &written.photos {
        let q = &p.quality;
        let rms = q.rms_px.map_or("-".to_string(), |r| format!("{r:.2} px"));
        println!(
            "{}: {} ({} of {} targets, rms {rms}){}",
            p.file.display(),
            q.verdict,
            q.targets_used,
            q.targets_seen,
            if q.reasons.is_empty() {
                String::new()
            } else {
                format!(": {}", q.reasons.join("; "))
            }
        );
    }
    println!("poses written to {}", request.out.display());
    let failed = failed_photos(&written);
    if failed.is_empty() {
        Ok(EXIT_OK)
    } else {
        eprintln!("error: {} photograph(s) have no pose:", failed.len());
        for f in &failed {
            eprintln!("  {f}");
        }
        Ok(EXIT_QUALITY)
    }
}
