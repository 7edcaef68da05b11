//! `campanile sky calibrate`: sun centroids of the mis-set all-sky camera
//! of `examples/sky-fisheye-sim-station.ron` (made here through its true
//! camera, with the ephemeris), calibrated into the file the station takes.

use std::fmt::Write as _;
mod common;

use campanile_process::pose::{HeadPose, Mount, Pinhole};
use campanile_process::sky_camera_calibration::SkyCameraModel;
use campanile_process::sun::{Observer, sun_position};
use chrono::{DateTime, Duration, Utc};
use common::campanile;

const STATION: &str = "examples/sky-fisheye-sim-station.ron";

fn station() -> campanile_config::Station {
    campanile_config::load_station(STATION.as_ref()).unwrap().value
}

/// The station's true camera (its `simulation.true_camera`) at the zenith.
fn truth() -> SkyCameraModel {
    let s = station();
    let t = s.simulation.as_ref().unwrap().true_camera.as_ref().unwrap();
    let truly = t.apply_to(&s).unwrap();
    SkyCameraModel {
        camera: Pinhole::of_camera(&truly.camera),
        mount: Mount::of_calibration(&truly.head.mount),
        head: HeadPose {
            pan_rad: 0.0,
            tilt_rad: std::f64::consts::FRAC_PI_2,
        },
    }
}

/// `count` sun shots from 13:00 UTC, `step_min` apart, with a
/// deterministic ±0.05 px jitter.
fn shots_csv(count: i64, step_min: i64) -> String {
    let s = station();
    let site = Observer::from_degrees(
        s.site.latitude_deg,
        s.site.longitude_deg,
        s.site.elevation_m,
        s.site.pressure_mbar,
        s.site.temperature_c,
    );
    let model = truth();
    let start: DateTime<Utc> = "2026-06-21T13:00:00Z".parse().unwrap();
    let mut csv = String::from("time,u_px,v_px,note\n");
    for k in 0..count {
        let t = start + Duration::minutes(k * step_min);
        let sun = sun_position(t, &site, s.site.delta_t_s).unwrap();
        let (u, v) = model.pixel(sun.direction()).unwrap();
        let j = 0.05 * ((k * 7919 % 13) as f64 / 6.0 - 1.0);
        let _ = writeln!(csv, "{},{:.5},{:.5},clear", t.to_rfc3339(), u + j, v - j);
    }
    csv
}

#[test]
fn a_day_of_sun_shots_gives_the_calibrated_camera_the_station_takes() {
    let dir = tempfile::tempdir().unwrap();
    let shots = dir.path().join("shots.csv");
    std::fs::write(&shots, shots_csv(57, 15)).unwrap();
    let out = dir.path().join("camera.ron");
    let run = campanile(&[
        "sky",
        "calibrate",
        shots.to_str().unwrap(),
        "--station",
        STATION,
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("verdict: ok") && stderr.contains("level_roll_deg"),
        "{stderr}"
    );
    let cal = campanile_config::document::load_camera_calibration(&out).unwrap().value;
    let t = station().simulation.unwrap().true_camera.unwrap();
    assert!(
        (cal.mount.pan_zero_azimuth_deg - t.mount.pan_zero_azimuth_deg).abs() < 0.01,
        "{cal:?}"
    );
    assert!(
        (cal.mount.level_roll_deg - t.mount.level_roll_deg).abs() < 0.01,
        "{cal:?}"
    );
    assert!(
        (cal.mount.level_pitch_deg - t.mount.level_pitch_deg).abs() < 0.01,
        "{cal:?}"
    );
    assert!((cal.intrinsics.distortion.0 - 0.02).abs() < 2e-4, "{cal:?}");
    let check = campanile(&["config", "check", out.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&check.stdout);
    assert_eq!(
        check.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&check.stderr)
    );
    assert!(
        text.contains("valid camera calibration") && text.contains("Equidistant"),
        "{text}"
    );
    let calibrated = cal.apply_to(&station()).unwrap();
    assert_eq!(calibrated.head.mount, cal.mount);
    let quality = std::fs::read_to_string(dir.path().join("camera.quality.json")).unwrap();
    assert!(quality.contains("\"verdict\": \"ok\""), "{quality}");
}

#[test]
fn too_few_shots_exit_3_and_a_bad_file_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let shots = dir.path().join("few.csv");
    std::fs::write(&shots, shots_csv(4, 30)).unwrap();
    let out = dir.path().join("camera.ron");
    let run = campanile(&[
        "sky",
        "calibrate",
        shots.to_str().unwrap(),
        "--station",
        STATION,
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("4 usable sun shots, at least 8 needed"), "{stderr}");

    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time,u_px,v_px\n2026-06-21T13:00:00Z,12.5,nan\n").unwrap();
    let run = campanile(&["sky", "calibrate", bad.to_str().unwrap(), "--station", STATION]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.csv:2: v_px \"nan\": expected a pixel position"),
        "{stderr}"
    );

    let help = campanile(&["sky", "calibrate", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("campanile sky calibrate shots.csv --station"), "{text}");
}
