//! `campanile render` from a materials file: the image it writes is the
//! library's re-render for the same camera, time and sky; a sequence covers
//! sunrise to sunset; bad input is refused by name.

mod common;

use campanile_process::exr_io::read_rgb_exr;
use campanile_process::outdoor::atlas::write_materials;
use campanile_process::outdoor::observation::SamplingReport;
use campanile_process::outdoor::{
    CellEstimate, CellStatus, Grid, Illumination, Reflectance, RerenderSettings, rerender,
};
use campanile_process::pose::HeadPose;
use campanile_process::render::CameraRig;
use campanile_process::sky::{Atmosphere, Daylight};
use campanile_process::sun::{Observer, sun_position};
use campanile_sim::world::rig::{mount, pinhole_at};
use campanile_sim::world::{examples_dir, load_scene};
use chrono::{DateTime, Utc};
use common::campanile;
use nalgebra::Vector3;

/// A materials file giving the tower a uniform grey (ρ_sun = 0.5, ρ_se = 0.4).
fn grey_tower(dir: &std::path::Path) -> std::path::PathBuf {
    let loaded = load_scene(&examples_dir().join("campanile-scene.ron")).unwrap();
    let scene = &loaded.scene;
    let targets: Vec<usize> = ["south-face", "east-face", "north-face", "west-face"]
        .iter()
        .map(|s| scene.surface_index(s).unwrap())
        .collect();
    let views: Vec<Vector3<f64>> = loaded
        .description
        .poses
        .iter()
        .map(|p| Vector3::new(p.position_m.0, p.position_m.1, p.position_m.2))
        .collect();
    let grid = Grid::new(scene, &targets, 4.0, &views).unwrap();
    let cells = grid
        .cells
        .iter()
        .map(|_| CellEstimate {
            rho_sun: [0.5; 3],
            rho_se: [0.4; 3],
            sigma_sun: [0.0; 3],
            sigma_se: [0.0; 3],
            status: CellStatus::Solved,
            condition: 1.0,
            observations: 2,
            rms_relative: 0.0,
            amplification: 1.0,
        })
        .collect();
    let refl = Reflectance {
        face_ratio: vec![[1.25; 3]; grid.faces.len()],
        grid,
        cells,
        photos: Vec::new(),
        sampling: SamplingReport::default(),
        diagnostics: Vec::new(),
    };
    write_materials(scene, &refl, dir).unwrap()
}

