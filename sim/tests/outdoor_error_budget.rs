//! The outdoor reflectance stage (issue 9) against the simulated campanile
//! day with its ingredients controlled (the error budget of BENCHMARKS.md,
//! `cargo run --release -p campanile-sim --example outdoor_budget`): the
//! true sun, sky and environment, photographs with little Monte Carlo
//! noise, and the tower's materials either of constant albedo (so a cell's
//! truth is unambiguous) or with their brick texture.

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

use campanile_process::error_figures::{block_relative_rmse, quantile};
use campanile_process::outdoor::rerender::target_mask;
use campanile_process::outdoor::{
    CellStatus, Illumination, Reflectance, ReflectanceSettings, RerenderSettings, recover_reflectance, rerender,
};
use campanile_sim::world::campanile_day::{
    CampanileDay, HELD_OUT_VIEWS, held_out_time, illuminations, texture_correlation, training_times,
};

/// Photo size and samples: small, so the test stays fast (≈ 16 s in the dev
/// profile before path splitting, about twice that with its 4 branches); a
/// 2 m cell sees ~10 pixels per photo.
const WIDTH: usize = 128;
const HEIGHT: usize = 96;
const SPP: u32 = 64;
const SPACING_M: f64 = 2.0;

/// Sub-samples per cell side for a cell's true albedo. The mortar joints
/// are 5 cm wide and 12% of the wall: an 8 × 8 grid over a 2 m cell (25 cm
/// apart) aliases with the 0.6 m courses and put 0–25% of its points on
/// mortar, a ±3% error in the "truth" itself (measured: it was the whole
/// texture term of the budget).
const TRUTH_PER_SIDE: usize = 64;

struct Day {
    day: CampanileDay,
    refl: Reflectance,
    /// Truth per cell: the world's albedo averaged over the cell.
    truth: Vec<[f64; 3]>,
}

/// The day with the light known, the tower's materials flattened to their
/// mean albedo unless `textured`.
fn recover_day(textured: bool) -> Day {
    let mut day = CampanileDay::load(SPP, 2).unwrap();
    if !textured {
        day.flatten_tower().unwrap();
    }
    let times = training_times();
    let photos = day.photographs(&times, WIDTH, HEIGHT).unwrap();
    let days = day.daylights(&times).unwrap();
    let settings = ReflectanceSettings {
        spacing_m: SPACING_M,
        ..ReflectanceSettings::default()
    };
    let (refl, _) = recover_reflectance(
        &day.world.scene.scene,
        &day.targets().unwrap(),
        &photos,
        &illuminations(&days),
        &settings,
    )
    .unwrap();
    let truth = day.cell_truth(&refl.grid, TRUTH_PER_SIDE);
    Day { day, refl, truth }
}

fn flat_day() -> &'static Day {
    static DAY: OnceLock<Day> = OnceLock::new();
    DAY.get_or_init(|| recover_day(false))
}

/// |relative error| of ρ_se and ρ_sun over every cell some photo saw
/// (solved or filled), all channels: (ρ_se, ρ_sun).
fn errors(day: &Day) -> (Vec<f64>, Vec<f64>) {
    let (mut se, mut sun) = (Vec::new(), Vec::new());
    for (c, t) in day.truth.iter().enumerate() {
        let e = &day.refl.cells[c];
        if e.status == CellStatus::Unseen {
            continue;
        }
        for ch in 0..3 {
            se.push((e.rho_se[ch] / t[ch] - 1.0).abs());
            sun.push((e.rho_sun[ch] / t[ch] - 1.0).abs());
        }
    }
    (se, sun)
}

/// With the light known and the walls of constant albedo, what is left is
/// the solver's own error and the photos' noise (64 samples per pixel, 4
/// branches at the first surface): the pseudo-albedos of every seen cell
/// (solved or filled) within 1.5% (median; issue 9 asks 2%) and 8% (p95),
/// both pseudo-BRDFs.
/// Measured: ρ_se 1.12% / 4.4%, ρ_sun 0.55% / 2.7% (before path splitting
/// 1.75% / 8.6% and 1.04% / 5.6%; the old renderer at 256 samples per
/// pixel: 1.2% / 5.0% and 0.6% / 3.2%; BENCHMARKS.md, "Outdoor error
/// budget" and "Path splitting at the first surface"). Before the footprint test,
/// the amplification test and the fitted-value weights: 2.5% / 46% and
/// 1.8% / 370% at 256 samples.
#[test]
fn with_the_light_known_pseudo_albedos_are_within_two_percent() {
    let day = flat_day();
    let (mut se, mut sun) = errors(day);
    let seen = day.refl.grid.cells.len() - day.refl.count(CellStatus::Unseen);
    let (ms, ps, mu, pu) = (
        quantile(&mut se, 0.5),
        quantile(&mut se, 0.95),
        quantile(&mut sun, 0.5),
        quantile(&mut sun, 0.95),
    );
    eprintln!(
        "{seen} cells seen, {} solved; ρ_se median {ms:.4} p95 {ps:.4}; ρ_sun median {mu:.4} p95 {pu:.4}; {:?}",
        day.refl.count(CellStatus::Solved),
        day.refl.sampling
    );
    assert!(seen >= 300, "{seen} cells seen");
    assert!(ms <= 0.015 && mu <= 0.015, "medians ρ_se {ms}, ρ_sun {mu}");
    assert!(ps <= 0.08 && pu <= 0.08, "p95 ρ_se {ps}, ρ_sun {pu}");
    assert!(day.refl.photos.iter().all(|p| !p.outlier), "{:?}", day.refl.photos);
}

