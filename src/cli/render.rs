//! `campanile render`: the scene under new light from recovered
//! pseudo-albedos (thesis §5.5–§5.6): one time, a sunrise-to-sunset
//! sequence, or an overcast sky.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::{read_radiance_exr, read_rgb_exr, write_radiance_exr};
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::image_file::write_png;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::outdoor::atlas::read_materials;
use campanile_process::outdoor::photograph::photograph;
use campanile_process::outdoor::{
    Illumination, Photo, RerenderSettings, ZoomSettings, rerender, rerender_zoom, zoom_albedo,
};
use campanile_process::pose::HeadPose;
use campanile_process::render::CameraRig;
use campanile_process::sky::{Atmosphere, Daylight};
use campanile_process::sun::{Observer, sun_position};
use campanile_sim::world::load_scene;
use campanile_sim::world::rig::{mount, pinhole_at};
use chrono::{DateTime, Duration, NaiveDate, Utc};
use clap::Args;

use super::exit::{bad_input, shown};
use nalgebra::Vector3;

/// Overcast zenith radiance per channel (W·m⁻²·sr⁻¹) blended in with --overcast.
const OVERCAST_ZENITH: [f64; 3] = [30.0, 32.0, 36.0];

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

/// The zoom photograph of `path` as a posed photo from `rig`'s place and
/// aim, with its own size and focal length.
fn zoom_photo(path: &Path, rig: &CameraRig, focal_px: f64, time: DateTime<Utc>) -> Result<Photo> {
    if !(focal_px.is_finite() && focal_px > 0.0) {
        return Err(super::exit::bad_input(format!(
            "--zoom-focal-px {focal_px}: expected a focal length > 0 pixels"
        )));
    }
    let (image, mask) = match read_radiance_exr(path) {
        Ok(m) => {
            let mask = (0..m.width * m.height).map(|p| m.is_valid(p)).collect();
            (
                RadianceImage {
                    width: m.width,
                    height: m.height,
                    data: m.rgb,
                },
                Some(mask),
            )
        }
        Err(_) => (
            read_rgb_exr(path)
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("reading --zoom {}", path.display()))?,
            None,
        ),
    };
    let (w, h) = (image.width, image.height);
    if w == 0 || h == 0 {
        return Err(super::exit::bad_input(format!(
            "--zoom {}: the image is empty",
            path.display()
        )));
    }
    let mut zrig = *rig;
    zrig.pinhole.principal_px = (w as f64 / 2.0, h as f64 / 2.0);
    zrig.pinhole.focal_px = focal_px;
    zrig.width = w;
    zrig.height = h;
    Ok(Photo {
        label: path.display().to_string(),
        image,
        rig: zrig,
        time,
        mask,
    })
}

/// Per-pixel pseudo-albedos as an image.
fn albedo_image(rho: &[[f64; 3]], rig: &CameraRig) -> RadianceImage {
    RadianceImage {
        width: rig.width,
        height: rig.height,
        data: rho.iter().flat_map(|p| p.map(|v| v as f32)).collect(),
    }
}

fn write_exr(image: &RadianceImage, path: &Path) -> Result<()> {
    let n = image.width * image.height;
    let map = RadianceMap {
        width: image.width,
        height: image.height,
        rgb: image.data.clone(),
        variance: vec![0.0; n * 3],
        mask: vec![0; n],
    };
    write_radiance_exr(&map, path).with_context(|| format!("writing {}", path.display()))
}

