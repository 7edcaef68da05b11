//! The light of a time whose sky or sun was not measured (no sky scan, no
//! filtered sun shot: hand-taken brackets): the CIE clear-sky model of
//! [`Daylight::clear`] at the sun's position, its sun-to-sky split set by
//! the photographs themselves, its scale by what was measured.
//!
//! # The split from sunlit/shadowed pairs
//!
//! On a Lambertian surface of albedo ρ, eqs. (5.11)–(5.12) with
//! `ρ^sun = ρ^se = ρ` give the radiance of a point seen sunlit and of one
//! seen in shadow:
//!
//! `π L₁ = ρ (E_se + E_sun cos θ)`, `π L₀ = ρ E_se`,
//!
//! so `L₁ / L₀ = 1 + E_sun cos θ / E_se` whatever ρ is. Let the true sky be
//! `a` times the model's and the true sun `b` times the model's (per
//! channel). The model's light, gathered on the grid as the solver gathers
//! it ([`gather`], §5.4: sky App. B, occlusion, one bounce), splits each
//! cell's `E_se` into a part lit by the sky, `S` (open sky, its share hidden
//! by the scene, and the sky light the environment reflects), and a part
//! the sun lights, `U` (sunlit ground and neighbours reflecting), and gives
//! the sun's `D = E_n cos θ` on the cell. Then `E_se = a S + b U`,
//! `E_sun cos θ = b D`, and with `x = b / a` a pair of radiances measured
//! at the same time, the sunlit one on cell 1 and the shadowed one on cell
//! 0, gives
//!
//! `R = L₁ / L₀ = (S₁ + x U₁ + x D₁) / (S₀ + x U₀)`
//!
//! `x = (R S₀ − S₁) / (D₁ + U₁ − R U₀)`.
//!
//! The pairs are, among the photographs of one time (a Lambertian
//! surface's radiance does not depend on the view, and every photograph is
//! in the same radiance gauge), every cell seen sunlit with every cell of
//! the same material seen shadowed: the same cell where a cast shadow's
//! edge crosses it (cells 0 and 1 are then one), its neighbours across the
//! edge, and the same material on a wall the sun does not reach. Each pair
//! gives one `x` per channel; the estimate is their median (robust to
//! texture: two cells' albedos differ), its standard error
//! `1.2533 · 1.4826 MAD / √K` over K pairs (the pairs share cells, so this
//! understates it somewhat). Pairs whose sun term is
//! small against the sky term (`D₁ < MIN_SUN_TO_SKY · S₁`) are left out:
//! there `x` amplifies the radiances' noise by `S / D`.
//!
//! Assumed: Lambertian surfaces (the sunlit/shadowed ratio of a specular
//! one depends on the view); the same albedo on both sides of the pair
//! (one material: its texture differences average out in the median); the geometry and the sun's position known (the shadow's
//! edge lies where the scene says); the model's sky *shape* (CIE type 12)
//! and its sky-to-environment proportions (the scene's non-target albedos).
//! The shadowed side of an edge sees a little less sky than the cell's
//! centre, where `S` is gathered (it is nearer the occluder): `x` then comes
//! out slightly high.
//!
//! # The scale
//!
//! The pair ratio fixes `b / a`, not `a`. What fixes the scale, in order:
//! - a fitted sky (the sky scan): `a = 1` against it, the sun `x` times the
//!   model's normal irradiance scaled to the fitted sky;
//! - a measured sun: `b = 1` against it, the sky the model's over `x`;
//! - sky pixels in the views (rays that leave the scene above
//!   [`SKY_PIXEL_MIN_ELEVATION_DEG`], away from the sun): `a` is the median
//!   of measured over modelled radiance per channel, in the camera's own
//!   units like everything the solver divides; its uncertainty the spread
//!   of that ratio (how far the sky's shape departs from the model's);
//! - the model alone: its global horizontal irradiance `a E_h + b E_n cos θs`
//!   is kept and split by `x`. That is W·m⁻²; the photographs are in the
//!   camera's gauge, which is W·m⁻²·sr⁻¹ only for a camera whose radiometric
//!   constant is 1 there (the simulated station's). Its uncertainty is
//!   [`MODEL_GLOBAL_UNCERTAINTY`].
//!
//! With no usable pair the model's split is kept (`x = 1`) and the notes
//! say so.

