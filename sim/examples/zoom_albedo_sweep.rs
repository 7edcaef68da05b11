//! Time against error of the high-resolution pseudo-albedo (thesis §5.6.4,
//! eq. 5.16) over zoom-image sizes: the campanile's south wall from the
//! zoom-south pose with a 6° field of view at 64 × 48 to 512 × 384 pixels,
//! `ρ̃` the world's true cell means (2 m cells), photos at 64 samples per
//! pixel. Per size: the time of `zoom_albedo` and of `rerender_zoom`, the
//! median per-pixel error of the pseudo-albedo (green) and its correlation
//! with the truth, high-res against the cell means, and the relative RMSE
//! of the re-render at a new time against the world's render.
//!
//! `cargo run --release -p campanile-sim --example zoom_albedo_sweep`

use std::time::Instant;

use campanile_process::error_figures::{correlation, quantile};
use campanile_process::outdoor::rerender::relative_rmse;
use campanile_process::outdoor::zoom_albedo::PixelFate;
use campanile_process::outdoor::{
    Grid, Illumination, Photo, RerenderSettings, ZoomSettings, rerender, rerender_zoom, zoom_albedo,
};
use campanile_sim::world::campanile_day::{CampanileDay, held_out_time};
use campanile_sim::world::zoom_truth::{cell_mean_reflectance, pixel_albedo_truth, zoom_rig};
use chrono::{DateTime, Utc};

fn main() {
    let day = CampanileDay::load(64, 2).expect("the example station and scene");
    let w = &day.world;
    let t0 = held_out_time();
    let t1: DateTime<Utc> = "2026-08-29T22:42:00Z".parse().unwrap();
    let (d0, d1) = (w.daylight(t0).unwrap().unwrap(), w.daylight(t1).unwrap().unwrap());
    let (l0, l1) = (Illumination { time: t0, sky: &d0 }, Illumination { time: t1, sky: &d1 });
    let targets = day.targets().expect("the tower's surfaces");
    let position = [0.0, -60.0, 1.5];
    let grid = Grid::new(&w.scene.scene, &targets, 2.0, &[position.into()]).unwrap();
    let refl = cell_mean_reflectance(w, grid, 64);
    println!(
        "| size | window px | zoom_albedo s | rerender_zoom s | used px | ρ median high / low | correlation high / low | re-render RMSE high / low |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (width, height) in [(64, 48), (128, 96), (256, 192), (512, 384)] {
        // The same 6° field of view at every size.
        let rig = zoom_rig(w, position, [0.0, -5.5, 40.0], 10.0, width, height);
        let photo = Photo {
            label: format!("zoom {width}×{height}"),
            image: w.render(t0, &rig, &[], 1).unwrap(),
            rig,
            time: t0,
            mask: None,
        };
        let start = Instant::now();
        let zoom = zoom_albedo(&w.scene.scene, &refl, &photo, &l0, &ZoomSettings::default()).unwrap();
        let t_zoom = start.elapsed().as_secs_f64();
        let settings = RerenderSettings::default();
        let start = Instant::now();
        let high = rerender_zoom(&w.scene.scene, &refl, &zoom, &l1, &settings);
        let t_render = start.elapsed().as_secs_f64();
        let (low, _) = rerender(&w.scene.scene, &refl, &rig, &l1, &settings);
        let reference = w.render(t1, &rig, &[], 9).unwrap();
        let mask = zoom.valid();
        let truth = pixel_albedo_truth(w, &refl.grid, &rig, 4);
        let (mut eh, mut el, mut t, mut h, mut l) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (i, tr) in truth.iter().enumerate() {
            let Some(tr) = tr else { continue };
            if zoom.fate[i] != PixelFate::Used {
                continue;
            }
            eh.push((zoom.rho_se[i][1] / tr[1] - 1.0).abs());
            el.push((zoom.low_se[i][1] / tr[1] - 1.0).abs());
            t.push(tr[1]);
            h.push(zoom.rho_se[i][1]);
            l.push(zoom.low_se[i][1]);
        }
        println!(
            "| {width}×{height} | {:.0} | {t_zoom:.3} | {t_render:.3} | {} | {:.4} / {:.4} | {:.3} / {:.3} | {:.4} / {:.4} |",
            zoom.report.window_px,
            zoom.report.used,
            quantile(&mut eh, 0.5),
            quantile(&mut el, 0.5),
            correlation(&h, &t),
            correlation(&l, &t),
            relative_rmse(&high, &reference, &mask).unwrap_or(f64::NAN),
            relative_rmse(&low, &reference, &mask).unwrap_or(f64::NAN),
        );
    }
}
