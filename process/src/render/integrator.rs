//! Path tracing: radiance along camera rays with direct sun (shadowed),
//! sky, point and spherical lights, emission, and a configurable number of
//! interreflections. This is the simulator's light transport and the
//! reference renderer; the solvers never call it.
//!
//! Direct light from the solar disc and from lamps is sampled explicitly
//! (next-event estimation) and only there, so BRDF-sampled rays that meet
//! the disc or a bulb add nothing: every light path is counted once. The sky
//! (without the disc) and emitting surfaces are found by BRDF-sampled rays.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::camera::CameraRig;
use super::light::{PointLight, SphereLight};
use super::mesh::Ray;
use super::scene::Scene;
use super::sky::{Sky, SolarDisc};
use super::surface_bsdf::SurfaceBsdf;
use crate::camera::image::RadianceImage;

/// Samples and path length: the speed-against-noise knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// Paths per pixel (stratified over the pixel).
    pub samples_per_pixel: u32,
    /// Scattering events per path: 1 is direct light only, 2 adds one
    /// interreflection (the default), more for reference renders.
    pub max_bounces: u32,
    /// Seed of every random choice; the same seed gives the same image on
    /// any number of threads.
    pub seed: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            samples_per_pixel: 16,
            max_bounces: 2,
            seed: 0,
        }
    }
}

/// Everything that emits light into a scene.
#[derive(Clone, Copy, Default)]
pub struct Lighting<'a> {
    /// The sky and sun, outdoors.
    pub sky: Option<&'a dyn Sky>,
    /// Point lights.
    pub points: &'a [PointLight],
    /// Spherical lamps.
    pub spheres: &'a [SphereLight],
}

impl std::fmt::Debug for Lighting<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lighting")
            .field("sky", &self.sky.map(|s| s.sun()))
            .field("points", &self.points)
            .field("spheres", &self.spheres)
            .finish()
    }
}

/// Offset of a new ray's origin off the surface it leaves, metres.
const SURFACE_OFFSET: f64 = 1e-6;

fn add_scaled(acc: &mut [f64; 3], beta: &[f64; 3], v: &[f64; 3], k: f64) {
    for c in 0..3 {
        acc[c] += beta[c] * v[c] * k;
    }
}

/// Two unit vectors completing unit `axis` to a right-handed orthonormal basis.
fn perpendicular_axes(axis: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if axis.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let a = axis.cross(&helper).normalize();
    (a, axis.cross(&a))
}

/// A direction uniformly distributed in the cone of half-angle `acos(cos_max)`
/// about unit `axis`.
fn sample_cone(axis: &Vector3<f64>, cos_max: f64, u1: f64, u2: f64) -> Vector3<f64> {
    let cos_t = 1.0 - u1 * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (a, b) = perpendicular_axes(axis);
    (a * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + axis * cos_t).normalize()
}

/// One path's estimate of the radiance arriving along `ray` (toward its origin).
pub fn trace(scene: &Scene, lighting: &Lighting, ray: Ray, max_bounces: u32, rng: &mut impl Rng) -> [f64; 3] {
    path(scene, lighting, ray, 0, max_bounces, rng)
}

/// The radiance along `ray` for a path that has already scattered `bounce`
/// times: the disc and the bulbs count only for camera rays (`bounce == 0`),
/// since every later vertex samples them explicitly.
fn path(scene: &Scene, lighting: &Lighting, ray: Ray, bounce: u32, max_bounces: u32, rng: &mut impl Rng) -> [f64; 3] {
    path_seeing_disc(scene, lighting, ray, bounce, max_bounces, true, rng)
}

