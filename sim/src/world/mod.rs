//! The simulated world: a scene with its true materials, the site's sun
//! and sky, and the station's lamps, rendered by `process::render`.
//!
//! The sun comes from the same ephemeris the station uses
//! ([`campanile_process::sun`]), the sky from [`campanile_process::sky::Daylight`]
//! (CIE clear sky per channel, extinction, reddening, optional clouds).
//! Everything the solvers should recover is exposed here as ground truth.

pub mod broken_clouds;
pub mod campanile_day;
pub mod cube_room;
pub mod igi_photograph;
pub mod range_scanner;
pub mod range_truth;
pub mod rig;
pub mod room_igi;
pub mod scanned_scene;
pub mod scene_file;
pub mod sun_track;
pub mod target_photos;
pub mod texture_truth;
pub mod tower_from_scans;
pub mod truth;
pub mod zoom_truth;

use std::path::PathBuf;

use campanile_process::camera::image::RadianceImage;
use campanile_process::pose::{HeadPose, Mount};
use campanile_process::render::{self, CameraRig, Lighting, RenderSettings, SphereLight};
use campanile_process::sky::{Atmosphere, Daylight};
use campanile_process::sun::{Observer, SunPosition, sun_position};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

use crate::camera::{FrameSource, View};

pub use scene_file::{LoadedScene, examples_dir, from_description, load_scene};
pub use truth::{Appearance, Finish, Setting};

/// Why a world could not be built or asked.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// A configuration file is invalid.
    #[error("{path}: {message}")]
    Config {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The geometry could not be read.
    #[error("{path}: {message}")]
    Geometry {
        /// The OBJ file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The sun could not be computed for this time and site.
    #[error("solar position at {time}: {message}")]
    Sun {
        /// The time asked.
        time: DateTime<Utc>,
        /// What is wrong.
        message: String,
    },
}

/// One of the station's lamps as the world sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct Lamp {
    /// Name in the station config.
    pub name: String,
    /// The bulb at full level.
    pub bulb: SphereLight,
    /// Output fraction = level^gamma.
    pub gamma: f64,
}

/// The smallest lamp radius rendered, metres: a "point" lamp in the config
/// (radius 0) still needs a visible bulb.
pub const MIN_BULB_RADIUS_M: f64 = 0.01;

/// The true outdoor pseudo-albedos at a surface point (thesis §5.2, §5.4):
/// one for light with the sun's spectrum, one for the sky and environment.
/// The simulator renders in the camera's three channels, so its
/// pseudo-BRDFs are its BRDFs channel by channel; its outdoor surfaces are
/// Lambertian, so both pseudo-albedos are the diffuse albedo texture there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PseudoAlbedos {
    /// ρ^sun per channel.
    pub sun: [f64; 3],
    /// ρ^se (sky and environment) per channel.
    pub sky_environment: [f64; 3],
}

/// The world a simulated station photographs.
#[derive(Debug, Clone)]
pub struct World {
    /// The scene and its true materials.
    pub scene: LoadedScene,
    /// Outdoors or indoors.
    pub setting: Setting,
    /// The site.
    pub observer: Observer,
    /// ΔT for the ephemeris, seconds.
    pub delta_t_s: Option<f64>,
    /// The clear atmosphere.
    pub atmosphere: Atmosphere,
    /// Cloud cover: fraction of sunlight blocked and the overcast zenith radiance per channel.
    pub clouds: Option<(f64, [f64; 3])>,
    /// A drifting broken-cloud layer over the clear sky (issue 29's truth);
    /// when set, it replaces [`World::clouds`] in rendering.
    pub broken_clouds: Option<broken_clouds::BrokenClouds>,
    /// The station's camera, as it truly is (the simulation's `true_camera`
    /// lens where one is given).
    pub camera: campanile_config::Camera,
    /// The head's mount, as it truly is (the `true_camera`'s where given).
    pub mount: Mount,
    /// The station's lamps.
    pub lamps: Vec<Lamp>,
    /// Samples per pixel and bounces for frames (the seed comes per frame).
    pub quality: RenderSettings,
}