use chrono::{DateTime, Utc};
use nalgebra::Vector3;

use super::MeasuredSky;
use crate::irradiance::{SkySubdivision, sky_irradiance};
use crate::outdoor::cell_irradiance::{GatherSettings, TimeLight, gather};
use crate::outdoor::grid::Grid;
use crate::outdoor::observation::{Footprint, Observation, observe};
use crate::outdoor::{Illumination, OutdoorError, Photo};
use crate::render::{Scene, Sky};
use crate::sky::{Atmosphere, Daylight, SkyModel, angle_between};

/// Relative standard uncertainty of the clear-sky model's global horizontal
/// irradiance on a clear day: the aerosol load of clear skies (Linke
/// turbidity 2 to 6) moves it by about ±15% at mid elevations of the sun,
/// and the model has one turbidity.
pub const MODEL_GLOBAL_UNCERTAINTY: f64 = 0.15;

/// Pairs whose sun term is less than this fraction of the sky term are
/// left out (their `x` amplifies the radiances' noise by more than 5).
pub const MIN_SUN_TO_SKY: f64 = 0.2;

/// The sun's stated relative uncertainty when no pair measured the split:
/// the model's sun/sky ratio is then unverified, and a turbid sky under the
/// clear model puts the sun 2× off (`process/tests/estimated_light.rs`:
/// +105 % at one time). Above the `outdoor.estimated_light` gate's failed
/// bound (0.5): such pseudo-albedos are `failed`.
pub const MODEL_SPLIT_UNCERTAINTY: f64 = 1.0;

/// The least relative uncertainty stated for a measured split. Measured
/// against the truth: 0.994 and 1.039 for 1 on the simulated campanile, but
/// 0.683, 0.879 and 0.407 for 0.68 on the small site of
/// `process/tests/estimated_light.rs` (a street 4 m wide: pairs whose
/// `D₁ + U₁ − R U₀` is mostly the sunlit neighbour's light amplify every
/// error of the model's environment light; keeping only pairs dominated by
/// the direct sun fixed the site and broke the campanile, 0.90 and 0.55);
/// the pairs' own standard error was 0.1–2 %. The floor keeps the verdict
/// `poor` at best; the split is not yet trustworthy near other buildings.
pub const SPLIT_FLOOR: f64 = 0.15;

/// Fewer pairs than this: the model's split is kept.
pub const MIN_PAIRS: usize = 5;

/// Sky pixels are taken this far above the horizon only (the model's
/// gradation is least sure near it, and distant landscape is not in the scene).
pub const SKY_PIXEL_MIN_ELEVATION_DEG: f64 = 5.0;

/// Sky pixels are taken this far from the sun only (the aureole and flare).
pub const SKY_PIXEL_SUN_MARGIN_DEG: f64 = 10.0;

/// Fewer sky pixels than this: the views do not fix the scale.
pub const MIN_SKY_PIXELS: usize = 50;

/// Knobs of the estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateSettings {
    /// The clear-sky model.
    pub atmosphere: Atmosphere,
    /// Grid spacing, metres (the pseudo-albedo grid's).
    pub spacing_m: f64,
    /// Gathering of the model's light on the grid.
    pub gather: GatherSettings,
    /// Where a pixel's footprint must lie.
    pub footprint: Footprint,
}

impl Default for EstimateSettings {
    fn default() -> Self {
        EstimateSettings {
            atmosphere: Atmosphere::clear(),
            spacing_m: 2.0,
            gather: GatherSettings::default(),
            footprint: Footprint::Face,
        }
    }
}

/// What was measured of the light at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnownLight {
    /// Unit vector toward the sun.
    pub sun_direction: [f64; 3],
    /// The fitted sky per channel, if a sky scan was fitted.
    pub sky: Option<[SkyModel; 3]>,
    /// The sun's normal irradiance per channel, if it was measured.
    pub sun_irradiance: Option<[f64; 3]>,
}

