//! Zoom photographs in `campanile process` (thesis §5.6.4; issue 27:
//! "`process` uses registered poses for views taken off the head (a moved
//! tripod, handheld zoom photos)").
//!
//! The quick day at the bell tower is captured on the simulated station,
//! with one more bracket in the afternoon, aimed at the scene's
//! "zoom-south" pose. The same bracket is captured a second time by the
//! same station with a 6° lens (ten times the station's focal length, no
//! distortion or falloff: `simulation.true_camera`), and its frames take
//! the place of the first capture's in the session, their journal lines
//! given the lens's focal length (`focal_px`), as `session import` writes a
//! photograph taken at another focal length than the session's camera.
//! `campanile process` then keeps the zoom view out of the fit, gives each
//! of its pixels the pseudo-albedo of eq. (5.16), and re-renders the view
//! with them at its own time. Against the simulator's truth per pixel, the
//! eq. (5.16) albedos are measured beside the grid's interpolated ones.

mod common;

use std::path::{Path, PathBuf};

use campanile_process::pose::{HeadPose, Pinhole};
use campanile_sim::world::zoom_truth::pixel_albedo_truth;
use campanile_sim::world::{World, examples_dir, load_scene};
use common::campanile_exits as run;

/// The zoom lens's horizontal field of view, degrees (the station's is 60°).
const ZOOM_FOV_DEG: f64 = 6.0;
const WIDTH: usize = 256;
const HEIGHT: usize = 192;

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8")
}

/// The quick day with the zoom bracket first in the afternoon.
fn plan_text() -> String {
    let text = std::fs::read_to_string(examples_dir().join("campanile-quick.ron")).expect("the quick plan");
    let scene = examples_dir().join("campanile-scene.ron");
    let text = text.replace(
        "scene: Some(\"campanile-scene.ron\")",
        &format!("scene: Some({:?})", path(&scene)),
    );
    let anchor = "trigger: SolarAzimuth(azimuth_deg: 240.0),\n            steps: [\n";
    assert!(text.contains(anchor), "the quick plan's afternoon changed");
    text.replacen(
        anchor,
        &format!(
            "{anchor}{}",
            "                Bracket(aim: Pose(\"zoom-south\"), exposures_s: [0.0005, 0.002, 0.008, 0.032]),\n"
        ),
        1,
    )
}

/// The afternoon's zoom bracket alone, at the same trigger.
fn zoom_plan_text() -> String {
    let scene = examples_dir().join("campanile-scene.ron");
    format!(
        r#"Plan(
    name: "zoom bracket",
    start_date: "2026-08-28",
    scene: Some({:?}),
    sessions: [
        (name: "afternoon", trigger: SolarAzimuth(azimuth_deg: 240.0), steps: [
            Bracket(aim: Pose("zoom-south"), exposures_s: [0.0005, 0.002, 0.008, 0.032]),
        ]),
    ],
)
"#,
        path(&scene)
    )
}

/// The example station, its camera truly holding a 6° lens (no distortion,
/// no falloff) on the station's own mount.
fn zoom_station_text() -> String {
    let text = std::fs::read_to_string(examples_dir().join("sim-station.ron")).expect("example station");
    let old = "simulation: Some((seed: 1, link_drop_chance: 0.0, link_corrupt_chance: 0.0)),";
    assert!(text.contains(old), "the example station's simulation block changed");
    let lens = format!(
        "true_camera: Some((resolution: (width: {WIDTH}, height: {HEIGHT}), \
         intrinsics: (focal: HorizontalFovDeg({ZOOM_FOV_DEG}), distortion: (0.0, 0.0), falloff: (0.0, 0.0)), \
         mount: (pan_zero_azimuth_deg: 0.0, tilt_zero_deg: 0.0, level_roll_deg: 0.15, level_pitch_deg: -0.1)))"
    );
    assert!(
        text.contains("level_roll_deg: 0.15") && text.contains("level_pitch_deg: -0.1"),
        "the example station's mount changed"
    );
    text.replace(
        old,
        &format!("simulation: Some((seed: 1, link_drop_chance: 0.0, link_corrupt_chance: 0.0, {lens})),"),
    )
}

/// The zoom lens's focal length, pixels.
fn zoom_focal_px() -> f64 {
    WIDTH as f64 / 2.0 / (ZOOM_FOV_DEG.to_radians() / 2.0).tan()
}

