//! Photographs for inverse global illumination: radiance images whose
//! direct term is exact and whose indirect term is path-traced, so that
//! image noise lives only in the (smaller) interreflected light.
//!
//! Each pixel is sampled once, at its centre (no anti-aliasing: the
//! solver evaluates its model along the same ray). There, the light
//! arriving straight from each lamp is reflected through the true BRDF
//! (shadow-tested, no noise); the light arriving from other surfaces is
//! estimated by `indirect_samples` independent BRDF-sampled rays, each
//! continued as a path for up to `max_bounces − 1` further scattering
//! events, with next-event estimation to every lamp at each vertex and
//! Russian roulette from the second vertex on: the path loop of
//! [`campanile_process::igi::lamp_paths`], which the relighting renderer
//! shares (unbiased, and the deep bounces of a dim room then cost little).
//! A bulb (sphere light) seen
//! by the camera shows its emitted radiance; its light on surfaces is that
//! of a point at its centre with the same intensity (exact for irradiance
//! when the whole bulb is above the horizon).

use campanile_process::camera::image::RadianceImage;
use campanile_process::igi::ViewCamera;
use campanile_process::igi::lamp_paths::{PathVertex, surface_radiance};
use campanile_process::render::{PointLight, Ray, Scene, SphereLight};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Noise against time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhotoSettings {
    /// BRDF-sampled rays per pixel for the interreflected light.
    pub indirect_samples: u32,
    /// Scattering events per path, the first (direct) included.
    pub max_bounces: u32,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for PhotoSettings {
    fn default() -> Self {
        PhotoSettings {
            indirect_samples: 16,
            max_bounces: 6,
            seed: 7,
        }
    }
}

/// The radiance image `camera` sees of `scene` lit by `points` and `bulbs` (module doc).
pub fn photograph(
    scene: &Scene,
    points: &[PointLight],
    bulbs: &[SphereLight],
    camera: &ViewCamera,
    settings: &PhotoSettings,
) -> RadianceImage {
    let ray = |u: f64, v: f64| {
        Some(Ray {
            origin: camera.position,
            direction: camera.direction(u, v),
        })
    };
    photograph_rays(scene, points, bulbs, (camera.width, camera.height), ray, settings)
}

/// The radiance image of `width` × `height` pixels whose pixel `(x, y)`
/// looks along `ray(x + 0.5, y + 0.5)` (any camera: the simulated station's
/// distorted pinhole on its head, for instance); pixels without a ray are
/// black. Otherwise as [`photograph`].
pub fn photograph_rays(
    scene: &Scene,
    points: &[PointLight],
    bulbs: &[SphereLight],
    (w, h): (usize, usize),
    ray: impl Fn(f64, f64) -> Option<Ray> + Sync,
    settings: &PhotoSettings,
) -> RadianceImage {
    let mut all: Vec<PointLight> = points.to_vec();
    all.extend(bulbs.iter().map(|b| PointLight {
        position: b.center,
        intensity: b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius),
    }));
    let mut data = vec![0f32; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        rng.set_stream(y as u64);
        for x in 0..w {
            let Some(ray) = ray(x as f64 + 0.5, y as f64 + 0.5) else {
                continue;
            };
            let l = pixel(scene, &all, bulbs, &ray, settings, &mut rng);
            for c in 0..3 {
                row[x * 3 + c] = l[c] as f32;
            }
        }
    });
    RadianceImage {
        width: w,
        height: h,
        data,
    }
}

/// The radiance along one camera ray.
fn pixel(
    scene: &Scene,
    points: &[PointLight],
    bulbs: &[SphereLight],
    ray: &Ray,
    settings: &PhotoSettings,
    rng: &mut ChaCha8Rng,
) -> [f64; 3] {
    let hit = scene.intersect(ray, f64::INFINITY);
    let limit = hit.map_or(f64::INFINITY, |h| h.t);
    if let Some(b) = bulbs
        .iter()
        .filter_map(|b| b.intersect(&ray.origin, &ray.direction, 0.0, limit).map(|t| (t, b)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
    {
        return b.1.radiance;
    }
    let Some(hit) = hit else {
        return [0.0; 3];
    };
    let tri = &scene.triangles()[hit.triangle];
    let material = &scene.materials()[tri.material as usize];
    let v = PathVertex::at(material, tri, &hit.point, -ray.direction);
    let l = surface_radiance(
        scene,
        points,
        &v,
        (settings.indirect_samples, settings.max_bounces, false),
        rng,
    );
    [0, 1, 2].map(|c| material.emission[c] + l[c])
}