/// The held-out time re-rendered from those pseudo-albedos, against the
/// simulator's photographs of three views (64 samples per pixel), per
/// 4 × 4-pixel block (about one 2 m cell): ≤ 3% (measured 2.05%, 0.54%,
/// 1.27%; before path splitting 2.1%, 0.8%, 1.9%).
#[test]
fn with_the_light_known_the_held_out_time_is_within_three_percent() {
    let day = flat_day();
    let w = &day.day.world;
    let held = day.day.daylight(held_out_time()).unwrap();
    let light = Illumination {
        time: held_out_time(),
        sky: &held,
    };
    for v in HELD_OUT_VIEWS {
        let r = day.day.view_rig(v, WIDTH, HEIGHT).unwrap();
        let reference = w.render(held_out_time(), &r, &[], 7).unwrap();
        let (image, _) = rerender(&w.scene.scene, &day.refl, &r, &light, &RerenderSettings::default());
        let mask = target_mask(&w.scene.scene, &day.refl, &r);
        let block = block_relative_rmse(&image, &reference, &mask, 4);
        eprintln!("{v}: relative RMSE per 4×4 block {block:.4}");
        assert!(block <= 0.03, "{v}: block relative RMSE {block}");
    }
}

/// A pixel straddling the tower's corner sees a sunlit and a shaded wall at
/// once; without the footprint test the corner cells came out up to twice
/// too bright and their ρ_sun wrong tenfold (p95 of |error| 3.7 before).
/// The worst cell of the four walls is now within 20% (measured 14%, a
/// cell under the belfry seen by four pixels; 24% before path splitting).
#[test]
fn corner_cells_are_not_polluted_by_the_next_wall() {
    let day = flat_day();
    let mut worst: f64 = 0.0;
    let mut which = 0;
    for (c, t) in day.truth.iter().enumerate() {
        let e = &day.refl.cells[c];
        let surface = &day.day.world.scene.scene.surfaces()[day.refl.grid.cells[c].surface];
        if e.status == CellStatus::Unseen || !surface.ends_with("-face") {
            continue;
        }
        for ch in 0..3 {
            let err = (e.rho_se[ch] / t[ch] - 1.0)
                .abs()
                .max((e.rho_sun[ch] / t[ch] - 1.0).abs());
            if err > worst {
                worst = err;
                which = c;
            }
        }
    }
    eprintln!(
        "walls: worst |relative error| {worst:.4} at cell {which} {:?} {:?}",
        day.refl.grid.cells[which].centre.as_slice(),
        day.refl.cells[which]
    );
    assert!(worst <= 0.20, "worst wall cell {worst}");
}

fn textured_day() -> &'static Day {
    static DAY: OnceLock<Day> = OnceLock::new();
    DAY.get_or_init(|| recover_day(true))
}

/// The simulated day itself, brick texture and all, with the light known
/// (64 samples per pixel, 4 branches at the first surface): the
/// pseudo-albedos of every seen cell against the texture averaged over
/// each cell, and the texture kept (correlation of recovered and true cell
/// albedos over the sunlit walls). Measured: ρ_se 1.54% median (p95 5.6%),
/// ρ_sun 1.27% (4.5%), correlation 0.53–0.61 (2 m cells average ~5 bricks
/// of ±12%, so cell means vary by only ~3%). Before path splitting: 2.2%
/// (9.2%), 1.6% (7.1%), correlation 0.35–0.48; the old renderer at 256
/// samples per pixel 1.6% / 1.2% (`outdoor_budget`, line "bricks"). Issue
/// 9's 2% median is met for both.
#[test]
fn the_textured_day_with_the_light_known() {
    let day = textured_day();
    let (mut se, mut sun) = errors(day);
    let (ms, ps, mu, pu) = (
        quantile(&mut se, 0.5),
        quantile(&mut se, 0.95),
        quantile(&mut sun, 0.5),
        quantile(&mut sun, 0.95),
    );
    let scene = &day.day.world.scene.scene;
    let corr: Vec<f64> = ["south-face", "east-face", "west-face"]
        .iter()
        .map(|name| texture_correlation(&day.refl, &day.truth, scene.surface_index(name).unwrap()))
        .collect();
    eprintln!(
        "textured: ρ_se median {ms:.4} p95 {ps:.4}; ρ_sun median {mu:.4} p95 {pu:.4}; texture correlation S/E/W {corr:.3?}"
    );
    assert!(ms <= 0.02 && mu <= 0.02, "medians ρ_se {ms}, ρ_sun {mu}");
    assert!(ps <= 0.08 && pu <= 0.08, "p95 ρ_se {ps}, ρ_sun {pu}");
    assert!(corr.iter().all(|&r| r >= 0.45), "texture correlation {corr:?}");
}