/// [`path`], with the solar disc seen by a camera ray only if `disc_seen`
/// (the renderer adds the disc of pixels near the sun exactly instead).
fn path_seeing_disc(
    scene: &Scene,
    lighting: &Lighting,
    ray: Ray,
    bounce: u32,
    max_bounces: u32,
    disc_seen: bool,
    rng: &mut impl Rng,
) -> [f64; 3] {
    let mut radiance = [0.0; 3];
    let mut beta = [1.0; 3];
    let mut ray = ray;
    let mut bounce = bounce;
    loop {
        // The nearest of the scene's surfaces and the lamps' bulbs.
        let surface = scene.intersect(&ray, f64::INFINITY);
        let limit = surface.map_or(f64::INFINITY, |h| h.t);
        let bulb = lighting
            .spheres
            .iter()
            .filter_map(|s| s.intersect(&ray.origin, &ray.direction, 0.0, limit).map(|t| (t, s)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, lamp)) = bulb {
            if bounce == 0 {
                add_scaled(&mut radiance, &beta, &lamp.radiance, 1.0);
            }
            break;
        }
        let Some(hit) = surface else {
            if let Some(sky) = lighting.sky {
                add_scaled(&mut radiance, &beta, &sky.radiance(&ray.direction), 1.0);
                if bounce == 0
                    && disc_seen
                    && let Some(sun) = sky.sun().filter(|s| s.contains(&ray.direction))
                {
                    add_scaled(&mut radiance, &beta, &sun.radiance, 1.0);
                }
            }
            break;
        };
        let tri = &scene.triangles()[hit.triangle];
        let material = &scene.materials()[tri.material as usize];
        add_scaled(&mut radiance, &beta, &material.emission, 1.0);
        if bounce == max_bounces {
            break;
        }
        bounce += 1;
        let wo = -ray.direction;
        // Two-sided surfaces: shade on the side the ray came from.
        let normal = if tri.normal.dot(&wo) >= 0.0 {
            tri.normal
        } else {
            -tri.normal
        };
        let bsdf = SurfaceBsdf::at(material, tri, &hit.point, normal);
        let origin = hit.point + normal * SURFACE_OFFSET * (1.0 + hit.point.norm() * 1e-3);

        direct(scene, lighting, &bsdf, &origin, &normal, &wo, &beta, &mut radiance, rng);

        // Continue the path.
        let Some(sample) = bsdf.sample(&wo, [rng.random(), rng.random(), rng.random()]) else {
            break;
        };
        let cos = sample.direction.dot(&normal);
        if cos <= 0.0 || sample.pdf <= 0.0 {
            break;
        }
        for (b, f) in beta.iter_mut().zip(sample.value) {
            *b *= f * cos / sample.pdf;
        }
        if beta.iter().all(|b| *b == 0.0) {
            break;
        }
        ray = Ray {
            origin,
            direction: sample.direction,
        };
    }
    radiance
}

/// Samples per pixel for pixels within a few pixels of the solar disc.
pub const SUN_PIXEL_SAMPLES: u32 = 1024;

/// Points per side of the grid over the solar disc's bounding box that
/// measures how much of each pixel the (unoccluded) disc covers.
pub const SUN_COVERAGE_GRID: usize = 96;

/// The fraction of each pixel of `camera`'s image that sees the solar
/// disc, unoccluded by the scene or a lamp, keyed by `y · width + x`: a
/// `SUN_COVERAGE_GRID`² grid of image points over the disc's bounding box,
/// each cast through the camera (distortion included) and kept if its ray
/// falls on the disc and escapes the scene. The grid spacing is a small
/// fraction of the disc whatever the pixel size, so the coverage of a disc
/// much smaller than a pixel (a wide sky camera) is measured to about 0.1 %
/// instead of being sampled by the few of a pixel's paths that hit it.
fn sun_coverage(scene: &Scene, camera: &CameraRig, lighting: &Lighting, disc: &SolarDisc) -> Vec<(usize, f64)> {
    let centre = camera.position + disc.direction * 1e9;
    let Some((cu, cv)) = camera.project(&centre) else {
        return Vec::new();
    };
    // Half-width in pixels: the disc's radius with room for the lens's
    // distortion (a few percent) and the off-axis stretch of the projection.
    let (pu, pv) = camera.pinhole.principal_px;
    let off_axis = ((cu - pu).hypot(cv - pv) / camera.pinhole.focal_px).atan().cos();
    let half = 1.25 * camera.pinhole.focal_px * disc.angular_radius_rad.tan() / (off_axis * off_axis);
    let (w, h) = (camera.width as f64, camera.height as f64);
    if cu + half < 0.0 || cv + half < 0.0 || cu - half > w || cv - half > h {
        return Vec::new();
    }
    let caster = camera.rays();
    let n = SUN_COVERAGE_GRID;
    let step = 2.0 * half / n as f64;
    let cell = step * step;
    let mut cover: Vec<(usize, f64)> = Vec::new();
    for j in 0..n {
        let v = cv - half + (j as f64 + 0.5) * step;
        if !(0.0..h).contains(&v) {
            continue;
        }
        for i in 0..n {
            let u = cu - half + (i as f64 + 0.5) * step;
            if !(0.0..w).contains(&u) {
                continue;
            }
            let Some(ray) = caster.ray(u, v) else { continue };
            if !disc.contains(&ray.direction)
                || scene.intersect(&ray, f64::INFINITY).is_some()
                || lighting
                    .spheres
                    .iter()
                    .any(|s| s.intersect(&ray.origin, &ray.direction, 0.0, f64::INFINITY).is_some())
            {
                continue;
            }
            let k = v as usize * camera.width + u as usize;
            match cover.iter_mut().find(|(p, _)| *p == k) {
                Some((_, c)) => *c += cell,
                None => cover.push((k, cell)),
            }
        }
    }
    cover
}

