//! The light of a time with no sky scan and no sun shot, estimated from the
//! clear-sky model and the photographs' sunlit/shadowed ratio
//! (`pipeline::estimated_light`), on a small site rendered by Campanile's
//! path tracer: a building of two materials (brick south wall, plaster
//! elsewhere), a neighbour that shades it, a ground; three cameras, three
//! times. The truth's sun and sky are not the model's: the sky is 1.25
//! times the model's and the sun 0.85 times (so the sun-to-sky ratio is
//! 0.68 of the model's), or a turbid atmosphere of another CIE type.

use std::fmt::Write as _;

use campanile_process::outdoor::{Illumination, Photo, ReflectanceSettings, recover_reflectance};
use campanile_process::pipeline::{
    EstimateSettings, EstimatedLight, KnownLight, MeasuredSky, ScaleSource, estimated_light,
};
use campanile_process::render::{CameraRig, Lighting, Material, RenderSettings, Scene, Sky, render};
use campanile_process::scene_geometry::load_obj;
use campanile_process::sky::{Atmosphere, CieSkyType, Daylight};
use campanile_process::sun::{Observer, sun_position};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

const PLASTER: [f64; 3] = [0.62, 0.57, 0.50];
const BRICK: [f64; 3] = [0.46, 0.31, 0.22];

const SCENE: &str = r#"Scene(
    name: "test-site",
    geometry: "site.obj",
    materials: [
        (name: "plaster", model: PseudoBrdf),
        (name: "brick", model: PseudoBrdf),
        (name: "ground", model: Diffuse, albedo: (0.20, 0.19, 0.17)),
        (name: "neighbour", model: Diffuse, albedo: (0.40, 0.38, 0.35)),
    ],
    surfaces: [
        (name: "south-wall", groups: ["south"], material: "brick"),
        (name: "east-wall", groups: ["east"], material: "plaster"),
        (name: "west-wall", groups: ["west"], material: "plaster"),
        (name: "north-wall", groups: ["north"], material: "plaster"),
        (name: "roof", groups: ["roof"], material: "plaster"),
        (name: "ground", groups: ["ground"], material: "ground"),
        (name: "neighbour", groups: ["n-south", "n-north", "n-east", "n-west", "n-roof"], material: "neighbour"),
    ],
)
"#;

const CAMERAS: [([f64; 3], [f64; 3]); 3] = [
    ([3.0, -24.0, 1.6], [0.0, 0.0, 3.0]),
    ([20.0, -18.0, 1.6], [1.0, 0.0, 3.0]),
    ([-24.0, -8.0, 1.6], [0.0, 0.0, 3.0]),
];
const TIMES: [&str; 3] = ["2026-06-21T16:30:00Z", "2026-06-21T20:00:00Z", "2026-06-21T23:30:00Z"];

fn boxed(obj: &mut String, v: &mut usize, lo: [f64; 3], hi: [f64; 3], groups: [&str; 5]) {
    let [x0, y0, z0] = lo;
    let [x1, y1, z1] = hi;
    let faces: [(&str, [[f64; 3]; 4]); 5] = [
        (groups[0], [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]]),
        (groups[1], [[x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]]),
        (groups[2], [[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]]),
        (groups[3], [[x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]]),
        (groups[4], [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]),
    ];
    for (g, quad) in faces {
        writeln!(obj, "g {g}").unwrap();
        for p in quad {
            writeln!(obj, "v {} {} {}", p[0], p[1], p[2]).unwrap();
        }
        writeln!(obj, "f {} {} {} {}", *v + 1, *v + 2, *v + 3, *v + 4).unwrap();
        *v += 4;
    }
}

/// The site and the indices of its target surfaces.
fn site() -> (Scene, Vec<usize>) {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::from("g ground\n");
    for p in [[-60.0, -60.0], [60.0, -60.0], [60.0, 60.0], [-60.0, 60.0]] {
        writeln!(obj, "v {} {} 0", p[0], p[1]).unwrap();
    }
    obj.push_str("f 1 2 3 4\n");
    let mut v = 4;
    boxed(
        &mut obj,
        &mut v,
        [-5.0, -3.0, 0.0],
        [5.0, 3.0, 7.0],
        ["south", "north", "east", "west", "roof"],
    );
    boxed(
        &mut obj,
        &mut v,
        [9.0, -6.0, 0.0],
        [13.0, 4.0, 10.0],
        ["n-south", "n-north", "n-east", "n-west", "n-roof"],
    );
    std::fs::write(dir.path().join("site.obj"), &obj).unwrap();
    let description: campanile_config::Scene = campanile_config::source::ron_options().from_str(SCENE).unwrap();
    let geometry = load_obj(&description, &dir.path().join("site.obj")).unwrap();
    let albedo = |m: &str| match m {
        "plaster" => PLASTER,
        "brick" => BRICK,
        "ground" => [0.20, 0.19, 0.17],
        _ => [0.40, 0.38, 0.35],
    };
    let materials = geometry
        .material_names
        .iter()
        .map(|m| Material::diffuse(m, albedo(m)))
        .collect();
    let scene = Scene::new(geometry.triangles, materials, geometry.surface_names).unwrap();
    let targets = ["south-wall", "east-wall", "west-wall", "north-wall", "roof"]
        .iter()
        .map(|s| scene.surface_index(s).unwrap())
        .collect();
    (scene, targets)
}

