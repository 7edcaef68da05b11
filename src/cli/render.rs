//! `campanile render`: the scene under new light from recovered
//! pseudo-albedos (thesis §5.5–§5.6): one time, a sunrise-to-sunset
//! sequence, or an overcast sky (the work is
//! `campanile_session::scene_render`'s).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_process::quality::QualityReport;
use campanile_session::igi::{RelightRequest, lights_file, recover_scene, relight_views};
use campanile_session::scene_render::{self, Rendered, SceneRenderOptions};
use chrono::{DateTime, NaiveDate, Utc};
use clap::Args;

use super::exit::{bad_input, shown};

/// Render the scene at a date and time from a materials file.
///
/// The scene's target surfaces take the pseudo-albedos of MATERIALS
/// (written by the outdoor reflectance recovery: materials.ron with its
/// EXR atlases); the other surfaces keep the scene's materials. The sun
/// comes from the ephemeris at the station's site; the sky is the clear
/// daylight model (CIE clear sky per channel, extinction, reddening near
/// the horizon) — not yet skies fitted to a session. --overcast P blends
/// an overcast sky blocking a fraction P of the sunlight (§5.6.3).
///
/// Writes OpenEXR radiance (render-<time>.exr) and, with --curve, 8-bit
/// PNGs through that response curve at --shutter-s (the thesis's figures
/// use 1/1500 s).
///
/// Example: campanile render --scene examples/campanile-scene.ron \
///            --station examples/sim-station.ron --materials out/materials.ron \
///            --pose view-se --time 2026-08-29T20:30:00Z --out renders/
///          campanile render ... --sequence 2026-08-29 --step-min 60 --out day/
///
/// Indoors (room mode): --igi SCENE.ron --lights LIGHTS.ron recovers the
/// scene file's materials and albedo maps (as `campanile igi`) and renders
/// the room under the new lights from each camera with an image (or
/// --camera NAME), writing relit-CAMERA.exr.
///
/// Example: campanile render --igi room/scene.ron --lights new-lights.ron --out relit/
///
/// --error F (room mode) draws paths until each 4 x 4 block's mean is
/// known to a relative standard error F instead of a fixed count:
///
/// Example: campanile render --igi room/scene.ron --lights new-lights.ron --error 0.01 --out relit/
///
/// High resolution (§5.6.4, eq. 5.16): --zoom EXR is a radiance photo
/// taken from --pose with a longer lens (--zoom-focal-px, its focal length
/// in its own pixels) at --zoom-time. Its detail finer than the grid's
/// cells becomes per-pixel pseudo-albedos (zoom-albedo-sun.exr,
/// zoom-albedo-se.exr), and that view is rendered at its own resolution
/// (render-zoom-<time>.exr; --width/--height are ignored). Pixels at a
/// sun-shadow edge, on a face outline, clipped in the merge or off the
/// targets keep the grid's pseudo-albedos; their counts are printed.
///
/// Example: campanile render --scene examples/campanile-scene.ron \
///            --station examples/sim-station.ron --materials out/materials.ron \
///            --pose zoom-south --zoom zoom.exr --zoom-time 2026-08-29T20:30:00Z \
///            --zoom-focal-px 2217 --time 2026-08-29T22:42:00Z --out zoom/
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct RenderArgs {
    /// Scene description (RON) with its geometry.
    #[arg(long, required_unless_present = "igi")]
    scene: Option<PathBuf>,
    /// Station description (RON): the site and the camera.
    #[arg(long, required_unless_present = "igi")]
    station: Option<PathBuf>,
    /// Materials file (RON) from the reflectance recovery.
    #[arg(long, required_unless_present = "igi")]
    materials: Option<PathBuf>,
    /// Camera pose named in the scene.
    #[arg(long, required_unless_present = "igi")]
    pose: Option<String>,
    /// Room mode: an indoor scene file (RON, see `campanile igi`) whose recovered materials are relit.
    #[arg(long, requires = "lights", conflicts_with_all = ["scene", "station", "materials", "pose", "time", "sequence"])]
    igi: Option<PathBuf>,
    /// Room mode: the new lights (a RON list of Known(...) lights).
    #[arg(long, requires = "igi")]
    lights: Option<PathBuf>,
    /// Room mode: render only this camera of the scene file.
    #[arg(long, requires = "igi")]
    camera: Option<String>,
    /// Room mode: the faster, coarser recovery.
    #[arg(long, requires = "igi")]
    quick: bool,
    /// Room mode: the relative standard error wanted of each 4 x 4 block's
    /// mean (0.01: 1 %), paths drawn until it is met (8 to 1024 per pixel)
    /// instead of a fixed 256 (64 with --quick).
    #[arg(long, requires = "igi", value_name = "FRACTION")]
    error: Option<f64>,
    /// UTC time to render (RFC 3339).
    #[arg(long, conflicts_with = "sequence")]
    time: Option<DateTime<Utc>>,
    /// Render from sunrise to sunset of this date (the site's solar day).
    #[arg(long)]
    sequence: Option<NaiveDate>,
    /// Minutes between frames of a sequence.
    #[arg(long, default_value_t = 60.0)]
    step_min: f64,
    /// Fraction of sunlight blocked by clouds, 0–1.
    #[arg(long, default_value_t = 0.0)]
    overcast: f64,
    /// Image width, pixels.
    #[arg(long, default_value_t = 256)]
    width: usize,
    /// Image height, pixels.
    #[arg(long, default_value_t = 192)]
    height: usize,
    /// Response curve (CSV from `hdr calibrate`) for 8-bit output.
    #[arg(long)]
    curve: Option<PathBuf>,
    /// Shutter time for 8-bit output, seconds.
    #[arg(long, default_value_t = 1.0 / 1500.0)]
    shutter_s: f64,
    /// Radiance of one unit of relative exposure per second (the merge's radiometric scale).
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// A zoom photograph from --pose (radiance EXR, as `campanile hdr` writes, or plain RGB):
    /// render that view with per-pixel pseudo-albedos (eq. 5.16).
    #[arg(long, requires_all = ["zoom_time", "zoom_focal_px"], conflicts_with = "igi")]
    zoom: Option<PathBuf>,
    /// UTC time the zoom photograph was taken (RFC 3339): its sun tells sunlit pixels from shadowed.
    #[arg(long, requires = "zoom")]
    zoom_time: Option<DateTime<Utc>>,
    /// Focal length of the zoom photograph, in its own pixels.
    #[arg(long, requires = "zoom")]
    zoom_focal_px: Option<f64>,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
}

