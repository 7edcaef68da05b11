//! The simulated room (thesis §4.7.2) end to end on plain files: writes
//! the room's `campanile igi` scene file (EXR photographs, bulb images),
//! loads it (lamps triangulated), recovers the materials and albedo maps,
//! relights the room under two new lamps and compares with the simulator's
//! render; prints each stage's time and error.
//!
//! `cargo run --release -p campanile-sim --example igi_room [-- WIDE_W WIDE_H CELLS GATHER_RAYS RELIGHT_SAMPLES]`
//! (defaults 128 96 6 64 32).

use std::time::Instant;

use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::relight::{RelightSettings, relative_rmse, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::scene_file::load;
use campanile_process::igi::{IgiLight, IgiOptions, format_table, recover};
use campanile_process::render::SphereLight;
use campanile_sim::world::examples_dir;
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::{ROOM_BOUNCES, RoomIgi, SceneFileShot, block_average};
use nalgebra::Vector3;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (w, h) = (arg(1, 128), arg(2, 96));
    let station = match campanile_config::document::load_station(&examples_dir().join("sim-station.ron")) {
        Ok(s) => s.value,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let room = RoomIgi::load(&examples_dir().join("room-scene.ron"), &station).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let dir = std::env::temp_dir().join(format!("campanile-igi-room-{}", std::process::id()));
    let shot = SceneFileShot {
        wide_px: (w, h),
        highlight: (20.0, (w * 3 / 8).max(16)),
        ..SceneFileShot::default()
    };
    let t = Instant::now();
    let scene = room.write_scene_file(&dir, &shot).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let photo_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let loaded = load(&scene).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let load_s = t.elapsed().as_secs_f64();
    let mut worst_mm: f64 = 0.0;
    let mut worst_i: f64 = 0.0;
    for (name, tl) in &loaded.triangulated {
        if let Some((_, b)) = room.lamps.iter().find(|(n, _)| n == name) {
            worst_mm = worst_mm.max((tl.light.position - b.center).norm() * 1e3);
            let ti = b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius);
            for (got, want) in tl.light.intensity.iter().zip(ti) {
                worst_i = worst_i.max((got / want - 1.0).abs());
            }
        }
    }
    let opts = IgiOptions {
        cells_per_edge: arg(3, 6),
        gather_rays: arg(4, 64) as u32,
        ..IgiOptions::default()
    };
    let t = Instant::now();
    let result = recover(&loaded.input, &opts).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let recover_s = t.elapsed().as_secs_f64();
    let truth: Vec<_> = room
        .true_materials()
        .unwrap_or_default()
        .into_iter()
        .map(Some)
        .collect();
    println!("{}", format_table(&result, &truth, None));
    let t = Instant::now();
    let map = AlbedoMap::build(&loaded.input, &result, &AlbedoMapOptions::default()).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1);
    });
    let map_s = t.elapsed().as_secs_f64();
    let names = room.material_names();
    let map_err: Vec<String> = ["paint", "paper", "wood"]
        .iter()
        .filter_map(|n| {
            names
                .iter()
                .position(|m| m == n)
                .map(|s| (n, room.albedo_map_error(&map, s).0))
        })
        .map(|(n, e)| format!("{n} {:.1} %", 100.0 * e))
        .collect();
    let bulbs = [
        SphereLight::with_intensity(Vector3::new(2.0, 2.2, 2.4), 0.05, [2.5, 2.4, 2.0]),
        SphereLight::with_intensity(Vector3::new(3.6, 2.8, 2.0), 0.05, [1.4, 1.7, 2.3]),
    ];
    let lights: Vec<IgiLight> = bulbs
        .iter()
        .map(|b| IgiLight {
            position: b.center,
            radius: b.radius,
            intensity: b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius),
        })
        .collect();
    let camera = loaded.cameras[0].1;
    let samples = arg(5, 32) as u32;
    let t = Instant::now();
    let relit = match recovered_scene(&loaded.input, &result) {
        Ok(scene) => relight(
            &scene,
            Some(&map),
            &lights,
            &camera,
            &RelightSettings {
                indirect_samples: samples,
                ..RelightSettings::default()
            },
        ),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let relight_s = t.elapsed().as_secs_f64();
    let sim = room.photograph(
        &bulbs,
        &[],
        &camera,
        &PhotoSettings {
            indirect_samples: samples,
            max_bounces: ROOM_BOUNCES,
            seed: 99,
        },
    );
    let same = relight(
        room.scene(),
        None,
        &lights,
        &camera,
        &RelightSettings {
            indirect_samples: samples,
            ..RelightSettings::default()
        },
    );
    let (a, b, f) = (
        block_average(&relit, 4),
        block_average(&sim, 4),
        block_average(&same, 4),
    );
    let keep = |i: usize| b.data[i * 3] < 20.0;
    println!(
        "wide {w}x{h}, {} views; lamps: worst {worst_mm:.3} mm, intensity {:.2} %; albedo maps (median): {}; relit RMSE {:.2} % (4x4 blocks), noise floor {:.2} %",
        loaded.input.views.len(),
        100.0 * worst_i,
        map_err.join(", "),
        100.0 * relative_rmse(&a, &b, keep).unwrap_or(f64::NAN),
        100.0 * relative_rmse(&f, &b, keep).unwrap_or(f64::NAN)
    );
    println!(
        "seconds: photographs + scene file {photo_s:.1}, load + triangulate {load_s:.1}, recover {recover_s:.1}, albedo maps {map_s:.1}, relight {relight_s:.1}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
