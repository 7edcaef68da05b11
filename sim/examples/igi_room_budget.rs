//! Error budget of the room's recovery (issue 10): the same room
//! photographed with paths cut after `max_bounces` scattering events, for
//! several cuts, and recovered; prints, per material, the recovered ρd
//! against the true texture mean, the model chosen and why; then the
//! albedo maps' median error, and the room relit under two new lamps
//! against the simulator's render of them (relative RMSE per 4×4 block),
//! beside the same renderer with the true materials (its noise floor).
//! With `RELIT=0` the relighting is skipped.
//!
//! `cargo run --release -p campanile-sim --example igi_room_budget [-- W H BOUNCES...]`
//! (defaults 80 60 4 16); the solver's cells per edge, gather rays and ΔS
//! passes from the environment variables `CELLS`, `GATHER`, `ITER`,
//! `LOBE`, `SPARSE` (defaults 6, 64, 3, 16, 2500); the photographs'
//! indirect samples per pixel from `SPP` (16), the albedo maps' rays per
//! irradiance cell, texel and cell sides from `IRR_RAYS` (64), `TEXEL_MM`
//! (20), `CELL_MM` (250).

use std::time::Instant;

use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::relight::{RelightSettings, relative_rmse, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiLight, IgiOptions, recover};
use campanile_process::render::SphereLight;
use campanile_sim::world::examples_dir;
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::{CEILING_ELEVATION_DEG, RoomIgi, block_average};
use nalgebra::Vector3;

