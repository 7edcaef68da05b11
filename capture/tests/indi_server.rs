//! The INDI camera and filter wheel against a real `indiserver` running
//! INDI's own CCD and filter-wheel simulators (Debian's `indi-bin`, which
//! `.ci/run` installs): the conformance suites, the frames as stored and
//! read back, the FITS header in the journal's metadata, and a server that
//! goes away in the middle of an exposure and comes back.
//!
//! Each test starts its own server on a free loopback port and stops it by
//! its PID when done.

mod common;

use std::time::Duration;

use campanile_capture::conformance;
use campanile_capture::device::{Camera, CaptureSettings, DeviceError, ExposureTime, FrameFormat, Gain};
use campanile_capture::driver::backoff::{Backoff, reopen};
use campanile_capture::driver::indi::{IndiCamera, IndiClient, IndiWheel, LocalServer};
use campanile_capture::store::{FrameMeta, ShotKind, decode_frame};
use common::run_plan;

const CCD: &str = "CCD Simulator";
const WHEEL: &str = "Filter Simulator";

const DRIVERS: [&str; 2] = ["indi_simulator_ccd", "indi_simulator_wheel"];

/// A server with the CCD and wheel simulators on a free port.
fn server() -> LocalServer {
    LocalServer::start(&DRIVERS).unwrap_or_else(|e| panic!("{e}"))
}

fn settings(seconds: f64) -> CaptureSettings {
    CaptureSettings {
        exposure: ExposureTime::from_seconds(seconds).unwrap(),
        gain: Gain::UNITY,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_ccd_simulator_passes_the_camera_suite() {
    let server = server();
    let mut camera = IndiCamera::open(&server.address(), CCD, Some((256, 192)))
        .await
        .unwrap();
    let info = camera.info();
    assert_eq!((info.width, info.height, info.bits), (256, 192, 16));
    assert!(info.model.contains("indi_simulator_ccd"), "{}", info.model);
    let report = conformance::camera::run(&mut camera).await;
    assert!(report.passed(), "{report}");
    assert_eq!(report.checks.len(), 3);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_wheel_simulator_passes_the_wheel_suite() {
    let server = server();
    let mut wheel = IndiWheel::open(&server.address(), WHEEL).await.unwrap();
    use campanile_capture::device::FilterWheel;
    assert_eq!(wheel.slots(), 8, "the INDI filter simulator has 8 slots");
    let report = conformance::filter_wheel::run(&mut wheel).await;
    assert!(report.passed(), "{report}");
}

/// A frame keeps the camera's FITS file byte for byte; the store decodes it
/// to the very codes the driver delivered, and the journal's metadata
/// carries the camera's header, whose exposure is the one reported.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn frames_keep_their_fits_file_and_header() {
    let server = server();
    let mut camera = IndiCamera::open(&server.address(), CCD, Some((64, 48))).await.unwrap();
    let frame = camera.capture(settings(0.25)).await.unwrap();
    let file = frame.file.as_ref().expect("the FITS file");
    assert_eq!(file.format, FrameFormat::Fits);
    let decoded = decode_frame(
        std::path::Path::new("f.fits"),
        &file.bytes,
        FrameFormat::Fits,
        frame.bits,
    )
    .unwrap();
    assert_eq!((decoded.width, decoded.height), (64, 48));
    assert_eq!(
        decoded.data, frame.data,
        "the stored file decodes to the driver's codes"
    );
    assert!(
        (frame.exposure_actual.seconds() - 0.25).abs() < 1e-9,
        "{:?}",
        frame.exposure_actual
    );
    let meta = FrameMeta::from_frame(&frame, ShotKind::Data);
    let card = |k: &str| {
        meta.camera_report
            .iter()
            .find(|c| c.starts_with(&format!("{k} = ")))
            .cloned()
    };
    let exptime: f64 = card("EXPTIME").unwrap()["EXPTIME = ".len()..]
        .replace('D', "E")
        .parse()
        .unwrap();
    assert!((exptime - 0.25).abs() < 1e-9, "EXPTIME card {exptime}");
    assert!(card("DATE-OBS").is_some(), "{:?}", meta.camera_report);
    assert!(
        card("NAXIS1").is_some_and(|c| c.ends_with("64")),
        "{:?}",
        meta.camera_report
    );
    // Consecutive captures count up.
    let second = camera.capture(settings(0.1)).await.unwrap();
    assert_eq!(second.sequence, frame.sequence + 1);
}

/// The server killed during an exposure: the capture fails as a link error
/// (no hang, no panic, no frame); the camera reopened with backoff after the
/// server is back on the same port takes the next frame.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_lost_mid_exposure_is_a_link_error_and_reopens() {
    let mut server = server();
    let address = server.address();
    let mut camera = IndiCamera::open(&address, CCD, Some((64, 48))).await.unwrap();
    let exposing = tokio::spawn(async move {
        let r = camera.capture(settings(5.0)).await;
        (camera, r)
    });
    tokio::time::sleep(Duration::from_millis(800)).await;
    server.stop();
    let (_, result) = tokio::time::timeout(Duration::from_secs(20), exposing)
        .await
        .expect("the capture must end when the server goes away")
        .unwrap();
    match result {
        Err(DeviceError::Link(e)) => assert!(e.to_string().contains(&address), "{e}"),
        other => panic!("expected a link error, got {:?}", other.map(|f| f.sequence)),
    }
    let port = server.port();
    let restarted = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(1500));
        LocalServer::start_on(port, &DRIVERS).unwrap_or_else(|e| panic!("{e}"))
    });
    let backoff = Backoff {
        attempts: 8,
        first: Duration::from_millis(250),
        cap: Duration::from_secs(2),
    };
    let mut camera = reopen("INDI camera", backoff, || {
        IndiCamera::open(&address, CCD, Some((64, 48)))
    })
    .await
    .expect("reopened once the server is back");
    let _server = restarted.join().unwrap();
    let frame = camera.capture(settings(0.1)).await.unwrap();
    assert_eq!((frame.width, frame.height), (64, 48));
}

