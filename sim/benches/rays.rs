//! Ray casting throughput of the shared hierarchy
//! (`process::render::accel`, used by the renderer, the simulator, the
//! outdoor and indoor solvers and visibility): camera rays through every
//! pixel of the scenes' named views (coherent) and rays from random surface
//! points in random directions (incoherent, as a gather or a shadow test),
//! nearest hit and any-hit (occlusion), in Mrays/s on all cores.
//!
//! ```text
//! cargo bench -p campanile-sim --bench rays
//! ```

use std::time::Instant;

use campanile_process::render::{Ray, Scene};
use campanile_sim::world::{examples_dir, load_scene};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Rays from random points on the scene's triangles (area-weighted) in
/// uniformly random directions on the sphere; seeded.
fn incoherent(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
    let tris = scene.triangles();
    let mut cdf = Vec::with_capacity(tris.len());
    let mut acc = 0.0;
    for t in tris {
        acc += t.area();
        cdf.push(acc);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let pick = rng.random::<f64>() * acc;
            let t = &tris[cdf.partition_point(|&c| c < pick).min(tris.len() - 1)];
            let (mut u, mut v) = (rng.random::<f64>(), rng.random::<f64>());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let z = 2.0 * rng.random::<f64>() - 1.0;
            let phi = std::f64::consts::TAU * rng.random::<f64>();
            let r = (1.0 - z * z).sqrt();
            let d = Vector3::new(r * phi.cos(), r * phi.sin(), z);
            Ray {
                origin: t.point(u, v) + t.normal * 1e-6 * d.dot(&t.normal).signum(),
                direction: d,
            }
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("| scene | triangles | rays | query | Mrays/s | hits |");
    println!("|---|---|---|---|---|---|");
    for file in ["campanile-scene.ron", "room-scene.ron"] {
        let loaded = load_scene(&examples_dir().join(file))?;
        let scene = &loaded.scene;
        let views = loaded.pinhole_views(60f64.to_radians(), 640, 480)?;
        let camera: Vec<Ray> = views
            .iter()
            .flat_map(|v| {
                (0..v.width * v.height).map(move |i| v.ray((i % v.width) as f64 + 0.5, (i / v.width) as f64 + 0.5))
            })
            .collect();
        let random = incoherent(scene, 1_000_000, 7);
        for (kind, rays) in [("camera (coherent)", &camera), ("surface, random directions", &random)] {
            for query in ["nearest", "occluded"] {
                // Warm up once, then take the best of three.
                let mut best = f64::INFINITY;
                let mut hits = 0;
                for _ in 0..4 {
                    let start = Instant::now();
                    hits = match query {
                        "nearest" => rays
                            .par_iter()
                            .filter(|r| scene.intersect(r, f64::INFINITY).is_some())
                            .count(),
                        _ => rays.par_iter().filter(|r| scene.occluded(r, f64::INFINITY)).count(),
                    };
                    best = best.min(start.elapsed().as_secs_f64());
                }
                println!(
                    "| {file} | {} | {} {kind} | {query} | {:.2} | {:.1}% |",
                    scene.triangles().len(),
                    rays.len(),
                    rays.len() as f64 / best / 1e6,
                    100.0 * hits as f64 / rays.len() as f64
                );
            }
        }
    }
    Ok(())
}
