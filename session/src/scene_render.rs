//! The scene under new light from recovered pseudo-albedos (thesis
//! §5.5–§5.6), as `campanile render` runs it: one time, a sunrise-to-sunset
//! sequence, or an overcast sky, from a pose of the scene; optionally a
//! zoom photograph's view at its own resolution with per-pixel
//! pseudo-albedos (eq. 5.16).

use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_config::Station;
use campanile_config::scene::CameraPose as ScenePose;
use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::{read_radiance_exr, read_rgb_exr};
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::image_file::write_png;
use campanile_process::outdoor::atlas::read_materials;
use campanile_process::outdoor::photograph::photograph;
use campanile_process::outdoor::zoom_albedo::ZoomReport;
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
use nalgebra::Vector3;

use crate::{Error, Result};

/// Overcast zenith radiance per channel (W·m⁻²·sr⁻¹) blended in with an overcast fraction.
const OVERCAST_ZENITH: [f64; 3] = [30.0, 32.0, 36.0];

/// What to render (`campanile render`'s outdoor mode).
#[derive(Debug, Clone)]
pub struct SceneRenderOptions {
    /// Scene description (RON) with its geometry.
    pub scene: PathBuf,
    /// Station description (RON): the site and the camera.
    pub station: PathBuf,
    /// Materials file (RON) from the reflectance recovery.
    pub materials: PathBuf,
    /// Camera pose named in the scene.
    pub pose: String,
    /// One UTC time to render.
    pub time: Option<DateTime<Utc>>,
    /// Or sunrise to sunset of this date (the site's solar day).
    pub sequence: Option<NaiveDate>,
    /// Minutes between frames of a sequence.
    pub step_min: f64,
    /// Fraction of sunlight blocked by clouds, 0–1.
    pub overcast: f64,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Response curve (CSV) for 8-bit output.
    pub curve: Option<PathBuf>,
    /// Shutter time for 8-bit output, seconds.
    pub shutter_s: f64,
    /// Radiance of one unit of relative exposure per second.
    pub scale: f64,
    /// A zoom photograph from the pose, the UTC time it was taken and its
    /// focal length in its own pixels.
    pub zoom: Option<(PathBuf, DateTime<Utc>, f64)>,
    /// Output directory.
    pub out: PathBuf,
}

