//! The error budget of the outdoor reflectance stage (issue 9) on the
//! simulated campanile day: start from an ideal setup (true sun, sky and
//! environment, the tower's surfaces of constant albedo, high-sample
//! photographs) and put back one ingredient at a time — texture, Monte
//! Carlo noise, more bounces than the solver's one, grid spacing, image
//! size, a fitted sky, a sun measured a few percent off, an environment of
//! mean albedo — printing for each the pseudo-albedo errors (median / p95
//! over the solved cells, all channels) and the held-out re-render error.
//!
//! cargo run --release -p campanile-sim --example outdoor_budget -- \
//!     [--cases ideal,bricks,...] [--reference-spp 256]

// Channel loops index several arrays at once; they read better with an index.
#![allow(clippy::needless_range_loop)]

use std::collections::HashMap;
use std::time::Instant;

use campanile_process::camera::image::RadianceImage;
use campanile_process::error_figures::{block_relative_rmse, quantile};
use campanile_process::outdoor::observation::Footprint;
use campanile_process::outdoor::rerender::{relative_rmse, target_mask};
use campanile_process::outdoor::{
    CellStatus, Illumination, Photo, ReflectanceSettings, RerenderSettings, recover_reflectance, rerender,
};
use campanile_process::render::CameraRig;
use campanile_process::sky::Daylight;
use campanile_sim::world::campanile_day::{
    CampanileDay, HELD_OUT_VIEWS, TOWER, fitted_skies, flattened, held_out_time, illuminations, training_times,
};
use chrono::{DateTime, Utc};

/// Sub-samples per cell side for a cell's true albedo (see `CampanileDay::cell_truth`).
const TRUTH_PER_SIDE: usize = 64;

/// One line of the budget.
#[derive(Clone)]
struct Case {
    name: &'static str,
    /// The tower's materials keep their texture (bricks, copper stripes).
    textured: bool,
    spp: u32,
    bounces: u32,
    spacing_m: f64,
    width: usize,
    /// The solver is given skies fitted to ±2% samples of the true sky.
    fitted_sky: bool,
    /// The solver's sun radiance is the truth times this.
    sun_scale: f64,
    /// The solver's environment (ground, landscape) has the textures' mean albedo.
    mean_environment: bool,
    /// Where a pixel's footprint must lie.
    footprint: Footprint,
}

const IDEAL: Case = Case {
    name: "ideal",
    textured: false,
    spp: 256,
    bounces: 2,
    spacing_m: 2.0,
    width: 128,
    fitted_sky: false,
    sun_scale: 1.0,
    mean_environment: false,
    footprint: Footprint::Face,
};

fn cases() -> Vec<Case> {
    vec![
        IDEAL,
        Case {
            name: "footprint-centre",
            footprint: Footprint::Centre,
            ..IDEAL
        },
        Case {
            name: "footprint-square",
            footprint: Footprint::Square,
            ..IDEAL
        },
        Case {
            name: "spp16",
            spp: 16,
            ..IDEAL
        },
        Case {
            name: "spp2",
            spp: 2,
            ..IDEAL
        },
        Case {
            name: "bounces3",
            bounces: 3,
            ..IDEAL
        },
        Case {
            name: "spacing1",
            spacing_m: 1.0,
            ..IDEAL
        },
        Case {
            name: "spacing4",
            spacing_m: 4.0,
            ..IDEAL
        },
        Case {
            name: "width64",
            width: 64,
            ..IDEAL
        },
        Case {
            name: "fitted-sky",
            fitted_sky: true,
            ..IDEAL
        },
        Case {
            name: "sun+3%",
            sun_scale: 1.03,
            ..IDEAL
        },
        Case {
            name: "mean-environment",
            mean_environment: true,
            ..IDEAL
        },
        Case {
            name: "bricks",
            textured: true,
            ..IDEAL
        },
        Case {
            name: "bricks-square",
            textured: true,
            footprint: Footprint::Square,
            ..IDEAL
        },
        Case {
            name: "bricks-centre",
            textured: true,
            footprint: Footprint::Centre,
            ..IDEAL
        },
        Case {
            name: "bricks-width256",
            textured: true,
            width: 256,
            spp: 64,
            ..IDEAL
        },
        Case {
            name: "bricks-spacing1",
            textured: true,
            spacing_m: 1.0,
            ..IDEAL
        },
        Case {
            name: "bricks-spp16",
            textured: true,
            spp: 16,
            ..IDEAL
        },
        Case {
            name: "all",
            textured: true,
            spp: 16,
            fitted_sky: true,
            sun_scale: 1.03,
            mean_environment: true,
            ..IDEAL
        },
    ]
}

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// The daylight the solver is given at `t`: the truth, or skies fitted to
/// ±2% samples of it (the disc unchanged), with the sun scaled by `sun_scale`.
fn given_daylight(day: &CampanileDay, t: DateTime<Utc>, fitted: bool, sun_scale: f64, salt: u64) -> Daylight {
    let mut out = day.daylight(t).expect("daylight");
    if fitted {
        let mut counter = salt * 1000;
        out.sky = fitted_skies(&out, t, &mut counter).expect("a sky fit");
        out.overcast = None;
    }
    out.sun_radiance = out.sun_radiance.map(|v| v * sun_scale);
    out
}