impl World {
    /// The world of `scene` seen by `station`.
    pub fn new(station: &campanile_config::Station, scene: LoadedScene) -> World {
        // The camera as it truly is: the simulation's true camera where it
        // has one (a lens and mount the station's configuration does not know).
        let truly = station
            .simulation
            .as_ref()
            .and_then(|s| s.true_camera.as_ref())
            .and_then(|t| t.apply_to(station).ok());
        let station = truly.as_ref().unwrap_or(station);
        let s = &station.site;
        let lamps = station
            .lights
            .iter()
            .flat_map(|l| l.channels.iter())
            .map(|ch| {
                let (x, y, z) = ch.position_m;
                let (r, g, b) = ch.intensity.radiant_intensity_w_sr;
                Lamp {
                    name: ch.name.clone(),
                    bulb: SphereLight::with_intensity(
                        Vector3::new(x, y, z),
                        ch.radius_m.max(MIN_BULB_RADIUS_M),
                        [r, g, b],
                    ),
                    gamma: ch.intensity.gamma,
                }
            })
            .collect();
        World {
            setting: truth::setting(&scene.description.name),
            scene,
            observer: Observer::from_degrees(
                s.latitude_deg,
                s.longitude_deg,
                s.elevation_m,
                s.pressure_mbar,
                s.temperature_c,
            ),
            delta_t_s: s.delta_t_s,
            atmosphere: Atmosphere::clear(),
            clouds: None,
            broken_clouds: None,
            camera: station.camera.clone(),
            mount: rig::mount(&station.head.mount),
            lamps,
            quality: RenderSettings {
                samples_per_pixel: 16,
                max_bounces: 2,
                seed: 0,
                ..RenderSettings::default()
            },
        }
    }

    /// The true solar position at `time`.
    pub fn sun(&self, time: DateTime<Utc>) -> Result<SunPosition, WorldError> {
        sun_position(time, &self.observer, self.delta_t_s).map_err(|e| WorldError::Sun {
            time,
            message: e.to_string(),
        })
    }

    /// The true sun and sky at `time`; `None` indoors.
    pub fn daylight(&self, time: DateTime<Utc>) -> Result<Option<Daylight>, WorldError> {
        if self.setting == Setting::Indoor {
            return Ok(None);
        }
        let sun = self.sun(time)?;
        let day = Daylight::clear(sun.direction(), &self.atmosphere);
        Ok(Some(match self.clouds {
            Some((p, zenith)) => day.with_clouds(p, zenith),
            None => day,
        }))
    }

    /// The lamps' bulbs at `levels` (0–1 per lamp, in config order; missing
    /// levels are off).
    pub fn bulbs(&self, levels: &[f64]) -> Vec<SphereLight> {
        self.lamps
            .iter()
            .enumerate()
            .filter_map(|(i, lamp)| {
                let level = levels.get(i).copied().unwrap_or(0.0).clamp(0.0, 1.0);
                let k = level.powf(lamp.gamma);
                (k > 0.0).then(|| SphereLight {
                    radiance: lamp.bulb.radiance.map(|l| l * k),
                    ..lamp.bulb
                })
            })
            .collect()
    }

    /// Runs `f` with everything that lights the world at `time`: the sun and
    /// sky outdoors, the lamps at `light_levels`.
    fn lit<R>(
        &self,
        time: DateTime<Utc>,
        light_levels: &[f64],
        f: impl FnOnce(&Lighting) -> R,
    ) -> Result<R, WorldError> {
        let bulbs = self.bulbs(light_levels);
        if let Some(layer) = self.broken_clouds.as_ref().filter(|_| self.setting == Setting::Outdoor) {
            let clear = Daylight::clear(self.sun(time)?.direction(), &self.atmosphere);
            let sky = layer.sky(clear, time);
            let lighting = Lighting {
                sky: Some(&sky as &dyn render::Sky),
                points: &[],
                spheres: &bulbs,
            };
            return Ok(f(&lighting));
        }
        let daylight = self.daylight(time)?;
        let lighting = Lighting {
            sky: daylight.as_ref().map(|d| d as &dyn render::Sky),
            points: &[],
            spheres: &bulbs,
        };
        Ok(f(&lighting))
    }

    /// The camera on its head at `position_m`, rendered at `width` × `height`.
    pub fn rig(&self, head: HeadPose, position_m: [f64; 3], width: usize, height: usize) -> CameraRig {
        CameraRig {
            pinhole: rig::pinhole_at(&self.camera, width, height),
            mount: self.mount,
            head,
            position: Vector3::from(position_m),
            width,
            height,
        }
    }

