//! The simulated station photographing the simulated world: device
//! emulators, the camera and the renderer together under paused time.

use std::sync::Arc;
use std::time::Duration;

use campanile_capture::device::{Camera, CaptureSettings, ExposureTime, Gain, PanTilt, Pose};
use campanile_sim::camera::FrameSource;
use campanile_sim::station::{SimOptions, SimStation};
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Utc};

fn small_station() -> campanile_config::Station {
    let mut st = campanile_config::document::load_station(&examples_dir().join("sim-station.ron"))
        .unwrap()
        .value;
    st.camera.resolution.width = 48;
    st.camera.resolution.height = 36;
    st
}

fn settings(exposure_s: f64) -> CaptureSettings {
    CaptureSettings {
        exposure: ExposureTime::from_seconds(exposure_s).unwrap(),
        gain: Gain::UNITY,
    }
}

/// A frame through the station is exactly the world's radiance for the view
/// the camera recorded (same head angles, time and seed), and the head
/// reaches the pose asked for.
#[tokio::test(start_paused = true)]
async fn the_station_photographs_the_world_it_is_told_about() {
    let station = small_station();
    let mut world = World::new(
        &station,
        load_scene(&examples_dir().join("campanile-scene.ron")).unwrap(),
    );
    world.quality.samples_per_pixel = 2;
    let world = Arc::new(world);
    let origin: DateTime<Utc> = "2026-08-29T22:00:00Z".parse().unwrap();
    let options = SimOptions {
        origin,
        position_m: [0.0, -60.0, 1.5],
        ..SimOptions::default()
    };
    let mut sim = SimStation::start(&station, world.clone(), options).await.unwrap();
    let (pan, tilt) = station.head.reach(0.0, 20.0).unwrap();
    sim.head.move_to(Pose::from_degrees(pan, tilt)).await.unwrap();
    let reached = sim.head.wait_idle(Duration::from_secs(30)).await.unwrap();
    assert!((reached.pan.degrees() - pan).abs() < 0.01 && (reached.tilt.degrees() - tilt).abs() < 0.01);
    let frame = sim.camera.capture(settings(0.01)).await.unwrap();
    let truth = sim.camera.last_truth().unwrap();
    assert!((truth.view.head.pan_rad.to_degrees() - pan).abs() < 0.01);
    // The slew took simulated time, and the frame's time is the view's.
    assert!(truth.view.time > origin && truth.view.time < origin + chrono::Duration::seconds(10));
    assert_eq!(frame.timestamp, truth.view.time);
    let again = world.radiance(&truth.view);
    let seen = sim.camera.last_sensor_radiance().unwrap();
    // The sensor saw the world's radiance times falloff (1 at the centre, no filter in slot 1).
    let centre = (18 * 48 + 24) * 3 + 1;
    let ratio = seen.data[centre] / again.data[centre];
    assert!(
        (ratio - 1.0).abs() < 0.01,
        "centre pixel: sensor {} vs world {}",
        seen.data[centre],
        again.data[centre]
    );
    // The tower stands in the middle of the frame and the sky above it.
    let top = (2 * 48 + 24) * 3 + 1;
    assert!(again.data[centre] != again.data[top]);
}

/// A simulated day: a frame of the zenith every 30 minutes for 24 hours,
/// through the devices and the renderer, runs under paused time; the
/// zenith is black at night and brightest near solar noon (its radiance
/// grows with the sun's elevation).
#[tokio::test(start_paused = true)]
async fn a_simulated_day_of_zenith_frames() {
    let station = small_station();
    let mut world = World::new(
        &station,
        load_scene(&examples_dir().join("campanile-scene.ron")).unwrap(),
    );
    world.quality.samples_per_pixel = 1;
    world.quality.max_bounces = 1;
    let origin: DateTime<Utc> = "2026-08-29T07:00:00Z".parse().unwrap(); // midnight, local
    let options = SimOptions {
        origin,
        position_m: [30.0, -60.0, 1.5],
        ..SimOptions::default()
    };
    let world = Arc::new(world);
    let mut sim = SimStation::start(&station, world.clone(), options).await.unwrap();
    let (pan, tilt) = station.head.reach(0.0, 89.0).unwrap();
    sim.head.move_to(Pose::from_degrees(pan, tilt)).await.unwrap();
    sim.head.wait_idle(Duration::from_secs(30)).await.unwrap();
    let mut zenith = Vec::new();
    for i in 0..48u32 {
        tokio::time::sleep_until(
            sim.clock()
                .instant_of(origin + chrono::Duration::minutes(30 * i64::from(i))),
        )
        .await;
        sim.camera.capture(settings(0.001)).await.unwrap();
        // The centre pixels look at the zenith (the frame's edges see the aureole).
        let l = sim.camera.last_sensor_radiance().unwrap();
        let centre = [(17, 23), (17, 24), (18, 23), (18, 24)];
        let mean = centre
            .iter()
            .map(|(y, x)| f64::from(l.data[(y * 48 + x) * 3 + 1]))
            .sum::<f64>()
            / 4.0;
        // What the world's sky model says along those pixels' rays, for the
        // head angles and the time the camera recorded.
        let view = sim.camera.last_truth().unwrap().view;
        let rig = world.rig(view.head, view.position_m, 48, 36);
        let expected = match world.daylight(view.time).unwrap() {
            Some(day) => {
                centre
                    .iter()
                    .map(|(y, x)| {
                        let d = rig.ray(*x as f64 + 0.5, *y as f64 + 0.5).unwrap().direction;
                        day.sky_radiance([d.x, d.y, d.z])[1]
                    })
                    .sum::<f64>()
                    / 4.0
            }
            None => 0.0,
        };
        if expected > 0.0 {
            assert!(
                (mean / expected - 1.0).abs() < 0.03,
                "{}: zenith {mean} vs model {expected}",
                view.time
            );
        } else {
            assert_eq!(mean, 0.0, "{}: the sky is black at night", view.time);
        }
        zenith.push((view.time, expected));
    }
    assert_eq!(sim.frames_taken(), 48);
    let (brightest, _) = zenith.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    // Solar noon in Berkeley on 29 August is about 20:09 UTC.
    let noon: DateTime<Utc> = "2026-08-29T20:09:00Z".parse().unwrap();
    assert!(
        (brightest - noon).num_minutes().abs() <= 45,
        "brightest zenith at {brightest}"
    );
    let midnight = zenith[0].1;
    assert_eq!(midnight, 0.0, "the sky at local midnight is black");
}
