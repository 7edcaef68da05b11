//! The GenICam camera driver against Aravis's own fake camera, in-process
//! (Aravis's `Fake` interface, device `Fake_1`; Debian's `libaravis-dev`,
//! which `.ci/run` installs). Built only with the `aravis` feature.
//!
//! The fake fills each frame with a diagonal ramp (Aravis 0.8.26,
//! `arv_fake_camera_diagonal_ramp`): with `b` its frame counter,
//! `s = 1 + GainRaw + log10(ExposureTimeAbs / 10 000 µs)` and
//! `i = (x + y + b) mod 255`, a Mono8 pixel is `min(255, ⌊i · s⌋)`, a
//! Mono16 pixel `min(65535, ⌊(256 (x + y + b) mod 65535) · s⌋)`, an RGB8
//! pixel the colour `jet[min(255, ⌊i · s⌋)]` of a 256-entry jet colour map,
//! and a Bayer pixel that colour's component for the photosite's filter.
//! At 10 ms and no gain, `s = 1` exactly. The frame counter is not
//! reported, so each check finds the offset `b` that fits and then requires
//! every pixel to fit it exactly (tolerance 0).

mod common;

use std::path::Path;
use std::time::Duration;

use campanile_capture::conformance;
use campanile_capture::device::{Camera, CaptureSettings, DeviceError, ExposureTime, Frame, Gain};
use campanile_capture::driver::aravis_camera::{self, AravisCamera, AravisOptions, FAKE_ID};
use campanile_capture::driver::camera_thread::BlockingCamera;
use campanile_capture::station::camera::{list_genicam_cameras, open_station_camera};
use campanile_config::camera::{Camera as CameraConfig, CameraDriver, DeviceRef, GainLimits, Resolution};
use campanile_process::camera::bayer::CfaPattern;

