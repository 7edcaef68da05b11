//! The light of `campanile outdoor recover|render` (README: "Outdoor
//! files"): per photo time, the solar disc's irradiance and the sky as
//! eq. (5.9) per channel (a fitted-sky file as `campanile sky fit` writes
//! it, or an HDR fisheye image of the sky to fit). The sun's direction is
//! given, or computed from the site and the time, or taken from the sky
//! file. Paths are relative to the file.
//!
//! ```ron
//! OutdoorLight(
//!     site: Some((latitude_deg: 37.87, longitude_deg: -122.26, elevation_m: 60.0)),
//!     times: [
//!         (time: "2026-06-21T08:00:00Z", sun: Irradiance((830.0, 810.0, 760.0)),
//!          sky: File("skies/0800.ron"), below_horizon: Some((30.0, 29.0, 31.0))),
//!         (time: "2026-06-21T12:00:00Z", sun_direction: Some((azimuth_deg: 180.0, zenith_deg: 14.5)),
//!          sun: Disc(image: "sun-1200.exr", vfov_deg: 4.0, transmittance: Some((1e-5, 1e-5, 1e-5))),
//!          sky: Image(image: "skies/1200-fisheye.hdr", view: "from-image")),
//!     ],
//! )
//! ```

use std::path::{Path, PathBuf};

use chrono::{DateTime, Utc};
use serde::Deserialize;

use super::sky_image::fit_fisheye_sky;
use crate::igi::scene_file::{SceneFileError, read_ron_file};
use nalgebra::Vector3;

use crate::pipeline::MeasuredSky;
use crate::radiance_file::read_radiance_image;
use crate::render::{Sky, SolarDisc};
use crate::sky::{ChannelSky, SkyFile, angle_between, direction};
use crate::sun::{Observer, sun_position};

/// Where the photographs were taken.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteEntry {
    /// Geodetic latitude, degrees north.
    pub latitude_deg: f64,
    /// Longitude, degrees east.
    pub longitude_deg: f64,
    /// Height above sea level, metres.
    #[serde(default)]
    pub elevation_m: f64,
}

/// A direction toward the sun.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunDirectionEntry {
    /// Degrees from north through east.
    pub azimuth_deg: f64,
    /// Degrees from the zenith.
    pub zenith_deg: f64,
}

/// The solar disc.
#[derive(Debug, Clone, Deserialize)]
pub enum SunEntry {
    /// The disc's irradiance on a plane normal to the sun, W·m⁻² per
    /// channel (r, g, b), in the photos' radiance units times sr.
    Irradiance((f64, f64, f64)),
    /// A photograph of the disc to integrate (thesis §5.3.1,
    /// [`crate::sun::measure_sun`]): an HDR radiance image (OpenEXR, RGBE,
    /// PFM) from a rectified pinhole camera, principal point at the image
    /// centre, taken through a filter of the given transmittance per
    /// channel (a neutral-density filter: 1e-5 for ND 5.0).
    Disc {
        /// The image.
        image: PathBuf,
        /// Vertical field of view, degrees (or `hfov_deg`).
        #[serde(default)]
        vfov_deg: Option<f64>,
        /// Horizontal field of view, degrees (or `vfov_deg`).
        #[serde(default)]
        hfov_deg: Option<f64>,
        /// The filter's transmittance per channel, in (0, 1]; absent: none.
        #[serde(default)]
        transmittance: Option<(f64, f64, f64)>,
    },
    /// No direct sunlight (clouds over the disc, or the sun set).
    Hidden,
}

