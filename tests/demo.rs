//! `campanile demo --quick` end to end: it captures the quick day (two
//! training times and a held-out one) on the simulated station, processes
//! it, recovers the thesis's cube indoors and writes the report. Then
//! `campanile process` on the demo's session: the response, the sun and
//! the sky it recovers from the session's own frames, against the
//! simulator's truth. Every bound is stated where it is asserted.

mod common;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::sky::{SkyFile, angle_between, direction};
use campanile_sim::world::{World, examples_dir, load_scene};
use common::campanile;

#[test]
fn the_quick_demo_runs_end_to_end_and_its_figures_match_the_simulator() {
    let tmp = tempfile::tempdir().unwrap();
    let demo = tmp.path().join("demo");
    let out = campanile(&["-q", "demo", "--quick", "--out", demo.to_str().unwrap()]);
    println!("{}", String::from_utf8_lossy(&out.stdout));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    // The report: every section, every figure inline.
    let html = std::fs::read_to_string(demo.join("report.html")).unwrap();
    // CI opens this report in headless Chromium (.ci/check-report) rather
    // than run the quick demo a second time: it asks for a copy here.
    if let Some(keep) = std::env::var_os("CAMPANILE_KEEP_DEMO_REPORT") {
        std::fs::write(&keep, &html).unwrap();
    }
    for title in [
        "Pseudo-albedos",
        "Held-out time",
        "Sunrise to sunset",
        "Overcast",
        "Camera response",
        "Sun and extinction",
        "Sky",
        "Environment",
        "Indoor: inverse global illumination on the thesis&#39;s cube",
        "Indoor: the room relit (inverse global illumination, §4.7.2)",
        "Speed",
    ] {
        let title = title.replace("&#39;", "'");
        assert!(html.contains(&format!("<h2>{title}</h2>")), "section {title:?} missing");
    }
    let images = html.matches("<img src=\"data:image/").count();
    assert!(images >= 6, "{images} inline images");

    // The cube (§4.7.1) at the quick settings (64 px, 16 indirect samples):
    // every ρd, ρs, α within 5% and γ within 0.5° (the thesis: up to 8.9%).
    let figures: serde_json::Value =
        serde_json::from_slice(&std::fs::read(demo.join("demo-figures.json")).unwrap()).unwrap();
    let worst = figures["cube_worst_relative"].as_f64().unwrap();
    let gamma = figures["cube_worst_gamma_deg"].as_f64().unwrap();
    println!(
        "cube: worst relative error {:.2}%, worst γ error {gamma:.3}°",
        100.0 * worst
    );
    assert!(worst < 0.05, "cube worst relative error {worst}");
    assert!(gamma < 0.5, "cube worst γ error {gamma}°");

    // The room (§4.7.2) at the quick settings, captured through the
    // controller and processed as `campanile process` does: the lamps
    // triangulated from their bulbs in the merged, rectified views within
    // 3 mm and 3 % (the camera's gauge error divided out; measured 1.4 mm,
    // 1.4 %), and the room relit under new lamps within 10 % per 4×4 block
    // of the simulator's render (measured 6.8 % at 64×48 with a Monte
    // Carlo floor of 2.7 %, 64 stratified paths per pixel and the albedo
    // maps' noise shrinkage; 10.6 % and 5.3 % before: issue 10's 3 % is
    // not met).
    let room = |k: &str| figures[k].as_f64().unwrap_or(f64::NAN);
    println!(
        "room: relit {:.1}% (floor {:.1}%), lamps {:.2} mm, {:.2}%",
        100.0 * room("room_relit_rmse"),
        100.0 * room("room_noise_floor_rmse"),
        room("room_triangulation_mm"),
        100.0 * room("room_intensity_relative")
    );
    assert!(room("room_triangulation_mm") < 3.0);
    assert!(room("room_intensity_relative") < 0.03);
    assert!(room("room_relit_rmse") < 0.10);
    assert!(room("room_noise_floor_rmse") < room("room_relit_rmse"));
    // The scene file the room session became: a camera per pose with every
    // lamp on (12) plus the full-size views the bulbs were cut from, and
    // every lamp as bulb images.
    let scene_file = demo.join("room/processed/room/scene.ron");
    let text = std::fs::read_to_string(&scene_file).expect("the room's scene file");
    let scene: campanile_process::igi::scene_file::IgiScene =
        campanile_process::igi::scene_file::parse(&scene_file, &text).expect("a valid scene file");
    assert_eq!(
        scene.images.len(),
        12,
        "one view per pose of examples/room-igi-scene.ron"
    );
    assert_eq!(scene.lights.len(), 3);
    for l in &scene.lights {
        let campanile_process::igi::scene_file::LightEntry::Bulb { name, images } = l else {
            panic!("lights are triangulated from bulb images: {l:?}")
        };
        assert!(images.len() >= 2, "{name}: {} bulb images", images.len());
    }

    // Outdoors, at the quick plan's two training times and two views (4
    // render samples per pixel, each split into 4 branches at the surface
    // it shows): the pseudo-albedo medians within 5% (measured 2.5% and
    // 2.1% against the truth averaged over 64×64 points per cell; 5.2% and
    // 3.7% at 2 samples without splitting) and the held-out views within
    // 9.5% per 4×4 block (measured 8.5% and 8.4%; were 8.5% and 8.7%, 9.2%
    // and 9.0%): with two training times the predicted light carries it
    // (8.3–8.6% against a noise-free render; 2.5–2.9% under the held-out
    // time's measured light, `demo --quick --held-out-budget`). The floor,
    // one 4-spp photograph's own noise, is 2.2–2.4% per block.
    // Issue 9's 2% / 3% are met on less noisy photographs with the light
    // known (sim/tests/outdoor_error_budget.rs); BENCHMARKS "Path splitting
    // at the first surface".
    for key in ["albedo_se_median", "albedo_sun_median"] {
        let v = figures[key].as_f64().unwrap_or(f64::NAN);
        println!("{key}: {:.1}%", 100.0 * v);
        assert!(v < 0.05, "{key} = {v}");
    }
    let held = figures["held_out_rmse_pixel_block"].as_array().unwrap();
    assert!(!held.is_empty(), "no held-out view was compared");
    let floor = figures["held_out_floor_pixel_block"].as_array().unwrap();
    assert_eq!(floor.len(), held.len(), "one floor per held-out view");
    for (v, f) in held.iter().zip(floor) {
        let block = v[1].as_f64().unwrap_or(f64::NAN);
        let floor_block = f[1].as_f64().unwrap_or(f64::NAN);
        println!(
            "held-out view: {:.1}% per 4×4 block (floor {:.1}%)",
            100.0 * block,
            100.0 * floor_block
        );
        assert!(block < 0.095, "held-out block RMSE {block}");
        assert!((0.01..0.04).contains(&floor_block), "held-out floor {floor_block}");
    }

    // `campanile process` on the demo's session, finding the scene's
    // geometry through the session's record of where it was captured from.
    let session = demo.join("campanile-session");
    let processed = tmp.path().join("processed");
    let out = campanile(&[
        "-q",
        "process",
        session.to_str().unwrap(),
        "--out",
        processed.to_str().unwrap(),
    ]);
    println!("{}", String::from_utf8_lossy(&out.stdout));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(processed.join("report.html").is_file());
    // The clean session: every product passes its quality gate (issue 21;
    // `tests/quality_gates.rs` has the session that does not).
    let quality: serde_json::Value =
        serde_json::from_slice(&std::fs::read(processed.join("quality.json")).expect("quality.json")).unwrap();
    let not_ok: Vec<String> = quality["products"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["verdict"] != "ok")
        .map(|p| format!("{} {}: {}", p["product"], p["verdict"], p["checks"]))
        .collect();
    assert!(not_ok.is_empty(), "products not ok: {not_ok:#?}");
    assert_eq!(quality["verdict"], "ok");
    let html = std::fs::read_to_string(processed.join("report.html")).unwrap();
    assert!(html.contains("<div class=\"quality ok\" id=\"quality\"><strong>Quality: ok</strong>"));
    // The morning's environment map as EXR: 36 × 18 regions, those the tiles
    // saw (elevations −30° to 10°: 4 of the 18 bands at least) with radiance.
    let env = std::fs::read_dir(processed.join("light"))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.to_string_lossy().ends_with("-environment.exr"))
        .expect("an environment EXR");
    let map = campanile_process::exr_io::read_radiance_exr(&env).unwrap();
    assert_eq!((map.width, map.height), (36, 18));
    let seen = (0..36 * 18)
        .filter(|&i| map.mask[i] == 0 && map.rgb[3 * i + 1] > 0.0)
        .count();
    println!("environment map: {seen} of 648 regions seen");
    assert!(seen >= 4 * 36, "{seen} regions seen");

    // The response, from the plan's dense calibration bracket: shape within
    // 0.025 log-RMS of the simulated camera's over codes 400–3800, and the
    // full-well gauge within 0.05.
    let csv = std::fs::read_to_string(processed.join("response.csv")).unwrap();
    let curve = campanile_process::hdr::curve::ResponseCurve::from_csv(&csv, &processed.join("response.csv")).unwrap();
    let truth = CameraModel::typical(12);
    let mut failures: Vec<(String, f64, f64)> = Vec::new();
    for c in 0..3 {
        let d: Vec<f64> = (400..=3800)
            .step_by(100)
            .map(|code| curve.ln_exposure(c, f64::from(code)) - truth.true_ln_exposure(f64::from(code), c))
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let shape = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        println!(
            "  Δ at codes 400, 800, …: {:?}",
            d.iter()
                .step_by(4)
                .map(|x| (x * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>()
        );
        println!("response channel {c}: gauge offset {mean:+.4}, shape log-RMS {shape:.4} over codes 400–3800");
        failures.push((format!("response {c} shape"), shape, 0.025));
        failures.push((format!("response {c} gauge"), mean.abs(), 0.05));
    }

    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(processed.join("summary.json")).unwrap()).unwrap();
    let station = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value;
    let world = World::new(
        &station,
        load_scene(&examples_dir().join("campanile-scene.ron")).unwrap(),
    );
    let occurrences = summary["occurrences"].as_array().unwrap();
    assert_eq!(occurrences.len(), 3);
    for o in occurrences {
        let name = o["occurrence"].as_str().unwrap();
        let time: chrono::DateTime<chrono::Utc> = o["time"].as_str().unwrap().parse().unwrap();
        let daylight = world.daylight(time).unwrap().unwrap();
        // The sun: irradiance normal to it within 6% per channel, gauge
        // error included. (The measurement is at the sun shot, a minute
        // before the sky scan's reference time; the truth is taken at the
        // sky's time.)
        let e = o["sun_irradiance"].as_array().expect("a sun measurement");
        let truth_e = daylight.sun_irradiance();
        for c in 0..3 {
            let got = e[c].as_f64().unwrap();
            let rel = got / truth_e[c] - 1.0;
            println!(
                "{name} sun channel {c}: {got:.1} vs {:.1} W·m⁻² ({:+.2}%)",
                truth_e[c],
                100.0 * rel
            );
            failures.push((format!("{name} sun {c}"), rel.abs(), 0.06));
        }
        // The sky: within 6% RMS of the true sky over the sky above 10°
        // and more than 10° from the sun, per channel, absolute (gauge included).
        let sky: SkyFile = serde_json::from_value(o["sky"].clone()).unwrap();
        let sun = daylight.sun_direction;
        let dirs: Vec<[f64; 3]> = (0..27)
            .flat_map(|i| {
                (0..72).map(move |j| direction((3.0 * f64::from(i)).to_radians(), (5.0 * f64::from(j)).to_radians()))
            })
            .filter(|d| d[2] > 10f64.to_radians().sin() && angle_between(*d, sun) > 10f64.to_radians())
            .collect();
        for (c, ch) in sky.channels.iter().enumerate() {
            let ms: f64 = dirs
                .iter()
                .map(|&d| {
                    let t = daylight.sky_radiance(d)[c];
                    (ch.model.radiance(d[2].acos(), angle_between(d, sun)) / t - 1.0).powi(2)
                })
                .sum::<f64>()
                / dirs.len() as f64;
            println!(
                "{name} sky channel {c}: {:.2}% RMS against the truth ({})",
                100.0 * ms.sqrt(),
                ch.chosen
            );
            failures.push((format!("{name} sky {c}"), ms.sqrt(), 0.06));
        }
    }
    let failed: Vec<_> = failures
        .iter()
        .filter(|(_, v, bound)| v.is_nan() || v >= bound)
        .collect();
    assert!(failed.is_empty(), "beyond bounds: {failed:?}");
}