type PhotoKey = (bool, u32, u32, usize);

fn main() {
    let wanted: Option<Vec<String>> = arg("--cases").map(|s| s.split(',').map(str::to_string).collect());
    let reference_spp: u32 = arg("--reference-spp").map_or(256, |v| v.parse().expect("--reference-spp N"));
    let base = CampanileDay::load(256, 2).expect("the example station and scene");
    let tower_materials = base.tower_materials().expect("the tower's surfaces");
    let targets = base.targets().expect("the tower's surfaces");
    let mut photo_cache: HashMap<PhotoKey, Vec<Photo>> = HashMap::new();
    let mut reference_cache: HashMap<(bool, u32, usize), Vec<(CameraRig, RadianceImage)>> = HashMap::new();
    println!(
        "| case | footprint | textured | spp | bounces | spacing (m) | width (px) | sky | sun | environment | seen / solved | ρ_se median / p95 | ρ_sun median / p95 | solved only: ρ_se / ρ_sun median | held-out RMSE pixel | block 4×4 | time (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for case in cases() {
        if wanted.as_ref().is_some_and(|w| !w.iter().any(|n| n == case.name)) {
            continue;
        }
        let t0 = Instant::now();
        let mut day = base.clone();
        if !case.textured {
            day.flatten_tower().expect("the tower's materials");
        }
        day.world.quality.samples_per_pixel = case.spp;
        day.world.quality.max_bounces = case.bounces;
        let w = &day.world;
        let height = case.width * 3 / 4;
        let key = (case.textured, case.spp, case.bounces, case.width);
        let photos = photo_cache.entry(key).or_insert_with(|| {
            day.photographs(&training_times(), case.width, height)
                .expect("the photographs")
        });
        let solver_scene = if case.mean_environment {
            flattened(&w.scene.scene, |m| !tower_materials.iter().any(|t| t == m))
        } else {
            w.scene.scene.clone()
        };
        let days: Vec<(DateTime<Utc>, Daylight)> = training_times()
            .into_iter()
            .enumerate()
            .map(|(i, t)| (t, given_daylight(&day, t, case.fitted_sky, case.sun_scale, i as u64)))
            .collect();
        let lights = illuminations(&days);
        let settings = ReflectanceSettings {
            spacing_m: case.spacing_m,
            footprint: case.footprint,
            ..ReflectanceSettings::default()
        };
        let (refl, _) = recover_reflectance(&solver_scene, &targets, photos, &lights, &settings).expect("recovery");
        let tr = day.cell_truth(&refl.grid, TRUTH_PER_SIDE);
        let (mut es, mut eu, mut ss, mut su) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for c in 0..tr.len() {
            if refl.cells[c].status == CellStatus::Unseen {
                continue;
            }
            for ch in 0..3 {
                let (a, b) = (
                    (refl.cells[c].rho_se[ch] / tr[c][ch] - 1.0).abs(),
                    (refl.cells[c].rho_sun[ch] / tr[c][ch] - 1.0).abs(),
                );
                es.push(a);
                eu.push(b);
                if refl.cells[c].status == CellStatus::Solved {
                    ss.push(a);
                    su.push(b);
                }
            }
        }
        if std::env::args().any(|a| a == "--detail") {
            for (si, name) in TOWER.iter().enumerate() {
                let (mut a, mut b, mut sa, mut sb) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
                for c in 0..tr.len() {
                    if refl.cells[c].status == CellStatus::Unseen || refl.grid.cells[c].surface != targets[si] {
                        continue;
                    }
                    for ch in 0..3 {
                        let (x, y) = (
                            refl.cells[c].rho_se[ch] / tr[c][ch] - 1.0,
                            refl.cells[c].rho_sun[ch] / tr[c][ch] - 1.0,
                        );
                        a.push(x.abs());
                        b.push(y.abs());
                        sa.push(x);
                        sb.push(y);
                    }
                }
                println!(
                    "  {name}: {} values; ρ_se |e| median {:.4} p95 {:.4} signed median {:+.4}; ρ_sun |e| median {:.4} p95 {:.4} signed median {:+.4}",
                    a.len(),
                    quantile(&mut a, 0.5),
                    quantile(&mut a, 0.95),
                    quantile(&mut sa, 0.5),
                    quantile(&mut b, 0.5),
                    quantile(&mut b, 0.95),
                    quantile(&mut sb, 0.5)
                );
            }
            let mut worst: Vec<(f64, usize)> = (0..tr.len())
                .filter(|&c| refl.cells[c].status != CellStatus::Unseen)
                .map(|c| ((refl.cells[c].rho_sun[1] / tr[c][1] - 1.0).abs(), c))
                .collect();
            worst.sort_by(|a, b| b.0.total_cmp(&a.0));
            for (e, c) in worst.iter().take(12) {
                let cell = &refl.grid.cells[*c];
                let est = &refl.cells[*c];
                println!(
                    "  worst ρ_sun cell {c} {:?} {} centre {:.1?} n {:.2?} e_sun {e:+.3} e_se {:+.3} cond {:.1} obs {} rms {:.3}",
                    est.status,
                    TOWER[targets.iter().position(|&t| t == cell.surface).unwrap()],
                    cell.centre.as_slice(),
                    cell.normal.as_slice(),
                    est.rho_se[1] / tr[*c][1] - 1.0,
                    est.condition,
                    est.observations,
                    est.rms_relative
                );
            }
        }
        if let Some(cells) = arg("--cells") {
            let times: Vec<usize> = (0..photos.len()).map(|k| k / 4).collect();
            let (obs, _) = campanile_process::outdoor::observation::observe(
                &solver_scene,
                &refl.grid,
                photos,
                &lights,
                &times,
                settings.footprint,
            )
            .expect("observations");
            let tls: Vec<_> = lights
                .iter()
                .map(|l| {
                    campanile_process::outdoor::cell_irradiance::gather(&solver_scene, &refl.grid, l, &settings.gather)
                })
                .collect();
            for c in cells.split(',').map(|v| v.parse::<usize>().expect("--cells a,b")) {
                let cell = &refl.grid.cells[c];
                println!(
                    "cell {c}: centre {:.2?} normal {:.2?} truth {:.3?}",
                    cell.centre.as_slice(),
                    cell.normal.as_slice(),
                    tr[c]
                );
                for o in obs.iter().filter(|o| o.cell == c) {
                    let e_se = tls[o.time].se_irradiance(c, &tr, &tr);
                    let e_sun = if o.sunlit {
                        tls[o.time].sun_irradiance(c)
                    } else {
                        [0.0; 3]
                    };
                    let probe = w
                        .irradiance(
                            training_times()[o.time],
                            [cell.centre.x, cell.centre.y, cell.centre.z],
                            [cell.normal.x, cell.normal.y, cell.normal.z],
                            &[],
                            20000,
                            5,
                        )
                        .unwrap();
                    println!(
                        "  photo {:2} t{} sunlit {} px {:3}: πL/ρ {:8.2} | solver E_se {:8.2} E_sun {:8.2} sum {:8.2} | probe {:8.2} sun cos {:.3}",
                        o.photo,
                        o.time,
                        o.sunlit,
                        o.pixels,
                        std::f64::consts::PI * o.radiance[1] / tr[c][1],
                        e_se[1],
                        e_sun[1],
                        e_se[1] + e_sun[1],
                        probe[1],
                        tls[o.time].cells[c].sun_cosine
                    );
                }
            }
        }
        let references = reference_cache
            .entry((case.textured, case.bounces, case.width))
            .or_insert_with(|| {
                let mut fine = w.clone();
                fine.quality.samples_per_pixel = reference_spp;
                HELD_OUT_VIEWS
                    .iter()
                    .map(|v| {
                        let r = day.view_rig(v, case.width, height).expect("a view");
                        let img = fine.render(held_out_time(), &r, &[], 7).expect("a render");
                        (r, img)
                    })
                    .collect()
            });
        let held = given_daylight(&day, held_out_time(), case.fitted_sky, case.sun_scale, 9);
        let (mut px, mut bl) = (0.0f64, 0.0f64);
        for (r, reference) in references.iter() {
            let mask = target_mask(&solver_scene, &refl, r);
            let light = Illumination {
                time: held_out_time(),
                sky: &held,
            };
            let (img, _) = rerender(&solver_scene, &refl, r, &light, &RerenderSettings::default());
            px = px.max(relative_rmse(&img, reference, &mask).unwrap_or(f64::NAN));
            bl = bl.max(block_relative_rmse(&img, reference, &mask, 4));
        }
        println!(
            "| {} | {:?} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} / {:.4} | {px:.4} | {bl:.4} | {:.1} |",
            case.name,
            case.footprint,
            case.textured,
            case.spp,
            case.bounces,
            case.spacing_m,
            case.width,
            if case.fitted_sky { "fitted" } else { "true" },
            case.sun_scale,
            if case.mean_environment { "mean" } else { "true" },
            refl.grid.cells.len() - refl.count(CellStatus::Unseen),
            refl.count(CellStatus::Solved),
            quantile(&mut es, 0.5),
            quantile(&mut es, 0.95),
            quantile(&mut eu, 0.5),
            quantile(&mut eu, 0.95),
            quantile(&mut ss, 0.5),
            quantile(&mut su, 0.5),
            t0.elapsed().as_secs_f64(),
        );
    }
}
