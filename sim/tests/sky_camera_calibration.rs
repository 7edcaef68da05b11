//! The all-sky fisheye station of `examples/sky-fisheye-sim-station.ron`,
//! whose true camera is mis-set (3° of azimuth, 1.5° of tilt, focal 3%
//! long, k1 = 0.02): one clear summer day of rendered sun shots, the disc
//! centroids measured from the frames, and the station's nominal camera
//! calibrated from them. The goal: orientation and every ray of
//! the field within 0.05°.

use campanile_process::pose::{HeadPose, Mount, Pinhole};
use campanile_process::quality::Verdict;
use campanile_process::render::Sky;
use campanile_process::sky::{SkyFrame, sky_samples};
use campanile_process::sky_camera_calibration::{
    CalibrationOptions, SkyCameraModel, calibrate_sky_camera, calibration_report, direction_error_deg,
};
use campanile_process::sun::Observer;
use campanile_sim::world::sun_track::sun_shots;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Duration, Utc};

fn zenith() -> HeadPose {
    HeadPose {
        pan_rad: 0.0,
        tilt_rad: std::f64::consts::FRAC_PI_2,
    }
}

#[test]
fn rendered_sun_shots_calibrate_the_mis_set_fisheye_within_0_05_degrees() {
    let station = campanile_config::load_station(&examples_dir().join("sky-fisheye-sim-station.ron"))
        .unwrap()
        .value;
    let mut world = World::new(&station, load_scene(&examples_dir().join("sky-scene.ron")).unwrap());
    world.quality.samples_per_pixel = 1;
    world.quality.max_bounces = 0;
    let start: DateTime<Utc> = "2026-06-21T12:30:00Z".parse().unwrap();
    let times: Vec<DateTime<Utc>> = (0..16 * 4).map(|k| start + Duration::minutes(15 * k)).collect();
    let clock = std::time::Instant::now();
    let (shots, missed) = sun_shots(&world, zenith(), &times, 1e-5, 3).unwrap();
    let render_s = clock.elapsed().as_secs_f64();
    assert!(shots.len() >= 50, "{} shots, missed {missed:?}", shots.len());
    // The measured centroids against the true camera's image of the sun.
    let centroid_err: Vec<f64> = shots
        .iter()
        .map(|s| {
            let (u, v) = s.sighting.centroid_px;
            (u - s.true_pixel.0).hypot(v - s.true_pixel.1)
        })
        .collect();
    let worst_centroid = centroid_err.iter().copied().fold(0.0, f64::max);

    let nominal = SkyCameraModel {
        camera: Pinhole::of_camera(&station.camera),
        mount: Mount::of_calibration(&station.head.mount),
        head: zenith(),
    };
    let truth = SkyCameraModel {
        camera: Pinhole::of_camera(&world.camera),
        mount: world.mount,
        head: zenith(),
    };
    let s = &station.site;
    let observer = Observer::from_degrees(
        s.latitude_deg,
        s.longitude_deg,
        s.elevation_m,
        s.pressure_mbar,
        s.temperature_c,
    );
    let sightings: Vec<_> = shots.iter().map(|s| s.sighting).collect();
    let clock = std::time::Instant::now();
    let cal = calibrate_sky_camera(
        &sightings,
        &observer,
        s.delta_t_s,
        &nominal,
        &CalibrationOptions::default(),
    )
    .unwrap();
    let fit_s = clock.elapsed().as_secs_f64();
    let (before, after) = (
        nominal.orientation_error_deg(&truth),
        cal.model.orientation_error_deg(&truth),
    );
    let (_, field_before) = direction_error_deg(&truth, &nominal, (512, 512), 4, 90.0);
    let (field_rms, field_max) = direction_error_deg(&truth, &cal.model, (512, 512), 4, 90.0);
    println!(
        "{} shots rendered in {render_s:.1} s, centroid error ≤ {worst_centroid:.3} px; fit {fit_s:.3} s\n\
         orientation {before:.3}° → {after:.4}°; field max {field_before:.3}° → {field_max:.4}° (RMS {field_rms:.4}°)\n{}",
        shots.len(),
        calibration_report(&cal)
    );
    assert!(
        worst_centroid < 0.3,
        "a measured centroid {worst_centroid} px from the true image"
    );
    assert!(before > 3.0 && field_before > 5.0, "the nominal camera is mis-set");
    assert!(after < 0.05, "orientation off by {after}°");
    assert!(field_max < 0.05, "a ray of the field off by {field_max}°");
    assert_eq!(cal.verdict, Verdict::Ok, "{:?}", cal.reasons);

    // Used: the sun's direction from each measured centroid, and the sky
    // sampled from a frame at 20:00 UTC, through the nominal camera and
    // through the calibrated one, against the world's truth.
    let sun_error = |m: &SkyCameraModel| {
        shots
            .iter()
            .map(|s| {
                let (u, v) = s.sighting.centroid_px;
                let d = m.ray(u, v).unwrap();
                let t = world.sun(s.sighting.time).unwrap().direction();
                let dot: f64 = (0..3).map(|k| d[k] * t[k]).sum();
                dot.clamp(-1.0, 1.0).acos().to_degrees()
            })
            .fold(0.0, f64::max)
    };
    let (sun_before, sun_after) = (sun_error(&nominal), sun_error(&cal.model));
    world.quality.samples_per_pixel = 4;
    let time: DateTime<Utc> = "2026-06-21T20:00:00Z".parse().unwrap();
    let rig = world.rig(zenith(), [0.0, 0.0, 2.0], 512, 512);
    let image = world.render(time, &rig, &[], 11).unwrap();
    let daylight = world.daylight(time).unwrap().unwrap();
    let sun = world.sun(time).unwrap().direction();
    let sky_error = |m: &SkyCameraModel| {
        let frame = SkyFrame {
            width: 512,
            height: 512,
            rgb: &image.data,
            valid: None,
            camera: m.camera,
            mount: m.mount,
            pose: m.head,
        };
        let table = sky_samples(&[frame], sun, 4, 5f64.to_radians()).unwrap();
        let mut sum = 0.0;
        for (k, (zenith_rad, azimuth_rad)) in table.directions.iter().enumerate() {
            let d = campanile_process::sky::direction(*zenith_rad, *azimuth_rad);
            let truth = Sky::radiance(&daylight, &nalgebra::Vector3::from(d))[1];
            sum += (table.values[1][k] / truth - 1.0).powi(2);
        }
        ((sum / table.directions.len() as f64).sqrt(), table.directions.len())
    };
    let ((sky_before, n_before), (sky_after, n_after)) = (sky_error(&nominal), sky_error(&cal.model));
    println!(
        "sun direction from the centroids: ≤ {sun_before:.3}° nominal, ≤ {sun_after:.4}° calibrated\n\
         sky radiance (green) at the sampled directions: {:.2}% RMS nominal ({n_before} samples), {:.2}% calibrated ({n_after})",
        100.0 * sky_before,
        100.0 * sky_after
    );
    assert!(sun_after < 0.05 && sun_before > 3.0, "{sun_before} → {sun_after}");
    assert!(sky_after < 0.02, "sky {sky_after} RMS through the calibrated camera");
    assert!(sky_before > 3.0 * sky_after, "sky {sky_before} → {sky_after}");
}
