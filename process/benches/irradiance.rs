//! Sky irradiance, speed against error (Appendix B): the adaptive
//! subdivision swept over its tolerance, and Monte Carlo (cosine-weighted
//! sampling of the same sky function) over its sample count, both against
//! a converged Gauss–Legendre reference. Prints a Markdown table.
//!
//! `cargo bench -p campanile-process --bench irradiance`

use std::hint::black_box;
use std::time::Instant;

use campanile_process::irradiance::{
    Occlusion, ReferenceGrid, SkySubdivision, reference_sky_irradiance, sky_irradiance, sky_irradiance_with,
};
use campanile_process::render::{Material, Ray, Scene, Triangle};
use campanile_process::sky::{Atmosphere, COS_XI_FLOOR, Daylight, direction};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Seconds per call of `f`, repeated for at least `budget` seconds.
fn time_per_call<T>(budget: f64, mut f: impl FnMut() -> T) -> f64 {
    let start = Instant::now();
    let mut calls = 0u64;
    loop {
        black_box(f());
        calls += 1;
        let t = start.elapsed().as_secs_f64();
        if t >= budget {
            return t / calls as f64;
        }
    }
}

/// Monte Carlo irradiance from `sky` on the side `n`: `π · mean L` over cosine-distributed rays.
fn monte_carlo(sky: &impl Fn([f64; 3]) -> [f64; 3], n: &Vector3<f64>, samples: u64, seed: u64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let helper = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let a = n.cross(&helper).normalize();
    let b = n.cross(&a);
    let mut sum = 0.0;
    for _ in 0..samples {
        let (u1, u2): (f64, f64) = (rng.random(), rng.random());
        let r = u1.sqrt();
        let phi = std::f64::consts::TAU * u2;
        let d = a * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        if d.z > 0.0 {
            sum += sky([d.x, d.y, d.z])[1];
        }
    }
    std::f64::consts::PI * sum / samples as f64
}

/// Monte Carlo as [`monte_carlo`], with a shadow ray per sample into `scene`.
fn monte_carlo_occluded(
    sky: &impl Fn([f64; 3]) -> [f64; 3],
    n: &Vector3<f64>,
    scene: &Scene,
    samples: u64,
    seed: u64,
) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let helper = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
    let a = n.cross(&helper).normalize();
    let b = n.cross(&a);
    let origin = n * 1e-6;
    let mut sum = 0.0;
    for _ in 0..samples {
        let (u1, u2): (f64, f64) = (rng.random(), rng.random());
        let r = u1.sqrt();
        let phi = std::f64::consts::TAU * u2;
        let d = a * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
        if d.z > 0.0 && !scene.occluded(&Ray { origin, direction: d }, f64::INFINITY) {
            sum += sky([d.x, d.y, d.z])[1];
        }
    }
    std::f64::consts::PI * sum / samples as f64
}

/// The 10 m × 3 m wall 2 m south of the point, standing on its horizon.
fn wall() -> Scene {
    let c = [
        Vector3::new(-5.0, -2.0, 0.0),
        Vector3::new(5.0, -2.0, 0.0),
        Vector3::new(5.0, -2.0, 3.0),
        Vector3::new(-5.0, -2.0, 3.0),
    ];
    Scene::new(
        vec![
            Triangle::new([c[0], c[1], c[2]], 0, 0).expect("wall"),
            Triangle::new([c[0], c[2], c[3]], 0, 0).expect("wall"),
        ],
        vec![Material::diffuse("wall", [0.5; 3])],
        vec!["wall".into()],
    )
    .expect("wall scene")
}

