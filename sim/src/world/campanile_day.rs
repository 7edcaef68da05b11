//! The simulated campanile day (thesis §5.6) as the outdoor tests and
//! benchmarks use it without the capture chain: the example station and
//! scene, the plan's four training times and its held-out time, the tower's
//! views, the world's photographs of them, the true light, and the true
//! pseudo-albedo of each grid cell.
//!
//! `campanile demo` photographs the same day through the simulated station
//! (brackets, sun shots, sky scans); this module gives the solver's inputs
//! directly, so that each ingredient can be controlled (the error budget of
//! `examples/outdoor_budget.rs`).

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use campanile_process::error_figures::correlation;
use campanile_process::outdoor::{CellStatus, Grid, Illumination, Photo, Reflectance};
use campanile_process::pose::HeadPose;
use campanile_process::render::{CameraRig, Scene, Texture};
use campanile_process::sky::{Daylight, SkyFitError, SkyModel, SkySample, angle_between, direction, fit_sky};
use chrono::{DateTime, Utc};

use super::zoom_truth::cell_mean_reflectance;
use super::{World, WorldError, examples_dir, load_scene};

/// The plan's training times (`campanile plan check examples/campanile-day.ron`).
const TRAINING: [&str; 4] = [
    "2026-08-29T15:48:00Z",
    "2026-08-29T20:10:00Z",
    "2026-08-29T22:42:00Z",
    "2026-08-30T01:38:00Z",
];
/// The plan's held-out time (13:30 PDT).
const HELD_OUT: &str = "2026-08-29T20:30:00Z";

/// The plan's view poses, in the order the plan photographs them.
pub const VIEWS: [&str; 4] = ["view-se", "view-sw", "view-nw", "view-ne"];
/// The views the held-out time is compared from.
pub const HELD_OUT_VIEWS: [&str; 3] = ["view-se", "view-sw", "view-nw"];
/// The tower's surfaces, which get pseudo-albedos: the four faces, the
/// pillars and the roof.
pub const TOWER: [&str; 6] = ["south-face", "east-face", "north-face", "west-face", "pillars", "roof"];

/// The first seed of the training photographs: photo `k` (time-major, then
/// [`VIEWS`]) is rendered with seed `PHOTO_SEED + k`.
pub const PHOTO_SEED: u64 = 100;

/// Why the day could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum DayError {
    /// The world failed (configuration, geometry, sun).
    #[error(transparent)]
    World(#[from] WorldError),
    /// The scene has no pose of that name, or the head cannot reach it.
    #[error("pose {name:?}: {message}")]
    Pose {
        /// The pose's name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// The scene has no surface of that name.
    #[error("the scene has no surface {0:?}")]
    Surface(String),
    /// Outdoors was expected.
    #[error("the world at {0} has no daylight: the campanile day is outdoors")]
    NoDaylight(DateTime<Utc>),
    /// A sky could not be fitted to the sampled sky.
    #[error("sky fit at {time}, channel {channel}: {source}")]
    SkyFit {
        /// The time.
        time: DateTime<Utc>,
        /// The colour channel.
        channel: usize,
        /// Why.
        source: SkyFitError,
    },
}

fn constant_time(s: &str) -> DateTime<Utc> {
    s.parse().expect("the module's constant times are RFC 3339")
}

/// The four training times.
pub fn training_times() -> [DateTime<Utc>; 4] {
    TRAINING.map(constant_time)
}

/// The held-out time.
pub fn held_out_time() -> DateTime<Utc> {
    constant_time(HELD_OUT)
}

/// The solver's illuminations borrowing `days`.
pub fn illuminations(days: &[(DateTime<Utc>, Daylight)]) -> Vec<Illumination<'_>> {
    days.iter().map(|(t, d)| Illumination { time: *t, sky: d }).collect()
}

