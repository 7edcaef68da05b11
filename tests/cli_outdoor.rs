//! `campanile outdoor recover|render` on plain files.
//!
//! - A small site rendered by Campanile's own path tracer (shared formulas:
//!   this checks the files, the cameras and the commands end to end, not
//!   the model): a building with two wall materials, a ground and a
//!   neighbour of known albedo, three cameras, four training times and one
//!   held-out time, CIE clear skies per channel.
//! - Bad input: each refused with exit 2 and the file and field named.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use campanile_process::camera::image::RadianceImage;
use campanile_process::exr_io::write_radiance_exr;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::pipeline::MeasuredSky;
use campanile_process::render::{CameraRig, Lighting, Material, RenderSettings, Scene, render};
use campanile_process::scene_geometry::load_obj;
use campanile_process::sky::{ChannelSky, CieSky, CieSkyType, SkyFile, SkyModel};
use campanile_process::sun::{Observer, sun_position};
use chrono::{DateTime, Utc};
use common::campanile;
use nalgebra::Vector3;

const LAT: f64 = 37.87;
const LON: f64 = -122.26;
const PLASTER: [f64; 3] = [0.62, 0.57, 0.50];
const BRICK: [f64; 3] = [0.46, 0.31, 0.22];
const GROUND: [f64; 3] = [0.20, 0.19, 0.17];
const NEIGHBOUR: [f64; 3] = [0.40, 0.38, 0.35];

