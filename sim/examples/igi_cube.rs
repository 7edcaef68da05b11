//! Inverse global illumination on the thesis's simulated cube (§4.7.1):
//! photographs the cube (twelve views), recovers the six walls' Ward BRDFs
//! and prints them in the layout of Table 4.1 with the thesis's errors.
//!
//! `cargo run --release -p campanile-sim --example igi_cube [-- SAMPLES ITERATIONS [GATHER_RAYS LOBE_RAYS CELLS SEED [WIDE_PX HIGHLIGHT_PX [SPARSE]]]]`
//!
//! SAMPLES: indirect samples per pixel of the photographs (32); ITERATIONS:
//! ΔS iterations (3, the solver's default); then the solver's gather rays per cell (256), lobe
//! rays per sample (16), cells per triangle edge (24) and seed (1); then
//! the sizes of the wide and highlight views (96 and 64 pixels square), and
//! the sparse set's size per surface (2500).

use std::time::Instant;

use campanile_process::igi::table::{THESIS_TABLE_4_1_ERRORS_PCT, errors};
use campanile_process::igi::{IgiOptions, format_table, recover};
use campanile_sim::world::cube_room::CubeRoom;
use campanile_sim::world::igi_photograph::PhotoSettings;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let samples: u32 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(32);
    let iterations: u32 = args
        .get(2)
        .and_then(|a| a.parse().ok())
        .unwrap_or(IgiOptions::default().iterations);
    let size = |i: usize, default: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let cube = CubeRoom::new(1.0);
    let t0 = Instant::now();
    let input = cube.igi_input(
        size(7, 96),
        size(8, 64),
        &PhotoSettings {
            indirect_samples: samples,
            max_bounces: 6,
            seed: 7,
        },
    );
    let photo_s = t0.elapsed().as_secs_f64();
    let d = IgiOptions::default();
    let arg = |i: usize, default: u64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let options = IgiOptions {
        iterations,
        gather_rays: arg(3, u64::from(d.gather_rays)) as u32,
        lobe_rays: arg(4, u64::from(d.lobe_rays)) as u32,
        cells_per_edge: arg(5, d.cells_per_edge as u64) as usize,
        seed: arg(6, d.seed),
        sparse_samples: arg(9, d.sparse_samples as u64) as usize,
        ..d
    };
    let result = match recover(&input, &options) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("igi_cube: {e}");
            std::process::exit(1);
        }
    };
    let truth: Vec<_> = cube.materials.iter().copied().map(Some).collect();
    println!("{}", format_table(&result, &truth, Some(&THESIS_TABLE_4_1_ERRORS_PCT)));
    for (k, it) in result.iterations.iter().enumerate() {
        println!(
            "ΔS iteration {}: max relative change {:.2e}, {:.2} s",
            k + 1,
            it.max_relative_change,
            it.seconds
        );
    }
    let mut worst = [0.0f64; 5];
    for (r, t) in result.surfaces.iter().zip(&cube.materials) {
        if let Some(m) = &r.material {
            for (w, e) in worst.iter_mut().zip(errors(m, t)) {
                *w = w.max(e.unwrap_or(0.0));
            }
        }
    }
    println!(
        "photographs: {samples} indirect samples/pixel, {photo_s:.2} s; recovery: {:.2} s",
        result.seconds
    );
    println!(
        "worst: rho_d {:.2} %, rho_s {:.2} %, alpha_x {:.2} %, alpha_y {:.2} %, gamma {:.3} deg",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
}
