//! The outdoor reflectance stage on the simulated campanile day, timed:
//! photos of the four training times (true radiance from the simulator),
//! pseudo-albedos recovered at several grid spacings (time against error),
//! re-renders at the held-out time with the true sky and with a sky
//! predicted from skies fitted at the training times (thesis §5.5.1), and
//! the materials file of the finest grid.
//!
//! cargo run --release -p campanile-sim --example outdoor_day -- \
//!     [--width 128] [--spp 16] [--spacings 1,2,3,4] [--out target/outdoor-day]

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use std::time::Instant;

use campanile_process::camera::image::RadianceImage;
use campanile_process::error_figures::{block_relative_rmse, quantile};
use campanile_process::outdoor::atlas::write_materials;
use campanile_process::outdoor::rerender::{relative_rmse, target_mask};
use campanile_process::outdoor::{
    CellStatus, Illumination, Reflectance, ReflectanceSettings, RerenderSettings, recover_reflectance, rerender,
};
use campanile_process::render::CameraRig;
use campanile_process::sky::{Daylight, KnownSky, predict_sky};
use campanile_sim::world::campanile_day::{
    CampanileDay, HELD_OUT_VIEWS, fitted_skies, held_out_time, illuminations, training_times,
};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// Skies fitted to noisy samples of the world's sky at the training times,
/// interpolated to the held-out sun (§5.5.1); the disc keeps the world's
/// radiance (what the sun shots measure).
fn predicted_daylight(day: &CampanileDay) -> Daylight {
    let mut known: Vec<Vec<KnownSky>> = vec![Vec::new(); 3];
    let mut counter = 0u64;
    for t in training_times() {
        let truth = day.daylight(t).expect("daylight");
        let skies = fitted_skies(&truth, t, &mut counter).expect("a sky fit");
        for (c, list) in known.iter_mut().enumerate() {
            list.push(KnownSky {
                sun: truth.sun_direction,
                model: skies[c],
            });
        }
    }
    let truth = day.daylight(held_out_time()).expect("daylight");
    let models = [0, 1, 2].map(|c| {
        predict_sky(&known[c], truth.sun_direction, 5.0)
            .expect("a prediction")
            .model
    });
    Daylight {
        sky: models,
        overcast: None,
        ..truth
    }
}

fn main() {
    let width: usize = arg("--width").map_or(128, |v| v.parse().expect("--width N"));
    let spp: u32 = arg("--spp").map_or(16, |v| v.parse().expect("--spp N"));
    let spacings: Vec<f64> = arg("--spacings")
        .unwrap_or_else(|| "1,2,3,4".into())
        .split(',')
        .map(|s| s.parse().expect("--spacings a,b,c"))
        .collect();
    let out = std::path::PathBuf::from(arg("--out").unwrap_or_else(|| "target/outdoor-day".into()));
    let day = CampanileDay::load(spp, 2).expect("the example station and scene");
    let w = &day.world;
    let targets = day.targets().expect("the tower's surfaces");
    let height = width * 3 / 4;
    let t0 = Instant::now();
    let photos = day
        .photographs(&training_times(), width, height)
        .expect("the photographs");
    println!(
        "simulated photos: 16 × {}×{} at {spp} spp in {:.2?}",
        width,
        width * 3 / 4,
        t0.elapsed()
    );
    let days = day.daylights(&training_times()).expect("daylight");
    let lights = illuminations(&days);
    let held = day.daylight(held_out_time()).expect("daylight");
    let predicted = predicted_daylight(&day);
    let mut fine = w.clone();
    fine.quality.samples_per_pixel = spp * 4;
    let references: Vec<(CameraRig, RadianceImage)> = HELD_OUT_VIEWS
        .iter()
        .map(|v| {
            let r = day.view_rig(v, width, height).expect("a view");
            let img = fine.render(held_out_time(), &r, &[], 7).expect("a render");
            (r, img)
        })
        .collect();
    println!(
        "| spacing (m) | cells | solved | reflectance (s) | re-render 3 views (s) | ρ_se median / p95 | ρ_sun median / p95 | held-out RMSE pixel (true sky) | block 4×4 (true sky) | block 4×4 (predicted sky) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut first: Option<Reflectance> = None;
    for &spacing in &spacings {
        let settings = ReflectanceSettings {
            spacing_m: spacing,
            ..ReflectanceSettings::default()
        };
        let t1 = Instant::now();
        let (refl, _) = recover_reflectance(&w.scene.scene, &targets, &photos, &lights, &settings).expect("recovery");
        let t_refl = t1.elapsed().as_secs_f64();
        let tr = day.cell_truth(&refl.grid, 64);
        let (mut es, mut eu) = (Vec::new(), Vec::new());
        for c in 0..tr.len() {
            if refl.cells[c].status != CellStatus::Solved {
                continue;
            }
            for ch in 0..3 {
                es.push((refl.cells[c].rho_se[ch] / tr[c][ch] - 1.0).abs());
                eu.push((refl.cells[c].rho_sun[ch] / tr[c][ch] - 1.0).abs());
            }
        }
        let t2 = Instant::now();
        let (mut px, mut bl, mut bp) = (0.0f64, 0.0f64, 0.0f64);
        for (r, reference) in &references {
            let mask = target_mask(&w.scene.scene, &refl, r);
            let light = Illumination {
                time: held_out_time(),
                sky: &held,
            };
            let (img, _) = rerender(&w.scene.scene, &refl, r, &light, &RerenderSettings::default());
            px = px.max(relative_rmse(&img, reference, &mask).unwrap_or(f64::NAN));
            bl = bl.max(block_relative_rmse(&img, reference, &mask, 4));
            let light = Illumination {
                time: held_out_time(),
                sky: &predicted,
            };
            let (img, _) = rerender(&w.scene.scene, &refl, r, &light, &RerenderSettings::default());
            bp = bp.max(block_relative_rmse(&img, reference, &mask, 4));
        }
        let t_render = t2.elapsed().as_secs_f64() / 2.0;
        println!(
            "| {spacing} | {} | {} | {t_refl:.2} | {t_render:.2} | {:.4} / {:.4} | {:.4} / {:.4} | {px:.4} | {bl:.4} | {bp:.4} |",
            refl.grid.cells.len(),
            refl.count(CellStatus::Solved),
            quantile(&mut es, 0.5),
            quantile(&mut es, 0.95),
            quantile(&mut eu, 0.5),
            quantile(&mut eu, 0.95),
        );
        if first.is_none() {
            first = Some(refl);
        }
    }
    if let Some(refl) = first {
        let path = write_materials(&w.scene.scene, &refl, &out).expect("materials written");
        println!("materials file: {}", path.display());
        for d in &refl.diagnostics {
            println!("  {d}");
        }
    }
    println!(
        "total {:.2?} (worst of the three held-out views in each RMSE column)",
        t0.elapsed()
    );
}
