//! Path tracing: radiance along camera rays with direct sun (shadowed),
//! sky, point and spherical lights, emission, and a configurable number of
//! interreflections. This is the simulator's light transport and the
//! reference renderer; the solvers never call it.
//!
//! Direct light from the solar disc and from lamps is sampled explicitly
//! (next-event estimation) and only there, so BRDF-sampled rays that meet
//! the disc or a bulb add nothing: every light path is counted once. The sky
//! (without the disc) and emitting surfaces are found by BRDF-sampled rays.
//!
//! The first surface a camera ray meets (the one the pixel shows) gathers
//! the light arriving over its hemisphere through
//! [`RenderSettings::split_rays`] branches instead of one continuation
//! (path splitting; the reflection equation, thesis eq. 5.1, is the
//! BRDF-weighted integral of what arrives, estimated by their mean):
//!
//! - the branches' directions are BRDF-sampled on a randomly shifted 2-D
//!   lattice, so each is distributed as the BRDF sampler's own draw
//!   (unbiased) while together they cover the hemisphere evenly;
//! - each branch that escapes adds the sky; each that meets a surface adds
//!   that surface's emission, its direct light (sun and lamps, sampled as
//!   at any vertex) and its sky (one BRDF-sampled occlusion ray, kept if it
//!   escapes), all weighted by the branch's `f cos / pdf` over their number;
//! - the light that surface reflects from other surfaces (the third
//!   scattering event on) is carried by one path continued from one branch
//!   chosen uniformly, weighted by that branch's `f cos / pdf` (the choice
//!   probability cancels the mean's 1/K); that path's first ray adds no sky
//!   if it escapes (counted by the occlusion ray).
//!
//! On a shaded wall lit by the sky and the sunlit ground, the pixel's
//! noise is mostly which of its few continuation rays met the bright ground
//! and which the sky: the branches average it out while the camera ray and
//! its direct light are traced once. Splitting only the sky off (occlusion
//! rays for the sky, one continuation for the surfaces that adds nothing
//! when it escapes) was measured first and made that noise *worse*: the
//! continuation then scores 0 or the ground instead of the sky or the
//! ground, two values much closer together (BENCHMARKS.md, "Path splitting
//! at the first surface"). With `split_rays` 0 the path is traced as
//! before, one continuation per vertex.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::camera::CameraRig;
use super::light::{PointLight, SphereLight};
use super::mesh::Ray;
use super::scene::{Scene, SurfaceHit};
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
    /// Branches per path at the first surface a camera ray meets (see the
    /// module's doc): 0 continues the path with one ray, as a plain path
    /// tracer does. Default [`DEFAULT_SPLIT_RAYS`].
    pub split_rays: u32,
}

/// Branches per path at the camera-visible surface, by default: chosen by
/// measured time against noise on the campanile (BENCHMARKS.md, "Path
/// splitting at the first surface").
pub const DEFAULT_SPLIT_RAYS: u32 = 4;

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            samples_per_pixel: 16,
            max_bounces: 2,
            seed: 0,
            split_rays: DEFAULT_SPLIT_RAYS,
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

/// One path's estimate of the radiance arriving along `ray` (toward its
/// origin), one continuation per vertex (no splitting).
pub fn trace(scene: &Scene, lighting: &Lighting, ray: Ray, max_bounces: u32, rng: &mut impl Rng) -> [f64; 3] {
    let gather = Gathering {
        disc_seen: true,
        split_rays: 0,
    };
    path(scene, lighting, ray, 0, max_bounces, gather, rng)
}

/// How a path gathers the light of its first surface.
#[derive(Debug, Clone, Copy)]
struct Gathering {
    /// Whether a camera ray that meets the solar disc adds it (the renderer
    /// adds the disc of pixels near the sun exactly instead).
    disc_seen: bool,
    /// Branches at the path's first surface (see the module's doc); 0: one
    /// continuation.
    split_rays: u32,
}

/// What a ray meets first.
#[derive(Debug, Clone, Copy)]
enum Arrival<'a> {
    /// Nothing: the sky.
    Sky,
    /// A lamp's bulb, before any surface.
    Bulb(&'a SphereLight),
    /// A surface of the scene.
    Surface(SurfaceHit),
}