#[test]
fn a_render_at_one_time_is_the_library_rerender() {
    let dir = tempfile::tempdir().unwrap();
    let materials = grey_tower(dir.path());
    let out = dir.path().join("renders");
    let o = campanile(&[
        "render",
        "--scene",
        "examples/campanile-scene.ron",
        "--station",
        "examples/sim-station.ron",
        "--materials",
        materials.to_str().unwrap(),
        "--pose",
        "view-se",
        "--time",
        "2026-08-29T20:30:00Z",
        "--width",
        "48",
        "--height",
        "36",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let image = read_rgb_exr(&out.join("render-20260829T203000Z.exr")).unwrap();
    // The same render through the library.
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value;
    let loaded = load_scene(&examples_dir().join("campanile-scene.ron")).unwrap();
    let refl = campanile_process::outdoor::atlas::read_materials(&loaded.scene, &materials).unwrap();
    let pose = loaded.description.pose("view-se").unwrap();
    let (pan, tilt) = station.head.reach(pose.azimuth_deg, pose.elevation_deg).unwrap();
    let rig = CameraRig {
        pinhole: pinhole_at(&station.camera, 48, 36),
        mount: mount(&station.head.mount),
        head: HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        },
        position: Vector3::new(pose.position_m.0, pose.position_m.1, pose.position_m.2),
        width: 48,
        height: 36,
    };
    let s = &station.site;
    let observer = Observer::from_degrees(
        s.latitude_deg,
        s.longitude_deg,
        s.elevation_m,
        s.pressure_mbar,
        s.temperature_c,
    );
    let t: DateTime<Utc> = "2026-08-29T20:30:00Z".parse().unwrap();
    let sun = sun_position(t, &observer, s.delta_t_s).unwrap();
    let day = Daylight::clear(sun.direction(), &Atmosphere::clear());
    let (want, _) = rerender(
        &loaded.scene,
        &refl,
        &rig,
        &Illumination { time: t, sky: &day },
        &RerenderSettings::default(),
    );
    assert_eq!((image.width, image.height), (48, 36));
    for (a, b) in image.data.iter().zip(&want.data) {
        assert!((a - b).abs() <= 1e-5 * b.abs().max(1.0), "{a} vs {b}");
    }
    assert!(image.data.iter().all(|v| v.is_finite() && *v > 0.0));
}

#[test]
fn a_sequence_runs_from_sunrise_to_sunset_and_bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let materials = grey_tower(dir.path());
    let out = dir.path().join("day");
    let o = campanile(&[
        "render",
        "--scene",
        "examples/campanile-scene.ron",
        "--station",
        "examples/sim-station.ron",
        "--materials",
        materials.to_str().unwrap(),
        "--pose",
        "view-sw",
        "--sequence",
        "2026-08-29",
        "--step-min",
        "180",
        "--overcast",
        "0.5",
        "--width",
        "16",
        "--height",
        "12",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let elevations: Vec<f64> = text
        .lines()
        .filter_map(|l| l.split("sun elevation ").nth(1))
        .map(|s| {
            s.trim_end_matches(|c: char| !c.is_ascii_digit())
                .split('°')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    // Daylight at 37.8° N in late August lasts about 13 h: 4 or 5 frames 3 h apart, all with the sun up.
    assert!((4..=5).contains(&elevations.len()), "{text}");
    assert!(elevations.iter().all(|e| *e > 0.0 && *e < 70.0), "{elevations:?}");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), elevations.len());

    let o = campanile(&[
        "render",
        "--scene",
        "examples/campanile-scene.ron",
        "--station",
        "examples/sim-station.ron",
        "--materials",
        materials.to_str().unwrap(),
        "--pose",
        "view-sw",
        "--time",
        "2026-08-29T20:30:00Z",
        "--overcast",
        "1.5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "bad input exits 2");
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--overcast: found 1.5; expected a fraction from 0 to 1"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `render --zoom`: a zoom photo of the grey tower with a checkerboard of
/// ±20% painted over it (the detail finer than the 4 m cells) gives
/// per-pixel pseudo-albedos 0.5·f and 0.4·f (eq. 5.16: ρ̃ · I/Ĩ, the
/// checkerboard averaging to 1 over a cell's ≈ 32-pixel window), and the
/// zoom view re-rendered at a new time carries the same factor over the
/// grid's render. Clipped pixels (mask ≠ 0 in the radiance EXR) are refused.
/// Measured: 99.8% of the pixels within 3% (asserted ≥ 85%).
#[test]
fn a_zoom_photo_gives_per_pixel_albedos_and_a_sharp_render() {
    use campanile_process::exr_io::write_radiance_exr;
    use campanile_process::hdr::merge::RadianceMap;
    use campanile_process::outdoor::rerender::relative_rmse;
    let dir = tempfile::tempdir().unwrap();
    let materials = grey_tower(dir.path());
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value;
    let loaded = load_scene(&examples_dir().join("campanile-scene.ron")).unwrap();
    let refl = campanile_process::outdoor::atlas::read_materials(&loaded.scene, &materials).unwrap();
    let pose = loaded.description.pose("zoom-south").unwrap();
    let (pan, tilt) = station.head.reach(pose.azimuth_deg, pose.elevation_deg).unwrap();
    let (w, h) = (64, 48);
    let mut pinhole = pinhole_at(&station.camera, w, h);
    pinhole.focal_px *= 10.0;
    let rig = CameraRig {
        pinhole,
        mount: mount(&station.head.mount),
        head: HeadPose {
            pan_rad: pan.to_radians(),
            tilt_rad: tilt.to_radians(),
        },
        position: Vector3::new(pose.position_m.0, pose.position_m.1, pose.position_m.2),
        width: w,
        height: h,
    };
    let s = &station.site;
    let observer = Observer::from_degrees(
        s.latitude_deg,
        s.longitude_deg,
        s.elevation_m,
        s.pressure_mbar,
        s.temperature_c,
    );
    let day_at = |t: &str| {
        let t: DateTime<Utc> = t.parse().unwrap();
        let sun = sun_position(t, &observer, s.delta_t_s).unwrap();
        (t, Daylight::clear(sun.direction(), &Atmosphere::clear()))
    };
    let ((t0, d0), (t1, d1)) = (day_at("2026-08-29T20:30:00Z"), day_at("2026-08-29T22:42:00Z"));
    let f = |i: usize| if (i % w + i / w).is_multiple_of(2) { 1.2 } else { 0.8 };
    let (base0, _) = rerender(
        &loaded.scene,
        &refl,
        &rig,
        &Illumination { time: t0, sky: &d0 },
        &RerenderSettings::default(),
    );
    let mut mask = vec![0u8; w * h];
    mask[24 * w + 30..24 * w + 35].iter_mut().for_each(|m| *m = 1);
    let photo = RadianceMap {
        width: w,
        height: h,
        rgb: base0
            .data
            .iter()
            .enumerate()
            .map(|(k, v)| v * f(k / 3) as f32)
            .collect(),
        variance: vec![0.0; w * h * 3],
        mask,
    };
    let zoom_exr = dir.path().join("zoom.exr");
    write_radiance_exr(&photo, &zoom_exr).unwrap();
    let out = dir.path().join("zoom");
    let focal = format!("{}", rig.pinhole.focal_px);
    let args = |focal: &str| {
        campanile(&[
            "render",
            "--scene",
            "examples/campanile-scene.ron",
            "--station",
            "examples/sim-station.ron",
            "--materials",
            materials.to_str().unwrap(),
            "--pose",
            "zoom-south",
            "--zoom",
            zoom_exr.to_str().unwrap(),
            "--zoom-time",
            "2026-08-29T20:30:00Z",
            &format!("--zoom-focal-px={focal}"),
            "--time",
            "2026-08-29T22:42:00Z",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let o = args(&focal);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    eprintln!("{text}");
    assert!(text.contains("5 invalid radiance"), "{text}");
    let sun = read_rgb_exr(&out.join("zoom-albedo-sun.exr")).unwrap();
    let se = read_rgb_exr(&out.join("zoom-albedo-se.exr")).unwrap();
    let render = read_rgb_exr(&out.join("render-zoom-20260829T224200Z.exr")).unwrap();
    assert_eq!((render.width, render.height), (w, h));
    let (low, _) = rerender(
        &loaded.scene,
        &refl,
        &rig,
        &Illumination { time: t1, sky: &d1 },
        &RerenderSettings::default(),
    );
    let within = |got: f32, want: f64| (f64::from(got) / want - 1.0).abs() <= 0.03;
    let good: Vec<bool> = (0..w * h)
        .map(|i| {
            let k = i * 3 + 1;
            within(sun.data[k], 0.5 * f(i))
                && within(se.data[k], 0.4 * f(i))
                && within(render.data[k], f64::from(low.data[k]) * f(i))
        })
        .collect();
    let share = good.iter().filter(|g| **g).count() as f64 / (w * h) as f64;
    eprintln!(
        "{:.3} of the pixels within 3% of 0.5·f, 0.4·f and the grid's render × f",
        share
    );
    assert!(share >= 0.85, "{share}");
    // Against the grid's render times f over those pixels: the factor is applied.
    let mut want = low.clone();
    want.data
        .iter_mut()
        .enumerate()
        .for_each(|(k, v)| *v *= f(k / 3) as f32);
    assert!(relative_rmse(&render, &want, &good).unwrap() <= 0.03);

    let o = args("-3");
    assert!(!o.status.success());
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--zoom-focal-px -3"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