/// The gain set on opening is the one the frames' FITS headers state; a
/// gain outside CCD_GAIN's range and an ISO on a CCD without CCD_ISO are
/// refused, naming what the device offers.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_gain_set_on_opening_is_in_the_fits_header_and_bad_ones_are_refused() {
    use campanile_capture::driver::indi::CcdSettings;
    let server = server();
    let address = server.address();
    let sensor = CcdSettings {
        gain: Some(50.0),
        iso: None,
    };
    let mut camera = IndiCamera::open_with(&address, CCD, Some((64, 48)), &sensor)
        .await
        .unwrap();
    let frame = camera.capture(settings(0.05)).await.unwrap();
    let meta = FrameMeta::from_frame(&frame, ShotKind::Data);
    let gain = meta
        .camera_report
        .iter()
        .find_map(|c| c.strip_prefix("GAIN = "))
        .and_then(|v| v.parse::<f64>().ok());
    assert_eq!(gain, Some(50.0), "{:?}", meta.camera_report);
    drop(camera);
    let too_high = CcdSettings {
        gain: Some(1.0e5),
        iso: None,
    };
    match IndiCamera::open_with(&address, CCD, Some((64, 48)), &too_high).await {
        Err(DeviceError::OutOfRange { what, requested, .. }) => {
            assert_eq!((what, requested), ("INDI CCD_GAIN", 1.0e5));
        }
        other => panic!("expected out of range, got {:?}", other.map(|c| c.info())),
    }
    let iso = CcdSettings {
        gain: None,
        iso: Some("100".into()),
    };
    match IndiCamera::open_with(&address, CCD, Some((64, 48)), &iso).await {
        Err(DeviceError::Camera(e)) => assert!(e.contains("has no CCD_ISO"), "{e}"),
        other => panic!("expected a camera error, got {:?}", other.map(|c| c.info())),
    }
}