/// The sun-to-sky ratio the photographs gave.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitEstimate {
    /// `x = b / a` per channel: how much brighter the sun is against the
    /// sky than the model (or fitted sky and model sun) says.
    pub x: [f64; 3],
    /// Standard error of `x` per channel.
    pub sigma: [f64; 3],
    /// Pairs used (sunlit × shadowed observations of one material).
    pub pairs: usize,
    /// Of those, pairs within one cell of one photograph (a shadow edge crossing it).
    pub same_cell_pairs: usize,
}

/// Where the scale of the light came from.
#[derive(Debug, Clone, PartialEq)]
pub enum ScaleSource {
    /// The fitted sky.
    FittedSky,
    /// The measured sun.
    MeasuredSun,
    /// Sky pixels in the views: how many, and the robust relative spread
    /// of their measured-to-model ratio (green).
    SkyPixels {
        /// Pixels used.
        pixels: usize,
        /// 1.4826 MAD / median of the ratio, green channel.
        spread: f64,
    },
    /// The model's global horizontal irradiance.
    Model,
}

/// The light of one time, estimated.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimatedLight {
    /// The light to divide by.
    pub sky: MeasuredSky,
    /// The CIE standard sky type of the model.
    pub sky_type: u8,
    /// The sky radiance relative to the base sky, per channel (`a`): the
    /// fitted sky when there is one (then 1), else the model's.
    pub sky_scale: [f64; 3],
    /// The sun's normal irradiance relative to the model's, per channel (`b`).
    pub sun_scale: [f64; 3],
    /// The split from the photographs, if they gave one.
    pub split: Option<SplitEstimate>,
    /// Where the scale came from.
    pub scale: ScaleSource,
    /// Relative standard uncertainty of the estimated sky (green; 0 when fitted).
    pub sky_uncertainty: f64,
    /// Relative standard uncertainty of the estimated sun (green; 0 when measured).
    pub sun_uncertainty: f64,
    /// What was estimated and how, in words.
    pub notes: Vec<String>,
}

impl EstimatedLight {
    /// The larger relative uncertainty of the two (green).
    pub fn scale_uncertainty(&self) -> f64 {
        self.sky_uncertainty.max(self.sun_uncertainty)
    }

    /// One line for a verdict's notes.
    pub fn describe(&self) -> String {
        let split = match &self.split {
            Some(s) => format!(
                "sun/sky ratio from {} sunlit/shadowed pairs ({} within a cell): {:.3} ± {:.3} of the model's (green)",
                s.pairs, s.same_cell_pairs, s.x[1], s.sigma[1]
            ),
            None => "sun/sky ratio the model's (no usable sunlit/shadowed pair)".to_owned(),
        };
        let scale = match &self.scale {
            ScaleSource::FittedSky => "scale from the fitted sky".to_owned(),
            ScaleSource::MeasuredSun => "scale from the measured sun".to_owned(),
            ScaleSource::SkyPixels { pixels, spread } => format!(
                "scale from {pixels} sky pixels in the views (spread {:.1}% against the model's shape)",
                100.0 * spread
            ),
            ScaleSource::Model => format!(
                "scale the model's global horizontal irradiance (±{:.0}%; W·m⁻², right only for a camera whose gauge is W·m⁻²·sr⁻¹)",
                100.0 * MODEL_GLOBAL_UNCERTAINTY
            ),
        };
        format!(
            "sky from the CIE clear-sky model (type {}), {split}; {scale}; uncertainty of the sky ±{:.1}%, of the sun ±{:.1}%; not measured",
            self.sky_type,
            100.0 * self.sky_uncertainty,
            100.0 * self.sun_uncertainty
        )
    }
}

/// The median of `v` (sorted in place); `None` when empty.
pub(crate) fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// Median and the standard error of the median (1.2533 · 1.4826 MAD / √n).
fn robust_mean(v: &mut [f64]) -> Option<(f64, f64)> {
    let m = median(v)?;
    let mut dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    let mad = median(&mut dev)?;
    Some((m, 1.2533 * 1.4826 * mad / (v.len() as f64).sqrt()))
}