/// Renders the radiance image a camera sees: `samples_per_pixel` stratified
/// paths per pixel, rows in parallel, each row from its own random stream;
/// pixels near the solar disc take [`SUN_PIXEL_SAMPLES`] for the sky around
/// it, and the disc itself as its measured coverage of the pixel times its
/// radiance (`sun_coverage`), not as the paths that happen to hit it.
pub fn render(scene: &Scene, camera: &CameraRig, lighting: &Lighting, settings: &RenderSettings) -> RadianceImage {
    let (w, h) = (camera.width, camera.height);
    let spp = settings.samples_per_pixel.max(1);
    let side = (f64::from(spp)).sqrt().ceil() as u32;
    let mut data = vec![0f32; w * h * 3];
    // Pixels that may see part of the solar disc are sampled densely: the
    // disc spans a few pixels, and its coverage of each one (what a sun
    // photograph integrates, §5.3.1) would otherwise carry sampling noise
    // of tens of percent.
    let caster = camera.rays();
    let sun = lighting.sky.and_then(|s| s.sun());
    let pixel_rad = camera.pinhole.focal_px.recip();
    let near_sun = |u: f64, v: f64| {
        sun.as_ref().is_some_and(|disc| {
            caster.ray(u, v).is_some_and(|r| {
                r.direction.dot(&disc.direction).clamp(-1.0, 1.0).acos() < disc.angular_radius_rad + 3.0 * pixel_rad
            })
        })
    };
    let coverage = sun
        .as_ref()
        .map_or_else(Vec::new, |d| sun_coverage(scene, camera, lighting, d));
    data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        rng.set_stream(y as u64);
        for x in 0..w {
            let mut sum = [0.0; 3];
            let near = near_sun(x as f64 + 0.5, y as f64 + 0.5);
            let (spp, side) = if near {
                (spp.max(SUN_PIXEL_SAMPLES), side.max(SUN_PIXEL_SAMPLES.isqrt()))
            } else {
                (spp, side)
            };
            for s in 0..spp {
                let (sx, sy) = (s % side, s / side % side);
                let u = x as f64 + (f64::from(sx) + rng.random::<f64>()) / f64::from(side);
                let v = y as f64 + (f64::from(sy) + rng.random::<f64>()) / f64::from(side);
                if let Some(ray) = caster.ray(u, v) {
                    // Near the sun the disc itself is added exactly below.
                    let l = path_seeing_disc(scene, lighting, ray, 0, settings.max_bounces, !near, &mut rng);
                    (0..3).for_each(|c| sum[c] += l[c]);
                }
            }
            for c in 0..3 {
                row[x * 3 + c] = (sum[c] / f64::from(spp)) as f32;
            }
            if near && let Some(disc) = &sun {
                let k = y * w + x;
                if let Some((_, f)) = coverage.iter().find(|(p, _)| *p == k) {
                    for c in 0..3 {
                        row[x * 3 + c] += (f * disc.radiance[c]) as f32;
                    }
                }
            }
        }
    });
    RadianceImage {
        width: w,
        height: h,
        data,
    }
}

/// A latitude-longitude panorama of everything seen from `position`:
/// `width` × `width / 2` pixels covering the whole sphere, the top row at
/// the zenith and the bottom row at the nadir, the left edge facing north
/// and azimuth growing eastward to the right. The ground truth of the
/// environment map (thesis §5.3.3): sky, sun disc, landscape and the scene itself.
pub fn render_latlong(
    scene: &Scene,
    lighting: &Lighting,
    position: &Vector3<f64>,
    width: usize,
    settings: &RenderSettings,
) -> RadianceImage {
    let (w, h) = (width.max(2), (width / 2).max(1));
    let spp = settings.samples_per_pixel.max(1);
    let mut data = vec![0f32; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(y, row)| {
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        rng.set_stream(y as u64);
        for x in 0..w {
            let mut sum = [0.0; 3];
            for _ in 0..spp {
                let zenith = (y as f64 + rng.random::<f64>()) / h as f64 * std::f64::consts::PI;
                let azimuth = (x as f64 + rng.random::<f64>()) / w as f64 * std::f64::consts::TAU;
                let d = crate::sky::direction(zenith, azimuth);
                let ray = Ray {
                    origin: *position,
                    direction: Vector3::new(d[0], d[1], d[2]),
                };
                let l = trace(scene, lighting, ray, settings.max_bounces, &mut rng);
                (0..3).for_each(|c| sum[c] += l[c]);
            }
            for c in 0..3 {
                row[x * 3 + c] = (sum[c] / f64::from(spp)) as f32;
            }
        }
    });
    RadianceImage {
        width: w,
        height: h,
        data,
    }
}

