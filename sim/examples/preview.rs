//! Renders PNG previews of the built-in scenes into `docs/`:
//!
//! ```text
//! cargo run --release -p campanile-sim --example preview [-- SPP]
//! ```

use campanile_process::pose::HeadPose;
use chrono::{DateTime, Utc};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spp: u32 = std::env::args().nth(1).map(|s| s.parse()).transpose()?.unwrap_or(64);
    let examples = campanile_sim::world::examples_dir();
    let station = campanile_config::document::load_station(&examples.join("sim-station.ron"))?.value;
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    std::fs::create_dir_all(&docs)?;

    // A wide view from 130 m south-east, looking at the tower's middle.
    let wide = ("wide", [70.0, -110.0, 1.5], 327.5, 16.4);
    let shots: [(&str, &str, &str, &[f64]); 4] = [
        ("campanile-scene.ron", "wide", "2026-08-29T22:00:00Z", &[]),
        ("campanile-scene.ron", "view-se", "2026-08-29T22:00:00Z", &[]),
        ("campanile-scene.ron", "zoom-south", "2026-08-29T20:30:00Z", &[]),
        ("room-scene.ron", "wide-sw", "2026-08-29T03:00:00Z", &[1.0, 1.0, 1.0]),
    ];
    for (scene_file, pose_name, time, levels) in shots {
        let scene = campanile_sim::world::load_scene(&examples.join(scene_file))?;
        let mut world = campanile_sim::world::World::new(&station, scene);
        world.quality.samples_per_pixel = spp;
        let (position, azimuth, elevation) = if pose_name == wide.0 {
            (wide.1, wide.2, wide.3)
        } else {
            let pose = world.scene.description.pose(pose_name).ok_or("missing pose")?;
            let (x, y, z) = pose.position_m;
            ([x, y, z], pose.azimuth_deg, pose.elevation_deg)
        };
        let (pan, tilt) = station.head.reach(azimuth, elevation).ok_or("pose out of reach")?;
        let head = HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        };
        let rig = world.rig(head, position, 512, 384);
        let time: DateTime<Utc> = time.parse()?;
        let t0 = std::time::Instant::now();
        let image = world.render(time, &rig, levels, 1)?;
        let elapsed = t0.elapsed();
        // Expose the median at 0.3 unless that would blow out the brightest
        // 2%, compress highlights (Reinhard), then the sRGB curve.
        let mut lum: Vec<f32> = image.data.chunks(3).map(|p| p[1]).collect();
        lum.sort_by(f32::total_cmp);
        let p98 = lum[lum.len() * 98 / 100].max(1e-6);
        let key = (0.3 / lum[lum.len() / 2].max(1e-6)).min(2.0 / p98);
        let srgb = |v: f32| {
            let v = v * key;
            let v = (v / (1.0 + v / 4.0)).clamp(0.0, 1.0);
            let s = if v <= 0.0031308 {
                12.92 * v
            } else {
                1.055 * v.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0).round() as u8
        };
        let bytes: Vec<u8> = image.data.iter().map(|&v| srgb(v)).collect();
        let name = format!("{}-{pose_name}.png", world.scene.description.name);
        image::save_buffer(
            docs.join(&name),
            &bytes,
            rig.width as u32,
            rig.height as u32,
            image::ColorType::Rgb8,
        )?;
        println!(
            "{name}: {}×{} at {spp} spp in {:.2} s",
            rig.width,
            rig.height,
            elapsed.as_secs_f64()
        );
    }
    Ok(())
}