/// The normal irradiance per channel integrated from a sun photograph;
/// `Err((value, expected))` names what was wrong.
fn measured_disc(
    base: &Path,
    image: &Path,
    fov: (Option<f64>, Option<f64>),
    transmittance: Option<(f64, f64, f64)>,
    time: DateTime<Utc>,
) -> Result<[f64; 3], SceneFileError> {
    let full = base.join(image);
    let file_err = |message: String| SceneFileError::File {
        path: full.clone(),
        message,
    };
    let picture = read_radiance_image(&full).map_err(|e| file_err(e.message))?;
    let img = &picture.image;
    let half = |deg: f64| (0.5 * deg.to_radians()).tan();
    let focal_px = match fov {
        (Some(v), None) if v > 0.0 && v < 180.0 => 0.5 * img.height as f64 / half(v),
        (None, Some(h)) if h > 0.0 && h < 180.0 => 0.5 * img.width as f64 / half(h),
        _ => {
            return Err(file_err(format!(
                "the sun's camera: vfov_deg {:?}, hfov_deg {:?}: expected exactly one field of view in (0, 180) degrees",
                fov.0, fov.1
            )));
        }
    };
    let (tr, tg, tb) = transmittance.unwrap_or((1.0, 1.0, 1.0));
    let expected_sr = crate::sun::Ephemeris::at(time, None)
        .map(|e| crate::sun::sun_solid_angle_sr(e.earth_sun_distance_au()))
        .map_err(|e| file_err(format!("the sun's solid angle at {time}: {e}")))?;
    let mut out = [0.0; 3];
    for (c, t) in [tr, tg, tb].into_iter().enumerate() {
        if !(t > 0.0 && t <= 1.0) {
            return Err(file_err(format!(
                "transmittance {t} in channel {c}: expected a value in (0, 1]"
            )));
        }
        let channel: Vec<f32> = img.data.iter().skip(c).step_by(3).copied().collect();
        let frame = crate::sun::SunFrame {
            width: img.width,
            height: img.height,
            radiance: &channel,
            clipped: None,
            focal_px,
            principal_px: (0.5 * img.width as f64, 0.5 * img.height as f64),
            transmittance: t,
        };
        let disc = crate::sun::measure_sun(&frame, expected_sr)
            .map_err(|e| file_err(format!("channel {}: {e}", ["r", "g", "b"][c])))?;
        out[c] = disc.irradiance;
    }
    Ok(out)
}

/// The sky.
#[derive(Debug, Clone, Deserialize)]
pub enum SkyEntry {
    /// A fitted-sky file (RON, `campanile sky fit`'s output): eq. (5.9)
    /// per channel r, g, b.
    File(PathBuf),
    /// An HDR image of the sky to fit eq. (5.9) to, per channel.
    Image {
        /// The image (OpenEXR, RGBE or PFM), W·m⁻²·sr⁻¹.
        image: PathBuf,
        /// Its RADIANCE view (`-vta` angular or `-vth` hemispherical
        /// fisheye), or `"from-image"`: the `VIEW=` line of the RGBE file.
        view: String,
    },
}

/// The light at one time.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeEntry {
    /// When, UTC.
    pub time: DateTime<Utc>,
    /// The sun's direction; absent: from the site's ephemeris, else the sky file's.
    #[serde(default)]
    pub sun_direction: Option<SunDirectionEntry>,
    /// The solar disc.
    pub sun: SunEntry,
    /// The sky.
    pub sky: SkyEntry,
    /// The radiance below the horizon beyond the scene's geometry (the
    /// distant landscape; RADIANCE's ground glow), W·m⁻²·sr⁻¹ per channel,
    /// uniform; absent: none.
    #[serde(default)]
    pub below_horizon: Option<(f64, f64, f64)>,
}

/// The file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutdoorLight {
    /// The site, for the sun's position at each time.
    #[serde(default)]
    pub site: Option<SiteEntry>,
    /// One entry per time.
    pub times: Vec<TimeEntry>,
}

/// The light at one time, read.
#[derive(Debug, Clone)]
pub struct TimeLight {
    /// When.
    pub time: DateTime<Utc>,
    /// Sky and sun as the renderer and the solver take them.
    pub sky: PlainSky,
    /// The sky's channels as fitted (for their verdicts).
    pub channels: Vec<ChannelSky>,
    /// Where the sun's direction came from: `given`, `ephemeris` or `sky file`.
    pub sun_direction_source: &'static str,
    /// Where the sky came from (the file, or the image fitted).
    pub sky_source: String,
    /// Where the sun's irradiance came from: `given`, `hidden`, or
    /// `measured from IMAGE`.
    pub sun_source: String,
}