    /// The true radiance the camera sees (before lens falloff, filter and sensor).
    ///
    /// Outdoors, path-traced (`quality`: samples per pixel, bounces).
    /// Indoors, as inverse global illumination's photographs are taken
    /// ([`igi_photograph`]): each pixel at its centre, the lamps' direct
    /// light exact, the interreflected light from `quality.samples_per_pixel`
    /// paths of up to `quality.max_bounces` scattering events, so that a
    /// lamp-lit room's frames carry noise only in their indirect light.
    pub fn render(
        &self,
        time: DateTime<Utc>,
        rig: &CameraRig,
        light_levels: &[f64],
        seed: u64,
    ) -> Result<RadianceImage, WorldError> {
        if self.setting == Setting::Indoor {
            let bulbs = self.bulbs(light_levels);
            let rays = rig.rays();
            let settings = igi_photograph::PhotoSettings {
                indirect_samples: self.quality.samples_per_pixel,
                max_bounces: self.quality.max_bounces,
                seed,
            };
            return Ok(igi_photograph::photograph_rays(
                &self.scene.scene,
                &[],
                &bulbs,
                (rig.width, rig.height),
                |u, v| rays.ray(u, v),
                &settings,
            ));
        }
        let settings = RenderSettings { seed, ..self.quality };
        self.lit(time, light_levels, |lighting| {
            render::render(&self.scene.scene, rig, lighting, &settings)
        })
    }

    /// The true pseudo-albedos at `point` on triangle `triangle` of the
    /// scene (see [`PseudoAlbedos`]).
    pub fn pseudo_albedos(&self, triangle: usize, point: [f64; 3]) -> PseudoAlbedos {
        let albedo = self.scene.scene.albedo_at(triangle, &Vector3::from(point));
        PseudoAlbedos {
            sun: albedo,
            sky_environment: albedo,
        }
    }

    /// The true environment seen from `position_m` at `time`: a
    /// latitude-longitude panorama `width` pixels wide (see
    /// [`render::render_latlong`]), with the world's quality settings.
    pub fn environment_map(
        &self,
        time: DateTime<Utc>,
        position_m: [f64; 3],
        light_levels: &[f64],
        width: usize,
        seed: u64,
    ) -> Result<RadianceImage, WorldError> {
        let settings = RenderSettings { seed, ..self.quality };
        self.lit(time, light_levels, |lighting| {
            render::render_latlong(
                &self.scene.scene,
                lighting,
                &Vector3::from(position_m),
                width,
                &settings,
            )
        })
    }

    /// The true radiance of one pixel `(u, v)` of `rig`'s image, averaged
    /// over `samples` paths spread over the pixel: the ground truth of a
    /// single pixel without rendering the frame.
    pub fn pixel_radiance(
        &self,
        time: DateTime<Utc>,
        rig: &CameraRig,
        (u, v): (usize, usize),
        light_levels: &[f64],
        samples: u32,
        seed: u64,
    ) -> Result<[f64; 3], WorldError> {
        use rand::{Rng, SeedableRng};
        self.lit(time, light_levels, |lighting| {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mut sum = [0.0; 3];
            let n = samples.max(1);
            for _ in 0..n {
                let (du, dv): (f64, f64) = (rng.random(), rng.random());
                if let Some(ray) = rig.ray(u as f64 + du, v as f64 + dv) {
                    let l = render::trace(&self.scene.scene, lighting, ray, self.quality.max_bounces, &mut rng);
                    (0..3).for_each(|c| sum[c] += l[c]);
                }
            }
            sum.map(|s| s / f64::from(n))
        })
    }

    /// The true irradiance (W·m⁻² per channel) at `point` on the side of
    /// `normal`, by Monte Carlo with `samples` paths.
    pub fn irradiance(
        &self,
        time: DateTime<Utc>,
        point: [f64; 3],
        normal: [f64; 3],
        light_levels: &[f64],
        samples: u32,
        seed: u64,
    ) -> Result<[f64; 3], WorldError> {
        self.lit(time, light_levels, |lighting| {
            render::irradiance(
                &self.scene.scene,
                lighting,
                &Vector3::from(point),
                &Vector3::from(normal),
                self.quality.max_bounces,
                samples,
                seed,
            )
        })
    }
}

impl FrameSource for World {
    /// The world's true radiance for the simulated camera's view. A time the
    /// ephemeris cannot handle gives a black frame and an error in the log
    /// (the camera trait has no error path for the scene itself).
    fn radiance(&self, view: &View) -> RadianceImage {
        let rig = self.rig(view.head, view.position_m, view.width, view.height);
        self.render(view.time, &rig, &view.light_levels, view.seed)
            .unwrap_or_else(|e| {
                tracing::error!(error = %e, "the simulated world cannot render this view; the frame is black");
                RadianceImage {
                    width: view.width,
                    height: view.height,
                    data: vec![0.0; view.width * view.height * 3],
                }
            })
    }
}
