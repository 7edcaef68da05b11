//! Error budget of the room's recovery (issue 10): the same room
//! photographed with paths cut after `max_bounces` scattering events, for
//! several cuts, and recovered; prints, per material, the recovered ρd
//! against the true texture mean, the model chosen and why; then the
//! albedo maps' median error, and the room relit under two new lamps
//! against the simulator's render of them (relative RMSE per 4×4 block),
//! beside the same renderer with the true materials (its noise floor).
//! With `RELIT=0` the relighting is skipped.
//!
//! With `BUDGET=1`, the relit error's noise budget (each term measured by
//! swapping one input for a converged or true one; RMSE per 4×4 block):
//! (a) the reference render's noise (`REF_SPP`, default 32, against a
//! converged reference of `CONV_SPP`, default 512, paths per pixel); (b)
//! the relit render's noise (`RELIT_SPP`, default 32, against `CONV_SPP`);
//! (c) the albedo maps' noise from the photographs' Monte Carlo noise
//! (maps from photographs of `PHOTO_CONV`, default 256, paths per pixel);
//! (d) the maps' noise from their indirect-irradiance estimate
//! (`IRR_CONV`, default 1024, rays per lattice node); (e) the bias left
//! with converged photographs, irradiance and renders (the BRDF
//! parameters, the texels), beside the same renderer with the true
//! materials against the converged reference (the renderer's own bias).
//!
//! `cargo run --release -p campanile-sim --example igi_room_budget [-- W H BOUNCES...]`
//! (defaults 80 60 4 16); the solver's cells per edge, gather rays and ΔS
//! passes from the environment variables `CELLS`, `GATHER`, `ITER`,
//! `LOBE`, `SPARSE` (defaults 6, 64, 3, 16, 2500); the photographs'
//! indirect samples per pixel from `SPP` (16), the albedo maps' rays per
//! irradiance cell, texel and cell sides from `IRR_RAYS` (64), `TEXEL_MM`
//! (20), `CELL_MM` (250), the maps' noise shrinkage from `SHRINK` (1:
//! on), the rays sampled from the lobe for ΔS from `SPEC_RAYS` (8; 0:
//! the uniform-light approximation); the relit render's and the
//! reference's paths per pixel from `RELIT_SPP` and `REF_SPP` (32).
//!
//! With `ORACLE` (a sum of bits), the maps' and the materials' share of the
//! relit error, each input swapped for the truth through the same renders
//! against the same reference: 1, maps of the true textures on 20, 10 and
//! 5 mm texels (at each texel's centre, or its box mean); 2, the map as
//! built with one surface's texels made true; 4, the scene the paths
//! bounce through (true, recovered, or the map's means as ρd; each
//! recovered lobe in turn among true BRDFs) and `PASSES` (2) rebuilds of
//! the map gathered through the previous map's means.

use std::time::Instant;

