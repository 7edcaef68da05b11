//! Ray casting throughput of the shared hierarchy
//! (`process::render::accel`, used by the renderer, the simulator, the
//! outdoor and indoor solvers and visibility), in Mrays/s on all cores, for
//! the three kinds of ray a path tracer casts, on the example scenes:
//!
//! - **primary**: camera rays through every pixel of the scenes' named
//!   views (640 × 480), nearest hit;
//! - **shadow**: from each primary hit toward the light (the campanile: the
//!   sun at azimuth 200°, elevation 35°; the room: a point 0.3 m below the
//!   middle of its ceiling), any hit within the light's distance;
//! - **diffuse bounce**: from each primary hit, cosine-distributed about the
//!   normal facing the camera, nearest hit (incoherent).
//!
//! With `CAMPANILE_RAYS_DUMP=DIR` it also writes each scene's triangles and
//! rays as little-endian `f32` files, which `bench/rays/peer.py` traces with
//! Mitsuba 3 (Embree-class traversal) in the same run (`bench/rays/run.sh`).
//!
//! ```text
//! cargo bench -p campanile-sim --bench rays
//! ```

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use campanile_process::render::{Ray, Scene};
use campanile_sim::world::{examples_dir, load_scene};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// A ray and how far it may go.
type Query = (Ray, f64);

/// The three kinds of ray, from the primary hits.
fn rays(scene: &Scene, camera: Vec<Ray>, light: Light) -> [(&'static str, Vec<Query>); 3] {
    let hits: Vec<(Vector3<f64>, Vector3<f64>)> = camera
        .par_iter()
        .filter_map(|r| {
            let hit = scene.intersect(r, f64::INFINITY)?;
            let n = scene.triangles()[hit.triangle].normal;
            let n = if n.dot(&r.direction) > 0.0 { -n } else { n };
            // Off the surface by 0.1 mm, which the peer's f32 origins keep.
            Some((hit.point + n * 1e-4, n))
        })
        .collect();
    let shadow = hits
        .iter()
        .map(|&(p, _)| match light {
            Light::Direction(d) => (
                Ray {
                    origin: p,
                    direction: d,
                },
                f64::INFINITY,
            ),
            Light::Point(q) => {
                let to = q - p;
                (
                    Ray {
                        origin: p,
                        direction: to.normalize(),
                    },
                    to.norm(),
                )
            }
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let bounce = hits
        .iter()
        .map(|&(p, n)| {
            // Cosine-distributed about n (Malley: a uniform disc lifted).
            let (u, v): (f64, f64) = (rng.random(), rng.random());
            let (r, phi) = (u.sqrt(), std::f64::consts::TAU * v);
            let a = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
            let s = n.cross(&a).normalize();
            let t = n.cross(&s);
            let d = s * (r * phi.cos()) + t * (r * phi.sin()) + n * (1.0 - u).max(0.0).sqrt();
            (
                Ray {
                    origin: p,
                    direction: d.normalize(),
                },
                f64::INFINITY,
            )
        })
        .collect();
    let primary = camera.into_iter().map(|r| (r, f64::INFINITY)).collect();
    [("primary", primary), ("shadow", shadow), ("diffuse bounce", bounce)]
}

#[derive(Clone, Copy)]
enum Light {
    Direction(Vector3<f64>),
    Point(Vector3<f64>),
}

fn write_f32(path: &Path, values: impl Iterator<Item = f64>) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    for v in values {
        out.write_all(&(v as f32).to_le_bytes())?;
    }
    out.flush()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dump = std::env::var_os("CAMPANILE_RAYS_DUMP").map(std::path::PathBuf::from);
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
        let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
        for t in scene.triangles() {
            for v in &t.vertices {
                lo = lo.inf(v);
                hi = hi.sup(v);
            }
        }
        let light = if file.starts_with("campanile") {
            let (az, el) = (200f64.to_radians(), 35f64.to_radians());
            Light::Direction(Vector3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin()))
        } else {
            Light::Point(Vector3::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0, hi.z - 0.3))
        };
        let stem = file.trim_end_matches("-scene.ron");
        let kinds = rays(scene, camera, light);
        if let Some(dir) = &dump {
            std::fs::create_dir_all(dir)?;
            write_f32(
                &dir.join(format!("{stem}-triangles.f32")),
                scene
                    .triangles()
                    .iter()
                    .flat_map(|t| t.vertices.iter().flat_map(|v| v.iter().copied())),
            )?;
        }
        for (kind, rays) in &kinds {
            if let Some(dir) = &dump {
                let name = kind.replace(' ', "-");
                write_f32(
                    &dir.join(format!("{stem}-{name}.f32")),
                    rays.iter().flat_map(|(r, t)| {
                        r.origin
                            .iter()
                            .chain(r.direction.iter())
                            .copied()
                            .chain([t.min(f64::from(f32::MAX))])
                    }),
                )?;
            }
            let query = if *kind == "shadow" { "any hit" } else { "nearest" };
            // Warm up once, then take the best of at least three passes and
            // half a second (the campanile's shadow and bounce sets take
            // 10–20 ms a pass, too short for one timing to settle).
            let mut best = f64::INFINITY;
            let mut hits = 0;
            let begun = Instant::now();
            let mut passes = 0;
            while passes < 4 || begun.elapsed().as_secs_f64() < 0.5 {
                passes += 1;
                let start = Instant::now();
                hits = match query {
                    "nearest" => rays
                        .par_iter()
                        .filter(|(r, t)| scene.intersect(r, *t).is_some())
                        .count(),
                    _ => rays.par_iter().filter(|(r, t)| scene.occluded(r, *t)).count(),
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
    Ok(())
}
