//! Radiance images of the scene under new light (thesis §5.5, §5.6): at any
//! date and time with the predicted sun and sky, or under an overcast sky.
//!
//! Each pixel is traced through `k × k` sub-pixel positions. A ray that
//! meets a target cell returns `(ρ^sun E_sun + ρ^se E_se) / π`, with `E_sun`
//! from a shadow ray at the exact hit point and `E_se` (sky + one bounce)
//! gathered at the cell under the new light ([`super::cell_irradiance`]);
//! the pseudo-albedos are interpolated bilinearly between the cell centres
//! of the face (or taken per cell). A ray that meets a non-target surface
//! returns its material's albedo times its direct irradiance over π; a ray
//! that escapes returns the sky (and the solar disc). The back of a target
//! surface, which no photo saw, is shaded like the environment.
//! [`rerender_with_pixel_albedos`] takes the pseudo-albedos per pixel
//! instead where it is given them (a zoom photo's eq. 5.16 albedos,
//! [`mod@super::zoom_albedo`]); [`rerender`] is it with none.

use std::collections::HashMap;

use nalgebra::Vector3;
use rayon::prelude::*;

use super::cell_irradiance::{EnvKey, GatherSettings, TimeLight, env_key, env_sky, gather, open_sky, sun_visible};
use super::estimate::Reflectance;
use super::photo::Illumination;
use crate::camera::image::RadianceImage;
use crate::render::{CameraRig, Scene};

/// Knobs of the re-rendering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RerenderSettings {
    /// Irradiance gathering at the new time.
    pub gather: GatherSettings,
    /// Sub-pixel rays per pixel side.
    pub samples_per_side: usize,
    /// Interpolate the pseudo-albedos bilinearly between cell centres
    /// (`false`: constant per cell).
    pub bilinear: bool,
}

impl Default for RerenderSettings {
    fn default() -> Self {
        RerenderSettings {
            gather: GatherSettings::default(),
            samples_per_side: 2,
            bilinear: true,
        }
    }
}

/// The pseudo-albedos at `point` on target `triangle`, in cell `cell`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn albedos_at(
    scene: &Scene,
    refl: &Reflectance,
    rho_sun: &[[f64; 3]],
    rho_se: &[[f64; 3]],
    cell: usize,
    triangle: usize,
    point: &Vector3<f64>,
    bilinear: bool,
) -> ([f64; 3], [f64; 3]) {
    if !bilinear {
        return (rho_sun[cell], rho_se[cell]);
    }
    let g = &refl.grid;
    let face = g.cells[cell].face;
    let [s, t] = scene.triangles()[triangle].texture_coordinates(point);
    let fs = s / g.spacing_m - 0.5;
    let ft = t / g.spacing_m - 0.5;
    let (i0, j0) = (fs.floor() as i64, ft.floor() as i64);
    let (a, b) = (fs - i0 as f64, ft - j0 as f64);
    let mut sun = [0.0; 3];
    let mut se = [0.0; 3];
    let mut wsum = 0.0;
    for (di, dj, w) in [
        (0, 0, (1.0 - a) * (1.0 - b)),
        (1, 0, a * (1.0 - b)),
        (0, 1, (1.0 - a) * b),
        (1, 1, a * b),
    ] {
        if w <= 0.0 {
            continue;
        }
        if let Some(c) = g.face_cell(face, i0 + di, j0 + dj, triangle) {
            for ch in 0..3 {
                sun[ch] += w * rho_sun[c][ch];
                se[ch] += w * rho_se[c][ch];
            }
            wsum += w;
        }
    }
    if wsum <= 0.0 {
        return (rho_sun[cell], rho_se[cell]);
    }
    (sun.map(|v| v / wsum), se.map(|v| v / wsum))
}

/// Per-pixel pseudo-albedos that replace the grid's for one view: given
/// the pixel `(x, y)` and the target triangle a ray through it met, `(ρ^sun,
/// ρ^se)` per channel, or `None` to keep the grid's (see
/// [`rerender_with_pixel_albedos`]).
pub type PixelAlbedos<'a> = &'a (dyn Fn(usize, usize, usize) -> Option<([f64; 3], [f64; 3])> + Sync);