/// The texture kept: the correlation of the recovered ρ_se (green) with
/// the truth per cell over the cells of `surface` some photo saw (NaN with
/// fewer than two, or a constant truth).
pub fn texture_correlation(refl: &Reflectance, truth: &[[f64; 3]], surface: usize) -> f64 {
    let seen: Vec<usize> = (0..truth.len().min(refl.cells.len()))
        .filter(|&c| refl.grid.cells[c].surface == surface && refl.cells[c].status != CellStatus::Unseen)
        .collect();
    let recovered: Vec<f64> = seen.iter().map(|&c| refl.cells[c].rho_se[1]).collect();
    let true_values: Vec<f64> = seen.iter().map(|&c| truth[c][1]).collect();
    correlation(&recovered, &true_values)
}

/// `scene` with every material for which `flatten` says so (by name) given
/// its texture's mean albedo.
pub fn flattened(scene: &Scene, flatten: impl Fn(&str) -> bool) -> Scene {
    let materials = scene
        .materials()
        .iter()
        .map(|m| {
            let mut m = m.clone();
            if flatten(&m.name) {
                m.albedo = Texture::Constant(m.albedo.mean_albedo());
            }
            m
        })
        .collect();
    Scene::new(scene.triangles().to_vec(), materials, scene.surfaces().to_vec())
        .expect("the same triangles and surfaces with other albedos form a valid scene")
}

/// The sky of `day` in channel `channel` sampled as a scan sees it: 9
/// elevations from 5° by 9.5°, 24 azimuths, none within 1.1° of the sun,
/// each with a deterministic ±2% error drawn from `counter` (advanced once
/// per sample).
pub fn scanned_sky(day: &Daylight, channel: usize, counter: &mut u64) -> Vec<SkySample> {
    let sun = day.sun_direction;
    let mut samples = Vec::new();
    for i in 0..9 {
        for j in 0..24 {
            let d = direction(
                (5.0 + 9.5 * f64::from(i)).to_radians(),
                (15.0 * f64::from(j)).to_radians(),
            );
            let gamma = angle_between(d, sun);
            if gamma < 0.02 {
                continue;
            }
            *counter += 1;
            let noise = 1.0
                + 0.02
                    * ((*counter as f64 * 12.9898).sin() * 43758.5453)
                        .fract()
                        .mul_add(2.0, -1.0);
            samples.push(SkySample {
                xi: d[2].acos(),
                gamma,
                radiance: day.sky_radiance(d)[channel] * noise,
            });
        }
    }
    samples
}

/// Eq. (5.9) skies fitted per channel to [`scanned_sky`] samples of `day`
/// at `time`.
pub fn fitted_skies(day: &Daylight, time: DateTime<Utc>, counter: &mut u64) -> Result<[SkyModel; 3], DayError> {
    let zs = day.sun_direction[2].acos();
    let mut out = [None; 3];
    for (c, slot) in out.iter_mut().enumerate() {
        let fit = fit_sky(&scanned_sky(day, c, counter), zs).map_err(|source| DayError::SkyFit {
            time,
            channel: c,
            source,
        })?;
        *slot = Some(fit.model);
    }
    Ok(out.map(|m| m.expect("every channel fitted above")))
}

/// The simulated campanile day: the example station and scene.
#[derive(Debug, Clone)]
pub struct CampanileDay {
    /// The world photographed.
    pub world: World,
    /// The example station (its head reaches the poses).
    pub station: campanile_config::Station,
}

impl CampanileDay {
    /// `examples/sim-station.ron` and `examples/campanile-scene.ron`, the
    /// world's photographs at `samples_per_pixel` with `max_bounces`.
    pub fn load(samples_per_pixel: u32, max_bounces: u32) -> Result<CampanileDay, DayError> {
        let path = examples_dir().join("sim-station.ron");
        let station = campanile_config::document::load_station(&path)
            .map_err(|e| WorldError::Config {
                path: path.clone(),
                message: e.to_string(),
            })?
            .value;
        let mut world = World::new(&station, load_scene(&examples_dir().join("campanile-scene.ron"))?);
        world.quality.samples_per_pixel = samples_per_pixel;
        world.quality.max_bounces = max_bounces;
        Ok(CampanileDay { world, station })
    }