/// Irradiance (W·m⁻² per channel) on the side `normal` of a point, by
/// Monte Carlo: the sun, point lights and lamps sampled explicitly, and
/// cosine-distributed rays for the sky and the light reflected by the scene
/// (`max_bounces` as in [`RenderSettings`]: 1 counts direct light only).
/// Ground truth for the irradiance solvers, with the same light transport
/// as [`render`].
pub fn irradiance(
    scene: &Scene,
    lighting: &Lighting,
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    max_bounces: u32,
    samples: u32,
    seed: u64,
) -> [f64; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = normal.normalize();
    let origin = point + normal * SURFACE_OFFSET * (1.0 + point.norm() * 1e-3);
    let n = samples.max(1);
    let mut sum = [0.0; 3];
    // A white Lambertian probe: its BRDF is 1/π, so π × its NEE is the irradiance.
    let probe = SurfaceBsdf::white_probe(normal);
    for _ in 0..n {
        let mut e = [0.0; 3];
        direct(
            scene,
            lighting,
            &probe,
            &origin,
            &normal,
            &(normal),
            &[1.0; 3],
            &mut e,
            &mut rng,
        );
        let d = sample_cosine(&normal, rng.random(), rng.random());
        let l = path(scene, lighting, Ray { origin, direction: d }, 1, max_bounces, &mut rng);
        for c in 0..3 {
            sum[c] += e[c] * std::f64::consts::PI + l[c] * std::f64::consts::PI;
        }
    }
    sum.map(|s| s / f64::from(n))
}

/// A cosine-distributed direction about unit `normal`.
fn sample_cosine(normal: &Vector3<f64>, u1: f64, u2: f64) -> Vector3<f64> {
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (a, b) = perpendicular_axes(normal);
    (a * (r * phi.cos()) + b * (r * phi.sin()) + normal * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// Next-event estimation at a surface vertex: light arriving directly from
/// the solar disc, the point lights and the lamps, reflected toward `wo`,
/// weighted by the path throughput `beta`, added to `radiance`.
#[allow(clippy::too_many_arguments)]
fn direct(
    scene: &Scene,
    lighting: &Lighting,
    bsdf: &SurfaceBsdf,
    origin: &Vector3<f64>,
    normal: &Vector3<f64>,
    wo: &Vector3<f64>,
    beta: &[f64; 3],
    radiance: &mut [f64; 3],
    rng: &mut impl Rng,
) {
    let (origin, normal, wo) = (*origin, *normal, *wo);
    // The sun.
    if let Some(sun) = lighting.sky.and_then(|s| s.sun()) {
        let wi = sample_cone(&sun.direction, sun.angular_radius_rad.cos(), rng.random(), rng.random());
        let cos = wi.dot(&normal);
        if cos > 0.0 && !scene.occluded(&Ray { origin, direction: wi }, f64::INFINITY) {
            let f = bsdf.eval(&wi, &wo);
            let k = cos * sun.solid_angle();
            for c in 0..3 {
                radiance[c] += beta[c] * f[c] * sun.radiance[c] * k;
            }
        }
    }
    // Point lights.
    for light in lighting.points {
        let to = light.position - origin;
        let d2 = to.norm_squared();
        let wi = to / d2.sqrt();
        let cos = wi.dot(&normal);
        if cos > 0.0 && !scene.occluded(&Ray { origin, direction: wi }, d2.sqrt()) {
            let f = bsdf.eval(&wi, &wo);
            for c in 0..3 {
                radiance[c] += beta[c] * f[c] * light.intensity[c] * cos / d2;
            }
        }
    }
    // Spherical lamps: uniform over the cone they subtend.
    for lamp in lighting.spheres {
        let to = lamp.center - origin;
        let d2 = to.norm_squared();
        if d2 <= lamp.radius * lamp.radius {
            continue;
        }
        let d = d2.sqrt();
        let cos_max = (1.0 - lamp.radius * lamp.radius / d2).max(0.0).sqrt();
        let wi = sample_cone(&(to / d), cos_max, rng.random(), rng.random());
        let cos = wi.dot(&normal);
        if cos <= 0.0 {
            continue;
        }
        let Some(t) = lamp.intersect(&origin, &wi, 0.0, f64::INFINITY) else {
            continue;
        };
        if !scene.occluded(&Ray { origin, direction: wi }, t) {
            let f = bsdf.eval(&wi, &wo);
            let k = cos * std::f64::consts::TAU * (1.0 - cos_max);
            for c in 0..3 {
                radiance[c] += beta[c] * f[c] * lamp.radiance[c] * k;
            }
        }
    }
}
