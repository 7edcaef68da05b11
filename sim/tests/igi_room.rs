//! Inverse global illumination on the simulated room (thesis §4.7.2): the
//! lamps triangulated from their bulbs' images, the materials recovered
//! despite mutual illumination, albedo maps free of highlights and colour
//! bleeding, and the room relit under lamps the capture never used.

use campanile_process::camera::image::RadianceImage;
use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::light_triangulation::{BulbImage, triangulate};
use campanile_process::igi::relight::{RelightSettings, relative_rmse, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiOptions, SurfaceModel, ViewCamera, format_table, recover};
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::{ROOM_BOUNCES, RoomIgi, igi_lights_of, new_lamps, relit_block_error};

fn room() -> RoomIgi {
    RoomIgi::example().unwrap()
}

#[test]
fn the_lamps_are_triangulated_from_their_bulbs() {
    let room = room();
    for (name, bulb) in &room.lamps {
        let cams: Vec<ViewCamera> = room
            .cameras(60.0, 8, 8)
            .into_iter()
            .take(3)
            .map(|(_, c)| ViewCamera {
                look: bulb.center - c.position,
                vfov_rad: 8f64.to_radians(),
                width: 64,
                height: 64,
                ..c
            })
            .collect();
        let images: Vec<RadianceImage> = cams
            .iter()
            .map(|c| {
                room.photograph(
                    std::slice::from_ref(bulb),
                    &[],
                    c,
                    &PhotoSettings {
                        indirect_samples: 0,
                        max_bounces: 1,
                        seed: 1,
                    },
                )
            })
            .collect();
        let views: Vec<BulbImage> = cams
            .iter()
            .zip(&images)
            .map(|(c, i)| BulbImage {
                name: "bulb",
                camera: *c,
                image: i,
            })
            .collect();
        let t = triangulate(name, &views).unwrap();
        let mm = (t.light.position - bulb.center).norm() * 1e3;
        let truth = bulb
            .radiance
            .map(|l| l * std::f64::consts::PI * bulb.radius * bulb.radius);
        let worst = (0..3)
            .map(|c| (t.light.intensity[c] / truth[c] - 1.0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: position {mm:.2} mm, radius {:.4} m (true {:.4}), intensity {:.2} %",
            t.light.radius,
            bulb.radius,
            100.0 * worst
        );
        assert!(mm < 2.0, "{name}: {mm:.2} mm off");
        assert!(worst < 0.05, "{name}: intensity {:.2} % off", 100.0 * worst);
    }
}

#[test]
fn the_room_is_recovered_and_relit_under_new_lamps() {
    let room = room();
    let cams = room.solver_cameras(80, 60);
    let settings = PhotoSettings {
        indirect_samples: 16,
        max_bounces: ROOM_BOUNCES,
        seed: 7,
    };
    let input = room.igi_input(cams, &settings);
    // The roughness search on the default 2 500 samples per surface: the
    // brushed board's wide αy, which trades against ρd, comes back 4.2 %
    // off now that the metal sphere's lobe is recovered (6.2 % with it
    // diffuse, which took 6 000 samples to bring to 5.2 %).
    let opts = IgiOptions {
        cells_per_edge: 6,
        gather_rays: 64,
        ..IgiOptions::default()
    };
    let result = recover(&input, &opts).unwrap();
    let truth = room.true_materials().unwrap();
    let truth_opt: Vec<_> = truth.iter().copied().map(Some).collect();
    eprintln!("{}", format_table(&result, &truth_opt, None));
    for (r, t) in result.surfaces.iter().zip(&truth) {
        eprintln!(
            "{}: {:?} {:?}",
            r.name,
            r.model,
            errors(r.material.as_ref().unwrap(), t)
        );
    }
    // Tolerances (percent; γ in degrees) stated from the measured run
    // (ρd, ρs, αx, αy, γ): the shiny boards, floor and spheres, seen in
    // their highlight views, are recovered (the metal sphere's from the
    // free-position views of `RoomIgi::mirror_cameras`: no scene pose sees
    // its faceted highlight; the case of a highlight in no view is
    // `igi_hard_cases.rs`'s); the matte paint and paper, whose flagged
    // "highlights" a lobe cannot explain, stay diffuse.
    // Measured (photographs with 12 scattering events, BENCHMARKS.md):
    // wood 3.0, 30.6, 1.5, 1.5; brushed 0.8, 1.3, 1.7, 4.2, 0.4°;
    // plastic 4.4, 5.1, 3.6, 3.6; metal 3.1, 2.2, 2.4, 2.4; paint 0.4;
    // paper 0.6 (before the metal's views, with 6 000 sparse samples:
    // wood 3.7, 40.1, 2.2; brushed 2.1, 0.7, 2.0, 5.2, 0.3°; plastic 3.0,
    // 0.0, 2.3; paint 1.2; the metal diffuse-only, its ρd 15 times the truth).
    let expect: [(&str, SurfaceModel, [f64; 5]); 6] = [
        ("wood", SurfaceModel::Isotropic, [20.0, 40.0, 8.0, 8.0, 0.1]),
        ("brushed", SurfaceModel::Anisotropic, [6.0, 8.0, 8.0, 6.0, 2.0]),
        ("plastic", SurfaceModel::Isotropic, [25.0, 20.0, 18.0, 18.0, 0.1]),
        ("paint", SurfaceModel::DiffuseOnly, [3.0, 0.0, 0.0, 0.0, 0.0]),
        ("paper", SurfaceModel::DiffuseOnly, [3.0, 0.0, 0.0, 0.0, 0.0]),
        ("metal", SurfaceModel::Isotropic, [8.0, 6.0, 6.0, 6.0, 0.1]),
    ];
    for (name, model, tol) in expect {
        let s = result.surfaces.iter().position(|r| r.name == name).unwrap();
        let r = &result.surfaces[s];
        assert_eq!(r.model, model, "{name}: {}", r.reason);
        let e = errors(r.material.as_ref().unwrap(), &truth[s]);
        for k in 0..5 {
            if let Some(v) = e[k] {
                assert!(
                    v.is_finite() && v <= tol[k],
                    "{name} parameter {k}: {v:.2} off (tolerance {})",
                    tol[k]
                );
            }
        }
    }
    for name in ["paint", "paper"] {
        let r = result.surfaces.iter().find(|r| r.name == name).unwrap();
        assert!(r.reason.contains("of the diffuse fit's residual"), "{}", r.reason);
    }

    let map = AlbedoMap::build(
        &input,
        &result,
        // Indirect irradiance on a 12.5 cm lattice, 64 rays per node: the
        // lattice's interpolation error outweighs its nodes' noise (25 cm
        // with 256 rays: relit 3.72 %; 12.5 cm with 64: 3.44 % at half the
        // cost; 10 cm with 128: 3.09 % at four times it; BENCHMARKS.md).
        // 1 cm texels: 2 cm ones mix the posters' 5 cm stripes (true
        // texels' box means on 2 cm: paper 4.4 % per block; on 1 cm: 2.0 %).
        &AlbedoMapOptions {
            irradiance_rays: 64,
            irradiance_cell_m: 0.125,
            texel_m: 0.01,
            ..AlbedoMapOptions::default()
        },
    )
    .unwrap();
    // Albedo maps against the true textures: median relative error over
    // the seen texels, and against a baseline that divides by the lamps'
    // light only and keeps highlights (colour bleeding and interreflection
    // stay in it); the textured surfaces' pattern, by the correlation of
    // map and truth over the texels. Measured (noise shrinkage aware of
    // the gather's noise, 12.5 cm irradiance lattice, 1 cm texels): paint
    // 1.6 %, paper 12.5 % (correlation 0.90), wood 8.1 % (0.34: 3 cm
    // stripes seen by pixels about 5 cm wide); on 2 cm texels, the
    // shrinkage blind to the gather: 3.0 / 12.1 (0.70) / 9.9 % (0.22);
    // before the shrinkage 11.4 / 15.3 / 20.1 % (bounds 15 / 20 / 25 %).
    let naive = AlbedoMap::build(
        &input,
        &result,
        &AlbedoMapOptions {
            texel_m: 0.01,
            indirect: false,
            remove_specular: false,
            shrink_noise: false,
            ..AlbedoMapOptions::default()
        },
    )
    .unwrap();
    for (surface, tol, min_correlation) in [
        ("paint", 0.03, None),
        ("paper", 0.15, Some(0.85)),
        ("wood", 0.11, Some(0.28)),
    ] {
        let s = input.surfaces.iter().position(|n| n == surface).unwrap();
        let (median, n) = room.albedo_map_error(&map, s);
        let (base, _) = room.albedo_map_error(&naive, s);
        let correlation = room.albedo_map_texture_correlation(&map, s);
        eprintln!(
            "albedo map {surface}: median relative error {:.2} % over {n} texels; baseline {:.2} %; texture correlation {correlation:.3}",
            100.0 * median,
            100.0 * base
        );
        assert!(n > 500 && median < tol, "{surface}: {median} over {n} texels");
        assert!(median < base, "{surface}: {median} not below the baseline's {base}");
        if let Some(c) = min_correlation {
            assert!(correlation > c, "{surface}: texture correlation {correlation}");
        }
    }

    let scene = recovered_scene(&input, &result).unwrap();
    let new_lamps = new_lamps();
    let lights = igi_lights_of(&new_lamps);
    let camera = input.views[0].camera;
    // 256 stratified paths per pixel in both renders, so that their Monte
    // Carlo noise (the "floor", about 1.2 % per block together) stays well
    // below the 3 % checked.
    let rs = RelightSettings {
        indirect_samples: 256,
        max_bounces: ROOM_BOUNCES,
        seed: 5,
    };
    let ours = relight(&scene, Some(&map), &lights, &camera, &rs);
    let same = relight(room.scene(), None, &lights, &camera, &rs);
    let sim = room.photograph(
        &new_lamps,
        &[],
        &camera,
        &PhotoSettings {
            indirect_samples: 256,
            max_bounces: ROOM_BOUNCES,
            seed: 99,
        },
    );
    let relit = relit_block_error(&ours, &sim).unwrap();
    let floor = relit_block_error(&same, &sim).unwrap();
    eprintln!(
        "relit: {:.2} % (4x4 blocks); noise floor (true materials, same renderer) {:.2} %; per pixel {:.2} %",
        100.0 * relit,
        100.0 * floor,
        100.0 * relative_rmse(&ours, &sim, |i| sim.data[i * 3] < 20.0).unwrap()
    );
    // Measured: relit 2.67 %, floor 1.40 % (256 paths per pixel in both
    // renders). Before: 3.44 % without the metal's lobe (its reflections
    // of the new lamps missing from the walls), with ΔS as uniform light
    // and 2 cm texels, and the shrinkage blind to the gather's noise; 9.5 %
    // and 3.8 % at 32 paths, 64 irradiance rays on a 25 cm lattice and
    // without the maps' noise shrinkage (BENCHMARKS.md).
    assert!(floor < 0.02, "noise floor {floor}");
    assert!(relit < 0.03, "relit {relit}");
}