/// Room mode: the scene file's recovered materials under new lights.
fn run_room(args: &RenderArgs, scene: &Path, lights: &Path) -> Result<()> {
    super::exit::error_target(args.error)?;
    let lights = lights_file(lights)?;
    let r = recover_scene(scene, args.quick).with_context(|| format!("reading {}", scene.display()))?;
    for w in &r.loaded.warnings {
        eprintln!("warning: {w}");
    }
    let out = &mut std::io::stdout();
    let q = super::verdicts::thresholds(None, None)?;
    let request = RelightRequest {
        camera: args.camera.as_deref(),
        quick: args.quick,
        error: args.error,
    };
    let relit = relight_views(&r, &lights, request, &args.out, &q, out)?;
    // With an error target each view is judged (OUT/quality.json; exit 3
    // when one failed).
    if relit.is_empty() {
        return Ok(());
    }
    super::verdicts::finish(&QualityReport::new(relit, &q), &args.out.join("quality.json"))
}

pub fn run(args: RenderArgs) -> Result<()> {
    if let (Some(scene), Some(lights)) = (&args.igi, &args.lights) {
        return run_room(&args, scene, lights);
    }
    let (Some(station_path), Some(scene_path), Some(materials_path), Some(pose_name)) =
        (&args.station, &args.scene, &args.materials, &args.pose)
    else {
        return Err(super::exit::bad_input(
            "give --scene, --station, --materials and --pose (or --igi and --lights for the room)",
        ));
    };
    if !(0.0..=1.0).contains(&args.overcast) {
        return Err(bad_input(format!(
            "--overcast: found {}; expected a fraction from 0 to 1",
            shown(args.overcast)
        )));
    }
    if !(1..=4096).contains(&args.width) || !(1..=4096).contains(&args.height) {
        return Err(bad_input(format!(
            "--width {} --height {}: expected 1 to 4096 pixels each",
            args.width, args.height
        )));
    }
    if !(args.step_min.is_finite() && args.step_min >= 1.0) {
        return Err(bad_input(format!(
            "--step-min: found {}; expected at least 1 minute",
            shown(args.step_min)
        )));
    }
    let opts = SceneRenderOptions {
        scene: scene_path.clone(),
        station: station_path.clone(),
        materials: materials_path.clone(),
        pose: pose_name.clone(),
        time: args.time,
        sequence: args.sequence,
        step_min: args.step_min,
        overcast: args.overcast,
        width: args.width,
        height: args.height,
        curve: args.curve.clone(),
        shutter_s: args.shutter_s,
        scale: args.scale,
        zoom: match (&args.zoom, args.zoom_time, args.zoom_focal_px) {
            (Some(path), Some(t), Some(f)) => Some((path.clone(), t, f)),
            _ => None,
        },
        out: args.out.clone(),
    };
    scene_render::render(&opts, &mut |r| {
        match r {
            Rendered::Zoom(report) => outln!("zoom: {report}")?,
            Rendered::ZoomAlbedo(exr) => outln!("{}", exr.display())?,
            Rendered::Frame {
                time,
                sun_elevation_rad,
                exr,
            } => outln!(
                "{}  sun elevation {:.1}°  {}",
                time.to_rfc3339(),
                sun_elevation_rad.to_degrees(),
                exr.display()
            )?,
        }
        Ok(())
    })?;
    Ok(())
}