/// The journal's done frame lines whose key starts with `prefix`.
fn lines_of(journal: &str, prefix: &str) -> Vec<serde_json::Value> {
    journal
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("a journal line"))
        .filter(|v| matches!(v["status"].as_str(), Some("done" | "late")))
        .filter(|v| v["key"].as_str().is_some_and(|k| k.starts_with(prefix)))
        .collect()
}

/// Puts the frames of `zoom`'s bracket in place of `session`'s, frame for
/// frame: the file copied byte for byte, the line's checksum, size and
/// the lens's focal length. Returns the head reading the bracket was taken at.
fn transplant_zoom_frames(session: &Path, zoom: &Path) -> HeadPose {
    let journal = session.join("journal.jsonl");
    let text = std::fs::read_to_string(&journal).expect("journal");
    let zoom_lines = lines_of(
        &std::fs::read_to_string(zoom.join("journal.jsonl")).expect("journal"),
        "afternoon@",
    );
    assert_eq!(zoom_lines.len(), 4, "the zoom bracket's frames");
    let mut replaced = 0;
    let mut head = None;
    let mut lines = Vec::new();
    for line in text.lines() {
        let mut v: serde_json::Value = serde_json::from_str(line).expect("a journal line");
        let taken = matches!(v["status"].as_str(), Some("done" | "late"));
        let key = v["key"].as_str().unwrap_or_default().to_owned();
        if taken && key.starts_with("afternoon@") && key.split('/').nth(1) == Some("s0") {
            let z = &zoom_lines[replaced];
            assert_eq!(
                z["meta"]["exposure_actual_s"], v["meta"]["exposure_actual_s"],
                "frame {key}: the two brackets' exposures"
            );
            let time = |x: &serde_json::Value| {
                x["meta"]["time"]
                    .as_str()
                    .expect("a time")
                    .parse::<chrono::DateTime<chrono::Utc>>()
                    .expect("a time")
            };
            let apart = (time(z) - time(&v)).num_milliseconds().abs();
            assert!(apart < 20_000, "frame {key}: the two captures {apart} ms apart");
            let file = v["file"].as_str().expect("a frame file").to_owned();
            std::fs::copy(
                zoom.join(z["file"].as_str().expect("a frame file")),
                session.join(&file),
            )
            .expect("copied");
            for field in ["crc32c", "bytes", "width", "height", "bits"] {
                v[field] = z[field].clone();
            }
            v["meta"]["focal_px"] = serde_json::json!(zoom_focal_px());
            let reached = &v["meta"]["pose_reached"];
            head = Some(HeadPose {
                pan_rad: reached["pan_deg"].as_f64().expect("a head reading").to_radians(),
                tilt_rad: reached["tilt_deg"].as_f64().expect("a head reading").to_radians(),
            });
            replaced += 1;
        }
        lines.push(serde_json::to_string(&v).expect("json"));
    }
    assert_eq!(replaced, 4, "the session's zoom bracket");
    std::fs::write(&journal, lines.join("\n") + "\n").expect("journal written");
    head.expect("a head reading")
}

/// Reads an albedo EXR's green channel.
fn green(path: &Path) -> Vec<f64> {
    let image = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_rgb32f();
    image.pixels().map(|p| f64::from(p.0[1])).collect()
}

