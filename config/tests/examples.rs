//! The shipped examples are valid, and each plan runs on every station.

use std::path::Path;

use campanile_config::{Document, check_plan_on_station, load, load_station};

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples").join(name)
}

#[test]
fn every_example_file_is_valid() {
    let mut n = 0;
    for entry in std::fs::read_dir(example("")).expect("examples/ exists") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "ron") {
            load(&path).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert_eq!(
        n, 18,
        "sim station, sky sim station, all-sky fisheye sim station, real station, six plans, four scenes, four targets files (tags and circles)"
    );
}

/// The INDI station and its plan (`examples/indi/`) are valid, and the plan
/// runs on it.
#[test]
fn the_indi_station_runs_its_plan() {
    let station = load_station(&example("indi/station.ron")).expect("valid INDI station");
    let Ok(Document::Plan(plan)) = load(&example("indi/sky-day.ron")) else {
        panic!("indi/sky-day.ron is a plan")
    };
    check_plan_on_station(&plan, &station.value).unwrap_or_else(|e| panic!("{e}"));
}

/// The gphoto2 station (`examples/gphoto2/`) is valid, and the sky and
/// campanile plans run on its ⅓-stop shutter.
#[test]
fn the_gphoto2_station_runs_the_plans() {
    let station = load_station(&example("gphoto2/station.ron")).expect("valid gphoto2 station");
    assert_eq!(
        station.value.camera.driver,
        campanile_config::camera::CameraDriver::Gphoto2
    );
    assert_eq!(station.value.camera.device, None);
    for plan in ["campanile-day.ron", "sky-day.ron", "sky-station.ron"] {
        let Ok(Document::Plan(plan)) = load(&example(plan)) else {
            panic!("{plan} is a plan")
        };
        check_plan_on_station(&plan, &station.value).unwrap_or_else(|e| panic!("{e}"));
    }
}

/// The GenICam station (`examples/aravis/station.ron`) is valid and names
/// Aravis's fake camera in a format the driver reads.
#[test]
fn the_aravis_station_is_valid() {
    let station = load_station(&example("aravis/station.ron")).expect("valid Aravis station");
    let camera = &station.value.camera;
    assert_eq!(camera.driver, campanile_config::camera::CameraDriver::Aravis);
    assert_eq!(
        camera.device,
        Some(campanile_config::camera::DeviceRef::Aravis {
            id: "Fake_1".into(),
            pixel_format: Some("BayerGR8".into()),
        })
    );
}

#[test]
fn plans_run_on_every_station() {
    for station in ["sim-station.ron", "real-station.ron", "sky-sim-station.ron"] {
        let station = load_station(&example(station)).expect("valid station");
        for plan in [
            "campanile-day.ron",
            "campanile-quick.ron",
            "room-lights.ron",
            "room-igi.ron",
            "sky-day.ron",
            "sky-station.ron",
        ] {
            let Ok(Document::Plan(plan)) = load(&example(plan)) else {
                panic!("{plan} is a plan")
            };
            check_plan_on_station(&plan, &station.value).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn the_day_plan_has_four_training_times_and_one_held_out() {
    let Ok(Document::Plan(plan)) = load(&example("campanile-day.ron")) else {
        panic!("plan")
    };
    let held: Vec<_> = plan.plan.value.sessions.iter().map(|s| s.held_out).collect();
    assert_eq!(held, [false, false, false, false, true]);
}

#[test]
fn a_scene_pose_maps_to_head_angles_through_the_mount() {
    // The real head's pan 0 faces azimuth 12.5° and its tilt reads 0.8° at
    // the horizon; its pan range is [0, 359.99]: azimuth 315° is pan 302.5°.
    let station = load_station(&example("real-station.ron")).expect("valid");
    let (pan, tilt) = station.value.head.reach(315.0, 30.0).expect("reachable");
    assert!(
        (pan - 302.5).abs() < 1e-12 && (tilt - 30.8).abs() < 1e-12,
        "{pan} {tilt}"
    );
    // The simulated head's pan range is [-180, 180]: the same azimuth is pan -45°.
    let station = load_station(&example("sim-station.ron")).expect("valid");
    assert_eq!(station.value.head.reach(315.0, 30.0), Some((-45.0, 30.0)));
    assert_eq!(
        station.value.head.reach(0.0, -45.0),
        None,
        "below the tilt limit of -30°"
    );
}