fn sun_at(time: DateTime<Utc>) -> [f64; 3] {
    let observer = Observer::from_degrees(37.87, -122.26, 0.0, 1013.25, 15.0);
    sun_position(time, &observer, None).unwrap().direction()
}

/// The model's daylight as a `MeasuredSky`, the sky times `a`, the sun times `b`.
fn light(day: &Daylight, a: f64, b: f64) -> MeasuredSky {
    MeasuredSky {
        sun_direction: day.sun_direction,
        models: day.sky.map(|m| campanile_process::sky::SkyModel { lz: m.lz * a, ..m }),
        sun_irradiance: day.sun_irradiance().map(|e| e * b),
        overcast: None,
    }
}

fn photos_at(scene: &Scene, time: DateTime<Utc>, truth: &MeasuredSky, seed: u64) -> Vec<Photo> {
    CAMERAS
        .iter()
        .enumerate()
        .map(|(k, (p, at))| {
            let look = Vector3::new(at[0] - p[0], at[1] - p[1], at[2] - p[2]);
            let rig = CameraRig::look_at(Vector3::from(*p), look, Vector3::z(), 40f64.to_radians(), 96, 72).unwrap();
            let lighting = Lighting {
                sky: Some(truth),
                points: &[],
                spheres: &[],
            };
            let settings = RenderSettings {
                samples_per_pixel: 16,
                max_bounces: 4,
                seed: seed * 10 + k as u64,
                ..RenderSettings::default()
            };
            Photo {
                label: format!("camera {k} at {time}"),
                image: render(scene, &rig, &lighting, &settings),
                rig,
                time,
                mask: None,
            }
        })
        .collect()
}

/// Per time: (true light, estimate); then the pseudo-albedos' median
/// relative errors (plaster ρ_se, ρ_sun) recovered under the estimates.
fn run(truth_of: &dyn Fn([f64; 3]) -> MeasuredSky) -> (Vec<(MeasuredSky, EstimatedLight)>, f64, f64) {
    let (scene, targets) = site();
    let settings = EstimateSettings::default();
    let mut out = Vec::new();
    let mut all_photos = Vec::new();
    for (k, t) in TIMES.iter().enumerate() {
        let time: DateTime<Utc> = t.parse().unwrap();
        let sun = sun_at(time);
        let truth = truth_of(sun);
        let photos = photos_at(&scene, time, &truth, k as u64);
        let known = KnownLight {
            sun_direction: sun,
            sky: None,
            sun_irradiance: None,
        };
        let est = estimated_light(&scene, &targets, &photos, &known, time, &settings).unwrap();
        all_photos.extend(photos);
        out.push((time, truth, est));
    }
    // The pseudo-albedos from the times whose split the photographs gave
    // (a time without a well-conditioned pair keeps the model's split,
    // stated as ±15 %: `process` marks it `poor`).
    let measured: Vec<DateTime<Utc>> = out
        .iter()
        .filter(|(_, _, e)| e.split.is_some())
        .map(|(t, _, _)| *t)
        .collect();
    all_photos.retain(|p| measured.contains(&p.time));
    let lights: Vec<Illumination> = out
        .iter()
        .filter(|(_, _, e)| e.split.is_some())
        .map(|(time, _, e)| Illumination {
            time: *time,
            sky: &e.sky,
        })
        .collect();
    let (refl, _) =
        recover_reflectance(&scene, &targets, &all_photos, &lights, &ReflectanceSettings::default()).unwrap();
    let plaster = scene.materials().iter().position(|m| m.name == "plaster").unwrap() as u32;
    let (mut se, mut sun) = (Vec::new(), Vec::new());
    for (cell, c) in refl.grid.cells.iter().zip(&refl.cells) {
        if scene.triangles()[cell.triangle].material == plaster
            && c.status == campanile_process::outdoor::CellStatus::Solved
        {
            se.push((c.rho_se[1] / PLASTER[1] - 1.0).abs());
            sun.push((c.rho_sun[1] / PLASTER[1] - 1.0).abs());
        }
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!("{} solved plaster cells", se.len());
    let (m_se, m_sun) = (med(&mut se), med(&mut sun));
    (out.into_iter().map(|(_, t, e)| (t, e)).collect(), m_se, m_sun)
}

/// Horizontal irradiance of a sky (without the disc) by quadrature.
fn sky_horizontal(sky: &MeasuredSky) -> f64 {
    let n = 200;
    let mut e = 0.0;
    for i in 0..n {
        let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) / (2 * n) as f64 * std::f64::consts::TAU;
            let d = Vector3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos());
            e += sky.radiance(&d)[1] * theta.cos() * theta.sin();
        }
    }
    e * (std::f64::consts::FRAC_PI_2 / n as f64) * (std::f64::consts::TAU / (2 * n) as f64)
}

