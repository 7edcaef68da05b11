//! Relighting speed against error (issue 30): the simulated room's scene
//! file with every photographed view at SIDE × SIDE pixels (23 views: 3
//! wide, 3 ceiling, 17 highlight and mirror views), its materials and
//! albedo maps recovered as `campanile igi` does, then its first VIEWS
//! views (12: the 3 wide, 6 highlight and 3 ceiling views) relit under the
//! two new lamps of the room's check, once with
//! the fixed 256 paths per pixel and once to an error target, timed (wall
//! and CPU seconds of this process) and compared per 4 × 4 block with a
//! high-path reference of the first REF_VIEWS views (another seed); one
//! adaptive run per target in the comma-separated ERROR list.
//!
//! `cargo run --release -p campanile-session --example relight_speed -- [DIR] [SIDE] [ERROR,...] [REF_SPP] [REF_VIEWS] [FIXED] [VIEWS]`
//! (defaults: a temporary directory, 128, 0.01, 1024, 2, 1, 12). DIR keeps the
//! scene file and `new-lights.ron` for timing the command line on them
//! (bench/relight/run.sh). FIXED 0 skips the fixed-count renders. The
//! environment's ROUND sets the paths per pixel of a round (and two rounds
//! as the minimum), DARK the dark floor (a fraction of the image's mean).

use std::path::PathBuf;
use std::time::Instant;

use campanile_process::igi::error_target::ErrorTarget;
use campanile_process::igi::relight::{RelightSettings, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_session::igi::recover_scene;
use campanile_sim::world::room_igi::{RoomIgi, SceneFileShot, igi_lights_of, new_lamps, relit_block_error};

/// CPU seconds (user + system) of this process so far (Linux).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of the file (utime, stime, in ticks of 1/100 s) are
    // the 12th and 13th after ")" (the state, field 3, is the first).
    let tick = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok());
    tick(11).zip(tick(12)).map_or(f64::NAN, |(u, s)| (u + s) / 100.0)
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .next()
        .unwrap_or("?")
        .to_owned()
}

fn fail(e: impl std::fmt::Display) -> ! {
    eprintln!("{e}");
    std::process::exit(1)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = args.get(1).map_or_else(
        || std::env::temp_dir().join(format!("relight-speed-{}", std::process::id())),
        PathBuf::from,
    );
    let num = |i: usize, d: f64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (side, errors_wanted, ref_spp, ref_views, fixed, views) = (
        num(2, 128.0) as usize,
        args.get(3).map_or("0.01", |s| s.as_str()),
        num(4, 1024.0) as u32,
        num(5, 2.0) as usize,
        num(6, 1.0) > 0.0,
        num(7, 12.0) as usize,
    );
    let errors_wanted: Vec<f64> = errors_wanted
        .split(',')
        .map(|e| {
            e.parse()
                .unwrap_or_else(|_| fail(format!("ERROR {e:?}: expected fractions separated by commas")))
        })
        .collect();
    let room = RoomIgi::example().unwrap_or_else(|e| fail(e));
    let shot = SceneFileShot {
        wide_px: (side, side),
        highlight: (20.0, side),
        ..SceneFileShot::default()
    };
    let scene = room.write_scene_file(&dir, &shot).unwrap_or_else(|e| fail(e));
    let bulbs = new_lamps();
    let lights = igi_lights_of(&bulbs);
    let mut text = String::from("[\n");
    for (n, l) in ["a", "b"].iter().zip(&lights) {
        text.push_str(&format!(
            "  Known(name: {n:?}, position_m: ({:?}, {:?}, {:?}), radius_m: {:?}, intensity_w_sr: ({:?}, {:?}, {:?})),\n",
            l.position.x, l.position.y, l.position.z, l.radius, l.intensity[0], l.intensity[1], l.intensity[2]
        ));
    }
    text.push_str("]\n");
    std::fs::write(dir.join("new-lights.ron"), text).unwrap_or_else(|e| fail(e));
    println!("scene file {} (views {side}x{side})", scene.display());
    let (t, c) = (Instant::now(), cpu_s());
    let r = recover_scene(&scene, false).unwrap_or_else(|e| fail(format!("{e:#}")));
    println!(
        "recovered in {:.1} s wall, {:.1} CPU-s",
        t.elapsed().as_secs_f64(),
        cpu_s() - c
    );
    let mut cams = r.image_cameras();
    let all = cams.len();
    cams.truncate(views);
    println!("{} of {all} views relit: {}", cams.len(), cams.join(", "));
    let mut fixed_images = Vec::new();
    if fixed {
        let (t, c, l0) = (Instant::now(), cpu_s(), load());
        for cam in &cams {
            fixed_images.push(r.relight(&lights, cam, false).unwrap_or_else(|e| fail(e)));
        }
        println!(
            "fixed 256 paths/px: {:.1} s wall, {:.1} CPU-s, load {l0} → {}",
            t.elapsed().as_secs_f64(),
            cpu_s() - c,
            load()
        );
    }
    let recovered = recovered_scene(&r.loaded.input, &r.result).unwrap_or_else(|e| fail(e));
    let settings = RelightSettings {
        indirect_samples: ref_spp,
        seed: 1_000_003,
        ..RelightSettings::default()
    };
    let t = Instant::now();
    let references: Vec<_> = cams
        .iter()
        .take(ref_views)
        .filter_map(|cam| r.loaded.cameras.iter().find(|(n, _)| n == cam))
        .map(|(_, camera)| relight(&recovered, Some(&r.map), &lights, camera, &settings))
        .collect();
    println!(
        "references: {} views at {ref_spp} paths/px in {:.0} s",
        references.len(),
        t.elapsed().as_secs_f64()
    );
    // Each view's error per 4 × 4 block against its reference, in %.
    let errors = |images: &[campanile_process::camera::image::RadianceImage]| -> String {
        images
            .iter()
            .zip(&references)
            .map(|(i, r)| format!("{:.2}", relit_block_error(i, r).map_or(f64::NAN, |e| 100.0 * e)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if fixed {
        println!("fixed 256 paths/px: error per 4x4 block {} %", errors(&fixed_images));
    }
    for error in errors_wanted {
        let mut target = ErrorTarget::new(error);
        if let Some(k) = std::env::var("ROUND").ok().and_then(|k| k.parse().ok()) {
            target.round_samples = k;
            target.min_samples = 2 * k;
        }
        if let Some(f) = std::env::var("DARK").ok().and_then(|f| f.parse().ok()) {
            target.dark_floor = f;
        }
        let (t, c, l0) = (Instant::now(), cpu_s(), load());
        let mut adaptive = Vec::new();
        let (mut blocks, mut unconverged, mut paths, mut worst) = (0, 0, 0.0, 0f64);
        for cam in &cams {
            let (img, rep) = r
                .relight_to_error(&lights, cam, &target, &|| {})
                .unwrap_or_else(|e| fail(e));
            blocks += rep.blocks;
            unconverged += rep.not_converged;
            paths += rep.mean_samples / cams.len() as f64;
            worst = worst.max(rep.worst_estimated);
            adaptive.push(img);
        }
        println!(
            "error target {:.2} % (rounds of {} paths/px, dark floor {}): {:.1} s wall, {:.1} CPU-s, load {l0} → {}; {} of {blocks} blocks converged, {paths:.1} paths/px on average, worst estimated {:.2} %; error per 4x4 block {} %",
            100.0 * error,
            target.round_samples,
            target.dark_floor,
            t.elapsed().as_secs_f64(),
            cpu_s() - c,
            load(),
            blocks - unconverged,
            100.0 * worst,
            errors(&adaptive)
        );
    }
}