/// What [`render`] has just written.
pub enum Rendered<'a> {
    /// The zoom photograph's per-pixel pseudo-albedos: what they rest on.
    Zoom(&'a ZoomReport),
    /// One of the zoom photograph's albedo images.
    ZoomAlbedo(&'a Path),
    /// A frame at `time`.
    Frame {
        /// Its time.
        time: DateTime<Utc>,
        /// The sun's elevation then, radians.
        sun_elevation_rad: f64,
        /// The OpenEXR file.
        exr: &'a Path,
    },
}

/// The zoom photograph of `path` as a posed photo from `rig`'s place and
/// aim, with its own size and focal length.
fn zoom_photo(path: &Path, rig: &CameraRig, focal_px: f64, time: DateTime<Utc>) -> Result<Photo> {
    if !(focal_px.is_finite() && focal_px > 0.0) {
        return Err(Error::input(format!(
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
        return Err(Error::input(format!("--zoom {}: the image is empty", path.display())));
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
pub(crate) fn albedo_image(rho: &[[f64; 3]], rig: &CameraRig) -> RadianceImage {
    RadianceImage {
        width: rig.width,
        height: rig.height,
        data: rho.iter().flat_map(|p| p.map(|v| v as f32)).collect(),
    }
}

/// The camera of scene pose `pose` at `width` × `height`: through the
/// station's head and mount for a level pose, or, for a pose with a roll
/// (a hand-held photograph's, as `campanile register` writes it), held
/// exactly at the pose's three angles ([`campanile_process::pose::Mount::holding`]).
pub fn pose_rig(station: &Station, pose: &ScenePose, width: usize, height: usize) -> Result<CameraRig> {
    let (x, y, z) = pose.position_m;
    let (held_by, head) = if pose.roll_deg == 0.0 {
        let (pan, tilt) = station
            .head
            .reach(pose.azimuth_deg, pose.elevation_deg)
            .with_context(|| format!("the head cannot reach pose {:?}", pose.name))?;
        let head = HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        };
        (mount(&station.head.mount), head)
    } else {
        campanile_process::registration::CameraPose::from_angles(
            pose.azimuth_deg,
            pose.elevation_deg,
            pose.roll_deg,
            Vector3::zeros(),
        )
        .holding()
    };
    Ok(CameraRig {
        pinhole: pinhole_at(&station.camera, width, height),
        mount: held_by,
        head,
        position: Vector3::new(x, y, z),
        width,
        height,
    })
}

/// Renders what `opts` ask for into `opts.out`, calling `on` after each
/// file (the frames of a sequence in time order).
pub fn render(opts: &SceneRenderOptions, on: &mut dyn FnMut(Rendered<'_>) -> Result<()>) -> Result<()> {
    let station = campanile_config::document::load_station(&opts.station)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("reading {}", opts.station.display()))?
        .value;
    let loaded = load_scene(&opts.scene).with_context(|| format!("reading {}", opts.scene.display()))?;
    let scene = &loaded.scene;
    let refl =
        read_materials(scene, &opts.materials).with_context(|| format!("reading {}", opts.materials.display()))?;
    let pose = loaded.description.pose(&opts.pose).with_context(|| {
        let names: Vec<&str> = loaded.description.poses.iter().map(|p| p.name.as_str()).collect();
        format!(
            "--pose {:?} is not in {}: it has {names:?}",
            opts.pose,
            opts.scene.display()
        )
    })?;
    let rig = pose_rig(&station, pose, opts.width, opts.height)?;
    let site = &station.site;
    let observer = Observer::from_degrees(
        site.latitude_deg,
        site.longitude_deg,
        site.elevation_m,
        site.pressure_mbar,
        site.temperature_c,
    );
    let times: Vec<DateTime<Utc>> = match (opts.time, opts.sequence) {
        (Some(t), None) => vec![t],
        (None, Some(date)) => {
            // The solar day: local mean midnight to midnight at the site's longitude.
            let start = date.and_hms_opt(0, 0, 0).context("date")?.and_utc()
                - Duration::seconds((site.longitude_deg / 15.0 * 3600.0) as i64);
            let step = Duration::seconds((opts.step_min * 60.0) as i64);
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
        _ => return Err(Error::input("give --time or --sequence")),
    };
    let curve = match &opts.curve {
        Some(p) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            Some(ResponseCurve::from_csv(&text, p).map_err(|e| anyhow::anyhow!("{e}"))?)
        }
        None => None,
    };
    std::fs::create_dir_all(&opts.out).with_context(|| format!("creating {}", opts.out.display()))?;
    let clear_day = |t: DateTime<Utc>| -> Result<(Daylight, f64)> {
        let sun = sun_position(t, &observer, site.delta_t_s).map_err(|e| anyhow::anyhow!("{e}"))?;
        if sun.elevation_rad() <= 0.0 {
            return Err(Error::input(format!(
                "the sun is below the horizon at {t} ({:.1}°): nothing to render in daylight",
                sun.elevation_rad().to_degrees()
            )));
        }
        Ok((
            Daylight::clear(sun.direction(), &Atmosphere::clear()),
            sun.elevation_rad(),
        ))
    };
    let zoom = match &opts.zoom {
        Some((path, t, f)) => {
            let photo = zoom_photo(path, &rig, *f, *t)?;
            let (day, _) = clear_day(*t).context("--zoom-time")?;
            let light = Illumination { time: *t, sky: &day };
            let z = zoom_albedo(scene, &refl, &photo, &light, &ZoomSettings::default())
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("--zoom {}", path.display()))?;
            on(Rendered::Zoom(&z.report))?;
            for (name, rho) in [("zoom-albedo-sun", &z.rho_sun), ("zoom-albedo-se", &z.rho_se)] {
                let exr = opts.out.join(format!("{name}.exr"));
                crate::igi::write_exr(&albedo_image(rho, &z.rig), &exr)?;
                on(Rendered::ZoomAlbedo(&exr))?;
            }
            Some(z)
        }
        _ => None,
    };
    for t in times {
        let (mut day, elevation) = clear_day(t)?;
        if opts.overcast > 0.0 {
            day = day.with_clouds(opts.overcast, OVERCAST_ZENITH);
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
        let exr = opts.out.join(format!("{stem}.exr"));
        crate::igi::write_exr(&image, &exr)?;
        on(Rendered::Frame {
            time: t,
            sun_elevation_rad: elevation,
            exr: &exr,
        })?;
        if let Some(c) = &curve {
            let png = opts.out.join(format!("{stem}.png"));
            write_png(&photograph(&image, c, opts.shutter_s, opts.scale), &png)
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("writing {}", png.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-held pose with a roll is rendered exactly where registration
    /// put it: every point projects through the rig to the pixel
    /// `CameraPose::from_angles` projects it to, within 1e-6 px; a level
    /// pose still goes through the station's head.
    #[test]
    fn a_rolled_pose_renders_from_the_registered_orientation() {
        let station = campanile_config::load_station(&campanile_sim::world::examples_dir().join("sim-station.ron"))
            .expect("station")
            .value;
        let pose = ScenePose {
            name: "hand".into(),
            position_m: (3.0, -20.0, 1.6),
            azimuth_deg: 12.0,
            elevation_deg: 18.0,
            roll_deg: -23.5,
        };
        let rig = pose_rig(&station, &pose, 320, 240).expect("a rig");
        let truth =
            campanile_process::registration::CameraPose::from_angles(12.0, 18.0, -23.5, Vector3::new(3.0, -20.0, 1.6));
        let mut compared = 0;
        for p in [[0.0, 0.0, 5.0], [4.0, 2.0, 9.0], [-3.0, -5.0, 2.0], [6.0, 1.0, 1.0]] {
            let p = Vector3::from(p);
            if let (Some(a), Some(b)) = (rig.project(&p), truth.project(&rig.pinhole, &p)) {
                assert!(
                    (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6,
                    "{a:?} against {b:?}"
                );
                compared += 1;
            }
        }
        assert!(compared >= 3, "{compared} points in view");
        // Level: the head's reading through the station's mount.
        let level = ScenePose { roll_deg: 0.0, ..pose };
        let rig = pose_rig(&station, &level, 320, 240).expect("a rig");
        assert_eq!(rig.mount, mount(&station.head.mount));
    }
}
