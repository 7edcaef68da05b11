//! The view-dependent re-rendering of §5.6.4, eq. (5.16), carried across
//! viewpoints: the texture finer than the grid, as photographed from other
//! cameras, projected onto a new one.
//!
//! [`super::rerender::rerender_with_references`] needs a reference photo
//! from the very camera being rendered. Here each reference photo `I` (a
//! training view, under its own light) and its grid-only re-render `Ĩ_ref`
//! give, per reference pixel, the factor `f = I / Ĩ_ref` by which the true
//! pseudo-albedo departs from the grid's there. A pixel of the new camera
//! that sees the point `P` of a target surface takes `f` from every
//! reference whose camera sees `P` unoccluded (the reference's ray through
//! the pixel `P` projects to meets the same triangle within
//! [`SAME_POINT_M`] of `P`), drops factors more than
//! [`TEXTURE_FACTOR_SPREAD`] in log from their median (shadow edges that
//! moved), averages the rest weighted by `Ĩ_ref` (the photos' relative
//! noise is smaller where they are brighter), and multiplies its grid-only
//! re-render `Ĩ_new` by the result. Pixels with no reference keep `Ĩ_new`.
//! For a reference from the new camera itself the point projects back to
//! the same pixel, which is [`super::rerender::rerender_with_references`].

use rayon::prelude::*;

use super::estimate::Reflectance;
use super::photo::Illumination;
use super::rerender::{RerenderSettings, TEXTURE_FACTOR_SPREAD, rerender};
use crate::camera::image::RadianceImage;
use crate::render::{CameraRig, Scene};

/// Largest distance, metres, between the point a pixel of the new camera
/// sees and the point the reference camera's ray meets, for the reference
/// to be taken as seeing it.
pub const SAME_POINT_M: f64 = 0.05;

/// A reference photo with its grid-only re-render under its own light
/// (`Ĩ_ref` of eq. 5.16), computed once and shared by every new view.
pub struct TextureSource<'a> {
    /// The photo.
    pub photo: &'a super::photo::Photo,
    /// Its grid-only re-render under the light it was taken in.
    pub low: RadianceImage,
}

/// The texture sources of `references`: each photo's grid-only re-render under its light.
pub fn texture_sources<'a>(
    scene: &Scene,
    refl: &Reflectance,
    references: &[super::rerender::Reference<'a>],
    settings: &RerenderSettings,
) -> Vec<TextureSource<'a>> {
    references
        .iter()
        .map(|r| TextureSource {
            photo: r.photo,
            low: rerender(scene, refl, &r.photo.rig, r.light, settings).0,
        })
        .collect()
}

/// `base` (the grid-only re-render of `rig`, `Ĩ_new`) with the texture of
/// `sources` carried onto it (see the module doc). Returns the image and
/// how many pixels took a factor from at least one source.
pub fn transfer_texture(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    base: &RadianceImage,
    sources: &[&TextureSource],
) -> (RadianceImage, usize) {
    let (w, h) = (rig.width, rig.height);
    let mut out = base.clone();
    if base.width != w || base.height != h {
        return (out, 0);
    }
    let textured: usize = out
        .data
        .par_chunks_mut(w * 3)
        .enumerate()
        .map(|(y, row)| {
            let mut count = 0;
            for x in 0..w {
                let Some(ray) = rig.ray(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                    continue;
                };
                let faces = refl
                    .grid
                    .visible_normal(scene, hit.triangle)
                    .is_some_and(|n| n.dot(&ray.direction) < 0.0);
                if !faces || refl.grid.cell_at(scene, hit.triangle, &hit.point).is_none() {
                    continue;
                }
                let mut seen: Vec<(usize, &TextureSource)> = Vec::new();
                for &s in sources {
                    let r = &s.photo.rig;
                    let Some((u, v)) = r.project(&hit.point) else { continue };
                    if !(u >= 0.0 && v >= 0.0) {
                        continue;
                    }
                    let (px, py) = (u.floor() as usize, v.floor() as usize);
                    if px >= r.width || py >= r.height || s.low.width != r.width || s.low.height != r.height {
                        continue;
                    }
                    let Some(back) = r.ray(u, v) else { continue };
                    let same = scene
                        .intersect(&back, f64::INFINITY)
                        .is_some_and(|b| b.triangle == hit.triangle && (b.point - hit.point).norm() <= SAME_POINT_M);
                    let valid = s.photo.mask.as_ref().is_none_or(|m| m[py * r.width + px]);
                    if same && valid {
                        seen.push((py * r.width + px, s));
                    }
                }
                let mut any = false;
                for ch in 0..3 {
                    let mut f: Vec<(f64, f64)> = seen
                        .iter()
                        .filter_map(|(j, s)| {
                            let lo = f64::from(s.low.data[j * 3 + ch]);
                            let hi = f64::from(s.photo.image.data[j * 3 + ch]);
                            (lo > 0.0 && hi.is_finite() && hi > 0.0).then(|| ((hi / lo).ln(), lo))
                        })
                        .collect();
                    if f.is_empty() {
                        continue;
                    }
                    f.sort_by(|a, b| a.0.total_cmp(&b.0));
                    let med = f[f.len() / 2].0;
                    let (mut sum, mut wsum) = (0.0, 0.0);
                    for (lf, lo) in f.iter().filter(|(lf, _)| (lf - med).abs() <= TEXTURE_FACTOR_SPREAD) {
                        sum += lf * lo;
                        wsum += lo;
                    }
                    if wsum > 0.0 {
                        let i = x * 3 + ch;
                        row[i] = (f64::from(row[i]) * (sum / wsum).exp()) as f32;
                        any = true;
                    }
                }
                count += usize::from(any);
            }
            count
        })
        .sum();
    (out, textured)
}

/// [`rerender`] of `rig` under `light`, with the texture of `sources`
/// carried onto it: the view-dependent re-rendering of §5.6.4 from photos
/// of any viewpoint. Returns the image and the pixels textured.
pub fn rerender_with_texture(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    light: &Illumination,
    sources: &[TextureSource],
    settings: &RerenderSettings,
) -> (RadianceImage, usize) {
    let (base, _) = rerender(scene, refl, rig, light, settings);
    let all: Vec<&TextureSource> = sources.iter().collect();
    transfer_texture(scene, refl, rig, &base, &all)
}
