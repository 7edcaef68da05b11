//! Speed against error for inverse global illumination on the §4.7.1
//! cube: the photographs' indirect samples per pixel, the solver's ΔS
//! iterations, lobe rays per sample (ΔS) and gather rays per cell, each
//! against the worst error over the six walls and the time taken.
//!
//! `cargo bench -p campanile-sim --bench igi_sweep`
//!
//! Prints a Markdown table. The photographs are taken once per sample
//! count (96 px wide views, 64 px highlight views, as the demo); each
//! solver configuration is run once with six ΔS iterations, and the error
//! after each pass is read from [`IterationReport::materials`] (a run of k
//! iterations is the first k passes of a longer one: each pass's random
//! numbers depend only on its index). Times: wall clock, and the process's
//! CPU time (user + system, from `/proc/self/stat`; the machine is shared,
//! so CPU time is the steadier figure).
//!
//! [`IterationReport::materials`]: campanile_process::igi::IterationReport

use std::time::Instant;

use campanile_process::brdf::WardMaterial;
use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiInput, IgiOptions, recover};
use campanile_sim::world::cube_room::CubeRoom;
use campanile_sim::world::igi_photograph::PhotoSettings;

/// CPU seconds (user + system) this process has used, if `/proc` tells.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name's closing parenthesis; utime and stime
    // are the 14th and 15th fields of the line, in clock ticks (100 Hz on Linux).
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// Worst ρd, ρs, α (αx and αy) percent errors and γ degrees over the walls.
fn worst(materials: &[Option<WardMaterial>], truth: &[WardMaterial; 6]) -> [f64; 4] {
    let mut w = [0.0f64; 4];
    for (m, t) in materials.iter().zip(truth) {
        let Some(m) = m else {
            return [f64::INFINITY; 4];
        };
        let e = errors(m, t);
        w[0] = w[0].max(e[0].unwrap_or(f64::INFINITY));
        w[1] = w[1].max(e[1].unwrap_or(f64::INFINITY));
        w[2] = w[2]
            .max(e[2].unwrap_or(f64::INFINITY))
            .max(e[3].unwrap_or(f64::INFINITY));
        w[3] = w[3].max(e[4].unwrap_or(0.0));
    }
    w
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument is ignored.
    let cube = CubeRoom::new(1.0);
    let d = IgiOptions::default();
    println!(
        "load average at start: {}",
        std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim()
    );
    println!();
    println!(
        "| photo samples/px | photographs wall (CPU) s | gather rays | lobe rays | ΔS iterations | recovery wall (CPU) s | total wall (CPU) s | ρd % | ρs % | α % | γ ° |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let runs: [(u32, u32, u32, u32); 8] = [
        // (photo samples, gather rays, lobe rays, iterations)
        (8, d.gather_rays, d.lobe_rays, 6),
        (16, d.gather_rays, d.lobe_rays, 6),
        (32, d.gather_rays, d.lobe_rays, 6),
        (32, d.gather_rays, 4, 4),
        (32, d.gather_rays, 8, 4),
        (32, d.gather_rays, 32, 4),
        (32, 64, d.lobe_rays, 4),
        (32, 1024, d.lobe_rays, 4),
    ];
    let mut photos: Option<(u32, IgiInput, f64, f64)> = None;
    for (samples, gather_rays, lobe_rays, iterations) in runs {
        if photos.as_ref().is_none_or(|p| p.0 != samples) {
            let (t, c) = (Instant::now(), cpu_seconds());
            let input = cube.igi_input(
                96,
                64,
                &PhotoSettings {
                    indirect_samples: samples,
                    max_bounces: 6,
                    seed: 7,
                },
            );
            let cpu = match (c, cpu_seconds()) {
                (Some(a), Some(b)) => b - a,
                _ => f64::NAN,
            };
            photos = Some((samples, input, t.elapsed().as_secs_f64(), cpu));
        }
        let Some((_, input, photo_wall, photo_cpu)) = photos.as_ref() else {
            continue;
        };
        let options = IgiOptions {
            gather_rays,
            lobe_rays,
            iterations,
            ..d
        };
        let c0 = cpu_seconds();
        let setup = Instant::now();
        let result = match recover(input, &options) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("igi_sweep: {e}");
                std::process::exit(1);
            }
        };
        let cpu_total = match (c0, cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => f64::NAN,
        };
        let wall_total = setup.elapsed().as_secs_f64();
        // The passes' share of the wall time; the CPU time is split alike.
        let pass_wall: f64 = result.iterations.iter().map(|i| i.seconds).sum();
        let before = wall_total - pass_wall;
        let mut elapsed = before;
        for (k, it) in result.iterations.iter().enumerate() {
            elapsed += it.seconds;
            let cpu = cpu_total * elapsed / wall_total;
            let w = worst(&it.materials, &cube.materials);
            println!(
                "| {samples} | {photo_wall:.1} ({photo_cpu:.1}) | {gather_rays} | {lobe_rays} | {} | {elapsed:.1} ({cpu:.1}) | {:.1} ({:.1}) | {:.2} | {:.2} | {:.2} | {:.3} |",
                k + 1,
                photo_wall + elapsed,
                photo_cpu + cpu,
                w[0],
                w[1],
                w[2],
                w[3]
            );
        }
    }
    println!();
    println!(
        "load average at end: {}",
        std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim()
    );
}