#[test]
fn a_zoom_photograph_gets_pseudo_albedos_at_its_own_pixels() {
    let mut tmp = tempfile::tempdir().expect("tempdir");
    if std::env::var_os("CAMPANILE_KEEP_TEST_DIR").is_some() {
        tmp.disable_cleanup(true);
        println!("keeping {}", tmp.path().display());
    }
    let dir = tmp.path();
    let file = |name: &str| -> PathBuf { dir.join(name) };
    let station = examples_dir().join("sim-station.ron");
    std::fs::write(file("plan.ron"), plan_text()).expect("plan");
    std::fs::write(file("zoom-plan.ron"), zoom_plan_text()).expect("plan");
    std::fs::write(file("zoom-station.ron"), zoom_station_text()).expect("station");
    let (session, zoom_session) = (file("session"), file("zoom-session"));
    let capture = |plan: &Path, station: &Path, out: &Path| {
        run(
            &[
                "-q",
                "capture",
                path(plan),
                "--station",
                path(station),
                "--out",
                path(out),
            ],
            0,
        )
    };
    capture(&file("plan.ron"), &station, &session);
    capture(&file("zoom-plan.ron"), &file("zoom-station.ron"), &zoom_session);
    let head = transplant_zoom_frames(&session, &zoom_session);

    let out = file("processed");
    let said = run(&["process", path(&session), "--out", path(&out)], 0);
    println!("{said}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("outdoor.json")).expect("outdoor.json")).expect("json");
    let zoom = &json["zoom"];
    assert_eq!(zoom.as_array().map(Vec::len), Some(1), "{json}");
    let z = &zoom[0];
    println!("{}", serde_json::to_string_pretty(z).expect("json"));
    assert_eq!(z["light"], "measured");
    assert!((z["focal_px"].as_f64().expect("focal") - zoom_focal_px()).abs() < 1e-6);
    // The zoom view is not among the photographs fitted.
    let fitted: Vec<&str> = json["photos"]
        .as_array()
        .expect("photos")
        .iter()
        .filter_map(|p| p["photo"].as_str())
        .collect();
    assert!(fitted.iter().all(|p| !p.contains("/s0/")), "{fitted:?}");
    let quality = std::fs::read_to_string(out.join("quality.json")).expect("quality.json");
    assert!(quality.contains("zoom afternoon@"), "{quality}");

    // Per pixel against the simulator's truth: the eq. (5.16) albedos and
    // the grid's interpolated ones, over the pixels given eq. (5.16).
    let station_config = campanile_config::load_station(&station).expect("station").value;
    let scene = load_scene(&examples_dir().join("campanile-scene.ron")).expect("scene");
    let world = World::new(&station_config, scene);
    let refl = campanile_process::outdoor::atlas::read_materials(
        &world.scene.scene,
        &out.join("albedo").join("materials.ron"),
    )
    .expect("the pseudo-albedo atlas reads back");
    let pose = world
        .scene
        .description
        .pose("zoom-south")
        .expect("the zoom pose")
        .clone();
    let (x, y, zz) = pose.position_m;
    let mut rig = world.rig(head, [x, y, zz], WIDTH, HEIGHT);
    rig.pinhole = Pinhole::centred(zoom_focal_px(), WIDTH, HEIGHT);
    let truth = pixel_albedo_truth(&world, &refl.grid, &rig, 4);
    let stem = "afternoon_2026-08-28_s0_t0";
    let zoom_file = |name: &str| out.join("zoom").join(format!("{stem}-{name}"));
    let high = green(&zoom_file("albedo-se.exr"));
    let low = green(&zoom_file("grid-albedo-se.exr"));
    let used = image::open(zoom_file("used.png"))
        .expect("the used-pixel mask")
        .into_luma8();
    let (mut e_high, mut e_low) = (Vec::new(), Vec::new());
    for i in 0..WIDTH * HEIGHT {
        let Some(t) = truth[i] else { continue };
        if used.as_raw()[i] == 0 || t[1].is_nan() || t[1] <= 0.0 {
            continue;
        }
        e_high.push((high[i] / t[1] - 1.0).abs());
        e_low.push((low[i] / t[1] - 1.0).abs());
    }
    let n = e_high.len();
    let q = campanile_process::error_figures::quantile;
    let (h50, l50) = (q(&mut e_high, 0.5), q(&mut e_low, 0.5));
    let (h95, l95) = (q(&mut e_high, 0.95), q(&mut e_low, 0.95));
    println!(
        "zoom ρ_se per pixel against the truth over {n} pixels: eq. 5.16 median {:.2}% p95 {:.2}%; the grid's interpolated median {:.2}% p95 {:.2}%",
        100.0 * h50,
        100.0 * h95,
        100.0 * l50,
        100.0 * l95
    );
    // Measured 2026-11-28 (49 152 pixels, all on the south wall): eq. 5.16
    // 4.98% median (p95 19.6%), the grid's 8.71% (p95 30.6%). The grid's
    // cells come from the quick day's noisy photographs (its cells' median
    // error is about 9%), which bounds what eq. 5.16 can reach; on the
    // true cell means it gives 1.9% (`sim/tests/zoom_albedo.rs`).
    assert!(n > 40_000, "{n} pixels");
    assert!(h50 < 0.07, "eq. 5.16 median {h50}");
    assert!(l50 - h50 > 0.02, "eq. 5.16 {h50} against the grid's {l50}");
    // Re-rendered at its own time under the afternoon's measured light:
    // 3.85% per 4×4 block, 10.2% with the grid's pseudo-albedos alone.
    let block = z["rmse_block_4x4"].as_f64().expect("a figure");
    let grid_block = z["rmse_block_4x4_grid_only"].as_f64().expect("a figure");
    assert!(block < 0.05 && block < 0.6 * grid_block, "{block} against {grid_block}");
}