fn scaled(models: &[SkyModel; 3], k: [f64; 3]) -> [SkyModel; 3] {
    [0, 1, 2].map(|c| SkyModel {
        lz: models[c].lz * k[c],
        ..models[c]
    })
}

/// The horizontal irradiance of an unoccluded sky per channel (App. B).
fn horizontal(models: &[SkyModel; 3], sun: [f64; 3]) -> [f64; 3] {
    let sky = MeasuredSky {
        sun_direction: sun,
        models: *models,
        sun_irradiance: [0.0; 3],
        overcast: None,
    };
    let f = |d: [f64; 3]| sky.radiance(&Vector3::new(d[0], d[1], d[2]));
    let sub = SkySubdivision {
        tolerance: 1e-3,
        min_depth: 3,
        max_depth: 10,
    };
    sky_irradiance(&Vector3::zeros(), &Vector3::z(), &f, None, &sub).map_or([0.0; 3], |s| s.rgb)
}

/// Sky pixels of the views against the model's sky: (per-channel median
/// ratio, pixels, relative spread of the green ratio).
fn sky_pixel_scale(scene: &Scene, photos: &[Photo], model: &MeasuredSky) -> Option<([f64; 3], usize, f64)> {
    let min_z = SKY_PIXEL_MIN_ELEVATION_DEG.to_radians().sin();
    let margin = SKY_PIXEL_SUN_MARGIN_DEG.to_radians();
    let mut ratios: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    for p in photos {
        let (w, h) = (p.image.width, p.image.height);
        for y in 0..h {
            for x in 0..w {
                if p.mask
                    .as_ref()
                    .is_some_and(|m| !m.get(y * w + x).copied().unwrap_or(false))
                {
                    continue;
                }
                let Some(ray) = p.rig.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                let d = ray.direction;
                if d.z < min_z || angle_between([d.x, d.y, d.z], model.sun_direction) < margin {
                    continue;
                }
                if scene.intersect(&ray, f64::INFINITY).is_some() {
                    continue;
                }
                let l = model.radiance(&d);
                let m = [0, 1, 2].map(|c| f64::from(p.image.radiance(x, y, c)));
                if (0..3).all(|c| l[c] > 0.0 && m[c].is_finite() && m[c] > 0.0) {
                    for c in 0..3 {
                        ratios[c].push(m[c] / l[c]);
                    }
                }
            }
        }
    }
    let n = ratios[1].len();
    if n < MIN_SKY_PIXELS {
        return None;
    }
    let mut k = [0.0; 3];
    for c in 0..3 {
        k[c] = median(&mut ratios[c])?;
    }
    let mut dev: Vec<f64> = ratios[1].iter().map(|r| (r - k[1]).abs()).collect();
    let spread = 1.4826 * median(&mut dev)? / k[1].max(1e-300);
    Some((k, n, spread))
}

/// Per cell: the sky-lit part S and sun-lit part U of E_se, and the sun's D.
struct Parts {
    s: Vec<[f64; 3]>,
    u: Vec<[f64; 3]>,
    d: Vec<[f64; 3]>,
}

fn parts(
    scene: &Scene,
    grid: &Grid,
    sky_only: &MeasuredSky,
    sun_only: &MeasuredSky,
    time: DateTime<Utc>,
    g: &GatherSettings,
) -> Parts {
    let lit = |sky: &MeasuredSky| -> TimeLight { gather(scene, grid, &Illumination { time, sky }, g) };
    let (a, b) = (lit(sky_only), lit(sun_only));
    let n = grid.cells.len();
    // Target-to-target bounce: with a typical albedo of 0.3 (a small part).
    let rho = vec![[0.3; 3]; n];
    Parts {
        s: (0..n).map(|c| a.se_irradiance(c, &rho, &rho)).collect(),
        u: (0..n).map(|c| b.se_irradiance(c, &rho, &rho)).collect(),
        d: (0..n).map(|c| b.sun_irradiance(c)).collect(),
    }
}