use campanile_process::camera::image::RadianceImage;
use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::relight::{RelightSettings, relative_rmse, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiOptions, ViewCamera, recover};
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::{RoomIgi, block_average, igi_lights_of, new_lamps, relit_block_error};

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
    let room = RoomIgi::example().unwrap();
    let truth = room.true_materials().unwrap();
    let cams = room.solver_cameras(w, h);
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
        let map_options = AlbedoMapOptions {
            irradiance_rays: env("IRR_RAYS", 64) as u32,
            texel_m: env("TEXEL_MM", 20) as f64 * 1e-3,
            irradiance_cell_m: env("CELL_MM", 250) as f64 * 1e-3,
            max_bounces: b,
            shrink_noise: env("SHRINK", 1) == 1,
            specular_rays: env("SPEC_RAYS", 8) as u32,
            ..AlbedoMapOptions::default()
        };
        let map = AlbedoMap::build(&input, &result, &map_options).unwrap();
        let map_s = t.elapsed().as_secs_f64();
        for surface in ["paint", "paper", "wood"] {
            let s = input.surfaces.iter().position(|n| n == surface).unwrap();
            let (median, n) = room.albedo_map_error(&map, s);
            println!(
                "  albedo map {surface}: median relative error {:.2} % over {n} texels, median signed {:+.2} %, texture correlation {:.3}",
                100.0 * median,
                100.0 * room.albedo_map_bias(&map, s),
                room.albedo_map_texture_correlation(&map, s)
            );
        }
        let scene = recovered_scene(&input, &result).unwrap();
        let new_lamps = new_lamps();
        let lights = igi_lights_of(&new_lamps);
        let camera = cams[0].1;
        let rs = RelightSettings {
            indirect_samples: env("RELIT_SPP", 32) as u32,
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
                indirect_samples: env("REF_SPP", 32) as u32,
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
        println!("  relit by material: {}", by_material(&room, &camera, &ours, &sim));
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
        if env("ORACLE", 0) > 0 {
            let oracle = env("ORACLE", 0);
            // The maps' reconstruction alone: texel maps filled with the
            // true texture (at each texel's centre, or its box mean), the
            // recovered lobes, through the same renders.
            for texel_mm in if oracle & 1 != 0 { vec![20usize, 10, 5] } else { vec![] } {
                for boxed in [false, true] {
                    let m = truth_map(&room, texel_mm as f64 * 1e-3, boxed);
                    let r = relight(&scene, Some(&m), &lights, &camera, &rs);
                    println!(
                        "  oracle: true texels {texel_mm} mm ({}) relit {:.2} %; by material: {}",
                        if boxed { "box mean" } else { "centre" },
                        100.0 * relit_block_error(&r, &sim).unwrap_or(f64::NAN),
                        by_material(&room, &camera, &r, &sim)
                    );
                }
            }
            // The bounces: the first vertex's albedo from a map, the
            // further vertices from a scene with each surface's constant ρd
            // taken from the truth, the recovered material or the map's mean.
            if oracle & 4 != 0 {
                let exact = truth_map(&room, map_options.texel_m, true);
                let with_rho = |rho: &dyn Fn(usize) -> [f64; 3]| {
                    let mut r = result.clone();
                    for (s, sr) in r.surfaces.iter_mut().enumerate() {
                        if let Some(m) = sr.material.as_mut() {
                            m.rho_d = rho(s);
                        }
                    }
                    r
                };
                let mut true_all = result.clone();
                for (r, t) in true_all.surfaces.iter_mut().zip(&truth) {
                    r.material = Some(*t);
                }
                let true_flat = recovered_scene(&input, &true_all).unwrap();
                for (label, sc, m) in [
                    ("true scene, no map", room.scene(), None),
                    ("true scene, true texels", room.scene(), Some(&exact)),
                    ("true BRDFs flat, no map", &true_flat, None),
                    ("true BRDFs flat, true texels", &true_flat, Some(&exact)),
                ] {
                    let im = relight(sc, m, &lights, &camera, &rs);
                    println!(
                        "  oracle: {label}: relit {:.2} %; {}",
                        100.0 * relit_block_error(&im, &sim).unwrap_or(f64::NAN),
                        by_material(&room, &camera, &im, &sim)
                    );
                }
                for (s, name) in input.surfaces.iter().enumerate() {
                    let mut r = true_all.clone();
                    r.surfaces[s].material = result.surfaces[s].material.map(|mut m| {
                        m.rho_d = truth[s].rho_d;
                        m
                    });
                    let sc = recovered_scene(&input, &r).unwrap();
                    let im = relight(&sc, Some(&exact), &lights, &camera, &rs);
                    println!(
                        "  oracle: true BRDFs but {name}'s recovered lobe, true texels: relit {:.2} %; {}",
                        100.0 * relit_block_error(&im, &sim).unwrap_or(f64::NAN),
                        by_material(&room, &camera, &im, &sim)
                    );
                }
                let true_rho = with_rho(&|s| truth[s].rho_d);
                let map_means: Vec<[f64; 3]> = (0..input.surfaces.len()).map(|s| map_mean(&room, &map, s)).collect();
                let map_rho = with_rho(&|s| map_means[s]);
                for (label, r) in [
                    ("true ρd", &true_rho),
                    ("map means", &map_rho),
                    ("recovered ρd", &result),
                ] {
                    let sc = recovered_scene(&input, r).unwrap();
                    for (mlabel, m) in [("true texels", &exact), ("built map", &map)] {
                        let im = relight(&sc, Some(m), &lights, &camera, &rs);
                        println!(
                            "  oracle: first vertex {mlabel}, bounces {label}: relit {:.2} %; {}",
                            100.0 * relit_block_error(&im, &sim).unwrap_or(f64::NAN),
                            by_material(&room, &camera, &im, &sim)
                        );
                    }
                }
                println!(
                    "  map means vs truth (%): {}",
                    (0..input.surfaces.len())
                        .map(|s| format!(
                            "{} {:+.1}/{:+.1}/{:+.1}",
                            input.surfaces[s],
                            100.0 * (map_means[s][0] / truth[s].rho_d[0] - 1.0),
                            100.0 * (map_means[s][1] / truth[s].rho_d[1] - 1.0),
                            100.0 * (map_means[s][2] / truth[s].rho_d[2] - 1.0)
                        ))
                        .collect::<Vec<_>>()
                        .join("; ")
                );
                // The map rebuilt with the indirect light gathered through the
                // scene of the first map's means (one fixed-point step).
                let mut m2 = map.clone();
                let mut r2 = map_rho.clone();
                for pass in 1..=env("PASSES", 2) {
                    m2 = AlbedoMap::build(&input, &r2, &map_options).unwrap();
                    let means: Vec<[f64; 3]> = (0..input.surfaces.len()).map(|s| map_mean(&room, &m2, s)).collect();
                    let sc = recovered_scene(&input, &r2).unwrap();
                    let im = relight(&sc, Some(&m2), &lights, &camera, &rs);
                    println!(
                        "  oracle: map pass {pass} (gathered through the previous map's means): relit {:.2} %; {}",
                        100.0 * relit_block_error(&im, &sim).unwrap_or(f64::NAN),
                        by_material(&room, &camera, &im, &sim)
                    );
                    r2 = with_rho(&|s| means[s]);
                }
                let _ = m2;
            }
            // The map as built, with one surface at a time replaced by its
            // true texels (centre, the map's texel size).
            let exact = truth_map(&room, map_options.texel_m, false);
            for (s, name) in input.surfaces.iter().enumerate().filter(|_| oracle & 2 != 0) {
                let mut m = map.clone();
                for (k, tri) in room.scene().triangles().iter().enumerate() {
                    if tri.material as usize == s {
                        m.triangles[k] = exact.triangles[k].clone();
                    }
                }
                let r = relight(&scene, Some(&m), &lights, &camera, &rs);
                println!(
                    "  oracle: the map with {name}'s texels true: relit {:.2} %",
                    100.0 * relit_block_error(&r, &sim).unwrap_or(f64::NAN)
                );
            }
        }
        if env("BUDGET", 0) == 1 {
            let conv = env("CONV_SPP", 512) as u32;
            let e = |a: &campanile_process::camera::image::RadianceImage,
                     r: &campanile_process::camera::image::RadianceImage| {
                100.0 * relit_block_error(a, r).unwrap_or(f64::NAN)
            };
            let t = Instant::now();
            let reference = room.photograph(
                &new_lamps,
                &[],
                &camera,
                &PhotoSettings {
                    indirect_samples: conv,
                    max_bounces: b,
                    seed: 4242,
                },
            );
            let conv_rs = RelightSettings {
                indirect_samples: conv,
                seed: 77,
                ..rs
            };
            let ours_conv = relight(&scene, Some(&map), &lights, &camera, &conv_rs);
            let same_conv = relight(room.scene(), None, &lights, &camera, &conv_rs);
            println!(
                "  budget: converged renders ({conv} paths per pixel) {:.1} s",
                t.elapsed().as_secs_f64()
            );
            let t = Instant::now();
            let input_conv = room.igi_input(
                cams.clone(),
                &PhotoSettings {
                    indirect_samples: env("PHOTO_CONV", 256) as u32,
                    max_bounces: b,
                    seed: 7,
                },
            );
            let map_pc = AlbedoMap::build(&input_conv, &result, &map_options).unwrap();
            let irr = AlbedoMapOptions {
                irradiance_rays: env("IRR_CONV", 1024) as u32,
                ..map_options
            };
            let map_ic = AlbedoMap::build(&input, &result, &irr).unwrap();
            let map_both = AlbedoMap::build(&input_conv, &result, &irr).unwrap();
            println!(
                "  budget: converged photographs and maps {:.1} s",
                t.elapsed().as_secs_f64()
            );
            let r_pc = relight(&scene, Some(&map_pc), &lights, &camera, &conv_rs);
            let r_ic = relight(&scene, Some(&map_ic), &lights, &camera, &conv_rs);
            let r_both = relight(&scene, Some(&map_both), &lights, &camera, &conv_rs);
            let r_flat = relight(&scene, None, &lights, &camera, &conv_rs);
            // The true BRDFs in place of the recovered ones (ρd the true
            // texture's mean): what of (e) the parameters carry.
            let mut true_result = result.clone();
            for (r, t) in true_result.surfaces.iter_mut().zip(&truth) {
                r.material = Some(*t);
            }
            let true_scene = recovered_scene(&input, &true_result).unwrap();
            let map_true = AlbedoMap::build(&input_conv, &true_result, &irr).unwrap();
            let r_true = relight(&true_scene, Some(&map_true), &lights, &camera, &conv_rs);
            for (name, m) in [
                ("photos converged", &map_pc),
                ("irradiance converged", &map_ic),
                ("both converged", &map_both),
            ] {
                for surface in ["paint", "paper", "wood"] {
                    let s = input.surfaces.iter().position(|n| n == surface).unwrap();
                    println!(
                        "    map ({name}) {surface}: median error {:.2} %, texture correlation {:.3}",
                        100.0 * room.albedo_map_error(m, s).0,
                        room.albedo_map_texture_correlation(m, s)
                    );
                }
            }
            println!("  budget (RMSE per 4x4 block, %):");
            println!(
                "    total, relit vs reference as tested          {:6.2}",
                e(&ours, &sim)
            );
            println!(
                "    total, relit vs converged reference          {:6.2}",
                e(&ours, &reference)
            );
            println!(
                "    (a) reference noise: reference vs converged  {:6.2}",
                e(&sim, &reference)
            );
            println!(
                "    (b) relit render noise: relit vs converged   {:6.2}",
                e(&ours, &ours_conv)
            );
            println!(
                "    (c) maps from photos: map vs photos-converged map (converged renders) {:6.2}",
                e(&ours_conv, &r_pc)
            );
            println!(
                "    (d) maps' irradiance: map vs irradiance-converged map              {:6.2}",
                e(&ours_conv, &r_ic)
            );
            println!(
                "    (e) bias: converged maps and renders vs converged reference        {:6.2}",
                e(&r_both, &reference)
            );
            println!(
                "        by material (%): {}",
                by_material(&room, &camera, &r_both, &reference)
            );
            println!(
                "        the same with the true BRDFs (maps from converged photographs)  {:6.2}",
                e(&r_true, &reference)
            );
            println!(
                "        by material (%): {}",
                by_material(&room, &camera, &r_true, &reference)
            );
            println!(
                "        same renderer, true materials, vs converged reference          {:6.2}",
                e(&same_conv, &reference)
            );
            println!(
                "        recovered ρd per surface (no maps), vs converged reference     {:6.2}",
                e(&r_flat, &reference)
            );
            println!(
                "        converged renders, the map as built, vs converged reference    {:6.2}",
                e(&ours_conv, &reference)
            );
        }
    }
}

