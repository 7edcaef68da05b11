//! Photographs for inverse global illumination: radiance images whose
//! direct term is exact and whose indirect term is path-traced, so that
//! image noise lives only in the (smaller) interreflected light.
//!
//! Each pixel is sampled once, at its centre (no anti-aliasing: the
//! solver evaluates its model along the same ray). There, the light
//! arriving straight from each lamp is reflected through the true BRDF
//! (shadow-tested, no noise); the light arriving from other surfaces is
//! estimated by `indirect_samples` BRDF-sampled rays, each continued as a
//! path for up to `max_bounces − 1` further scattering events, with next-
//! event estimation to every lamp at each vertex (as the renderer's
//! `process::render::trace` does) and Russian roulette from the second
//! vertex on (survival probability the path's largest throughput, capped
//! at 1; unbiased, and the deep bounces of a dim room then cost little).
//! A bulb (sphere light) seen
//! by the camera shows its emitted radiance; its light on surfaces is that
//! of a point at its centre with the same intensity (exact for irradiance
//! when the whole bulb is above the horizon).

use campanile_process::camera::image::RadianceImage;
use campanile_process::igi::ViewCamera;
use campanile_process::render::surface_bsdf::SurfaceBsdf;
use campanile_process::render::{PointLight, Ray, Scene, SphereLight};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
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
    let wo = -ray.direction;
    let normal = if tri.normal.dot(&wo) >= 0.0 {
        tri.normal
    } else {
        -tri.normal
    };
    let bsdf = SurfaceBsdf::at(material, tri, &hit.point, normal);
    let origin = hit.point + normal * 1e-6 * (1.0 + hit.point.norm());
    let mut l = material.emission;
    add_direct(scene, points, &bsdf, &origin, &normal, &wo, &[1.0; 3], &mut l);
    if settings.max_bounces < 2 || settings.indirect_samples == 0 {
        return l;
    }
    let n = settings.indirect_samples;
    let mut sum = [0.0; 3];
    for _ in 0..n {
        let Some(s) = bsdf.sample(&wo, [rng.random(), rng.random(), rng.random()]) else {
            continue;
        };
        let cos = s.direction.dot(&normal);
        if cos <= 0.0 || s.pdf <= 0.0 {
            continue;
        }
        let li = continue_path(
            scene,
            points,
            Ray {
                origin,
                direction: s.direction,
            },
            settings.max_bounces - 1,
            rng,
        );
        for c in 0..3 {
            sum[c] += s.value[c] * cos / s.pdf * li[c];
        }
    }
    for c in 0..3 {
        l[c] += sum[c] / f64::from(n);
    }
    l
}

/// Adds the light of every point lamp reflected by `bsdf` at `origin`
/// toward `wo` (shadow-tested), times `beta`, to `radiance`.
#[allow(clippy::too_many_arguments)]
fn add_direct(
    scene: &Scene,
    points: &[PointLight],
    bsdf: &SurfaceBsdf,
    origin: &Vector3<f64>,
    normal: &Vector3<f64>,
    wo: &Vector3<f64>,
    beta: &[f64; 3],
    radiance: &mut [f64; 3],
) {
    for light in points {
        let to = light.position - origin;
        let d2 = to.norm_squared();
        let wi = to / d2.sqrt();
        let cos = wi.dot(normal);
        if cos > 0.0
            && !scene.occluded(
                &Ray {
                    origin: *origin,
                    direction: wi,
                },
                d2.sqrt(),
            )
        {
            let f = bsdf.eval(&wi, wo);
            for c in 0..3 {
                radiance[c] += beta[c] * f[c] * light.intensity[c] * cos / d2;
            }
        }
    }
}

/// The radiance arriving along `ray` (module doc): up to `events`
/// scattering events, each with next-event estimation to every lamp, and
/// Russian roulette after the first.
fn continue_path(scene: &Scene, points: &[PointLight], ray: Ray, events: u32, rng: &mut ChaCha8Rng) -> [f64; 3] {
    let mut radiance = [0.0; 3];
    let mut beta = [1.0; 3];
    let mut ray = ray;
    for event in 0..=events {
        let Some(hit) = scene.intersect(&ray, f64::INFINITY) else {
            break;
        };
        let tri = &scene.triangles()[hit.triangle];
        let material = &scene.materials()[tri.material as usize];
        for c in 0..3 {
            radiance[c] += beta[c] * material.emission[c];
        }
        if event == events {
            break;
        }
        let wo = -ray.direction;
        let normal = if tri.normal.dot(&wo) >= 0.0 {
            tri.normal
        } else {
            -tri.normal
        };
        let bsdf = SurfaceBsdf::at(material, tri, &hit.point, normal);
        let origin = hit.point + normal * 1e-6 * (1.0 + hit.point.norm());
        add_direct(scene, points, &bsdf, &origin, &normal, &wo, &beta, &mut radiance);
        let Some(s) = bsdf.sample(&wo, [rng.random(), rng.random(), rng.random()]) else {
            break;
        };
        let cos = s.direction.dot(&normal);
        if cos <= 0.0 || s.pdf <= 0.0 {
            break;
        }
        for (b, f) in beta.iter_mut().zip(s.value) {
            *b *= f * cos / s.pdf;
        }
        if event >= 1 {
            // NaN-safe: a throughput that is not positive ends the path.
            let survive = beta.iter().copied().fold(0.0, f64::max).min(1.0);
            if survive.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || rng.random::<f64>() >= survive {
                break;
            }
            beta = beta.map(|b| b / survive);
        }
        ray = Ray {
            origin,
            direction: s.direction,
        };
    }
    radiance
}