/// With an occluder: the projection (App. B) against shadow rays and Monte
/// Carlo with shadow rays, against the projection at tolerance 1e-6.
fn occluded(sky: &impl Fn([f64; 3]) -> [f64; 3], n: &Vector3<f64>) {
    let scene = wall();
    let run = |occlusion: Occlusion<'_>, tolerance: f64, max_depth: u32| {
        let s = SkySubdivision {
            tolerance,
            min_depth: 2,
            max_depth,
        };
        sky_irradiance_with(&Vector3::zeros(), n, sky, occlusion, &s).expect("irradiance")
    };
    let reference = run(Occlusion::Projected(&scene), 1e-6, 14).rgb[1];
    println!();
    println!(
        "With the wall (10 m × 3 m, 2 m south, on the horizon); reference: projection at tolerance 1e-6, {reference:.12} W/m²"
    );
    println!();
    println!("| method | knob | patches / samples | time per evaluation | relative error |");
    println!("| --- | --- | --- | --- | --- |");
    for tolerance in [1e-2, 1e-3, 1e-4, 1e-5] {
        let e = run(Occlusion::Projected(&scene), tolerance, 14);
        let t = time_per_call(1.0, || run(Occlusion::Projected(&scene), tolerance, 14));
        println!(
            "| projected occluders (App. B) | tolerance {tolerance:.0e} | {} | {:.1} µs | {:.2e} |",
            e.patches,
            t * 1e6,
            ((e.rgb[1] - reference) / reference).abs()
        );
    }
    for depth in [8, 10, 12, 14] {
        let e = run(Occlusion::ShadowRays(&scene), 1e-4, depth);
        let t = time_per_call(1.0, || run(Occlusion::ShadowRays(&scene), 1e-4, depth));
        println!(
            "| shadow rays | tolerance 1e-4, depth {depth} | {} | {:.1} µs | {:.2e} |",
            e.patches,
            t * 1e6,
            ((e.rgb[1] - reference) / reference).abs()
        );
    }
    for samples in [10_000u64, 100_000, 1_000_000, 10_000_000] {
        let seeds = (20_000_000 / samples).clamp(4, 32);
        let start = Instant::now();
        let mut sq = 0.0;
        for seed in 0..seeds {
            let e = monte_carlo_occluded(sky, n, &scene, samples, seed);
            sq += ((e - reference) / reference).powi(2);
        }
        let t = start.elapsed().as_secs_f64() / seeds as f64;
        println!(
            "| Monte Carlo + shadow rays | {samples} samples (RMS of {seeds} seeds) | {samples} | {:.1} µs | {:.2e} |",
            t * 1e6,
            (sq / seeds as f64).sqrt()
        );
    }
}

fn main() {
    let sun = direction(70f64.to_radians(), 200f64.to_radians());
    let day = Daylight::clear(sun, &Atmosphere::clear());
    let sky = |d: [f64; 3]| day.sky_radiance(d);
    let nd = direction(45f64.to_radians(), 170f64.to_radians());
    let n = Vector3::new(nd[0], nd[1], nd[2]);
    let grid = ReferenceGrid {
        azimuth_panels: 96,
        zenith_panels: 48,
        features: vec![Vector3::new(sun[0], sun[1], sun[2])],
        zenith_breaks: vec![COS_XI_FLOOR.acos()],
    };
    let reference = reference_sky_irradiance(&n, &sky, &grid)[1];
    println!("Reference (green channel): {reference:.12} W/m²");
    println!();
    println!("| method | knob | patches / samples | sky evaluations | time per evaluation | relative error |");
    println!("| --- | --- | --- | --- | --- | --- |");
    let mut adaptive = Vec::new();
    for tolerance in [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5] {
        let s = SkySubdivision {
            tolerance,
            ..SkySubdivision::default()
        };
        let e = sky_irradiance(&Vector3::zeros(), &n, &sky, None, &s).expect("valid input");
        let err = ((e.rgb[1] - reference) / reference).abs();
        let t = time_per_call(0.5, || sky_irradiance(&Vector3::zeros(), &n, &sky, None, &s));
        println!(
            "| adaptive (App. B) | tolerance {tolerance:.0e} | {} | {} | {:.1} µs | {err:.2e} |",
            e.patches,
            e.evaluations,
            t * 1e6
        );
        adaptive.push((tolerance, err, t));
    }
    // Monte Carlo: RMS error over seeds at each count.
    let mut per_sample = 0.0;
    let mut sigma_rel = 0.0;
    for samples in [1_000u64, 10_000, 100_000, 1_000_000, 10_000_000] {
        let seeds = (20_000_000 / samples).clamp(4, 64);
        let start = Instant::now();
        let mut sq = 0.0;
        for seed in 0..seeds {
            let e = monte_carlo(&sky, &n, samples, seed);
            sq += ((e - reference) / reference).powi(2);
        }
        let t = start.elapsed().as_secs_f64() / seeds as f64;
        let rms = (sq / seeds as f64).sqrt();
        per_sample = t / samples as f64;
        sigma_rel = rms * (samples as f64).sqrt();
        println!(
            "| Monte Carlo, cosine-weighted | {samples} samples (RMS of {seeds} seeds) | {samples} | {samples} | {:.1} µs | {rms:.2e} |",
            t * 1e6
        );
    }
    println!();
    println!(
        "Monte Carlo relative standard deviation per sample: {sigma_rel:.3}; {:.1} ns per sample.",
        per_sample * 1e9
    );
    for (tolerance, err, t) in adaptive {
        let samples = (sigma_rel / err).powi(2);
        let mc_time = samples * per_sample;
        println!(
            "At tolerance {tolerance:.0e} (error {err:.2e}): Monte Carlo needs ≈{samples:.2e} samples, ≈{:.3e} s; adaptive {:.3e} s; ratio {:.0}×",
            mc_time,
            t,
            mc_time / t
        );
    }
    occluded(&sky, &n);
}