/// An axis-aligned box's faces as OBJ quads (outward winding), each its own group.
fn boxed(obj: &mut String, v: &mut usize, lo: [f64; 3], hi: [f64; 3], groups: [&str; 5]) {
    let [x0, y0, z0] = lo;
    let [x1, y1, z1] = hi;
    let faces: [(&str, [[f64; 3]; 4]); 5] = [
        (groups[0], [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]]), // south
        (groups[1], [[x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]]), // north
        (groups[2], [[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]]), // east
        (groups[3], [[x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]]), // west
        (groups[4], [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]), // roof
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

/// The cameras: (name, position, look-at point).
const CAMERAS: [(&str, [f64; 3], [f64; 3]); 3] = [
    ("south", [3.0, -24.0, 1.6], [0.0, 0.0, 3.0]),
    ("southeast", [20.0, -18.0, 1.6], [1.0, 0.0, 3.0]),
    ("west", [-24.0, -8.0, 1.6], [0.0, 0.0, 3.0]),
];
const WIDTH: usize = 64;
const HEIGHT: usize = 48;
const VFOV_DEG: f64 = 36.0;

/// Training times, then the held-out one (UTC; local solar noon is near 20:10).
const TIMES: [&str; 5] = [
    "2026-06-21T15:30:00Z",
    "2026-06-21T18:00:00Z",
    "2026-06-21T20:30:00Z",
    "2026-06-21T23:30:00Z",
    "2026-06-21T22:00:00Z",
];

fn sky_at(time: DateTime<Utc>) -> MeasuredSky {
    let observer = Observer::from_degrees(LAT, LON, 0.0, 1013.25, 15.0);
    let sun = sun_position(time, &observer, None).unwrap();
    let zenith = sun.zenith_rad;
    let lz = [55.0, 70.0, 100.0];
    let kind = CieSkyType::new(12).unwrap();
    MeasuredSky {
        sun_direction: sun.direction(),
        models: lz.map(|l| CieSky::new(kind, l * zenith.cos().sqrt(), zenith).as_seven_parameter()),
        sun_irradiance: [900.0, 860.0, 760.0].map(|e| e * (1.0 - 0.3 * (1.0 - zenith.cos()))),
        overcast: None,
    }
}

fn sky_file(sky: &MeasuredSky) -> String {
    let z = sky.sun_direction[2].acos();
    let a = sky.sun_direction[0]
        .atan2(sky.sun_direction[1])
        .rem_euclid(std::f64::consts::TAU);
    let channel = |name: &str, model: SkyModel| ChannelSky {
        channel: name.into(),
        model,
        chosen: "Cie(12)".into(),
        reason: "the simulated sky".into(),
        rms_relative: 0.0,
        samples: 0,
        masked_fraction: 0.0,
        masked: None,
        convergence: None,
    };
    let file = SkyFile {
        sun_zenith_deg: z.to_degrees(),
        sun_azimuth_deg: a.to_degrees(),
        channels: vec![
            channel("r", sky.models[0]),
            channel("g", sky.models[1]),
            channel("b", sky.models[2]),
        ],
    };
    ron::ser::to_string_pretty(&file, ron::ser::PrettyConfig::default()).unwrap()
}

/// Writes the site to `dir`: geometry, scene, photos (training and
/// held-out) and light files, images rendered by Campanile's path tracer.
fn make_site(dir: &Path) {
    let mut obj = String::new();
    let mut v = 0;
    writeln!(obj, "g ground").unwrap();
    for p in [[-60.0, -60.0], [60.0, -60.0], [60.0, 60.0], [-60.0, 60.0]] {
        writeln!(obj, "v {} {} 0", p[0], p[1]).unwrap();
    }
    writeln!(obj, "f 1 2 3 4").unwrap();
    v += 4;
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
    std::fs::write(dir.join("site.obj"), &obj).unwrap();
    std::fs::write(dir.join("scene.ron"), SCENE).unwrap();

    // The true scene: the targets' albedos known.
    let description: campanile_config::Scene = campanile_config::source::ron_options().from_str(SCENE).unwrap();
    let geometry = load_obj(&description, &dir.join("site.obj")).unwrap();
    let albedo = |m: &str| match m {
        "plaster" => PLASTER,
        "brick" => BRICK,
        "ground" => GROUND,
        _ => NEIGHBOUR,
    };
    let materials = geometry
        .material_names
        .iter()
        .map(|m| Material::diffuse(m, albedo(m)))
        .collect();
    let scene = Scene::new(geometry.triangles, materials, geometry.surface_names).unwrap();

    std::fs::create_dir_all(dir.join("images")).unwrap();
    std::fs::create_dir_all(dir.join("skies")).unwrap();
    let mut cameras = String::new();
    for (name, p, at) in CAMERAS {
        let look = [at[0] - p[0], at[1] - p[1], at[2] - p[2]];
        writeln!(
            cameras,
            "        (name: {name:?}, position_m: ({}, {}, {}), look: ({}, {}, {}), up: (0.0, 0.0, 1.0), vfov_deg: {VFOV_DEG}, width: {WIDTH}, height: {HEIGHT}),",
            p[0], p[1], p[2], look[0], look[1], look[2]
        )
        .unwrap();
    }
    let (mut training, mut held_out, mut light) = (String::new(), String::new(), String::new());
    for (k, t) in TIMES.iter().enumerate() {
        let time: DateTime<Utc> = t.parse().unwrap();
        let sky = sky_at(time);
        let stamp = time.format("%H%M");
        std::fs::write(dir.join(format!("skies/{stamp}.ron")), sky_file(&sky)).unwrap();
        let e = sky.sun_irradiance;
        writeln!(
            light,
            "        (time: {t:?}, sun: Irradiance(({}, {}, {})), sky: File(\"skies/{stamp}.ron\")),",
            e[0], e[1], e[2]
        )
        .unwrap();
        for (name, p, at) in CAMERAS {
            let look = Vector3::new(at[0] - p[0], at[1] - p[1], at[2] - p[2]);
            let rig = CameraRig::look_at(
                Vector3::from(p),
                look,
                Vector3::z(),
                VFOV_DEG.to_radians(),
                WIDTH,
                HEIGHT,
            )
            .unwrap();
            let lighting = Lighting {
                sky: Some(&sky),
                points: &[],
                spheres: &[],
            };
            let settings = RenderSettings {
                samples_per_pixel: 16,
                max_bounces: 2,
                seed: k as u64,
                ..RenderSettings::default()
            };
            let img = render(&scene, &rig, &lighting, &settings);
            let file = format!("images/{name}-{stamp}.exr");
            write_exr(&img, &dir.join(&file));
            let entry = format!("        (camera: {name:?}, time: {t:?}, image: {file:?}),\n");
            if k == TIMES.len() - 1 {
                held_out.push_str(&entry);
            } else {
                training.push_str(&entry);
            }
        }
    }
    let photos =
        |list: &str| format!("OutdoorPhotos(\n    cameras: [\n{cameras}    ],\n    photos: [\n{list}    ],\n)\n");
    std::fs::write(dir.join("photos.ron"), photos(&training)).unwrap();
    std::fs::write(dir.join("photos-heldout.ron"), photos(&held_out)).unwrap();
    std::fs::write(
        dir.join("light.ron"),
        format!(
            "OutdoorLight(\n    site: Some((latitude_deg: {LAT}, longitude_deg: {LON})),\n    times: [\n{light}    ],\n)\n"
        ),
    )
    .unwrap();
}

fn write_exr(img: &RadianceImage, path: &Path) {
    let map = RadianceMap {
        width: img.width,
        height: img.height,
        rgb: img.data.clone(),
        variance: vec![0.0; img.data.len()],
        mask: vec![0; img.width * img.height],
    };
    write_radiance_exr(&map, path).unwrap();
}

fn site() -> &'static Path {
    static SITE: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    SITE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        make_site(&dir);
        dir
    })
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Reads cells.csv: (surface, status, ρ_sun, ρ_se) per cell.
fn cells(out: &Path) -> Vec<(String, String, [f64; 3], [f64; 3])> {
    let text = std::fs::read_to_string(out.join("cells.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let n = |name: &str| f[col(name)].parse::<f64>().unwrap();
            (
                f[col("surface")].to_string(),
                f[col("status")].to_string(),
                [n("rho_sun_r"), n("rho_sun_g"), n("rho_sun_b")],
                [n("rho_se_r"), n("rho_se_g"), n("rho_se_b")],
            )
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Recovery and a held-out render on the simulated site: ρ_se of the
/// solved cells within 3 % (median, green) of the true albedo of each
/// wall; the held-out view within 5 % per 4×4 block (the simulator's noise
/// at 16 paths per pixel is 2–3 % per pixel).
#[test]
fn simulated_site_recovers_and_renders_a_held_out_time() {
    let dir = site();
    let out = tempfile::tempdir().unwrap();
    let rec = out.path().join("rec");
    let o = campanile(&[
        "outdoor",
        "recover",
        "--scene",
        s(&dir.join("scene.ron")),
        "--photos",
        s(&dir.join("photos.ron")),
        "--light",
        s(&dir.join("light.ron")),
        "--out",
        s(&rec),
        "--grid-spacing",
        "1.5",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "stdout:\n{stdout}\nstderr:\n{stderr}");
    for f in [
        "albedo/materials.ron",
        "cells.csv",
        "cell_points.csv",
        "outdoor.json",
        "quality.json",
        "recovery.json",
    ] {
        assert!(rec.join(f).is_file(), "{f} missing");
    }
    let cells = cells(&rec);
    for (surface, truth) in [("south-wall", BRICK), ("west-wall", PLASTER)] {
        let errs: Vec<f64> = cells
            .iter()
            .filter(|c| c.0 == surface && c.1 == "solved")
            .map(|c| (c.3[1] / truth[1] - 1.0).abs())
            .collect();
        assert!(errs.len() >= 5, "{surface}: {} solved cells\n{stdout}", errs.len());
        let m = median(errs);
        eprintln!("{surface}: rho_se median error {:.2} %", 100.0 * m);
        assert!(m < 0.03, "{surface}: median rho_se error {m}\n{stdout}");
    }

    let renders = out.path().join("renders");
    let o = campanile(&[
        "outdoor",
        "render",
        s(&rec),
        "--photos",
        s(&dir.join("photos-heldout.ron")),
        "--light",
        s(&dir.join("light.ron")),
        "--out",
        s(&renders),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        matches!(o.status.code(), Some(0)),
        "stdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(renders.join("render.json")).unwrap()).unwrap();
    let views = json["views"].as_array().unwrap();
    assert_eq!(views.len(), 3);
    for v in views {
        let r = v["rmse_block_4x4"].as_f64().unwrap();
        eprintln!("{}: block rmse {:.2} %", v["view"], 100.0 * r);
        assert!(r < 0.05, "{v}");
        assert!(renders.join(v["file"].as_str().unwrap()).is_file());
    }
}

// ---------------------------------------------------------------- RADIANCE

/// The RADIANCE building of `validation/outdoor` (rpict, -ab 5, gendaylit
/// per channel; README there): committed fixtures, no renderer needed.
fn radiance() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/outdoor/fixtures")
}

/// The truth's reflectance (green) at a world point of `surface`.
fn truth_green(truth: &serde_json::Value, surface: &str, p: [f64; 3]) -> f64 {
    let entry = truth["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == surface)
        .unwrap_or_else(|| panic!("no truth for {surface}"));
    let Some(tex) = entry.get("texture") else {
        return entry["rho"][1].as_f64().unwrap();
    };
    let v = |k: &str| -> [f64; 3] { [0, 1, 2].map(|i| tex[k][i].as_f64().unwrap()) };
    let (o, sa, ta) = (v("origin_m"), v("s_axis"), v("t_axis"));
    let rel = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
    let dot = |a: [f64; 3]| rel[0] * a[0] + rel[1] * a[1] + rel[2] * a[2];
    let px = tex["pixel_m"].as_f64().unwrap();
    let (w, h) = (tex["width"].as_i64().unwrap(), tex["height"].as_i64().unwrap());
    let i = ((dot(sa) / px).floor() as i64).clamp(0, w - 1) as usize;
    let j = ((dot(ta) / px).floor() as i64).clamp(0, h - 1) as usize;
    let level = tex["index"][j][i].as_u64().unwrap() as usize;
    tex["levels"][level][1].as_f64().unwrap()
}

/// Median and p95 of |ρ/ρ_true − 1| (green) over every cell, ρ_se then
/// ρ_sun, the truth averaged over each cell's points (cell_points.csv).
fn radiance_errors(out: &Path) -> (f64, f64, f64, f64) {
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(radiance().join("truth.json")).unwrap()).unwrap();
    let cells = cells(out);
    let points = std::fs::read_to_string(out.join("cell_points.csv")).unwrap();
    let mut sums = vec![(0.0, 0usize); cells.len()];
    for line in points.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let k = f[0] as usize;
        sums[k].0 += truth_green(&truth, &cells[k].0, [f[1], f[2], f[3]]);
        sums[k].1 += 1;
    }
    let (mut se, mut sun) = (Vec::new(), Vec::new());
    for (c, (sum, n)) in cells.iter().zip(&sums) {
        assert!(*n > 0, "a cell without points");
        let t = sum / *n as f64;
        se.push((c.3[1] / t - 1.0).abs());
        sun.push((c.2[1] / t - 1.0).abs());
    }
    let q = |mut v: Vec<f64>, p: f64| {
        v.sort_by(f64::total_cmp);
        v[((v.len() - 1) as f64 * p).round() as usize]
    };
    (q(se.clone(), 0.5), q(se, 0.95), q(sun.clone(), 0.5), q(sun, 0.95))
}

fn recover(light: &Path, out: &Path) -> std::process::Output {
    let f = radiance();
    campanile(&[
        "outdoor",
        "recover",
        "--scene",
        s(&f.join("scene.ron")),
        "--photos",
        s(&f.join("photos.ron")),
        "--light",
        s(light),
        "--out",
        s(out),
        "--grid-spacing",
        "1",
    ])
}

/// The issue's bounds on RADIANCE's building, through the commands: the
/// pseudo-albedos within 2 % median of RADIANCE's reflectances (measured
/// ρ_se 0.53 %, p95 3.7 %; ρ_sun 0.24 %, p95 1.7 %), with the sky given as
/// gendaylit's coefficients and as fitted from RADIANCE's fisheye images
/// (ρ_se 1.2 %); and the held-out time (14:30) within 3 % per 4×4 block of
/// RADIANCE's render in every view (measured 0.3–2.3 %), rendered as rpict
/// samples (one ray per pixel centre). Without the landscape below the
/// horizon (RADIANCE's ground glow beyond the ground plane) ρ_se is 2.7 %
/// high: the model needs it.
#[test]
fn radiance_building_within_the_issue_bounds() {
    let f = radiance();
    let tmp = tempfile::tempdir().unwrap();
    let rec = tmp.path().join("rec");
    let o = recover(&f.join("light.ron"), &rec);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let (se, se95, sun, sun95) = radiance_errors(&rec);
    eprintln!(
        "RADIANCE building: rho_se median {:.2} % p95 {:.2} %, rho_sun median {:.2} % p95 {:.2} %",
        100.0 * se,
        100.0 * se95,
        100.0 * sun,
        100.0 * sun95
    );
    assert!(se < 0.02 && sun < 0.02, "rho_se {se}, rho_sun {sun}");

    let renders = tmp.path().join("renders");
    let o = campanile(&[
        "outdoor",
        "render",
        s(&rec),
        "--photos",
        s(&f.join("photos-heldout.ron")),
        "--light",
        s(&f.join("light.ron")),
        "--out",
        s(&renders),
        "--pixel-samples",
        "1",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(renders.join("render.json")).unwrap()).unwrap();
    let views = json["views"].as_array().unwrap();
    assert_eq!(views.len(), 4);
    for v in views {
        let r = v["rmse_block_4x4"].as_f64().unwrap();
        eprintln!("held out {}: {:.2} % per 4x4 block", v["view"], 100.0 * r);
        assert!(r < 0.03, "{v}");
    }

    // The sky fitted from RADIANCE's fisheye pictures of it.
    let fish = tmp.path().join("fish");
    let o = recover(&f.join("light-fisheye.ron"), &fish);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stdout));
    let (se_f, _, sun_f, _) = radiance_errors(&fish);
    eprintln!(
        "fisheye skies: rho_se {:.2} %, rho_sun {:.2} %",
        100.0 * se_f,
        100.0 * sun_f
    );
    assert!(se_f < 0.02 && sun_f < 0.02, "rho_se {se_f}, rho_sun {sun_f}");

    // The same light without the landscape below the horizon.
    let bare = tmp.path().join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    let text = std::fs::read_to_string(f.join("light.ron")).unwrap();
    let stripped: String = text
        .lines()
        .filter(|l| !l.contains("below_horizon"))
        .map(|l| l.replace("skies/", &format!("{}/skies/", f.display())) + "\n")
        .collect();
    std::fs::write(bare.join("light.ron"), stripped).unwrap();
    let o = recover(&bare.join("light.ron"), &tmp.path().join("bare-out"));
    assert_eq!(o.status.code(), Some(0));
    let (se_b, _, _, _) = radiance_errors(&tmp.path().join("bare-out"));
    eprintln!("without below_horizon: rho_se {:.2} %", 100.0 * se_b);
    assert!(
        se_b > 0.02 && se_b > 3.0 * se,
        "rho_se {se_b} without the ground glow, {se} with"
    );
}

/// Runs `outdoor recover` on the RADIANCE building with one file replaced
/// by `edit` of it; returns the exit code and stderr.
fn recover_edited(file: &str, edit: &dyn Fn(String) -> String) -> (Option<i32>, String) {
    let f = radiance();
    let tmp = tempfile::tempdir().unwrap();
    // Copy the small files; point at the fixture's images and skies.
    for name in [
        "scene.ron",
        "photos.ron",
        "light.ron",
        "light-fisheye.ron",
        "building.obj",
    ] {
        let mut text = std::fs::read_to_string(f.join(name)).unwrap();
        for dir in ["views/", "masks/", "skies/"] {
            text = text.replace(&format!("\"{dir}"), &format!("\"{}/{dir}", f.display()));
        }
        if name == file {
            text = edit(text);
        }
        std::fs::write(tmp.path().join(name), text).unwrap();
    }
    let light = if file == "light-fisheye.ron" {
        "light-fisheye.ron"
    } else {
        "light.ron"
    };
    let o = campanile(&[
        "outdoor",
        "recover",
        "--scene",
        s(&tmp.path().join("scene.ron")),
        "--photos",
        s(&tmp.path().join("photos.ron")),
        "--light",
        s(&tmp.path().join(light)),
        "--out",
        s(&tmp.path().join("out")),
    ]);
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// A file to edit, the edit, and what the error must say.
type BadCase = (&'static str, Box<dyn Fn(String) -> String>, &'static [&'static str]);

/// Bad input exits 2 naming the file, the field and what was expected.
#[test]
fn bad_outdoor_files_exit_2_naming_the_field() {
    let cases: Vec<BadCase> = vec![
        (
            "scene.ron",
            Box::new(|t| {
                t.replace(
                    "(name: \"ground\", model: Diffuse, albedo: (0.20, 0.19, 0.17))",
                    "(name: \"ground\", model: Diffuse)",
                )
            }),
            &["scene.ron", "materials[3].albedo", "known diffuse albedo"],
        ),
        (
            "photos.ron",
            Box::new(|t| t.replacen("2026-06-21T15:10:27Z", "2026-06-21T16:10:27Z", 1)),
            &["south-west@2026-06-21T16:10:27Z", "no light within 120 s"],
        ),
        (
            "photos.ron",
            Box::new(|t| t.replacen("camera: \"south-west\"", "camera: \"south-wets\"", 1)),
            &["photos[0].camera", "\"south-wets\"", "a camera named in cameras"],
        ),
        (
            "light.ron",
            Box::new(|t| t.replacen("azimuth_deg: 79.240148", "azimuth_deg: 85.0", 1)),
            &["times[0].sky", "0700.ron", "apart, more than 1°"],
        ),
        (
            "light.ron",
            Box::new(|t| t.replacen("sun: Irradiance((939.983936", "sun: Irradiance((-939.983936", 1)),
            &["times[0].sun", "finite irradiances >= 0"],
        ),
        (
            "light-fisheye.ron",
            Box::new(|t| {
                t.replacen(
                    "view: \"from-image\"",
                    "view: \"-vtv -vd 0 0 1 -vu 0 1 0 -vh 60 -vv 60\"",
                    1,
                )
            }),
            &["times[0].sky.view", "-vta"],
        ),
    ];
    for (file, edit, want) in cases {
        let (code, stderr) = recover_edited(file, &*edit);
        assert_eq!(code, Some(2), "{file}: {stderr}");
        for w in want {
            assert!(stderr.contains(w), "{file}: {w:?} not in:\n{stderr}");
        }
    }
    // `outdoor render` on a directory `outdoor recover` did not write.
    let tmp = tempfile::tempdir().unwrap();
    let f = radiance();
    let o = campanile(&[
        "outdoor",
        "render",
        s(tmp.path()),
        "--photos",
        s(&f.join("photos-heldout.ron")),
        "--light",
        s(&f.join("light.ron")),
        "--out",
        s(&tmp.path().join("r")),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("recovery.json") && stderr.contains("outdoor recover"),
        "{stderr}"
    );
}