/// A measured sky with a uniform radiance below the horizon.
#[derive(Debug, Clone, PartialEq)]
pub struct PlainSky {
    /// Sky and sun.
    pub measured: MeasuredSky,
    /// Radiance below the horizon, per channel.
    pub below_horizon: [f64; 3],
}

impl Sky for PlainSky {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        if d.z <= 0.0 {
            self.below_horizon
        } else {
            self.measured.radiance(d)
        }
    }

    fn sun(&self) -> Option<SolarDisc> {
        self.measured.sun()
    }

    fn below_horizon(&self) -> [f64; 3] {
        self.below_horizon
    }
}

/// The sun's direction must agree with the sky file's within this (the
/// aureole is centred on it).
const SUN_AGREEMENT_DEG: f64 = 1.0;

/// Reads the light file at `path`, fitting any sky images.
pub fn load_light(path: &Path) -> Result<Vec<TimeLight>, SceneFileError> {
    let file: OutdoorLight = read_ron_file(path, "the OutdoorLight format of the README, \"Outdoor files\"")?;
    let base = path.parent().unwrap_or(Path::new("."));
    let field = |field: String, value: String, expected: &str| SceneFileError::Field {
        path: path.to_path_buf(),
        field,
        value,
        expected: expected.to_string(),
    };
    if file.times.is_empty() {
        return Err(field("times".into(), "[]".into(), "at least one time"));
    }
    if let Some(s) = &file.site
        && !(s.latitude_deg.abs() <= 90.0 && s.longitude_deg.abs() <= 180.0 && s.elevation_m.is_finite())
    {
        return Err(field(
            "site".into(),
            format!("({}, {}, {})", s.latitude_deg, s.longitude_deg, s.elevation_m),
            "latitude in [-90, 90], longitude in [-180, 180] degrees, a finite elevation in metres",
        ));
    }
    let mut out: Vec<TimeLight> = Vec::new();
    for (i, t) in file.times.iter().enumerate() {
        let at = |name: &str| format!("times[{i}].{name}");
        if out.iter().any(|o| o.time == t.time) {
            return Err(field(at("time"), t.time.to_rfc3339(), "one entry per time"));
        }
        // The sky's channels and the sun they were fitted with.
        let (channels, fitted_sun, sky_source) = match &t.sky {
            SkyEntry::File(f) => {
                let full = base.join(f);
                let sky: SkyFile = read_ron_file(&full, "a fitted-sky file as `campanile sky fit` writes it")?;
                (
                    sky.channels,
                    Some((sky.sun_zenith_deg, sky.sun_azimuth_deg)),
                    full.display().to_string(),
                )
            }
            SkyEntry::Image { .. } => (Vec::new(), None, String::new()),
        };
        // The sun's direction.
        let (sun_dir, source) = if let Some(d) = t.sun_direction {
            if !(d.zenith_deg.is_finite() && (0.0..=180.0).contains(&d.zenith_deg) && d.azimuth_deg.is_finite()) {
                return Err(field(
                    at("sun_direction"),
                    format!("(azimuth_deg: {}, zenith_deg: {})", d.azimuth_deg, d.zenith_deg),
                    "a zenith angle in [0, 180] degrees and a finite azimuth",
                ));
            }
            (
                direction(d.zenith_deg.to_radians(), d.azimuth_deg.to_radians()),
                "given",
            )
        } else if let Some(s) = &file.site {
            let observer = Observer::from_degrees(s.latitude_deg, s.longitude_deg, s.elevation_m, 1013.25, 15.0);
            let sun = sun_position(t.time, &observer, None).map_err(|e| {
                field(
                    at("time"),
                    t.time.to_rfc3339(),
                    &format!("a time the ephemeris covers ({e})"),
                )
            })?;
            (sun.direction(), "ephemeris")
        } else if let Some((z, a)) = fitted_sun {
            (direction(z.to_radians(), a.to_radians()), "sky file")
        } else {
            return Err(field(
                at("sun_direction"),
                "absent".into(),
                "the sun's direction (azimuth_deg, zenith_deg), or a site to compute it from",
            ));
        };
        let (channels, sky_source) = match &t.sky {
            SkyEntry::File(_) => {
                if let Some((z, a)) = fitted_sun {
                    let off = angle_between(sun_dir, direction(z.to_radians(), a.to_radians())).to_degrees();
                    if off > SUN_AGREEMENT_DEG {
                        return Err(field(
                            at("sky"),
                            format!("{sky_source}: sun at zenith {z:.2}°, azimuth {a:.2}°"),
                            &format!(
                                "a sky fitted with the sun where this time has it ({source}; {off:.2}° apart, more \
                                 than {SUN_AGREEMENT_DEG}°): the aureole is centred on the sun"
                            ),
                        ));
                    }
                }
                (channels, sky_source)
            }
            SkyEntry::Image { image, view } => {
                let full = base.join(image);
                let channels = fit_fisheye_sky(&full, view, sun_dir).map_err(|e| match e {
                    super::sky_image::SkyImageError::File(e) => e,
                    super::sky_image::SkyImageError::Field { value, expected } => {
                        field(at("sky.view"), value, &expected)
                    }
                })?;
                (channels, full.display().to_string())
            }
        };
        if channels.len() != 3 {
            return Err(field(
                at("sky"),
                format!("{sky_source}: {} channel(s)", channels.len()),
                "three channels r, g, b",
            ));
        }
        let models = [channels[0].model, channels[1].model, channels[2].model];
        let sun_source = match &t.sun {
            SunEntry::Irradiance(_) => "given".to_string(),
            SunEntry::Hidden => "hidden".to_string(),
            SunEntry::Disc { image, .. } => format!("measured from {}", base.join(image).display()),
        };
        let sun_irradiance = match &t.sun {
            SunEntry::Hidden => [0.0; 3],
            SunEntry::Disc {
                image,
                vfov_deg,
                hfov_deg,
                transmittance,
            } => {
                if sun_dir[2] <= 0.0 {
                    return Err(field(
                        at("sun"),
                        format!(
                            "Disc with the sun {:.2}° below the horizon",
                            -(sun_dir[2].asin().to_degrees())
                        ),
                        "Hidden when the sun is below the horizon",
                    ));
                }
                measured_disc(base, image, (*vfov_deg, *hfov_deg), *transmittance, t.time)?
            }
            &SunEntry::Irradiance((r, g, b)) => {
                if ![r, g, b].iter().all(|e| e.is_finite() && *e >= 0.0) {
                    return Err(field(
                        at("sun"),
                        format!("Irradiance(({r}, {g}, {b}))"),
                        "finite irradiances >= 0 W/m² per channel",
                    ));
                }
                if sun_dir[2] <= 0.0 && [r, g, b].iter().any(|e| *e > 0.0) {
                    return Err(field(
                        at("sun"),
                        format!(
                            "Irradiance(({r}, {g}, {b})) with the sun {:.2}° below the horizon",
                            -(sun_dir[2].asin().to_degrees())
                        ),
                        "Hidden when the sun is below the horizon",
                    ));
                }
                [r, g, b]
            }
        };
        let below_horizon = match t.below_horizon {
            None => [0.0; 3],
            Some((r, g, b)) if [r, g, b].iter().all(|v| v.is_finite() && *v >= 0.0) => [r, g, b],
            Some((r, g, b)) => {
                return Err(field(
                    at("below_horizon"),
                    format!("({r}, {g}, {b})"),
                    "finite radiances >= 0 W/m²/sr per channel",
                ));
            }
        };
        out.push(TimeLight {
            time: t.time,
            sky: PlainSky {
                measured: MeasuredSky {
                    sun_direction: sun_dir,
                    models,
                    sun_irradiance,
                    overcast: None,
                },
                below_horizon,
            },
            channels,
            sun_direction_source: source,
            sky_source,
            sun_source,
        });
    }
    Ok(out)
}