/// What a server offers: its devices, for `campanile devices`.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_client_lists_the_servers_devices() {
    let server = server();
    let client = IndiClient::connect(&server.address()).await.unwrap();
    client.defined(CCD, "CONNECTION").await.unwrap();
    client.defined(WHEEL, "CONNECTION").await.unwrap();
    let devices = client.devices();
    assert!(
        devices.contains(&CCD.to_owned()) && devices.contains(&WHEEL.to_owned()),
        "{devices:?}"
    );
    let e = IndiCamera::open(&server.address(), "No Such CCD", None)
        .await
        .err()
        .unwrap();
    let text = e.to_string();
    assert!(
        text.contains("no device \"No Such CCD\"") && text.contains(CCD),
        "{text}"
    );
}

/// `examples/indi/station.ron` on the server at `address`.
fn indi_station(address: &str) -> String {
    common::example("indi/station.ron").replace("127.0.0.1:7624", address)
}

/// A plan run by the session controller on the wall clock through the INDI
/// station's devices (the INDI CCD and filter wheel on a real server, the
/// head emulated): every promised frame is stored as the camera's FITS
/// file, with the filter asked for in place and the camera's header in the
/// journal, and reads back through the session reader.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_plan_runs_through_the_controller_on_the_indi_station() {
    use campanile_capture::store::SessionReader;

    let server = server();
    let run = run_plan(
        &indi_station(&server.address()),
        r#"
            Bracket(aim: PanTilt(pan_deg: 20.0, tilt_deg: 10.0), exposures_s: [0.01, 0.04, 0.16],
                    filter: Some("nd1"), on_error: (retries: 2, then: Continue)),
            Bracket(aim: PanTilt(pan_deg: 40.0, tilt_deg: 30.0), exposures_s: [0.02, 0.08],
                    filter: Some("clear"), on_error: (retries: 2, then: Continue)),"#,
        |_| {},
    )
    .await;
    assert_eq!((run.report.frames, run.report.missed), (5, 0), "{:?}", run.report);
    let frames = &run.frames;
    assert_eq!(frames.len(), 5, "{:?}", run.entries);
    for f in frames {
        assert_eq!(f.format, FrameFormat::Fits, "{}", f.key);
        // The camera's DATE-OBS, not before the session's trigger.
        assert!(
            f.meta.time >= run.start - chrono::TimeDelta::seconds(1),
            "{}: {}",
            f.key,
            f.meta.time
        );
        assert!(f.file.ends_with(".fits"), "{}", f.file);
        let exptime = f
            .meta
            .camera_report
            .iter()
            .find_map(|c| c.strip_prefix("EXPTIME = "))
            .and_then(|v| v.replace('D', "E").parse::<f64>().ok())
            .unwrap_or_else(|| panic!("{}: no EXPTIME in {:?}", f.key, f.meta.camera_report));
        assert!(
            (exptime - f.meta.exposure_actual_s).abs() < 1e-9,
            "{}: {exptime} vs {}",
            f.key,
            f.meta.exposure_actual_s
        );
        assert!(
            (f.meta.exposure_actual_s - f.meta.exposure_requested_s).abs() < 1e-6,
            "{}",
            f.key
        );
        // The second bracket (0.02 and 0.08 s) is taken through "clear".
        let second = [0.02, 0.08]
            .iter()
            .any(|t| (t - f.meta.exposure_requested_s).abs() < 1e-9);
        let wanted = if second { "clear" } else { "nd1" };
        assert_eq!(f.meta.filter.as_deref(), Some(wanted), "{}", f.key);
    }
    let reader = SessionReader::open(&run.dir).unwrap();
    for f in reader.frames() {
        let image = reader.read_frame(f).unwrap();
        assert_eq!((image.width, image.height), (256, 192), "{}", f.key);
    }
}

