//! Time per frame against per-pixel noise of the simulator's outdoor
//! photographs, with path splitting at the camera-visible surface
//! (`RenderSettings::split_rays` branches) and without it (0: one
//! continuation per vertex, the estimator before).
//!
//! The campanile through the station's camera from two of the day's views
//! (view-se, sunlit south and east walls; view-nw, the shaded north and
//! west walls) at a training time, 160 × 120 px. The noise is measured
//! without a reference: two renders with different seeds differ by √2
//! times one render's noise, so per pixel `|a − b| / √2` divided by a
//! 64-spp render's value of that pixel (a denominator only) is one frame's
//! relative noise there; the table gives its RMS and median over the
//! pixels that see the scene (not the open sky), and the mean of
//! `(a + b)/2 − reference` relative to the reference's mean (the bias
//! check: it must be within the noise). `efficiency` is `1 / (noise² ·
//! time)` relative to the unsplit estimator's mean over its rows: how much
//! less CPU time the same noise costs. Each time is the mean of renders
//! repeated for at least half a second.
//!
//! ```text
//! cargo run --release -p campanile-sim --example path_splitting -- [--bounces 3] [--width 160]
//! ```

use std::time::Instant;

use campanile_process::camera::image::RadianceImage;
use campanile_process::pose::HeadPose;
use campanile_process::render::{CameraRig, Ray};
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};

/// Relative noise of one frame per scene pixel (RMS, median), from two
/// renders with different seeds, normalized by `reference`; and the mean
/// bias of their average against `reference`, relative to its mean.
fn noise(a: &RadianceImage, b: &RadianceImage, reference: &RadianceImage, mask: &[bool]) -> (f64, f64, f64) {
    let mut rel = Vec::new();
    let (mut diff, mut total) = (0.0, 0.0);
    for (p, &m) in mask.iter().enumerate() {
        if !m {
            continue;
        }
        for c in 0..3 {
            let k = p * 3 + c;
            let (x, y, r) = (f64::from(a.data[k]), f64::from(b.data[k]), f64::from(reference.data[k]));
            if r <= 0.0 {
                continue;
            }
            rel.push(((x - y) / std::f64::consts::SQRT_2 / r).abs());
            diff += 0.5 * (x + y) - r;
            total += r;
        }
    }
    let rms = (rel.iter().map(|d| d * d).sum::<f64>() / rel.len() as f64).sqrt();
    rel.sort_by(f64::total_cmp);
    (rms, rel[rel.len() / 2], diff / total)
}

fn arg(args: &[String], name: &str, default: usize) -> usize {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let bounces = arg(&args, "--bounces", 3) as u32;
    let width = arg(&args, "--width", 160);
    let height = width * 3 / 4;
    let reference_spp = arg(&args, "--reference-spp", 64) as u32;
    let examples = examples_dir();
    let station = campanile_config::document::load_station(&examples.join("sim-station.ron"))?.value;
    let mut world = World::new(&station, load_scene(&examples.join("campanile-scene.ron"))?);
    world.quality.max_bounces = bounces;
    let time: DateTime<Utc> = "2026-08-29T20:10:00Z".parse()?;
    println!(
        "bounces {bounces}, {width} × {height} px, reference {reference_spp} spp, threads {}",
        rayon::current_num_threads()
    );
    println!(
        "| view | branches | spp | time per frame (s) | RMS noise per pixel | median noise per pixel | bias / mean | efficiency |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for view in ["view-se", "view-nw"] {
        let pose = world.scene.description.pose(view).ok_or("no such pose")?.clone();
        let (pan, tilt) = station
            .head
            .reach(pose.azimuth_deg, pose.elevation_deg)
            .ok_or("pose out of reach")?;
        let head = HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        };
        let (x, y, z) = pose.position_m;
        let rig: CameraRig = world.rig(head, [x, y, z], width, height);
        let caster = rig.rays();
        let mask: Vec<bool> = (0..width * height)
            .map(|p| {
                caster
                    .ray((p % width) as f64 + 0.5, (p / width) as f64 + 0.5)
                    .is_some_and(|r: Ray| world.scene.scene.intersect(&r, f64::INFINITY).is_some())
            })
            .collect();
        world.quality.samples_per_pixel = reference_spp;
        world.quality.split_rays = 4;
        let reference = world.render(time, &rig, &[], 99)?;
        let mut baseline = Vec::new();
        for split_rays in [0, 1, 2, 4, 8] {
            for spp in [1, 2, 4, 8] {
                world.quality.samples_per_pixel = spp;
                world.quality.split_rays = split_rays;
                let t0 = Instant::now();
                let mut reps = 0u32;
                let a = loop {
                    let a = world.render(time, &rig, &[], 1)?;
                    reps += 1;
                    if t0.elapsed().as_secs_f64() >= 0.5 {
                        break a;
                    }
                };
                let seconds = t0.elapsed().as_secs_f64() / f64::from(reps);
                let b = world.render(time, &rig, &[], 2)?;
                let (rms, median, bias) = noise(&a, &b, &reference, &mask);
                let merit = 1.0 / (rms * rms * seconds);
                if split_rays == 0 {
                    baseline.push(merit);
                }
                let base = baseline.iter().sum::<f64>() / baseline.len() as f64;
                println!(
                    "| {view} | {split_rays} | {spp} | {seconds:.3} | {rms:.4} | {median:.4} | {bias:+.4} | {:.2} |",
                    merit / base
                );
            }
        }
    }
    Ok(())
}