/// The seen texels' mean albedo of solver surface `surface` in `map`
/// (unweighted; the recovered fallback when none was seen).
fn map_mean(room: &RoomIgi, map: &AlbedoMap, surface: usize) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0.0);
    for (tri, texels) in room.scene().triangles().iter().zip(&map.triangles) {
        if tri.material as usize != surface {
            continue;
        }
        for (a, w) in texels.albedo.iter().zip(&texels.weight) {
            if *w > 0.0 {
                for c in 0..3 {
                    sum[c] += f64::from(a[c]);
                }
                n += 1.0;
            }
        }
    }
    if n > 0.0 {
        sum.map(|v| v / n)
    } else {
        map.fallback[surface]
    }
}

/// An albedo map of the true textures on `texel_m` texels (the map's own
/// grid per triangle), each texel the texture at its centre or (`boxed`)
/// its mean over 8 × 8 points.
fn truth_map(room: &RoomIgi, texel_m: f64, boxed: bool) -> AlbedoMap {
    use campanile_process::igi::albedo_map::TriangleTexels;
    let scene = room.scene();
    let appearances = &room.loaded.appearances;
    let triangles = scene
        .triangles()
        .iter()
        .map(|tri| {
            let st: Vec<[f64; 2]> = tri.vertices.iter().map(|v| tri.texture_coordinates(v)).collect();
            let lo = [0, 1].map(|k| st.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
            let hi = [0, 1].map(|k| st.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
            let size = [0, 1].map(|k| (((hi[k] - lo[k]) / texel_m).ceil() as usize).clamp(1, 4096));
            let tex = &appearances[tri.material as usize].albedo;
            let mut albedo = Vec::with_capacity(size[0] * size[1]);
            for j in 0..size[1] {
                for i in 0..size[0] {
                    let n = if boxed { 8 } else { 1 };
                    let mut sum = [0.0; 3];
                    for b in 0..n {
                        for a in 0..n {
                            let p = [
                                lo[0] + (i as f64 + (a as f64 + 0.5) / n as f64) * texel_m,
                                lo[1] + (j as f64 + (b as f64 + 0.5) / n as f64) * texel_m,
                            ];
                            let v = tex.albedo(p);
                            for c in 0..3 {
                                sum[c] += v[c] / (n * n) as f64;
                            }
                        }
                    }
                    albedo.push(sum.map(|v| v as f32));
                }
            }
            TriangleTexels {
                origin: lo,
                size,
                albedo,
                weight: vec![1.0; size[0] * size[1]],
            }
        })
        .collect();
    AlbedoMap {
        texel_m,
        triangles,
        fallback: appearances.iter().map(|a| a.albedo.mean_albedo()).collect(),
        samples: (0, 0),
    }
}

/// The relit error by the material a block's centre ray meets: per
/// material, the relative RMSE of `image`'s 4×4-block means against
/// `reference`'s, the blocks, and the share of the squared error (blocks
/// with a bulb left out).
fn by_material(room: &RoomIgi, camera: &ViewCamera, image: &RadianceImage, reference: &RadianceImage) -> String {
    let (ib, rb) = (block_average(image, 4), block_average(reference, 4));
    let names = room.material_names();
    let mut per = vec![(0.0f64, 0.0f64, 0usize); names.len() + 1];
    for y in 0..rb.height {
        for x in 0..rb.width {
            let i = y * rb.width + x;
            if rb.data[i * 3] >= 20.0 {
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
                let (a, r) = (f64::from(ib.data[i * 3 + c]), f64::from(rb.data[i * 3 + c]));
                per[m].0 += (a - r) * (a - r);
                per[m].1 += r;
                per[m].2 += 1;
            }
        }
    }
    let total: f64 = per.iter().map(|p| p.0).sum();
    per.iter()
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
        .collect::<Vec<_>>()
        .join("; ")
}
