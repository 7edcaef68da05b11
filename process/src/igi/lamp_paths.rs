//! Light paths in a room lit by point lamps, shared by the relighting
//! renderer ([`super::relight`]), the albedo maps' indirect irradiance
//! ([`super::albedo_map`]) and the simulator's photographs (one path loop,
//! not one per caller).
//!
//! At a surface point seen by the camera, the lamps' light is exact
//! (shadow-tested) and the light from other surfaces is estimated by
//! `samples` BRDF-sampled rays whose two direction numbers are, for the
//! renders, stratified ([`super::stratified`]: a jittered grid for a
//! square count, a Latin hypercube otherwise), so that the estimate of the
//! smooth interreflected light converges faster than with independent rays
//! at the same cost (the simulator's photographs keep independent rays).
//! Each ray is continued as a path with next-event estimation to every
//! lamp at each vertex and Russian roulette from its second vertex on
//! (survival probability the path's largest throughput, capped at 1):
//! unbiased, and the deep bounces of a dim room cost little.

use nalgebra::Vector3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::stratified::Strata;
use crate::render::surface_bsdf::SurfaceBsdf;
use crate::render::{Material, PointLight, Ray, Scene, Triangle};

/// A surface point as a path sees it: its BRDF, the offset origin of
/// rays leaving it, and the normal of the side the light leaves from.
#[derive(Debug, Clone, Copy)]
pub struct PathVertex {
    /// The reflectance there.
    pub bsdf: SurfaceBsdf,
    /// The point, moved off the surface along `normal`.
    pub origin: Vector3<f64>,
    /// Unit normal on the side of `wo`.
    pub normal: Vector3<f64>,
    /// Unit direction toward the viewer (or the previous vertex).
    pub wo: Vector3<f64>,
}

impl PathVertex {
    /// The vertex at `point` on triangle `tri` with `material`, seen from
    /// direction `wo` (unit, away from the surface).
    pub fn at(material: &Material, tri: &Triangle, point: &Vector3<f64>, wo: Vector3<f64>) -> PathVertex {
        let normal = if tri.normal.dot(&wo) >= 0.0 {
            tri.normal
        } else {
            -tri.normal
        };
        PathVertex {
            bsdf: SurfaceBsdf::at(material, tri, point, normal),
            origin: point + normal * 1e-6 * (1.0 + point.norm()),
            normal,
            wo,
        }
    }
}

/// The light of every point lamp reflected at `v` toward its viewer
/// (shadow-tested, exact), times `beta`, added to `radiance`.
pub fn add_direct(scene: &Scene, points: &[PointLight], v: &PathVertex, beta: &[f64; 3], radiance: &mut [f64; 3]) {
    for light in points {
        let to = light.position - v.origin;
        let d2 = to.norm_squared();
        let wi = to / d2.sqrt();
        let cos = wi.dot(&v.normal);
        if cos > 0.0
            && !scene.occluded(
                &Ray {
                    origin: v.origin,
                    direction: wi,
                },
                d2.sqrt(),
            )
        {
            let f = v.bsdf.eval(&wi, &v.wo);
            for c in 0..3 {
                radiance[c] += beta[c] * f[c] * light.intensity[c] * cos / d2;
            }
        }
    }
}

/// The radiance leaving `v` toward its viewer: the lamps' light (exact)
/// plus the interreflected light estimated by `samples` BRDF-sampled
/// paths of up to `max_bounces − 1` further scattering events (module
/// doc), their first directions stratified if `stratified`, otherwise
/// independent (the simulator's photographs, whose noise realisation the
/// solver's tests were measured with). `max_bounces < 2` or
/// `samples == 0`: direct only.
pub fn surface_radiance(
    scene: &Scene,
    points: &[PointLight],
    v: &PathVertex,
    paths: (u32, u32, bool),
    rng: &mut ChaCha8Rng,
) -> [f64; 3] {
    let mut l = [0.0; 3];
    add_direct(scene, points, v, &[1.0; 3], &mut l);
    let scattered = scattered_radiance(scene, points, v, paths, rng);
    for c in 0..3 {
        l[c] += scattered[c];
    }
    l
}

/// The interreflected part of [`surface_radiance`]: the light leaving `v`
/// toward its viewer after at least one other surface, estimated by
/// `samples` BRDF-sampled paths of up to `max_bounces − 1` further
/// scattering events, their first directions stratified if `stratified`.
/// Zero when `max_bounces < 2` or `samples == 0`.
pub fn scattered_radiance(
    scene: &Scene,
    points: &[PointLight],
    v: &PathVertex,
    (samples, max_bounces, stratified): (u32, u32, bool),
    rng: &mut ChaCha8Rng,
) -> [f64; 3] {
    if max_bounces < 2 || samples == 0 {
        return [0.0; 3];
    }
    let strata = stratified.then(|| Strata::new(samples, rng));
    let mut sum = [0.0; 3];
    for k in 0..samples {
        let u = match &strata {
            Some(strata) => {
                let [u1, u2] = strata.point(k, rng);
                [rng.random(), u1, u2]
            }
            None => [rng.random(), rng.random(), rng.random()],
        };
        let Some(s) = v.bsdf.sample(&v.wo, u) else {
            continue;
        };
        let cos = s.direction.dot(&v.normal);
        if cos <= 0.0 || s.pdf <= 0.0 {
            continue;
        }
        let li = path_radiance(
            scene,
            points,
            Ray {
                origin: v.origin,
                direction: s.direction,
            },
            max_bounces - 1,
            rng,
        );
        for c in 0..3 {
            sum[c] += s.value[c] * cos / s.pdf * li[c];
        }
    }
    sum.map(|v| v / f64::from(samples))
}