/// The pairs' `x` per channel: every sunlit observation with every
/// shadowed one of the same material (all the photographs are of one time).
fn split_from_pairs(scene: &Scene, grid: &Grid, obs: &[Observation], parts: &Parts) -> Option<SplitEstimate> {
    let material = |cell: usize| scene.triangles()[grid.cells[cell].triangle].material;
    let mut xs: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut same = 0;
    let of = |sunlit: bool| obs.iter().filter(move |o| o.sunlit == sunlit);
    for lit in of(true) {
        let (c1, m1) = (lit.cell, material(lit.cell));
        let (s1, u1, d1) = (parts.s[c1], parts.u[c1], parts.d[c1]);
        if d1[1] < MIN_SUN_TO_SKY * s1[1] {
            continue;
        }
        for shade in of(false).filter(|o| material(o.cell) == m1) {
            let (s0, u0) = (parts.s[shade.cell], parts.u[shade.cell]);
            let x = [0, 1, 2].map(|c| {
                let r = lit.radiance[c] / shade.radiance[c];
                (r * s0[c] - s1[c]) / (d1[c] + u1[c] - r * u0[c])
            });
            if x.iter().all(|v| v.is_finite() && *v > 0.0) {
                for c in 0..3 {
                    xs[c].push(x[c]);
                }
                same += usize::from(shade.cell == c1 && shade.photo == lit.photo);
            }
        }
    }
    let pairs = xs[1].len();
    if pairs < MIN_PAIRS {
        return None;
    }
    let mut x = [0.0; 3];
    let mut sigma = [0.0; 3];
    for c in 0..3 {
        (x[c], sigma[c]) = robust_mean(&mut xs[c])?;
    }
    Some(SplitEstimate {
        x,
        sigma,
        pairs,
        same_cell_pairs: same,
    })
}

