//! Render time against noise: a 256×256 frame of each built-in scene at
//! 1–256 samples per pixel, timed. The noise is measured without a
//! reference: two renders with different seeds differ by √2 times one
//! render's noise, so `RMS(a − b) / √2`, relative to the frame's mean
//! radiance, is the RMS noise of one frame; the median of `|a − b| / √2`
//! per sample, relative to the mean, is a measure that ignores the rare
//! bright paths (caustics off the metal sphere, light bounced off the
//! ceiling next to a lamp) that dominate the RMS indoors.
//!
//! ```text
//! cargo bench -p campanile-sim --bench render
//! ```

use campanile_process::camera::image::RadianceImage;
use campanile_process::pose::HeadPose;
use campanile_process::render::{Lighting, RenderSettings, render};
use campanile_sim::world::cube_room::CubeRoom;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;
use std::time::Instant;

/// RMS and median noise of one frame, relative to the mean, from two
/// independent renders.
fn noise(a: &RadianceImage, b: &RadianceImage) -> (f64, f64) {
    let n = a.data.len() as f64;
    let mean = a.data.iter().chain(&b.data).map(|&v| f64::from(v)).sum::<f64>() / (2.0 * n);
    let mut diffs: Vec<f64> = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs() / std::f64::consts::SQRT_2)
        .collect();
    let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / n).sqrt() / mean;
    diffs.sort_by(f64::total_cmp);
    (rms, diffs[diffs.len() / 2] / mean)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let examples = examples_dir();
    let station = campanile_config::document::load_station(&examples.join("sim-station.ron"))?.value;
    let time: DateTime<Utc> = "2026-08-29T22:00:00Z".parse()?;
    let head = |az: f64, el: f64| {
        let (pan, tilt) = station.head.reach(az, el).unwrap_or((0.0, 0.0));
        HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        }
    };
    println!("| scene | spp | bounces | time per frame (s) | Mpaths/s | RMS noise / mean | median noise / mean |");
    println!("|---|---:|---:|---:|---:|---:|---:|");

    // The two example scenes through the station's camera.
    for (file, position, az, el, levels) in [
        ("campanile-scene.ron", [70.0, -110.0, 1.5], 327.5, 16.4, vec![]),
        ("room-scene.ron", [0.5, 0.5, 1.6], 45.0, -15.0, vec![1.0, 1.0, 1.0]),
    ] {
        let mut world = World::new(&station, load_scene(&examples.join(file))?);
        let rig = world.rig(head(az, el), position, 256, 256);
        for spp in [1, 4, 16, 64, 256] {
            world.quality.samples_per_pixel = spp;
            let t0 = Instant::now();
            let a = world.render(time, &rig, &levels, 1)?;
            let s = t0.elapsed().as_secs_f64();
            let b = world.render(time, &rig, &levels, 2)?;
            let paths = 256.0 * 256.0 * f64::from(spp) / s / 1e6;
            let (rms, median) = noise(&a, &b);
            println!(
                "| {} | {spp} | {} | {s:.3} | {paths:.2} | {rms:.4} | {median:.4} |",
                world.scene.description.name, world.quality.max_bounces,
            );
        }
    }

    // The §4.7.1 cube, point lights only, from its centre.
    let cube = CubeRoom::new(1.0);
    let mut rig =
        World::new(&station, load_scene(&examples.join("room-scene.ron"))?).rig(head(30.0, 10.0), [0.5; 3], 256, 256);
    rig.position = Vector3::repeat(0.5);
    let lighting = Lighting {
        points: &cube.lights,
        ..Default::default()
    };
    let settings = |spp, seed| RenderSettings {
        samples_per_pixel: spp,
        max_bounces: 4,
        seed,
        ..RenderSettings::default()
    };
    for spp in [1, 4, 16, 64, 256] {
        let t0 = Instant::now();
        let a = render(&cube.scene, &rig, &lighting, &settings(spp, 1));
        let s = t0.elapsed().as_secs_f64();
        let b = render(&cube.scene, &rig, &lighting, &settings(spp, 2));
        let paths = 256.0 * 256.0 * f64::from(spp) / s / 1e6;
        let (rms, median) = noise(&a, &b);
        println!("| cube (§4.7.1) | {spp} | 4 | {s:.3} | {paths:.2} | {rms:.4} | {median:.4} |");
    }
    Ok(())
}