fn env(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (w, h) = (arg(1, 80), arg(2, 60));
    let bounces: Vec<u32> = if args.len() > 3 {
        args[3..].iter().filter_map(|a| a.parse().ok()).collect()
    } else {
        vec![4, 16]
    };
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron")).unwrap();
    let room = RoomIgi::load(&examples_dir().join("room-scene.ron"), &station.value).unwrap();
    let truth = room.true_materials().unwrap();
    let mut cams = room.cameras(60.0, w, h);
    cams.extend(room.highlight_cameras(20.0, w / 2));
    cams.extend(room.ceiling_cameras(CEILING_ELEVATION_DEG, 60.0, w, h));
    for b in bounces {
        let t = Instant::now();
        let input = room.igi_input(
            cams.clone(),
            &PhotoSettings {
                indirect_samples: env("SPP", 16) as u32,
                max_bounces: b,
                seed: 7,
            },
        );
        let photo_s = t.elapsed().as_secs_f64();
        let mean: f64 = input.views[0].image.data.iter().map(|v| f64::from(*v)).sum::<f64>()
            / input.views[0].image.data.len() as f64;
        let t = Instant::now();
        let result = recover(
            &input,
            &IgiOptions {
                cells_per_edge: env("CELLS", 6),
                gather_rays: env("GATHER", 64) as u32,
                iterations: env("ITER", 3) as u32,
                lobe_rays: env("LOBE", 16) as u32,
                sparse_samples: env("SPARSE", 2500),
                ..IgiOptions::default()
            },
        )
        .unwrap();
        println!(
            "max_bounces {b}: view 0 mean radiance {mean:.5}; photographs {photo_s:.1} s, recovery {:.1} s",
            t.elapsed().as_secs_f64()
        );
        for (r, t) in result.surfaces.iter().zip(&truth) {
            let m = r.material.as_ref().unwrap();
            let d: Vec<String> = (0..3)
                .map(|c| format!("{:+.1}", 100.0 * (m.rho_d[c] / t.rho_d[c] - 1.0)))
                .collect();
            println!(
                "  {:8} {:?} ρd {} %; errors {:?}; albedo {:.3}; lobe {:?}; BIC {:?}\n      {}",
                r.name,
                r.model,
                d.join("/"),
                errors(m, t).map(|e| e.map(|v| (v * 10.0).round() / 10.0)),
                r.directional_albedo[0],
                m.lobe.map(|l| (l.rho_s, l.alpha_x, l.alpha_y)),
                r.bic,
                r.reason
            );
        }
        if env("RELIT", 1) == 0 {
            continue;
        }
        let t = Instant::now();
        let map = AlbedoMap::build(
            &input,
            &result,
            &AlbedoMapOptions {
                irradiance_rays: env("IRR_RAYS", 64) as u32,
                texel_m: env("TEXEL_MM", 20) as f64 * 1e-3,
                irradiance_cell_m: env("CELL_MM", 250) as f64 * 1e-3,
                max_bounces: b,
                ..AlbedoMapOptions::default()
            },
        )
        .unwrap();
        let map_s = t.elapsed().as_secs_f64();
        for surface in ["paint", "paper", "wood"] {
            let s = input.surfaces.iter().position(|n| n == surface).unwrap();
            let (median, n) = room.albedo_map_error(&map, s);
            println!(
                "  albedo map {surface}: median relative error {:.2} % over {n} texels, median signed {:+.2} %",
                100.0 * median,
                100.0 * room.albedo_map_bias(&map, s)
            );
        }
        let scene = recovered_scene(&input, &result).unwrap();
        let new_lamps = [
            SphereLight::with_intensity(Vector3::new(2.0, 2.2, 2.4), 0.05, [2.5, 2.4, 2.0]),
            SphereLight::with_intensity(Vector3::new(3.6, 2.8, 2.0), 0.05, [1.4, 1.7, 2.3]),
        ];
        let lights: Vec<IgiLight> = new_lamps
            .iter()
            .map(|l| IgiLight {
                position: l.center,
                radius: l.radius,
                intensity: l.radiance.map(|v| v * std::f64::consts::PI * l.radius * l.radius),
            })
            .collect();
        let camera = cams[0].1;
        let rs = RelightSettings {
            indirect_samples: 32,
            max_bounces: b,
            seed: 5,
        };
        let t = Instant::now();
        let ours = relight(&scene, Some(&map), &lights, &camera, &rs);
        let relight_s = t.elapsed().as_secs_f64();
        let flat = relight(&scene, None, &lights, &camera, &rs);
        let same = relight(room.scene(), None, &lights, &camera, &rs);
        let sim = room.photograph(
            &new_lamps,
            &[],
            &camera,
            &PhotoSettings {
                indirect_samples: 32,
                max_bounces: b,
                seed: 99,
            },
        );
        let (ob, fb, sb) = (block_average(&ours, 4), block_average(&same, 4), block_average(&sim, 4));
        let flat_b = block_average(&flat, 4);
        let keep = |i: usize| sb.data[i * 3] < 20.0;
        let mean = |im: &campanile_process::camera::image::RadianceImage| {
            im.data.iter().map(|v| f64::from(*v)).sum::<f64>() / im.data.len() as f64
        };
        println!(
            "  relit {:.2} % (4x4 blocks), noise floor {:.2} %; mean relit/simulator − 1 {:+.2} %; albedo maps {map_s:.1} s, relight {relight_s:.1} s",
            100.0 * relative_rmse(&ob, &sb, keep).unwrap_or(f64::NAN),
            100.0 * relative_rmse(&fb, &sb, keep).unwrap_or(f64::NAN),
            100.0 * (mean(&ours) / mean(&sim) - 1.0)
        );
        {
            // The relit error by the material a block's centre ray meets.
            let names = room.material_names();
            let mut per = vec![(0.0f64, 0.0f64, 0usize); names.len() + 1];
            for y in 0..sb.height {
                for x in 0..sb.width {
                    let i = y * sb.width + x;
                    if !keep(i) {
                        continue;
                    }
                    let ray = campanile_process::render::Ray {
                        origin: camera.position,
                        direction: camera.direction(x as f64 * 4.0 + 2.0, y as f64 * 4.0 + 2.0),
                    };
                    let m = room
                        .scene()
                        .intersect(&ray, f64::INFINITY)
                        .map_or(names.len(), |h| room.scene().triangles()[h.triangle].material as usize);
                    for c in 0..3 {
                        let (a, r) = (f64::from(ob.data[i * 3 + c]), f64::from(sb.data[i * 3 + c]));
                        per[m].0 += (a - r) * (a - r);
                        per[m].1 += r;
                        per[m].2 += 1;
                    }
                }
            }
            let total: f64 = per.iter().map(|p| p.0).sum();
            let line: Vec<String> = per
                .iter()
                .enumerate()
                .filter(|(_, p)| p.2 > 0)
                .map(|(k, p)| {
                    format!(
                        "{} {:.1} % ({} blocks, {:.0} % of the squared error)",
                        names.get(k).map_or("none", String::as_str),
                        100.0 * (p.0 / p.2 as f64).sqrt() / (p.1 / p.2 as f64),
                        p.2 / 3,
                        100.0 * p.0 / total
                    )
                })
                .collect();
            println!("  relit by material: {}", line.join("; "));
        }
        if env("ASCII", 0) == 1 {
            // Per 4×4 block, relit / simulator − 1 in tens of per cent (channel sum).
            for y in 0..sb.height {
                let row: String = (0..sb.width)
                    .map(|x| {
                        let i = y * sb.width + x;
                        let a: f64 = (0..3).map(|c| f64::from(ob.data[i * 3 + c])).sum();
                        let r: f64 = (0..3).map(|c| f64::from(sb.data[i * 3 + c])).sum();
                        let e = (10.0 * (a / r - 1.0)).round() as i64;
                        match e {
                            0 => " .".to_string(),
                            e if e > 9 => " +".to_string(),
                            e if e < -9 => " -".to_string(),
                            e => format!("{e:2}"),
                        }
                    })
                    .collect();
                println!("  {row}");
            }
        }
        println!(
            "  relit with each surface's recovered ρd instead of the albedo maps: {:.2} %",
            100.0 * relative_rmse(&flat_b, &sb, keep).unwrap_or(f64::NAN)
        );
    }
}