/// The server killed in the middle of a plan's 2 s exposure and started
/// again on its port 1.5 s later: the controller reconnects the camera,
/// retakes the interrupted shot and journals the camera's outage (from the
/// failed capture to the first frame after); every promised frame is
/// stored once, none lost, none doubled. Measured here: an outage of 4.6 s
/// beginning 0.5 ms after the kill, one retry, one reconnect.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_restarted_mid_plan_is_journaled_and_nothing_is_lost_or_doubled() {
    use campanile_capture::store::{JOURNAL_FILE, JournalEntry};

    let server = std::sync::Arc::new(std::sync::Mutex::new(Some(server())));
    let address = server.lock().unwrap().as_ref().unwrap().address();
    let port = server.lock().unwrap().as_ref().unwrap().port();
    let killed_at = std::sync::Arc::new(std::sync::Mutex::new(None));
    let during = {
        let (server, killed_at) = (server.clone(), killed_at.clone());
        move |dir: std::path::PathBuf| {
            // Once the first frame is journaled, the 2 s exposure is next:
            // kill the server 0.8 s into it.
            let journal = dir.join(JOURNAL_FILE);
            let deadline = std::time::Instant::now() + Duration::from_secs(60);
            while std::fs::read_to_string(&journal).map_or(0, |t| t.lines().count()) < 1 {
                assert!(std::time::Instant::now() < deadline, "no first frame within 60 s");
                std::thread::sleep(Duration::from_millis(20));
            }
            std::thread::sleep(Duration::from_millis(800));
            if let Some(mut s) = server.lock().unwrap().take() {
                s.stop();
            }
            *killed_at.lock().unwrap() = Some(chrono::Utc::now());
            std::thread::sleep(Duration::from_millis(1500));
            let again = LocalServer::start_on(port, &DRIVERS).unwrap_or_else(|e| panic!("{e}"));
            *server.lock().unwrap() = Some(again);
        }
    };
    let run = run_plan(
        &indi_station(&address),
        r#"
            Bracket(aim: PanTilt(pan_deg: 20.0, tilt_deg: 10.0), exposures_s: [0.01, 2.0, 0.04],
                    filter: Some("nd1"), on_error: (retries: 4, then: Continue)),"#,
        during,
    )
    .await;
    assert_eq!((run.report.frames, run.report.missed), (3, 0), "{:?}", run.entries);
    assert!(run.report.reconnects >= 1, "{:?}", run.report);
    let frames = &run.frames;
    let mut keys: Vec<&str> = frames.iter().map(|f| f.key.as_str()).collect();
    keys.sort_unstable();
    keys.dedup();
    assert_eq!(keys.len(), 3, "one frame per shot: {keys:?}");
    let mut exposures: Vec<f64> = frames.iter().map(|f| f.meta.exposure_actual_s).collect();
    exposures.sort_by(f64::total_cmp);
    assert_eq!(exposures, [0.01, 0.04, 2.0]);
    let killed_at = killed_at.lock().unwrap().expect("the server was killed");
    let outages: Vec<_> = run
        .entries
        .iter()
        .filter_map(|e| match e {
            JournalEntry::Outage(o) => Some(o.clone()),
            _ => None,
        })
        .collect();
    println!("killed at {killed_at}; outages {outages:?}; report {:?}", run.report);
    let camera = outages
        .iter()
        .find(|o| o.device == "camera")
        .unwrap_or_else(|| panic!("no camera outage journaled: {outages:?}"));
    // The camera's capture failed once the server was gone (within a
    // second of the kill) and answered once it was back (1.5 s later).
    assert!(!camera.open, "{camera:?}");
    let lag = (camera.start - killed_at).as_seconds_f64();
    assert!((-0.2..2.0).contains(&lag), "outage began {lag} s after the kill");
    let length = (camera.end - camera.start).as_seconds_f64();
    assert!(length >= 1.0, "the outage lasted {length} s; the server was down 1.5 s");
    // The 2 s frame retaken after the outage.
    let long = frames.iter().find(|f| f.meta.exposure_actual_s == 2.0).unwrap();
    assert!(long.meta.time >= camera.end - chrono::TimeDelta::seconds(3), "{long:?}");
    assert!(outages.iter().all(|o| !o.open && o.end > o.start), "{outages:?}");
}