    /// The tower's surface indices ([`TOWER`]).
    pub fn targets(&self) -> Result<Vec<usize>, DayError> {
        TOWER
            .iter()
            .map(|s| {
                self.world
                    .scene
                    .scene
                    .surface_index(s)
                    .ok_or_else(|| DayError::Surface((*s).into()))
            })
            .collect()
    }

    /// The names of the materials on the tower's triangles.
    pub fn tower_materials(&self) -> Result<Vec<String>, DayError> {
        let scene = &self.world.scene.scene;
        let targets = self.targets()?;
        let mut names: Vec<String> = scene
            .triangles()
            .iter()
            .filter(|t| targets.contains(&(t.surface as usize)))
            .map(|t| scene.materials()[t.material as usize].name.clone())
            .collect();
        names.sort();
        names.dedup();
        Ok(names)
    }

    /// Gives the tower's materials their mean albedo: a world in which a
    /// cell's truth is unambiguous.
    pub fn flatten_tower(&mut self) -> Result<(), DayError> {
        let tower = self.tower_materials()?;
        self.world.scene.scene = flattened(&self.world.scene.scene, |m| tower.iter().any(|t| t == m));
        Ok(())
    }

    /// The camera at the scene's pose `name`, `width` × `height` pixels.
    pub fn view_rig(&self, name: &str, width: usize, height: usize) -> Result<CameraRig, DayError> {
        let pose = self.world.scene.description.pose(name).ok_or_else(|| DayError::Pose {
            name: name.into(),
            message: "not in the scene file".into(),
        })?;
        let (pan, tilt) = self
            .station
            .head
            .reach(pose.azimuth_deg, pose.elevation_deg)
            .ok_or_else(|| DayError::Pose {
                name: name.into(),
                message: format!(
                    "azimuth {}°, elevation {}° is outside the head's range",
                    pose.azimuth_deg, pose.elevation_deg
                ),
            })?;
        let head = HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        };
        let (x, y, z) = pose.position_m;
        Ok(self.world.rig(head, [x, y, z], width, height))
    }

    /// The world's photographs of the tower from every one of [`VIEWS`] at
    /// each of `times`, `width` × `height` pixels, seeded from [`PHOTO_SEED`].
    pub fn photographs(&self, times: &[DateTime<Utc>], width: usize, height: usize) -> Result<Vec<Photo>, DayError> {
        let mut out = Vec::new();
        for (i, &t) in times.iter().enumerate() {
            for (j, v) in VIEWS.iter().enumerate() {
                let rig = self.view_rig(v, width, height)?;
                let seed = PHOTO_SEED + (i * VIEWS.len() + j) as u64;
                out.push(Photo {
                    label: format!("{} {v}", t.format("%Y-%m-%dT%H:%M:%SZ")),
                    image: self.world.render(t, &rig, &[], seed)?,
                    rig,
                    time: t,
                    mask: None,
                });
            }
        }
        Ok(out)
    }

    /// The true sun and sky at `time`.
    pub fn daylight(&self, time: DateTime<Utc>) -> Result<Daylight, DayError> {
        self.world.daylight(time)?.ok_or(DayError::NoDaylight(time))
    }

    /// The true sun and sky at each of `times`.
    pub fn daylights(&self, times: &[DateTime<Utc>]) -> Result<Vec<(DateTime<Utc>, Daylight)>, DayError> {
        times.iter().map(|&t| Ok((t, self.daylight(t)?))).collect()
    }

    /// The true pseudo-albedo of each cell of `grid`: the world's albedo
    /// averaged over `per_side`² points of the cell (ρ_sun = ρ_se in the
    /// simulator). 64 keeps the 5 cm mortar joints from aliasing: an 8 × 8
    /// grid over a 2 m cell puts 0–25% of its points on mortar, a ±3% error
    /// in the "truth" itself.
    pub fn cell_truth(&self, grid: &Grid, per_side: usize) -> Vec<[f64; 3]> {
        cell_mean_reflectance(&self.world, grid.clone(), per_side)
            .cells
            .iter()
            .map(|c| c.rho_sun)
            .collect()
    }
}
