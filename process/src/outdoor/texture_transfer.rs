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

/// Fewest references whose factors must agree at a pixel for it to take
/// their texture, by default: with two, the median cannot tell a shadow
/// edge that moved (or a fit error of one lighting state) from texture.
/// On the simulated day with two training times the texture of two
/// references made a held-out view worse (8.3% → 10.3% per 4×4 block
/// against a noise-free reference; BENCHMARKS.md, "The held-out error,
/// term by term").
pub const MIN_REFERENCES: usize = 3;

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
/// `sources` carried onto it (see the module doc), where at least
/// `min_references` of them see the pixel's point and agree (within
/// [`TEXTURE_FACTOR_SPREAD`] of their median; [`MIN_REFERENCES`] is the
/// stage's choice). Returns the image and how many pixels took a factor.
pub fn transfer_texture(
    scene: &Scene,
    refl: &Reflectance,
    rig: &CameraRig,
    base: &RadianceImage,
    sources: &[&TextureSource],
    min_references: usize,
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
                    let (mut sum, mut wsum, mut n) = (0.0, 0.0, 0);
                    for (lf, lo) in f.iter().filter(|(lf, _)| (lf - med).abs() <= TEXTURE_FACTOR_SPREAD) {
                        sum += lf * lo;
                        wsum += lo;
                        n += 1;
                    }
                    if wsum > 0.0 && n >= min_references.max(1) {
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
    transfer_texture(scene, refl, rig, &base, &all, MIN_REFERENCES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outdoor::estimate::{CellEstimate, CellStatus};
    use crate::outdoor::grid::Grid;
    use crate::outdoor::observation::SamplingReport;
    use crate::outdoor::photo::Photo;
    use crate::outdoor::rerender::Reference;
    use crate::pose::{HeadPose, Mount, Pinhole};
    use crate::render::{Material, Triangle};
    use crate::sky::{Atmosphere, Daylight};
    use chrono::{TimeZone, Utc};
    use nalgebra::Vector3;

    /// An 8 m × 8 m wall in the plane y = 0, facing −y.
    fn wall() -> Scene {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let tris = vec![
            Triangle::new([v(-4.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(4.0, 0.0, 8.0)], 0, 0).unwrap(),
            Triangle::new([v(-4.0, 0.0, 0.0), v(4.0, 0.0, 8.0), v(-4.0, 0.0, 8.0)], 0, 0).unwrap(),
        ];
        Scene::new(tris, vec![Material::diffuse("m", [0.5; 3])], vec!["wall".into()]).unwrap()
    }

    fn rig(x: f64, pan_rad: f64) -> CameraRig {
        CameraRig {
            pinhole: Pinhole {
                focal_px: 40.0,
                principal_px: (32.0, 24.0),
                k1: 0.0,
                k2: 0.0,
                projection: crate::pose::Projection::Pinhole,
            },
            mount: Mount::default(),
            head: HeadPose { pan_rad, tilt_rad: 0.2 },
            position: Vector3::new(x, -10.0, 4.0),
            width: 64,
            height: 48,
        }
    }

    fn uniform(scene: &Scene) -> Reflectance {
        let grid = Grid::new(scene, &[0], 2.0, &[Vector3::new(0.0, -10.0, 4.0)]).unwrap();
        let cells = grid
            .cells
            .iter()
            .map(|_| CellEstimate {
                rho_sun: [0.5; 3],
                rho_se: [0.5; 3],
                sigma_sun: [0.0; 3],
                sigma_se: [0.0; 3],
                status: CellStatus::Solved,
                condition: 1.0,
                amplification: 1.0,
                observations: 2,
                rms_relative: 0.0,
            })
            .collect();
        Reflectance {
            face_ratio: vec![[1.0; 3]; grid.faces.len()],
            grid,
            cells,
            photos: Vec::new(),
            sampling: SamplingReport::default(),
            diagnostics: Vec::new(),
        }
    }

    /// Vertical stripes 1 m wide, ±20% about the grid's albedo.
    fn stripes(p: &Vector3<f64>) -> f64 {
        if (p.x.floor() as i64).rem_euclid(2) == 0 {
            1.2
        } else {
            0.8
        }
    }

    /// A reference photo from another camera (3 m to the side, turned
    /// towards the wall) under another sun carries the stripes: the new
    /// view's pixels take the factor of the point they see (exactly, away
    /// from the stripes' edges, where a reference pixel's centre may fall
    /// across the edge), and from a reference of the same camera every
    /// pixel takes it exactly.
    #[test]
    fn stripes_photographed_from_elsewhere_reach_the_new_view() {
        let scene = wall();
        let refl = uniform(&scene);
        let time = Utc.with_ymd_and_hms(2026, 8, 29, 20, 30, 0).unwrap();
        let sun = |d: Vector3<f64>| {
            let d = d.normalize();
            Daylight::clear([d.x, d.y, d.z], &Atmosphere::clear())
        };
        let (day_ref, day_new) = (sun(Vector3::new(0.5, -1.0, 1.0)), sun(Vector3::new(-0.3, -1.0, 0.6)));
        let light_ref = Illumination { time, sky: &day_ref };
        let light_new = Illumination { time, sky: &day_new };
        let settings = RerenderSettings::default();
        let textured_photo = |r: &CameraRig| {
            let (mut low, _) = rerender(&scene, &refl, r, &light_ref, &settings);
            for i in 0..r.width * r.height {
                let ray = r.ray((i % r.width) as f64 + 0.5, (i / r.width) as f64 + 0.5).unwrap();
                if let Some(hit) = scene.intersect(&ray, f64::INFINITY) {
                    (0..3).for_each(|c| low.data[i * 3 + c] *= stripes(&hit.point) as f32);
                }
            }
            Photo {
                label: "reference".into(),
                image: low,
                rig: *r,
                time,
                mask: None,
            }
        };
        let new_rig = rig(0.0, 0.0);
        let (base, _) = rerender(&scene, &refl, &new_rig, &light_new, &settings);
        for (other, exact_share) in [(rig(3.0, 0.29), 0.9), (new_rig, 1.0)] {
            let photo = textured_photo(&other);
            let refs = [Reference {
                photo: &photo,
                light: &light_ref,
            }];
            let sources = texture_sources(&scene, &refl, &refs, &settings);
            let all: Vec<&TextureSource> = sources.iter().collect();
            let (out, textured) = transfer_texture(&scene, &refl, &new_rig, &base, &all, 1);
            let (_, none) = transfer_texture(&scene, &refl, &new_rig, &base, &all, MIN_REFERENCES);
            assert_eq!(
                none, 0,
                "one reference cannot make the {MIN_REFERENCES} the stage asks for"
            );
            let (mut wall_px, mut changed, mut exact) = (0usize, 0u32, 0u32);
            for i in 0..64 * 48 {
                let ray = new_rig.ray((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5).unwrap();
                let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
                    continue;
                };
                wall_px += 1;
                let f = f64::from(out.data[i * 3 + 1]) / f64::from(base.data[i * 3 + 1]);
                if (f - 1.0).abs() > 1e-9 {
                    changed += 1;
                    if (f - stripes(&hit.point)).abs() < 1e-5 {
                        exact += 1;
                    }
                }
            }
            assert!(wall_px > 1000, "{wall_px} wall pixels");
            assert!(
                changed as usize > wall_px / 2,
                "{changed} of {wall_px} changed ({textured} textured)"
            );
            let share = f64::from(exact) / f64::from(changed);
            assert!(
                share >= exact_share,
                "{exact} of {changed} exact (want ≥ {exact_share})"
            );
            println!("{exact} of {changed} changed pixels exact ({textured} textured), {wall_px} on the wall");
        }
    }
}
