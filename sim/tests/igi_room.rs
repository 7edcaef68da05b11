//! Inverse global illumination on the simulated room (thesis §4.7.2).

use campanile_process::igi::albedo_map::{AlbedoMap, AlbedoMapOptions};
use campanile_process::igi::relight::{RelightSettings, relative_rmse, relight};
use campanile_process::igi::relit_scene::recovered_scene;
use campanile_process::igi::{IgiLight, IgiOptions, format_table, recover};
use campanile_process::render::SphereLight;
use campanile_sim::world::examples_dir;
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::room_igi::RoomIgi;
use nalgebra::Vector3;

fn room() -> RoomIgi {
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron")).unwrap();
    RoomIgi::load(&examples_dir().join("room-scene.ron"), &station.value).unwrap()
}

#[test]
fn explore() {
    let room = room();
    let t = std::time::Instant::now();
    let mut cams = room.cameras(60.0, 128, 96);
    let hl = room.highlight_cameras(20.0, 48);
    cams.extend(hl);
    let input = room.igi_input(
        cams,
        &PhotoSettings {
            indirect_samples: 16,
            max_bounces: 4,
            seed: 7,
        },
    );
    eprintln!("photo {:.1}s", t.elapsed().as_secs_f64());
    let opts = IgiOptions {
        cells_per_edge: 8,
        gather_rays: 64,
        ..IgiOptions::default()
    };
    let r = recover(&input, &opts).unwrap();
    let truth: Vec<_> = room.true_materials().unwrap().into_iter().map(Some).collect();
    eprintln!("{}", format_table(&r, &truth, None));
    let t = std::time::Instant::now();
    let map = AlbedoMap::build(&input, &r, &AlbedoMapOptions::default()).unwrap();
    eprintln!("albedo map {:.1}s {:?}", t.elapsed().as_secs_f64(), map.samples);
    let scene = recovered_scene(&input, &r).unwrap();
    let new_lights = [
        SphereLight::with_intensity(Vector3::new(2.0, 2.2, 2.4), 0.05, [2.5, 2.4, 2.0]),
        SphereLight::with_intensity(Vector3::new(3.6, 2.8, 2.0), 0.05, [1.4, 1.7, 2.3]),
    ];
    let igi_new: Vec<IgiLight> = new_lights
        .iter()
        .map(|b| IgiLight {
            position: b.center,
            radius: b.radius,
            intensity: b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius),
        })
        .collect();
    for (name, cam) in room.cameras(60.0, 128, 96).into_iter().take(1) {
        let same = relight(
            room.scene(),
            None,
            &igi_new,
            &cam,
            &RelightSettings {
                indirect_samples: 32,
                ..Default::default()
            },
        );
        let mean = |i: &campanile_process::camera::image::RadianceImage| {
            i.data.iter().filter(|v| **v < 50.0).map(|v| *v as f64).sum::<f64>() / i.data.len() as f64
        };
        let t = std::time::Instant::now();
        let ours = relight(
            &scene,
            Some(&map),
            &igi_new,
            &cam,
            &RelightSettings {
                indirect_samples: 32,
                ..Default::default()
            },
        );
        let flat = relight(
            &scene,
            None,
            &igi_new,
            &cam,
            &RelightSettings {
                indirect_samples: 32,
                ..Default::default()
            },
        );
        let truth = room.photograph(
            &new_lights,
            &[],
            &cam,
            &PhotoSettings {
                indirect_samples: 32,
                max_bounces: 4,
                seed: 99,
            },
        );
        let keep = |i: usize| truth.data[i * 3] < 50.0;
        eprintln!(
            "means truth {} same {} ours {} flat {} ; same rmse {:?}",
            mean(&truth),
            mean(&same),
            mean(&ours),
            mean(&flat),
            relative_rmse(&same, &truth, keep)
        );
        eprintln!(
            "{name}: relit rmse {:?} (no map {:?}) {:.1}s",
            relative_rmse(&ours, &truth, keep),
            relative_rmse(&flat, &truth, keep),
            t.elapsed().as_secs_f64()
        );
    }
}
