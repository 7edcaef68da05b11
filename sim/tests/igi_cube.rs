//! Inverse global illumination on the simulated cube of §4.7.1: the six
//! walls' Ward parameters (Table 4.1) recovered within 1 % (γ within 0.5°)
//! despite mutual illumination, with the model chosen per wall.

use campanile_process::igi::table::errors;
use campanile_process::igi::{IgiOptions, SurfaceModel, recover};
use campanile_sim::world::cube_room::CubeRoom;
use campanile_sim::world::igi_photograph::PhotoSettings;

#[test]
fn the_unit_cube_walls_are_recovered_within_one_percent() {
    let cube = CubeRoom::new(1.0);
    let input = cube.igi_input(
        96,
        64,
        &PhotoSettings {
            indirect_samples: 32,
            max_bounces: 6,
            seed: 7,
        },
    );
    let result = recover(&input, &IgiOptions::default()).unwrap();
    let expected = [
        SurfaceModel::Anisotropic,
        SurfaceModel::Isotropic,
        SurfaceModel::Isotropic,
        SurfaceModel::Isotropic,
        SurfaceModel::Isotropic,
        SurfaceModel::Anisotropic,
    ];
    let mut worst = [0.0f64; 5];
    for (i, (r, truth)) in result.surfaces.iter().zip(&cube.materials).enumerate() {
        assert_eq!(r.model, expected[i], "{}: {}", r.name, r.reason);
        assert!(r.energy_ok, "{}: {:?}", r.name, r.directional_albedo);
        let m = r.material.unwrap();
        let e = errors(&m, truth);
        for k in 0..4 {
            let v = e[k].unwrap();
            assert!(
                v.is_finite() && v < 1.0,
                "{} parameter {k}: {v:.3} % off ({m:?})",
                r.name
            );
            worst[k] = worst[k].max(v);
        }
        if expected[i] == SurfaceModel::Anisotropic {
            let g = e[4].unwrap();
            assert!(g < 0.5, "{}: γ {g:.3}° off", r.name);
            worst[4] = worst[4].max(g);
        }
    }
    eprintln!(
        "worst errors: ρd {:.2} %, ρs {:.2} %, αx {:.2} %, αy {:.2} %, γ {:.3}°",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
}
