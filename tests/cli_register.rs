//! `campanile register` as a user runs it: simulated photographs of the
//! tower's surveyed AprilTags (and of its circle targets) in, poses out,
//! against the simulator's truth; and its errors and exit statuses.

mod common;

use campanile_process::pose::Pinhole;
use campanile_process::registration::CameraPose;
use campanile_sim::world::target_photos::{PhotoSettings, photograph, pose_looking, with_circle_targets, with_targets};
use campanile_sim::world::{World, examples_dir, load_scene};
use common::campanile;

fn station() -> campanile_config::Station {
    campanile_config::load_station(&examples_dir().join("sim-station.ron"))
        .expect("station")
        .value
}

/// A 1600 × 1200 photo of the tower's south-east corner from `centre`,
/// written as a PNG; returns its true pose.
fn photo(dir: &std::path::Path, name: &str, centre: [f64; 3]) -> CameraPose {
    photo_of(dir, name, centre, "campanile-targets.ron", 2)
}

/// The same, of the targets of `survey` (coded or circles) hung on the
/// tower, rendered with `samples` paths a pixel.
fn photo_of(dir: &std::path::Path, name: &str, centre: [f64; 3], survey: &str, samples: u32) -> CameraPose {
    let survey = campanile_config::load_targets(&examples_dir().join(survey))
        .expect("survey")
        .value;
    let scene = load_scene(&examples_dir().join("campanile-scene.ron")).expect("scene");
    let hung = match survey.kind.circle_radius_m() {
        Some(r) => with_circle_targets(&scene, &survey.targets, r),
        None => with_targets(&scene, &survey.targets),
    };
    let mut w = World::new(&station(), hung.expect("targets"));
    w.quality.samples_per_pixel = samples;
    w.quality.max_bounces = 1;
    let c = &station().camera;
    let settings = PhotoSettings {
        pinhole: Pinhole::of_camera(c).rescaled(
            (c.resolution.width as usize, c.resolution.height as usize),
            1600,
            1200,
        ),
        width: 1600,
        height: 1200,
        time: "2026-06-21T19:30:00Z".parse().expect("time"),
        light_levels: [0.0; 4],
        blur_px: 0.7,
        exposure_scale: 1.0,
        seed: 7,
    };
    let look = [3.0 - centre[0], -3.0 - centre[1], 3.0 - centre[2]];
    let pose = pose_looking(centre, look, [0.0, 0.0, 1.0]).expect("pose");
    let shot = photograph(&w, &pose, &settings).expect("rendered");
    image::save_buffer(
        dir.join(name),
        &shot.rgb,
        shot.width as u32,
        shot.height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .expect("png written");
    shot.pose
}

#[test]
fn a_tripod_photo_is_registered_within_five_millimetres_and_a_blank_one_fails_with_status_3() {
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = photo(dir.path(), "tripod.png", [12.0, -13.0, 1.5]);
    // A photograph with no tags (all grey) has no pose.
    image::save_buffer(
        dir.path().join("blank.png"),
        &vec![128u8; 1600 * 1200],
        1600,
        1200,
        image::ExtendedColorType::L8,
    )
    .expect("png");
    let out_file = dir.path().join("poses.ron");
    let out = campanile(&[
        "register",
        dir.path().join("tripod.png").to_str().expect("utf-8"),
        dir.path().join("blank.png").to_str().expect("utf-8"),
        "--targets",
        examples_dir().join("campanile-targets.ron").to_str().expect("utf-8"),
        "--station",
        examples_dir().join("sim-station.ron").to_str().expect("utf-8"),
        "--out",
        out_file.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stdout}{stderr}");
    // A pose (ok, or poor when its covariance is over the limits), never failed.
    assert!(
        stdout.contains("tripod.png: ok") || stdout.contains("tripod.png: poor"),
        "{stdout}"
    );
    assert!(stderr.contains("blank.png: too few targets: 0 seen"), "{stderr}");
    let text = std::fs::read_to_string(&out_file).expect("poses written");
    let written: campanile_session::register_files::RegisteredPoses = ron::from_str(&text).expect("poses parse");
    assert_eq!(written.poses.len(), 1);
    let p = &written.poses[0];
    assert_eq!(p.name, "tripod");
    let position = nalgebra::Vector3::new(p.position_m.0, p.position_m.1, p.position_m.2);
    assert!(
        (position - truth.centre).norm() < 0.005,
        "{:?} vs {:?}",
        position,
        truth.centre
    );
    assert!((p.azimuth_deg - truth.azimuth_deg()).abs() < 0.05);
    assert!((p.elevation_deg - truth.elevation_deg()).abs() < 0.05);
    let roll = written.photos[0].roll_deg.expect("a roll");
    assert!(
        (roll - truth.roll_deg()).abs() < 0.05,
        "roll {roll} vs {}",
        truth.roll_deg()
    );
    // The poses are in the scene file's form: they parse as scene poses.
    let poses_only = ron::ser::to_string(&written.poses).expect("ser");
    let _: Vec<campanile_config::scene::CameraPose> = ron::from_str(&poses_only).expect("scene poses");
}

/// The thesis's own targets (white circles, no identity): found, paired
/// with the survey by search and registered by the command, rendered with
/// 1 path a pixel (as `sim/tests/circle_registration.rs`) to save time.
#[test]
fn a_photo_of_circle_targets_is_registered_by_search_within_five_millimetres() {
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = photo_of(
        dir.path(),
        "circles.png",
        [12.0, -13.0, 1.5],
        "campanile-circles.ron",
        1,
    );
    let out_file = dir.path().join("poses.ron");
    let out = campanile(&[
        "register",
        dir.path().join("circles.png").to_str().expect("utf-8"),
        "--targets",
        examples_dir().join("campanile-circles.ron").to_str().expect("utf-8"),
        "--station",
        examples_dir().join("sim-station.ron").to_str().expect("utf-8"),
        "--out",
        out_file.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    let text = std::fs::read_to_string(&out_file).expect("poses written");
    let written: campanile_session::register_files::RegisteredPoses = ron::from_str(&text).expect("poses parse");
    let p = &written.poses[0];
    let position = nalgebra::Vector3::new(p.position_m.0, p.position_m.1, p.position_m.2);
    assert!(
        (position - truth.centre).norm() < 0.005,
        "{:?} vs {:?}",
        position,
        truth.centre
    );
    assert!((p.azimuth_deg - truth.azimuth_deg()).abs() < 0.05);
    let circles = written.photos[0].circles.as_ref().expect("the circle search's figures");
    assert!(circles.matched.len() >= 6, "{circles:?}");
    assert!(circles.hypotheses > 0, "{circles:?}");
}

#[test]
fn bad_input_exits_2_and_names_the_file_and_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let targets = dir.path().join("targets.ron");
    std::fs::write(
        &targets,
        "Targets(targets: [(id: 3, centre_m: (0.0, 0.0, 1.0), normal: (0.0, -1.0, 0.0), size_m: -0.5)])\n",
    )
    .expect("write");
    let png = dir.path().join("grey.png");
    image::save_buffer(&png, &[128u8; 64 * 48], 64, 48, image::ExtendedColorType::L8).expect("png");
    let args = |t: &str, p: &str| {
        campanile(&[
            "register",
            p,
            "--targets",
            t,
            "--station",
            examples_dir().join("sim-station.ron").to_str().expect("utf-8"),
            "--out",
            dir.path().join("poses.ron").to_str().expect("utf-8"),
        ])
    };
    let out = args(targets.to_str().expect("utf-8"), png.to_str().expect("utf-8"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("targets.ron") && stderr.contains("targets[0].size_m"),
        "{stderr}"
    );
    assert!(stderr.contains("a positive side, metres"), "{stderr}");
    // A photograph that is not there.
    let out = args(
        examples_dir().join("campanile-targets.ron").to_str().expect("utf-8"),
        "/nonexistent/photo.png",
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("/nonexistent/photo.png: no such photograph"),
        "{stderr}"
    );
}
