//! A session on the INDI station from the command line, as a user runs it:
//! `campanile capture` of a short plan on `examples/indi/station.ron`
//! (INDI's CCD and filter-wheel simulators on a real `indiserver`, the
//! Pelco-D head's firmware emulator behind a pseudo-terminal), then
//! `campanile process` of what it stored.

mod common;

use campanile_capture::driver::indi::LocalServer;
use campanile_firmware_link::emulator::Emulator;
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use campanile_firmware_link::transport::serial;
use common::campanile;
use std::path::Path;
use std::time::Duration;

/// The bracket's exposures, seconds: 6 stops in 2-stop steps.
const EXPOSURES: [f64; 4] = [0.01, 0.04, 0.16, 0.64];

/// The bracket is captured as the CCD's FITS files, and `process` merges
/// it with the linear response a FITS sensor has (known, not recovered)
/// into one HDR view, every product's verdict ok, exit 0.
#[test]
fn an_indi_bracket_is_captured_and_processed() {
    let server = LocalServer::start(&["indi_simulator_ccd", "indi_simulator_wheel"]).unwrap_or_else(|e| panic!("{e}"));
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let _enter = rt.enter();
    let (head_master, head_slave) = serial::pty_pair().unwrap();
    let head_path = serial::device_path(&head_slave).unwrap();
    let head = PelcoConfig {
        speed: 90_000,
        pan_range: (-18_000, 17_999),
        ..PelcoConfig::default()
    };
    let _emulator = Emulator::spawn(PelcoDevice::new(head), head_master, Duration::from_millis(2));

    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let station = std::fs::read_to_string(root.join("examples/indi/station.ron"))
        .unwrap()
        .replace("/dev/ttyUSB0", &head_path)
        .replace("127.0.0.1:7624", &server.address());
    let tmp = tempfile::tempdir().unwrap();
    let station_file = tmp.path().join("station.ron");
    std::fs::write(&station_file, &station).unwrap();
    let start = chrono::Utc::now() + chrono::TimeDelta::seconds(4);
    let exposures = EXPOSURES.map(|t| t.to_string()).join(", ");
    let plan = format!(
        r#"Plan(
    name: "INDI bracket",
    start_date: "{}",
    sessions: [(
        name: "bracket",
        trigger: Clock(time: "{}"),
        steps: [
            Bracket(aim: PanTilt(pan_deg: 30.0, tilt_deg: 20.0), exposures_s: [{exposures}], filter: Some("clear")),
        ],
    )],
)"#,
        start.format("%Y-%m-%d"),
        start.format("%H:%M:%S")
    );
    let plan_file = tmp.path().join("plan.ron");
    std::fs::write(&plan_file, &plan).unwrap();
    let session = tmp.path().join("session");
    let out = campanile(&[
        "capture",
        "--sim-bounces",
        "1",
        plan_file.to_str().unwrap(),
        "--station",
        station_file.to_str().unwrap(),
        "--out",
        session.to_str().unwrap(),
    ]);
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    println!("{}{}", text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{}{}", text(&out.stdout), text(&out.stderr));
    let fits: Vec<_> = std::fs::read_dir(session.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fits"))
        .collect();
    assert_eq!(fits.len(), EXPOSURES.len(), "{fits:?}");

    let processed = tmp.path().join("processed");
    let out = campanile(&[
        "process",
        session.to_str().unwrap(),
        "--out",
        processed.to_str().unwrap(),
    ]);
    println!("{}{}", text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{}{}", text(&out.stdout), text(&out.stderr));
    let quality = std::fs::read_to_string(processed.join("quality.json")).unwrap();
    let quality: serde_json::Value = serde_json::from_str(&quality).unwrap();
    assert_eq!(quality["verdict"], "ok", "{quality:#}");
    let summary = std::fs::read_to_string(processed.join("summary.json")).unwrap();
    assert!(
        summary.contains("the response is known, not recovered"),
        "a FITS sensor is linear: {summary}"
    );

    // One HDR view of the bracket, at the camera's frame size. (Its values
    // are not checked here: without a telescope on the server the CCD
    // simulator draws only read noise, codes 0–9. The FITS path's numbers
    // are checked in tests/camera_files.rs, on the simulated station's
    // linear FITS frames against its truth.)
    let maps: Vec<_> = std::fs::read_dir(processed.join("radiance"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .collect();
    assert_eq!(maps.len(), 1, "{maps:?}");
    let map = campanile_process::exr_io::read_radiance_exr(&maps[0]).unwrap();
    assert_eq!((map.width, map.height), (256, 192));
    assert!(map.rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    drop(head_slave);
}