fn report(label: &str, runs: &[(MeasuredSky, EstimatedLight)]) -> Vec<(f64, f64, f64)> {
    runs.iter()
        .map(|(truth, est)| {
            // The truth's sun-to-sky ratio (normal sun over horizontal sky) over the model's.
            let model = light(&Daylight::clear(truth.sun_direction, &Atmosphere::clear()), 1.0, 1.0);
            let x_true = (truth.sun_irradiance[1] / sky_horizontal(truth))
                / (model.sun_irradiance[1] / sky_horizontal(&model));
            let sky_err = sky_horizontal(&est.sky) / sky_horizontal(truth) - 1.0;
            let sun_err = est.sky.sun_irradiance[1] / truth.sun_irradiance[1] - 1.0;
            println!(
                "{label}: zenith {:.1}°: x {:?} (truth {x_true:.3}), sky {:+.1}%, sun {:+.1}% (stated ±{:.1}%, ±{:.1}%); {}",
                truth.sun_direction[2].acos().to_degrees(),
                est.split.as_ref().map(|s| (s.x[1], s.sigma[1], s.pairs)),
                100.0 * sky_err,
                100.0 * sun_err,
                100.0 * est.sky_uncertainty,
                100.0 * est.sun_uncertainty,
                est.describe()
            );
            (x_true, sky_err, sun_err)
        })
        .collect()
}

/// The model's sky shape with another split: the pairs recover the ratio,
/// the views' sky pixels the sky's scale.
#[test]
fn the_sunlit_shadowed_ratio_recovers_the_suns_share_of_a_sky_brighter_than_the_model() {
    let atm = Atmosphere::clear();
    let (runs, se, sun) = run(&|s| light(&Daylight::clear(s, &atm), 1.25, 0.85));
    let figures = report("scaled", &runs);
    for (k, ((_, est), (x_true, sky_err, sun_err))) in runs.iter().zip(&figures).enumerate() {
        // The truth's x is 0.85 / 1.25 = 0.68 of the model's.
        assert!((x_true - 0.68).abs() < 1e-9, "{x_true}");
        assert!(matches!(est.scale, ScaleSource::SkyPixels { .. }), "{:?}", est.scale);
        assert!(sky_err.abs() < 0.02, "sky {sky_err}");
        let split = est.split.as_ref().expect("the site casts shadows on its walls");
        // The sun within three stated uncertainties (at least 15 % each,
        // SPLIT_FLOOR): measured x 0.683, 0.879, 0.407 for 0.68 (module
        // doc); the first time, whose pairs are dominated by the direct
        // sun, within 5 %.
        assert!(
            sun_err.abs() < 3.0 * est.sun_uncertainty,
            "sun {sun_err} vs ±{}",
            est.sun_uncertainty
        );
        assert!(est.sun_uncertainty >= 0.15, "{}", est.sun_uncertainty);
        if k == 0 {
            assert!((split.x[1] / 0.68 - 1.0).abs() < 0.05, "x {} vs 0.68", split.x[1]);
        }
    }
    // The pseudo-albedos: printed, not held to a bound here (two of the
    // three splits are 29 % and 40 % off, above); `tests/cli_clear_sky.rs`
    // bounds them on the campanile's 1496 cells.
    println!(
        "plaster pseudo-albedos under the estimated light: median |error| ρ_se {:.1}%, ρ_sun {:.1}%",
        100.0 * se,
        100.0 * sun
    );
}

/// A turbid sky (CIE type 14, twice the extinction, a brighter sky) under
/// the default model (type 12): the pairs still fix the split; the sky's
/// shape differs from the model's, which the sky pixels' spread states.
#[test]
fn a_turbid_sky_still_gives_the_split_and_states_its_scale_error() {
    let turbid = Atmosphere {
        beta: Atmosphere::clear().beta.map(|b| 2.0 * b),
        sky_type: CieSkyType::new(14).unwrap(),
        zenith_radiance: Atmosphere::clear().zenith_radiance.map(|l| 1.6 * l),
        ..Atmosphere::clear()
    };
    let (runs, se, sun) = run(&|s| light(&Daylight::clear(s, &turbid), 1.0, 1.0));
    let figures = report("turbid", &runs);
    println!(
        "plaster pseudo-albedos under the estimated light: median |error| ρ_se {:.1}%, ρ_sun {:.1}%",
        100.0 * se,
        100.0 * sun
    );
    for ((_, est), (_, sky_err, sun_err)) in runs.iter().zip(&figures) {
        // The error is within three stated standard uncertainties.
        assert!(
            sky_err.abs() < 3.0 * est.sky_uncertainty.max(0.01),
            "sky {sky_err} vs ±{}",
            est.sky_uncertainty
        );
        assert!(
            sun_err.abs() < 3.0 * est.sun_uncertainty.max(0.01),
            "sun {sun_err} vs ±{}",
            est.sun_uncertainty
        );
    }
}
