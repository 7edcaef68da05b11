//! The room under new lights with its recovered materials (thesis §4.7.2,
//! "re-rendered under novel lighting"): at each camera ray's first surface,
//! the diffuse albedo comes from the [`AlbedoMap`] and the specular lobe
//! from the recovered material; the lamps' light there is exact
//! (shadow-tested), and the light from other surfaces is estimated by
//! `indirect_samples` stratified BRDF-sampled paths through the recovered
//! scene (constant ρd per surface), with Russian roulette
//! ([`super::lamp_paths`], the path loop the simulator's photographs use). A bulb in view shows its radiance
//! I / (π r²).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::albedo_map::{AlbedoMap, sphere_hit};
use super::camera::ViewCamera;
use super::input::IgiLight;
use super::lamp_paths::{PathVertex, surface_radiance};
use super::relit_scene::point_lights;
use crate::camera::image::RadianceImage;
use crate::render::{Material, PointLight, Ray, Scene, Texture};

/// Noise against time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelightSettings {
    /// BRDF-sampled rays per pixel for the interreflected light.
    pub indirect_samples: u32,
    /// Scattering events per path, the first included. Default 12: in a
    /// closed room of light walls the light falls by about 0.6 per bounce,
    /// so 4 events miss about 13 % of it and 12 about 0.2 %.
    pub max_bounces: u32,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for RelightSettings {
    fn default() -> Self {
        RelightSettings {
            indirect_samples: 16,
            max_bounces: 12,
            seed: 11,
        }
    }
}

/// The radiance image `camera` sees of `scene` (from
/// [`super::relit_scene::recovered_scene`]) lit by `lights`, with the
/// diffuse albedo of `albedo` where given (module doc).
pub fn relight(
    scene: &Scene,
    albedo: Option<&AlbedoMap>,
    lights: &[IgiLight],
    camera: &ViewCamera,
    settings: &RelightSettings,
) -> RadianceImage {
    let points = point_lights(lights);
    let (w, h) = (camera.width, camera.height);
    let mut data = vec![0f32; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        rng.set_stream(y as u64);
        for x in 0..w {
            let ray = Ray {
                origin: camera.position,
                direction: camera.direction(x as f64 + 0.5, y as f64 + 0.5),
            };
            let l = pixel(scene, albedo, lights, &points, &ray, settings, &mut rng);
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

fn pixel(
    scene: &Scene,
    albedo: Option<&AlbedoMap>,
    lights: &[IgiLight],
    points: &[PointLight],
    ray: &Ray,
    settings: &RelightSettings,
    rng: &mut ChaCha8Rng,
) -> [f64; 3] {
    match primary(scene, albedo, lights, ray) {
        Primary::Radiance(l) => l,
        Primary::Surface(v) => surface_radiance(
            scene,
            points,
            &v,
            (settings.indirect_samples, settings.max_bounces, true),
            rng,
        ),
    }
}

/// What a camera ray sees first: a known radiance (a bulb, or nothing),
/// or a surface whose light must be estimated.
#[derive(Debug, Clone, Copy)]
pub(super) enum Primary {
    /// A bulb's radiance I / (π r²), or black where the ray leaves the scene.
    Radiance([f64; 3]),
    /// The first surface, with the recovered material there.
    Surface(PathVertex),
}

/// The first thing `ray` meets (module doc): a bulb in view, nothing, or
/// the surface vertex with the albedo map's ρd where given.
pub(super) fn primary(scene: &Scene, albedo: Option<&AlbedoMap>, lights: &[IgiLight], ray: &Ray) -> Primary {
    let hit = scene.intersect(ray, f64::INFINITY);
    let limit = hit.map_or(f64::INFINITY, |h| h.t);
    if let Some(l) = lights
        .iter()
        .find(|l| l.radius > 0.0 && sphere_hit(&l.position, l.radius, ray, limit))
    {
        return Primary::Radiance(l.intensity.map(|i| i / (std::f64::consts::PI * l.radius * l.radius)));
    }
    let Some(hit) = hit else {
        return Primary::Radiance([0.0; 3]);
    };
    let tri = &scene.triangles()[hit.triangle];
    let base = &scene.materials()[tri.material as usize];
    let material = match albedo {
        Some(map) => Material {
            name: String::new(),
            albedo: Texture::Constant(map.albedo_at(hit.triangle, tri.material as usize, tri, &hit.point)),
            specular: base.specular,
            emission: [0.0; 3],
        },
        None => base.clone(),
    };
    Primary::Surface(PathVertex::at(&material, tri, &hit.point, -ray.direction))
}

/// Relative root-mean-square difference of `a` from `reference` over the
/// pixels where `keep` is true: √(mean (a − r)²) / mean r, over channels.
/// `None` when no pixel is kept, the sizes differ or the reference is black.
pub fn relative_rmse(a: &RadianceImage, reference: &RadianceImage, keep: impl Fn(usize) -> bool) -> Option<f64> {
    if a.data.len() != reference.data.len() {
        return None;
    }
    let (mut se, mut sum, mut n) = (0.0, 0.0, 0usize);
    for i in 0..a.data.len() / 3 {
        if !keep(i) {
            continue;
        }
        for c in 0..3 {
            let (x, r) = (f64::from(a.data[i * 3 + c]), f64::from(reference.data[i * 3 + c]));
            se += (x - r) * (x - r);
            sum += r;
            n += 1;
        }
    }
    (n > 0 && sum > 0.0).then(|| (se / n as f64).sqrt() / (sum / n as f64))
}