/// The radiance arriving along `ray` (toward its origin) by one path of up
/// to `events` scattering events, each with next-event estimation to every
/// lamp, and Russian roulette after the first (module doc). Emission of the
/// surfaces hit counts; the lamps themselves are not in the scene.
pub fn path_radiance(scene: &Scene, points: &[PointLight], ray: Ray, events: u32, rng: &mut ChaCha8Rng) -> [f64; 3] {
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
        let v = PathVertex::at(material, tri, &hit.point, -ray.direction);
        add_direct(scene, points, &v, &beta, &mut radiance);
        let Some(s) = v.bsdf.sample(&v.wo, [rng.random(), rng.random(), rng.random()]) else {
            break;
        };
        let cos = s.direction.dot(&v.normal);
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
            origin: v.origin,
            direction: s.direction,
        };
    }
    radiance
}

#[cfg(test)]
pub(super) mod tests {
    use rand::SeedableRng;

    use super::*;
    use crate::render::Texture;

    /// The six faces of the cube [0, size]³, each a quad wound so that its
    /// normal points inward.
    pub(in crate::igi) fn cube_quads(size: f64) -> [[Vector3<f64>; 4]; 6] {
        let v = |x: f64, y: f64, z: f64| Vector3::new(size * x, size * y, size * z);
        [
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            [v(0., 0., 1.), v(0., 1., 1.), v(1., 1., 1.), v(1., 0., 1.)],
            [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)],
            [v(1., 0., 0.), v(1., 0., 1.), v(1., 1., 1.), v(1., 1., 0.)],
            [v(0., 0., 0.), v(0., 0., 1.), v(1., 0., 1.), v(1., 0., 0.)],
            [v(0., 1., 0.), v(1., 1., 0.), v(1., 1., 1.), v(0., 1., 1.)],
        ]
    }

    /// The twelve inward-facing triangles of the cube [0, 1]³ (material 0).
    fn unit_cube() -> Vec<Triangle> {
        cube_quads(1.0)
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .filter_map(|t| Triangle::new(t, 0, 0))
            .collect()
    }

    fn material(rho: f64, emission: f64) -> Material {
        Material {
            name: "wall".into(),
            albedo: Texture::Constant([rho; 3]),
            specular: None,
            emission: [emission; 3],
        }
    }

    /// A point lamp of intensity I at height h over a Lambertian floor of
    /// albedo ρ, alone in the scene: the radiance straight below it is
    /// ρ I / (π h²) (to the rays' 1e-6 offset off the
    /// surface), and paths find nothing else to add.
    #[test]
    fn a_lamp_over_a_floor_gives_its_exact_reflected_radiance() {
        let floor: Vec<Triangle> = unit_cube().into_iter().take(2).collect();
        let scene = Scene::new(floor, vec![material(0.6, 0.0)], vec!["floor".into()]).unwrap();
        let lamp = PointLight {
            position: Vector3::new(0.5, 0.5, 2.0),
            intensity: [3.0, 2.0, 1.0],
        };
        let tri = &scene.triangles()[0];
        let p = Vector3::new(0.5, 0.5, 0.0);
        let v = PathVertex::at(&scene.materials()[0], tri, &p, Vector3::new(0.3, 0.0, 1.0).normalize());
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let l = surface_radiance(&scene, &[lamp], &v, (64, 12, true), &mut rng);
        for c in 0..3 {
            let want = 0.6 * lamp.intensity[c] / (std::f64::consts::PI * 4.0);
            assert!((l[c] - want).abs() < 1e-5 * want, "channel {c}: {} vs {want}", l[c]);
        }
    }

    /// The furnace: inside a closed box whose walls emit Le and reflect ρ
    /// diffusely, the light arriving anywhere is Le / (1 − ρ), so a wall
    /// reflects ρ Le / (1 − ρ) (no emission counted at the first vertex).
    /// Russian roulette and stratification leave the estimate unbiased:
    /// within 1 % (about three standard errors of 64 000 paths) for both
    /// samplings.
    #[test]
    fn the_furnace_is_unbiased_with_roulette_and_strata() {
        let (rho, le) = (0.7, 1.0);
        let scene = Scene::new(unit_cube(), vec![material(rho, le)], vec!["box".into()]).unwrap();
        let want = rho * le / (1.0 - rho);
        let tri = &scene.triangles()[0];
        for stratified in [true, false] {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let trials = 4000;
            let mut sum = 0.0;
            for k in 0..trials {
                let p = Vector3::new(0.1 + 0.0002 * f64::from(k), 0.05 + 0.0001 * f64::from(k), 0.0);
                let v = PathVertex::at(&scene.materials()[0], tri, &p, Vector3::z());
                sum += surface_radiance(&scene, &[], &v, (16, 60, stratified), &mut rng)[0];
            }
            let got = sum / f64::from(trials);
            assert!(
                (got / want - 1.0).abs() < 0.01,
                "stratified {stratified}: {got} vs {want}"
            );
        }
    }
}