/// Room mode: the scene file's recovered materials under new lights.
fn run_room(args: &RenderArgs, scene: &Path, lights: &Path) -> Result<()> {
    let lights: Vec<campanile_process::igi::IgiLight> = campanile_process::igi::scene_file::load_lights(lights)
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .into_iter()
        .map(|(_, l)| l)
        .collect();
    let r = super::igi::recover_scene(scene, args.quick, Default::default())
        .with_context(|| format!("reading {}", scene.display()))?;
    let cameras = match &args.camera {
        Some(c) => vec![c.clone()],
        None => r.image_cameras(),
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    for cam in cameras {
        let img = r.relight(&lights, &cam, args.quick)?;
        let path = args.out.join(format!("relit-{cam}.exr"));
        write_exr(&img, &path)?;
        outln!("relit {}", path.display())?;
    }
    Ok(())
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
    let station = campanile_config::document::load_station(station_path)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("reading {}", station_path.display()))?
        .value;
    let loaded = load_scene(scene_path).with_context(|| format!("reading {}", scene_path.display()))?;
    let scene = &loaded.scene;
    let refl =
        read_materials(scene, materials_path).with_context(|| format!("reading {}", materials_path.display()))?;
    let pose = loaded.description.pose(pose_name).with_context(|| {
        let names: Vec<&str> = loaded.description.poses.iter().map(|p| p.name.as_str()).collect();
        format!(
            "--pose {:?} is not in {}: it has {names:?}",
            pose_name,
            scene_path.display()
        )
    })?;
    let (pan, tilt) = station
        .head
        .reach(pose.azimuth_deg, pose.elevation_deg)
        .with_context(|| format!("the head cannot reach pose {:?}", pose.name))?;
    let (x, y, z) = pose.position_m;
    let rig = CameraRig {
        pinhole: pinhole_at(&station.camera, args.width, args.height),
        mount: mount(&station.head.mount),
        head: HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        },
        position: Vector3::new(x, y, z),
        width: args.width,
        height: args.height,
    };
    let site = &station.site;
    let observer = Observer::from_degrees(
        site.latitude_deg,
        site.longitude_deg,
        site.elevation_m,
        site.pressure_mbar,
        site.temperature_c,
    );
    let times: Vec<DateTime<Utc>> = match (args.time, args.sequence) {
        (Some(t), None) => vec![t],
        (None, Some(date)) => {
            // The solar day: local mean midnight to midnight at the site's longitude.
            let start = date.and_hms_opt(0, 0, 0).context("date")?.and_utc()
                - Duration::seconds((site.longitude_deg / 15.0 * 3600.0) as i64);
            let step = Duration::seconds((args.step_min * 60.0) as i64);
            let mut out = Vec::new();
            let mut t = start;
            while t < start + Duration::hours(24) {
                let sun = sun_position(t, &observer, site.delta_t_s).map_err(|e| anyhow::anyhow!("{e}"))?;
                if sun.elevation_rad() > 0.0 {
                    out.push(t);
                }
                t += step;
            }
            out
        }
        _ => return Err(super::exit::bad_input("give --time or --sequence")),
    };
    let curve = match &args.curve {
        Some(p) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            Some(ResponseCurve::from_csv(&text, p).map_err(|e| anyhow::anyhow!("{e}"))?)
        }
        None => None,
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let clear_day = |t: DateTime<Utc>| -> Result<(Daylight, f64)> {
        let sun = sun_position(t, &observer, site.delta_t_s).map_err(|e| anyhow::anyhow!("{e}"))?;
        if sun.elevation_rad() <= 0.0 {
            return Err(super::exit::bad_input(format!(
                "the sun is below the horizon at {t} ({:.1}°): nothing to render in daylight",
                sun.elevation_rad().to_degrees()
            )));
        }
        Ok((
            Daylight::clear(sun.direction(), &Atmosphere::clear()),
            sun.elevation_rad(),
        ))
    };
    let zoom = match (&args.zoom, args.zoom_time, args.zoom_focal_px) {
        (Some(path), Some(t), Some(f)) => {
            let photo = zoom_photo(path, &rig, f, t)?;
            let (day, _) = clear_day(t).context("--zoom-time")?;
            let light = Illumination { time: t, sky: &day };
            let z = zoom_albedo(scene, &refl, &photo, &light, &ZoomSettings::default())
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("--zoom {}", path.display()))?;
            outln!("zoom: {}", z.report)?;
            for (name, rho) in [("zoom-albedo-sun", &z.rho_sun), ("zoom-albedo-se", &z.rho_se)] {
                let exr = args.out.join(format!("{name}.exr"));
                write_exr(&albedo_image(rho, &z.rig), &exr)?;
                outln!("{}", exr.display())?;
            }
            Some(z)
        }
        _ => None,
    };
    for t in times {
        let (mut day, elevation) = clear_day(t)?;
        if args.overcast > 0.0 {
            day = day.with_clouds(args.overcast, OVERCAST_ZENITH);
        }
        let light = Illumination { time: t, sky: &day };
        let (image, prefix) = match &zoom {
            Some(z) => (
                rerender_zoom(scene, &refl, z, &light, &RerenderSettings::default()),
                "render-zoom",
            ),
            None => (
                rerender(scene, &refl, &rig, &light, &RerenderSettings::default()).0,
                "render",
            ),
        };
        let stem = format!("{prefix}-{}", t.format("%Y%m%dT%H%M%SZ"));
        let exr = args.out.join(format!("{stem}.exr"));
        write_exr(&image, &exr)?;
        outln!(
            "{}  sun elevation {:.1}°  {}",
            t.to_rfc3339(),
            elevation.to_degrees(),
            exr.display()
        )?;
        if let Some(c) = &curve {
            let png = args.out.join(format!("{stem}.png"));
            write_png(&photograph(&image, c, args.shutter_s, args.scale), &png)
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("writing {}", png.display()))?;
        }
    }
    Ok(())
}