/// The scene's radiance seen by `rig` under `light`, from the recovered
/// pseudo-albedos `refl`. Also returns the light gathered on the grid.
pub fn rerender(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    light: &Illumination,
    settings: &RerenderSettings,
) -> (RadianceImage, TimeLight) {
    rerender_with_pixel_albedos(scene, refl, rig, light, settings, None)
}

/// [`rerender`], with the pseudo-albedos of the target cells a pixel sees
/// taken from `pixel_albedos` where it gives them (the high-resolution
/// pseudo-albedos of a zoom photograph from this very camera, §5.6.4,
/// [`mod@super::zoom_albedo`]); the irradiance is the grid's as in
/// [`rerender`]. With `None` it is [`rerender`].
pub fn rerender_with_pixel_albedos(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    light: &Illumination,
    settings: &RerenderSettings,
    pixel_albedos: Option<PixelAlbedos>,
) -> (RadianceImage, TimeLight) {
    let grid = &refl.grid;
    let tl = gather(scene, grid, light, &settings.gather);
    let rho_sun: Vec<[f64; 3]> = refl.cells.iter().map(|c| c.rho_sun).collect();
    let rho_se: Vec<[f64; 3]> = refl.cells.iter().map(|c| c.rho_se).collect();
    let e_se: Vec<[f64; 3]> = (0..grid.cells.len())
        .map(|c| tl.se_irradiance(c, &rho_sun, &rho_se))
        .collect();
    let sun = light.sky.sun();
    let e_sun = sun.map_or([0.0; 3], |s| s.normal_irradiance());
    let sky_of = |d: &Vector3<f64>| light.sky.radiance(d);
    let k = settings.samples_per_side.max(1);
    let (w, h) = (rig.width, rig.height);
    let base_m = settings.gather.environment_spacing_m.max(1e-3);
    let centre = if grid.cells.is_empty() {
        Vector3::zeros()
    } else {
        grid.cells.iter().map(|c| c.centre).sum::<Vector3<f64>>() / grid.cells.len() as f64
    };
    // The unoccluded sky on each side of each environment triangle the
    // image shows (App. B, the costly part), once per image rather than once
    // per row: a first pass finds them.
    let open: HashMap<(usize, bool), [f64; 3]> = {
        let mut sides: Vec<(usize, bool)> = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| {
                let mut row = Vec::new();
                for x in 0..w {
                    for a in 0..k {
                        for b in 0..k {
                            let u = x as f64 + (a as f64 + 0.5) / k as f64;
                            let v = y as f64 + (b as f64 + 0.5) / k as f64;
                            let Some(ray) = rig.ray(u, v) else { continue };
                            let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                                continue;
                            };
                            let tri = &scene.triangles()[hit.triangle];
                            let n = if tri.normal.dot(&ray.direction) < 0.0 {
                                tri.normal
                            } else {
                                -tri.normal
                            };
                            let on_target = grid
                                .visible_normal(scene, hit.triangle)
                                .filter(|vn| vn.dot(&n) > 0.0)
                                .and_then(|_| grid.nearest_cell(scene, hit.triangle, &hit.point))
                                .is_some();
                            if !on_target {
                                row.push((hit.triangle, n.dot(&tri.normal) > 0.0));
                            }
                        }
                    }
                }
                row.sort_unstable();
                row.dedup();
                row
            })
            .collect();
        sides.sort_unstable();
        sides.dedup();
        sides
            .par_iter()
            .map(|&(ti, front)| {
                let n = scene.triangles()[ti].normal * if front { 1.0 } else { -1.0 };
                ((ti, front), open_sky(light, &n, &settings.gather.sky))
            })
            .collect()
    };
    let mut data = vec![0f32; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
        let mut cache: HashMap<EnvKey, [f64; 3]> = HashMap::new();
        for x in 0..w {
            let mut sum = [0.0; 3];
            let mut count = 0.0;
            for a in 0..k {
                for b in 0..k {
                    let u = x as f64 + (a as f64 + 0.5) / k as f64;
                    let v = y as f64 + (b as f64 + 0.5) / k as f64;
                    let Some(ray) = rig.ray(u, v) else { continue };
                    count += 1.0;
                    let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                        let l = light.sky.radiance(&ray.direction);
                        let disc = sun
                            .filter(|s| s.contains(&ray.direction))
                            .map_or([0.0; 3], |s| s.radiance);
                        for ch in 0..3 {
                            sum[ch] += l[ch] + disc[ch];
                        }
                        continue;
                    };
                    let tri = &scene.triangles()[hit.triangle];
                    let n = if tri.normal.dot(&ray.direction) < 0.0 {
                        tri.normal
                    } else {
                        -tri.normal
                    };
                    let lit = sun.as_ref().is_some_and(|s| sun_visible(scene, s, &hit.point, &n));
                    let cos = sun.map_or(0.0, |s| n.dot(&s.direction).max(0.0));
                    let cell = grid
                        .visible_normal(scene, hit.triangle)
                        .filter(|vn| vn.dot(&n) > 0.0)
                        .and_then(|_| grid.nearest_cell(scene, hit.triangle, &hit.point));
                    if let Some(c) = cell {
                        let (rs, re) = pixel_albedos.and_then(|f| f(x, y, hit.triangle)).unwrap_or_else(|| {
                            albedos_at(
                                scene,
                                refl,
                                &rho_sun,
                                &rho_se,
                                c,
                                hit.triangle,
                                &hit.point,
                                settings.bilinear,
                            )
                        });
                        for ch in 0..3 {
                            let es = if lit { e_sun[ch] * cos } else { 0.0 };
                            sum[ch] += (rs[ch] * es + re[ch] * e_se[c][ch]) / std::f64::consts::PI;
                        }
                    } else {
                        // The environment, and the back of a target (seen
                        // from the side no photo saw): the scene's material.
                        let albedo = scene.albedo_at(hit.triangle, &hit.point);
                        let front = n.dot(&tri.normal) > 0.0;
                        let key = env_key(scene, hit.triangle, &hit.point, front, &centre, base_m);
                        let o = open
                            .get(&(hit.triangle, front))
                            .copied()
                            .unwrap_or_else(|| open_sky(light, &n, &settings.gather.sky));
                        let es = *cache.entry(key).or_insert_with(|| {
                            env_sky(
                                scene,
                                key,
                                base_m,
                                o,
                                &sky_of,
                                settings.gather.environment_rays_per_side,
                            )
                        });
                        for ch in 0..3 {
                            let direct = if lit { e_sun[ch] * cos } else { 0.0 };
                            sum[ch] += albedo[ch] * (direct + es[ch]) / std::f64::consts::PI;
                        }
                    }
                }
            }
            if count > 0.0 {
                for ch in 0..3 {
                    row[x * 3 + ch] = (sum[ch] / count) as f32;
                }
            }
        }
    });
    (
        RadianceImage {
            width: w,
            height: h,
            data,
        },
        tl,
    )
}