/// The light at `time`, from what is `known` of it, the clear-sky model and
/// the `photos` taken then of the `targets` surfaces of `scene` (module
/// documentation). With both sky and sun known it is those, unchanged.
pub fn estimated_light(
    scene: &Scene,
    targets: &[usize],
    photos: &[Photo],
    known: &KnownLight,
    time: DateTime<Utc>,
    settings: &EstimateSettings,
) -> Result<EstimatedLight, OutdoorError> {
    let sun_dir = known.sun_direction;
    let day = Daylight::clear(sun_dir, &settings.atmosphere);
    let sky_type = settings.atmosphere.sky_type.number();
    let model_sun = day.sun_irradiance();
    let base_sky = known.sky.unwrap_or(day.sky);
    let base_sun = known.sun_irradiance.unwrap_or(model_sun);
    let mut notes = Vec::new();
    let light = |a: [f64; 3], b: [f64; 3]| MeasuredSky {
        sun_direction: sun_dir,
        models: scaled(&base_sky, a),
        sun_irradiance: [0, 1, 2].map(|c| base_sun[c] * b[c]),
        overcast: None,
    };
    if known.sky.is_some() && known.sun_irradiance.is_some() {
        return Ok(EstimatedLight {
            sky: light([1.0; 3], [1.0; 3]),
            sky_type,
            sky_scale: [1.0; 3],
            sun_scale: [1.0; 3],
            split: None,
            scale: ScaleSource::FittedSky,
            sky_uncertainty: 0.0,
            sun_uncertainty: 0.0,
            notes,
        });
    }
    // 1. The split: observations (they depend only on the sun's direction)
    //    and the model's light gathered in parts.
    let split = if photos.is_empty() || sun_dir[2] <= 0.0 {
        None
    } else {
        let viewpoints: Vec<_> = photos.iter().map(|p| p.rig.position).collect();
        let grid = Grid::new(scene, targets, settings.spacing_m, &viewpoints)?;
        let full = light([1.0; 3], [1.0; 3]);
        let lights = [Illumination { time, sky: &full }];
        let (obs, _) = observe(
            scene,
            &grid,
            photos,
            &lights,
            &vec![0; photos.len()],
            settings.footprint,
        )?;
        let sky_only = MeasuredSky {
            sun_irradiance: [0.0; 3],
            ..full.clone()
        };
        let sun_only = MeasuredSky {
            models: scaled(&base_sky, [0.0; 3]),
            ..full.clone()
        };
        let p = parts(scene, &grid, &sky_only, &sun_only, time, &settings.gather);
        split_from_pairs(scene, &grid, &obs, &p)
    };
    let (x, sx) = match &split {
        Some(s) => (s.x, s.sigma),
        None => {
            notes.push(
                "no usable sunlit/shadowed pair in the photographs: the model's sun/sky split is kept".to_owned(),
            );
            ([1.0; 3], [0.0; 3])
        }
    };
    // The pairs' standard error understates it (they share cells, and the
    // model's environment light enters every pair alike): the split is
    // stated to no better than SPLIT_FLOOR.
    let rel_x = if split.is_some() {
        (sx[1] / x[1].max(1e-300)).max(SPLIT_FLOOR)
    } else {
        0.0
    };
    // 2. The scale.
    let (a, b, scale, sky_u, sun_u) = if known.sky.is_some() {
        // a = 1 against the fitted sky; the sun the model's times x.
        let u = if split.is_some() {
            rel_x
        } else {
            MODEL_SPLIT_UNCERTAINTY
        };
        ([1.0; 3], x, ScaleSource::FittedSky, 0.0, u)
    } else if known.sun_irradiance.is_some() {
        let u = if split.is_some() {
            rel_x
        } else {
            MODEL_GLOBAL_UNCERTAINTY
        };
        (x.map(|v| 1.0 / v), [1.0; 3], ScaleSource::MeasuredSun, u, 0.0)
    } else if let Some((k, pixels, spread)) = sky_pixel_scale(scene, photos, &light([1.0; 3], [1.0; 3])) {
        let b = [0, 1, 2].map(|c| k[c] * x[c]);
        let sun_u = if split.is_some() {
            (spread * spread + rel_x * rel_x).sqrt()
        } else {
            MODEL_SPLIT_UNCERTAINTY
        };
        (k, b, ScaleSource::SkyPixels { pixels, spread }, spread, sun_u)
    } else {
        // Keep the model's global horizontal irradiance: a (E_h + x E_n cos θs) = E_h + E_n cos θs.
        let eh = horizontal(&base_sky, sun_dir);
        let cos = sun_dir[2].max(0.0);
        let a = [0, 1, 2].map(|c| {
            let want = eh[c] + model_sun[c] * cos;
            let got = eh[c] + x[c] * model_sun[c] * cos;
            if got > 0.0 { want / got } else { 1.0 }
        });
        let b = [0, 1, 2].map(|c| a[c] * x[c]);
        let u = (MODEL_GLOBAL_UNCERTAINTY.powi(2) + rel_x * rel_x).sqrt();
        let sun_u = if split.is_some() { u } else { MODEL_SPLIT_UNCERTAINTY };
        (a, b, ScaleSource::Model, u, sun_u)
    };
    Ok(EstimatedLight {
        sky: light(a, b),
        sky_type,
        sky_scale: a,
        sun_scale: [0, 1, 2].map(|c| b[c] * base_sun[c] / model_sun[c].max(1e-300)),
        split,
        scale,
        sky_uncertainty: sky_u,
        sun_uncertainty: sun_u,
        notes,
    })
}

/// The light at a time no photograph was lit by measurement (a held-out
/// time of a session whose light was estimated): the model at `sun`,
/// scaled by the mean sky and sun scales of the `estimates`.
pub fn predicted_estimated_light(estimates: &[&EstimatedLight], sun: [f64; 3], atmosphere: &Atmosphere) -> MeasuredSky {
    let day = Daylight::clear(sun, atmosphere);
    let n = estimates.len().max(1) as f64;
    let mean = |f: &dyn Fn(&EstimatedLight) -> [f64; 3]| {
        if estimates.is_empty() {
            return [1.0; 3];
        }
        [0, 1, 2].map(|c| estimates.iter().map(|e| f(e)[c]).sum::<f64>() / n)
    };
    let (a, b) = (mean(&|e| e.sky_scale), mean(&|e| e.sun_scale));
    let e = day.sun_irradiance();
    MeasuredSky {
        sun_direction: sun,
        models: scaled(&day.sky, a),
        sun_irradiance: [0, 1, 2].map(|c| e[c] * b[c]),
        overcast: None,
    }
}