/// The fake camera at `width × height` in `format` (or the driver's
/// choice), its raw gain 0..=10 spread over 0..=20 dB.
fn config(format: Option<&str>, width: u32, height: u32) -> CameraConfig {
    let station =
        campanile_config::load_station(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/real-station.ron"))
            .unwrap()
            .value;
    CameraConfig {
        driver: CameraDriver::Aravis,
        device: Some(DeviceRef::Aravis {
            id: FAKE_ID.into(),
            pixel_format: format.map(str::to_owned),
        }),
        resolution: Resolution { width, height },
        bit_depth: 8,
        gain: GainLimits {
            min_db: 0.0,
            max_db: 20.0,
        },
        ..station.camera
    }
}

fn open(format: Option<&str>, width: u32, height: u32) -> AravisCamera {
    AravisCamera::open(&config(format, width, height), AravisOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn settings(seconds: f64, gain_db: f64) -> CaptureSettings {
    CaptureSettings {
        exposure: ExposureTime::from_seconds(seconds).unwrap(),
        gain: Gain::from_db(gain_db).unwrap(),
    }
}

fn px(f: &Frame, x: usize, y: usize) -> [u16; 3] {
    let i = (y * f.width + x) * 3;
    [f.data[i], f.data[i + 1], f.data[i + 2]]
}

/// The offsets `b` for which every pixel of a grey frame is `code(x, y, b)`.
/// Frames at least 255 pixels wide hold every residue of `x + y + b`, so
/// a saturated ramp still pins `b` down by where it wraps to 0.
fn fitting_offsets(f: &Frame, period: u32, code: impl Fn(usize, usize, u32) -> u16) -> Vec<u32> {
    (0..period)
        .filter(|&b| {
            (0..f.height).all(|y| {
                (0..f.width).all(|x| {
                    let p = px(f, x, y);
                    let want = code(x, y, b);
                    p == [want, want, want]
                })
            })
        })
        .collect()
}

/// Mono8's ramp at scale `s`: `min(255, ⌊((x + y + b) mod 255) · s⌋)`.
fn mono8(s: f64) -> impl Fn(usize, usize, u32) -> u16 {
    move |x, y, b| ((((x + y) as u32 + b) % 255) as f64 * s).clamp(0.0, 255.0) as u16
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_fake_camera_passes_the_camera_suite() {
    // Its default 512 × 512, in the format the driver chooses.
    let mut camera = aravis_camera::open(&config(None, 512, 512), AravisOptions::default()).unwrap();
    let info = camera.info();
    assert_eq!(
        (info.width, info.height, info.bits),
        (512, 512, 16),
        "Mono16, its deepest"
    );
    assert_eq!(info.model, "Aravis Fake (Fake_1)");
    // ExposureTimeAbs: 10 µs to 10 s; no increment stated, so 1 µs.
    assert_eq!(
        (
            info.exposure.min.seconds(),
            info.exposure.max.seconds(),
            info.exposure.step.seconds()
        ),
        (1e-5, 10.0, 1e-6)
    );
    let report = conformance::camera::run(&mut camera).await;
    assert!(report.passed(), "{report}");
    assert_eq!(report.checks.len(), 3);
}

#[test]
fn mono8_frames_are_the_fakes_ramp_exactly() {
    let mut camera = open(Some("Mono8"), 300, 4);
    let f = camera.capture(settings(0.01, 0.0)).unwrap();
    assert_eq!((f.width, f.height, f.bits, f.data.len()), (300, 4, 8, 300 * 4 * 3));
    assert_eq!(
        fitting_offsets(&f, 255, mono8(1.0)).len(),
        1,
        "one frame counter fits every pixel"
    );
}

#[test]
fn mono16_frames_are_the_fakes_ramp_exactly() {
    let mut camera = open(Some("Mono16"), 64, 48);
    let f = camera.capture(settings(0.01, 0.0)).unwrap();
    assert_eq!(f.bits, 16);
    // 256 (x + y + b) mod 65535 = (v₀₀ + 256 (x + y)) mod 65535.
    let v00 = u32::from(px(&f, 0, 0)[0]);
    let fits = fitting_offsets(&f, 1, |x, y, _| ((v00 + 256 * (x + y) as u32) % 65535) as u16);
    assert_eq!(fits, [0]);
}

/// The exposure reaches the camera: at 100 ms the ramp's scale is
/// 1 + log10(10) = 2, which the frame fits and the 10 ms scale does not;
/// and the exposure reported is the camera's (whole µs: its register
/// counts µs), not the one asked.
#[test]
fn exposure_is_applied_and_read_back_from_the_camera() {
    let mut camera = open(Some("Mono8"), 300, 2);
    let f = camera.capture(settings(0.1, 0.0)).unwrap();
    assert_eq!(fitting_offsets(&f, 255, mono8(2.0)).len(), 1);
    assert!(fitting_offsets(&f, 255, mono8(1.0)).is_empty());
    assert_eq!(f.exposure_actual.seconds(), 0.1);

    let asked = 0.012_345_6;
    let f = camera.capture(settings(asked, 0.0)).unwrap();
    assert_eq!(f.exposure_requested.seconds(), asked);
    let us = f.exposure_actual.seconds() * 1e6;
    assert!((us - us.round()).abs() < 1e-6, "whole µs as the camera holds it: {us}");
    assert!((us - asked * 1e6).abs() <= 1.0, "within the camera's 1 µs step: {us}");
    assert_ne!(
        f.exposure_actual.seconds(),
        asked,
        "the camera's value, not the request"
    );
}

/// The fake's GainRaw 0..=10 has no dB unit: spread over the configured
/// 0..=20 dB, 2 dB a step. 2 dB is raw 1, scale 1 + 1 = 2 at 10 ms; 5 dB
/// asks raw 2.5 → 3, scale 4, and reads back as 6 dB.
#[test]
fn raw_gain_is_spread_over_the_configured_decibels() {
    let mut camera = open(Some("Mono8"), 300, 2);
    let g = camera.info().gain;
    assert_eq!((g.min.db(), g.max.db(), g.step_db), (0.0, 20.0, 2.0));
    let f = camera.capture(settings(0.01, 2.0)).unwrap();
    assert_eq!(f.gain.db(), 2.0);
    assert_eq!(fitting_offsets(&f, 255, mono8(2.0)).len(), 1);
    let f = camera.capture(settings(0.01, 5.0)).unwrap();
    assert_eq!(f.gain.db(), 6.0);
    assert_eq!(fitting_offsets(&f, 255, mono8(4.0)).len(), 1);
    let e = camera.capture(settings(0.01, 21.0)).unwrap_err();
    assert_eq!(e.to_string(), "gain (dB) = 21 is outside 0..=20");
}

/// The jet colours of an RGB8 frame along its first row, `jet′[k] =
/// jet[(k + b) mod 255]`, after checking that every pixel is the colour of
/// its diagonal, `rgb(x, y) = jet′[(x + y) mod 255]`.
fn jet_from_rgb8(f: &Frame) -> Vec<[u16; 3]> {
    assert!(f.width >= 255);
    let jet: Vec<[u16; 3]> = (0..255).map(|k| px(f, k, 0)).collect();
    for y in 0..f.height {
        for x in 0..f.width {
            assert_eq!(px(f, x, y), jet[(x + y) % 255], "RGB8 at ({x}, {y})");
        }
    }
    jet
}

#[test]
fn rgb8_frames_are_the_fakes_colour_ramp() {
    let mut camera = open(Some("RGB8"), 256, 8);
    let f = camera.capture(settings(0.01, 0.0)).unwrap();
    assert_eq!(f.bits, 8);
    let jet = jet_from_rgb8(&f);
    // The jet map's first colour (index 0, where x + y + b ≡ 0) is dark
    // blue (0, 0, 132), and appears once along the diagonal period.
    assert_eq!(jet.iter().filter(|c| **c == [0, 0, 132]).count(), 1);
}

/// Each Bayer pattern the fake offers, demosaiced: every photosite keeps
/// its own colour's code, exactly the fake's (from the jet map an RGB8
/// frame shows), and every interpolated code lies within the codes of the
/// same filter colour around it. A wrongly read pattern fails the first
/// check.
///
/// Aravis's fake (0.8.26, and its main branch as of this writing) writes
/// its `BayerRG8` with blue at (0, 0) and its `BayerBG8` with red there,
/// against its own comments and PFNC; its `BayerGR8` and `BayerGB8` are as
/// named. The driver reads PFNC's layouts, so for those two it sees the
/// fake's blue photosites as red and the reverse: the test states the
/// layout the fake really writes.
#[test]
fn bayer_frames_demosaic_to_the_fakes_colours_in_all_four_patterns() {
    let mut rgb = open(Some("RGB8"), 256, 8);
    let jet = jet_from_rgb8(&rgb.capture(settings(0.01, 0.0)).unwrap());
    for (name, pattern, written) in [
        ("BayerRG8", CfaPattern::Rggb, CfaPattern::Bggr),
        ("BayerGR8", CfaPattern::Grbg, CfaPattern::Grbg),
        ("BayerGB8", CfaPattern::Gbrg, CfaPattern::Gbrg),
        ("BayerBG8", CfaPattern::Bggr, CfaPattern::Rggb),
    ] {
        let mut camera = open(Some(name), 64, 48);
        let f = camera.capture(settings(0.01, 0.0)).unwrap();
        assert_eq!(f.bits, 8);
        // The code the fake wrote at (x, y) for frame offset s.
        let raw = |x: usize, y: usize, s: usize| jet[(x + y + s) % 255][written.color_at(x, y)];
        let shifts: Vec<usize> = (0..255)
            .filter(|&s| {
                (0..f.height).all(|y| (0..f.width).all(|x| px(&f, x, y)[pattern.color_at(x, y)] == raw(x, y, s)))
            })
            .collect();
        assert_eq!(
            shifts.len(),
            1,
            "{name}: one frame counter fits every photosite: {shifts:?}"
        );
        let s = shifts[0];
        for y in 0..f.height {
            for x in 0..f.width {
                for c in 0..3 {
                    let around: Vec<u16> = (y.saturating_sub(1)..(y + 2).min(f.height))
                        .flat_map(|yy| (x.saturating_sub(1)..(x + 2).min(f.width)).map(move |xx| (xx, yy)))
                        .filter(|&(xx, yy)| pattern.color_at(xx, yy) == c)
                        .map(|(xx, yy)| raw(xx, yy, s))
                        .collect();
                    let (lo, hi) = (*around.iter().min().unwrap(), *around.iter().max().unwrap());
                    let v = px(&f, x, y)[c];
                    assert!(
                        (lo..=hi).contains(&v),
                        "{name} ({x}, {y}) channel {c}: {v} outside {lo}..={hi}"
                    );
                }
            }
        }
    }
}

/// The frame's time is the buffer's system timestamp less the exposure,
/// but not before the acquisition started: within the capture call, and
/// growing. At 5 ms (an eighth of the fake's 40 ms frame period) the
/// kept frame, the second after the start, is stamped at least one frame
/// period after the acquisition started, so its time is the buffer's
/// (less 5 ms), not the start's: later than the call began by 30 ms.
#[test]
fn timestamps_fall_within_the_capture_and_increase() {
    let mut camera = open(Some("Mono8"), 32, 32);
    let mut last = None;
    for exposure in [0.005, 0.2, 0.005, 0.05] {
        let before = chrono::Utc::now();
        let f = camera.capture(settings(exposure, 0.0)).unwrap();
        let after = chrono::Utc::now();
        assert!(
            f.timestamp >= before && f.timestamp <= after,
            "{} not within {before} .. {after}",
            f.timestamp
        );
        if exposure == 0.005 {
            assert!(
                f.timestamp - before >= chrono::TimeDelta::milliseconds(30),
                "{} is not the buffer's stamp ({before})",
                f.timestamp
            );
        }
        if let Some(t) = last {
            assert!(f.timestamp > t, "{} after {t}", f.timestamp);
        }
        last = Some(f.timestamp);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn errors_are_clear() {
    // No such camera, through the station's opener.
    let mut cfg = config(None, 64, 48);
    cfg.device = Some(DeviceRef::Aravis {
        id: "Nope-0000".into(),
        pixel_format: None,
    });
    let e = open_station_camera(&cfg)
        .await
        .err()
        .expect("no such camera")
        .to_string();
    assert!(
        e.starts_with("camera failure: no GenICam camera \"Nope-0000\"") && e.contains("campanile devices"),
        "{e}"
    );
    // A format the fake does not offer.
    let e = AravisCamera::open(&config(Some("BayerRG12"), 64, 48), AravisOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pixel format \"BayerRG12\" is not offered by the camera (it offers "),
        "{e}"
    );
    // Larger than the 2048 × 2048 sensor.
    let e = AravisCamera::open(&config(None, 4096, 64), AravisOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("asked for 4096×64, the sensor is 2048×2048"), "{e}");
    // Out of range: refused before anything is written.
    let mut camera = open(Some("Mono8"), 16, 16);
    assert!(matches!(
        camera.capture(settings(20.0, 0.0)),
        Err(DeviceError::OutOfRange {
            what: "exposure (s)",
            ..
        })
    ));
    assert!(matches!(
        camera.capture(settings(5e-6, 0.0)),
        Err(DeviceError::OutOfRange {
            what: "exposure (s)",
            ..
        })
    ));
    // Frames that do not come in time: one a second, two needed (the
    // settle frame and the kept one), 0.2 s allowed. (Dropping the camera
    // waits for the fake's stream thread, asleep until its next frame: a
    // longer period makes the test slower, not stricter.)
    let slow = AravisOptions {
        frame_timeout: Duration::from_millis(200),
        features: "AcquisitionFramePeriod=1000000".into(),
        ..AravisOptions::default()
    };
    let mut camera = AravisCamera::open(&config(Some("Mono8"), 16, 16), slow).unwrap();
    let started = std::time::Instant::now();
    let e = camera.capture(settings(1e-4, 0.0)).unwrap_err();
    assert!(matches!(e, DeviceError::Timeout(_)), "{e}");
    assert!(
        started.elapsed() < Duration::from_millis(900),
        "{:?}",
        started.elapsed()
    );
}

#[test]
fn the_fake_camera_is_listed_once_its_interface_is_on() {
    let found = list_genicam_cameras(true).expect("built with aravis");
    let fake = found.iter().find(|c| c.id == FAKE_ID).expect("Fake_1 listed");
    assert_eq!(fake.description, "Aravis Fake (Fake at 0.0.0.0)");
}

/// A plan run by the session controller on the wall clock through the
/// GenICam station of `examples/aravis/station.ron` (Aravis's fake camera
/// in BayerGR8, the head emulated): every promised frame is stored, with
/// the exposure the camera reported (whole µs, within 1 µs of the asked)
/// and the camera's time in the journal, and reads back through the
/// session reader at the station's size and depth; the 10 ms frame (ramp
/// scale 1) holds the fake's codes exactly at every photosite's own colour.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_plan_runs_through_the_controller_on_the_aravis_station() {
    use campanile_capture::store::SessionReader;

    let jet = tokio::task::spawn_blocking(|| {
        jet_from_rgb8(&open(Some("RGB8"), 256, 8).capture(settings(0.01, 0.0)).unwrap())
    })
    .await
    .unwrap();
    let run = common::run_plan(
        &common::example("aravis/station.ron"),
        r#"
            Bracket(aim: PanTilt(pan_deg: 20.0, tilt_deg: 10.0), exposures_s: [0.01, 0.04, 0.16],
                    on_error: (retries: 2, then: Continue)),
            Bracket(aim: PanTilt(pan_deg: 40.0, tilt_deg: 30.0), exposures_s: [0.02, 0.08],
                    on_error: (retries: 2, then: Continue)),"#,
        |_| {},
    )
    .await;
    assert_eq!((run.report.frames, run.report.missed), (5, 0), "{:?}", run.report);
    let (frames, start) = (&run.frames, run.start);
    assert_eq!(frames.len(), 5, "{:?}", run.entries);
    let mut asked: Vec<f64> = frames.iter().map(|f| f.meta.exposure_requested_s).collect();
    asked.sort_by(f64::total_cmp);
    assert_eq!(asked, [0.01, 0.02, 0.04, 0.08, 0.16]);
    for pair in frames.windows(2) {
        assert!(
            pair[1].meta.time > pair[0].meta.time,
            "{} then {}",
            pair[0].key,
            pair[1].key
        );
    }
    for f in frames {
        let us = f.meta.exposure_actual_s * 1e6;
        assert!((us - us.round()).abs() < 1e-6, "{}: {us} µs", f.key);
        assert!(
            (us - f.meta.exposure_requested_s * 1e6).abs() <= 1.0,
            "{}: {us} µs",
            f.key
        );
        assert!(f.meta.time >= start - chrono::TimeDelta::seconds(1), "{}", f.key);
    }
    let reader = SessionReader::open(&run.dir).unwrap();
    for f in reader.frames() {
        let image = reader.read_frame(f).unwrap();
        assert_eq!((image.width, image.height, image.bits), (512, 384, 8), "{}", f.key);
        if f.meta.exposure_requested_s == 0.01 {
            let (w, h) = (image.width, image.height);
            let own = |x: usize, y: usize| image.data[(y * w + x) * 3 + CfaPattern::Grbg.color_at(x, y)];
            let fits = (0..255)
                .filter(|&s| {
                    (0..h).all(|y| (0..w).all(|x| own(x, y) == jet[(x + y + s) % 255][CfaPattern::Grbg.color_at(x, y)]))
                })
                .count();
            assert_eq!(fits, 1, "{}: the fake's GR mosaic at every photosite", f.key);
        }
    }
}