/// Pixels of `rig`'s image whose centre sees a target cell of `refl` on its visible side.
pub fn target_mask(scene: &Scene, refl: &Reflectance, rig: &CameraRig) -> Vec<bool> {
    let mut out = vec![false; rig.width * rig.height];
    for y in 0..rig.height {
        for x in 0..rig.width {
            out[y * rig.width + x] = rig.ray(x as f64 + 0.5, y as f64 + 0.5).is_some_and(|r| {
                scene.intersect(&r, f64::INFINITY).is_some_and(|h| {
                    refl.grid
                        .visible_normal(scene, h.triangle)
                        .is_some_and(|n| n.dot(&r.direction) < 0.0)
                        && refl.grid.cell_at(scene, h.triangle, &h.point).is_some()
                })
            });
        }
    }
    out
}

/// Relative RMSE of `image` against `reference` over the pixels of `mask`
/// (all channels): `√(Σ (a − b)²) / √(Σ b²)`. `None` when the mask is
/// empty, the sizes differ or the reference is black there.
pub fn relative_rmse(image: &RadianceImage, reference: &RadianceImage, mask: &[bool]) -> Option<f64> {
    if image.width != reference.width || image.height != reference.height || mask.len() != image.width * image.height {
        return None;
    }
    let (mut num, mut den) = (0.0, 0.0);
    for (i, m) in mask.iter().enumerate() {
        if !*m {
            continue;
        }
        for ch in 0..3 {
            let a = f64::from(image.data[i * 3 + ch]);
            let b = f64::from(reference.data[i * 3 + ch]);
            num += (a - b).powi(2);
            den += b * b;
        }
    }
    (den > 0.0).then(|| (num / den).sqrt())
}