/// The nearest of the scene's surfaces and the lamps' bulbs along `ray`.
fn arrival<'a>(scene: &Scene, bulbs: &'a [SphereLight], ray: &Ray) -> Arrival<'a> {
    let surface = scene.intersect(ray, f64::INFINITY);
    let limit = surface.map_or(f64::INFINITY, |h| h.t);
    let bulb = bulbs
        .iter()
        .filter_map(|s| s.intersect(&ray.origin, &ray.direction, 0.0, limit).map(|t| (t, s)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    match (bulb, surface) {
        (Some((_, lamp)), _) => Arrival::Bulb(lamp),
        (None, Some(hit)) => Arrival::Surface(hit),
        (None, None) => Arrival::Sky,
    }
}

/// A scattering vertex: where a ray arriving along `direction` meets `hit`.
struct Vertex {
    bsdf: SurfaceBsdf,
    /// The face normal on the side the ray came from (surfaces are two-sided).
    normal: Vector3<f64>,
    /// Where rays leave from: the hit, moved off the surface.
    origin: Vector3<f64>,
    /// Toward where the light leaves: back along the arriving ray.
    wo: Vector3<f64>,
}

impl Vertex {
    fn at(scene: &Scene, hit: &SurfaceHit, direction: &Vector3<f64>) -> Vertex {
        let tri = &scene.triangles()[hit.triangle];
        let material = &scene.materials()[tri.material as usize];
        let wo = -direction;
        let normal = if tri.normal.dot(&wo) >= 0.0 {
            tri.normal
        } else {
            -tri.normal
        };
        Vertex {
            bsdf: SurfaceBsdf::at(material, tri, &hit.point, normal),
            normal,
            origin: hit.point + normal * SURFACE_OFFSET * (1.0 + hit.point.norm() * 1e-3),
            wo,
        }
    }

    /// A BRDF-sampled direction from uniform numbers `u` and its weight
    /// `f cos / pdf` per channel; `None` below the surface or with no density.
    fn scatter(&self, u: [f64; 3]) -> Option<(Vector3<f64>, [f64; 3])> {
        let sample = self.bsdf.sample(&self.wo, u)?;
        let cos = sample.direction.dot(&self.normal);
        if cos <= 0.0 || sample.pdf <= 0.0 {
            return None;
        }
        Some((sample.direction, sample.value.map(|f| f * cos / sample.pdf)))
    }
}

fn emission(scene: &Scene, hit: &SurfaceHit) -> [f64; 3] {
    let tri = &scene.triangles()[hit.triangle];
    scene.materials()[tri.material as usize].emission
}

/// The radiance along `ray` for a path that has already scattered `bounce`
/// times: the disc and the bulbs count only for camera rays (`bounce == 0`),
/// since every later vertex samples them explicitly.
fn path(
    scene: &Scene,
    lighting: &Lighting,
    ray: Ray,
    bounce: u32,
    max_bounces: u32,
    gather: Gathering,
    rng: &mut impl Rng,
) -> [f64; 3] {
    let mut radiance = [0.0; 3];
    let mut beta = [1.0; 3];
    let mut direction = ray.direction;
    let mut bounce = bounce;
    let mut split_rays = gather.split_rays;
    let mut arrived = arrival(scene, lighting.spheres, &ray);
    // The surface arrived at had its emission and direct light counted by
    // the split vertex before it, and the ray leaving it its sky.
    let (mut vertex_counted, mut sky_counted) = (false, false);
    loop {
        let hit = match arrived {
            Arrival::Bulb(lamp) => {
                if bounce == 0 {
                    add_scaled(&mut radiance, &beta, &lamp.radiance, 1.0);
                }
                break;
            }
            Arrival::Sky => {
                if let Some(sky) = lighting.sky {
                    if !sky_counted {
                        add_scaled(&mut radiance, &beta, &sky.radiance(&direction), 1.0);
                    }
                    if bounce == 0
                        && gather.disc_seen
                        && let Some(sun) = sky.sun().filter(|s| s.contains(&direction))
                    {
                        add_scaled(&mut radiance, &beta, &sun.radiance, 1.0);
                    }
                }
                break;
            }
            Arrival::Surface(hit) => hit,
        };
        if !vertex_counted {
            add_scaled(&mut radiance, &beta, &emission(scene, &hit), 1.0);
        }
        if bounce == max_bounces {
            break;
        }
        bounce += 1;
        let vertex = Vertex::at(scene, &hit, &direction);
        if !vertex_counted {
            direct(scene, lighting, &vertex, &beta, &mut radiance, rng);
        }

        if split_rays > 0 && !vertex_counted {
            // Branches over this vertex's hemisphere; the path goes on from one.
            let Some((weight, next_direction, next)) = split(
                scene,
                lighting,
                &vertex,
                bounce < max_bounces,
                split_rays,
                &beta,
                &mut radiance,
                rng,
            ) else {
                break;
            };
            split_rays = 0;
            for (b, w) in beta.iter_mut().zip(weight) {
                *b *= w;
            }
            direction = next_direction;
            arrived = Arrival::Surface(next);
            vertex_counted = true;
            sky_counted = false;
            continue;
        }

        // Continue the path.
        let Some((next_direction, weight)) = vertex.scatter([rng.random(), rng.random(), rng.random()]) else {
            break;
        };
        for (b, w) in beta.iter_mut().zip(weight) {
            *b *= w;
        }
        if beta.iter().all(|b| *b == 0.0) {
            break;
        }
        direction = next_direction;
        arrived = arrival(
            scene,
            lighting.spheres,
            &Ray {
                origin: vertex.origin,
                direction,
            },
        );
        // The sky of a vertex reached by a split branch was counted there.
        sky_counted = vertex_counted && lighting.sky.is_some();
        vertex_counted = false;
    }
    radiance
}

/// The fractional part of the golden ratio: the generator of the 2-D
/// lattice the branches are stratified on.
const GOLDEN_FRACTION: f64 = 0.618_033_988_749_894_8;

/// The `rays` branches of a split vertex (see the module's doc), adding
/// to `radiance` (through the path's throughput `beta`) everything they
/// find up to their surfaces' direct light and sky, the surfaces scattering
/// only if `can_scatter`. The `k`-th branch is BRDF-sampled from the
/// lattice point `((k + s₁)/rays, frac(k φ⁻¹ + s₂))` in the sampler's two
/// direction coordinates (s₁, s₂ uniform: each point uniform on the square),
/// the lobe choice independent. Returns the branch the path continues
/// from, chosen uniformly, as its weight `f cos / pdf`, its direction and
/// the surface it met; `None` when that branch met no surface, left the
/// hemisphere, or `!can_scatter`.
#[allow(clippy::too_many_arguments)]
fn split(
    scene: &Scene,
    lighting: &Lighting,
    vertex: &Vertex,
    can_scatter: bool,
    rays: u32,
    beta: &[f64; 3],
    radiance: &mut [f64; 3],
    rng: &mut impl Rng,
) -> Option<([f64; 3], Vector3<f64>, SurfaceHit)> {
    let (s1, s2): (f64, f64) = (rng.random(), rng.random());
    let chosen = rng.random_range(0..rays);
    let mut next = None;
    for k in 0..rays {
        let u1 = (f64::from(k) + s1) / f64::from(rays);
        let u2 = (f64::from(k) * GOLDEN_FRACTION + s2).fract();
        let Some((direction, weight)) = vertex.scatter([rng.random(), u1, u2]) else {
            continue;
        };
        let mut wb = [0.0; 3];
        for c in 0..3 {
            wb[c] = beta[c] * weight[c] / f64::from(rays);
        }
        let ray = Ray {
            origin: vertex.origin,
            direction,
        };
        match arrival(scene, lighting.spheres, &ray) {
            Arrival::Bulb(_) => {}
            Arrival::Sky => {
                if let Some(sky) = lighting.sky {
                    add_scaled(radiance, &wb, &sky.radiance(&direction), 1.0);
                }
            }
            Arrival::Surface(hit) => {
                add_scaled(radiance, &wb, &emission(scene, &hit), 1.0);
                if can_scatter {
                    let far = Vertex::at(scene, &hit, &direction);
                    direct(scene, lighting, &far, &wb, radiance, rng);
                    if let Some(sky) = lighting.sky {
                        let l = skylight(scene, lighting.spheres, sky, &far, rng);
                        add_scaled(radiance, &wb, &l, 1.0);
                    }
                    if k == chosen {
                        next = Some((weight, direction, hit));
                    }
                }
            }
        }
    }
    next
}

/// One BRDF-sampled estimate of the skylight `vertex` reflects,
/// `∫_sky f(wi, wo) L_sky(wi) cos θi dωi` over the directions that escape
/// the scene and miss every bulb (thesis eq. 5.1 restricted to the sky):
/// an occlusion test, cheaper than a nearest hit. The solar disc is not
/// part of the sky here: [`direct`] samples it.
fn skylight(scene: &Scene, bulbs: &[SphereLight], sky: &dyn Sky, vertex: &Vertex, rng: &mut impl Rng) -> [f64; 3] {
    let Some((direction, weight)) = vertex.scatter([rng.random(), rng.random(), rng.random()]) else {
        return [0.0; 3];
    };
    let ray = Ray {
        origin: vertex.origin,
        direction,
    };
    if scene.occluded(&ray, f64::INFINITY)
        || bulbs
            .iter()
            .any(|b| b.intersect(&ray.origin, &ray.direction, 0.0, f64::INFINITY).is_some())
    {
        return [0.0; 3];
    }
    let l = sky.radiance(&direction);
    [0, 1, 2].map(|c| weight[c] * l[c])
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
    // distortion (a few percent) and the stretch of the projection (a
    // fisheye's: the farthest of the disc's rim's images from its centre's).
    let axis = disc.direction;
    let helper = if axis.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let (e1, e2) = {
        let a = axis.cross(&helper).normalize();
        (a, axis.cross(&a))
    };
    let (sr, cr) = disc.angular_radius_rad.sin_cos();
    let mut rim = 0.0f64;
    for k in 0..16 {
        let (s, c) = (f64::from(k) * std::f64::consts::TAU / 16.0).sin_cos();
        let d = axis * cr + (e1 * c + e2 * s) * sr;
        match camera.project(&(camera.position + d * 1e9)) {
            Some((u, v)) => rim = rim.max((u - cu).hypot(v - cv)),
            None => rim = rim.max(2.0 * camera.pinhole.focal_px * disc.angular_radius_rad),
        }
    }
    let half = if camera.pinhole.projection.is_pinhole() {
        // The pinhole's off-axis stretch (1 / cos² θ) in closed form.
        let (pu, pv) = camera.pinhole.principal_px;
        let off_axis = ((cu - pu).hypot(cv - pv) / camera.pinhole.focal_px).atan().cos();
        1.25 * camera.pinhole.focal_px * disc.angular_radius_rad.tan() / (off_axis * off_axis)
    } else {
        1.25 * rim.max(1e-9)
    };
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
    let pixel_rad = match sun.as_ref().and_then(|d| {
        let c = camera
            .mount
            .to_camera(camera.head, [d.direction.x, d.direction.y, d.direction.z]);
        let theta = c[0].hypot(c[1]).atan2(c[2]);
        theta.is_finite().then_some(theta)
    }) {
        Some(theta) if camera.pinhole.projection.is_fisheye() => camera.pinhole.max_pixel_angle_rad(theta + 0.05),
        _ => camera.pinhole.focal_px.recip(),
    };
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
                    let gather = Gathering {
                        disc_seen: !near,
                        split_rays: settings.split_rays,
                    };
                    let l = path(scene, lighting, ray, 0, settings.max_bounces, gather, &mut rng);
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
                let gather = Gathering {
                    disc_seen: true,
                    split_rays: settings.split_rays,
                };
                let l = path(scene, lighting, ray, 0, settings.max_bounces, gather, &mut rng);
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
    let probe = Vertex {
        bsdf: SurfaceBsdf::white_probe(normal),
        normal,
        origin,
        wo: normal,
    };
    for _ in 0..n {
        let mut e = [0.0; 3];
        direct(scene, lighting, &probe, &[1.0; 3], &mut e, &mut rng);
        let d = sample_cosine(&normal, rng.random(), rng.random());
        // The probe's sky and the scene's light through one cosine ray.
        let gather = Gathering {
            disc_seen: true,
            split_rays: 0,
        };
        let l = path(
            scene,
            lighting,
            Ray { origin, direction: d },
            1,
            max_bounces,
            gather,
            &mut rng,
        );
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
/// the solar disc, the point lights and the lamps, reflected toward the
/// vertex's `wo`, weighted by the path throughput `beta`, added to `radiance`.
fn direct(
    scene: &Scene,
    lighting: &Lighting,
    vertex: &Vertex,
    beta: &[f64; 3],
    radiance: &mut [f64; 3],
    rng: &mut impl Rng,
) {
    let (origin, normal, wo, bsdf) = (vertex.origin, vertex.normal, vertex.wo, &vertex.bsdf);
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