/// A photo from the camera being rendered, with the light it was taken
/// under: the source of texture finer than the grid (§5.6.4).
#[derive(Clone, Copy)]
pub struct Reference<'a> {
    /// The photo.
    pub photo: &'a super::photo::Photo,
    /// The illumination at its time.
    pub light: &'a Illumination<'a>,
}

/// Largest |ln f| departure from the references' median texture factor
/// still averaged in (shadow edges and outliers beyond it are dropped).
pub const TEXTURE_FACTOR_SPREAD: f64 = 0.3;

/// The view-dependent re-rendering of §5.6.4, eq. (5.16): the grid's
/// pseudo-albedos give a low-resolution image `Ĩ` at any time; a reference
/// photo `I` from the same camera gives, per pixel, the factor
/// `f = I / Ĩ_ref` by which the true pseudo-albedo departs from the grid's
/// (`ρ = I / Ẽ`, `Ẽ = Ĩ / ρ̃`), and the new image is `Ĩ_new · f`.
/// Several references are averaged (weighted by their radiance, after
/// dropping factors more than [`TEXTURE_FACTOR_SPREAD`] in log from their
/// median, which removes shadow edges that moved); pixels that see no
/// target, or no reference from this camera, keep `Ĩ_new`. Returns the
/// image and how many references matched the camera.
pub fn rerender_with_references(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    light: &Illumination,
    references: &[Reference],
    settings: &RerenderSettings,
) -> (RadianceImage, usize) {
    let (base, _) = rerender(scene, refl, rig, light, settings);
    let same = |r: &CameraRig| {
        r.width == rig.width
            && r.height == rig.height
            && (r.position - rig.position).norm() < 1e-3
            && (r.head.pan_rad - rig.head.pan_rad).abs() < 1e-6
            && (r.head.tilt_rad - rig.head.tilt_rad).abs() < 1e-6
    };
    let refs: Vec<&Reference> = references.iter().filter(|r| same(&r.photo.rig)).collect();
    if refs.is_empty() {
        return (base, 0);
    }
    let mask = target_mask(scene, refl, rig);
    let low: Vec<RadianceImage> = refs
        .iter()
        .map(|r| rerender(scene, refl, rig, r.light, settings).0)
        .collect();
    let mut out = base.clone();
    for (i, m) in mask.iter().enumerate() {
        if !*m {
            continue;
        }
        for ch in 0..3 {
            let mut f: Vec<(f64, f64)> = refs
                .iter()
                .zip(&low)
                .filter_map(|(r, l)| {
                    let lo = f64::from(l.data[i * 3 + ch]);
                    let hi = f64::from(r.photo.image.data[i * 3 + ch]);
                    let ok = lo > 0.0 && hi.is_finite() && hi > 0.0 && r.photo.mask.as_ref().is_none_or(|m| m[i]);
                    ok.then(|| ((hi / lo).ln(), lo))
                })
                .collect();
            if f.is_empty() {
                continue;
            }
            f.sort_by(|a, b| a.0.total_cmp(&b.0));
            let med = f[f.len() / 2].0;
            let (mut s, mut w) = (0.0, 0.0);
            for (lf, lo) in f.iter().filter(|(lf, _)| (lf - med).abs() <= TEXTURE_FACTOR_SPREAD) {
                s += lf * lo;
                w += lo;
            }
            if w > 0.0 {
                out.data[i * 3 + ch] = (f64::from(base.data[i * 3 + ch]) * (s / w).exp()) as f32;
            }
        }
    }
    (out, refs.len())
}
