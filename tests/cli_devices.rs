//! `campanile devices`: listing, and `devices test` running the
//! conformance suites against a real station's serial devices, here the
//! firmware emulators behind pseudo-terminals (the Pelco-D head, FW102C
//! wheel and DMX USB Pro of examples/real-station.ron, opened by their
//! /dev/pts paths exactly as real ports are), and against the simulated
//! station.

mod common;

use campanile_firmware_link::emulator::Emulator;
use campanile_firmware_link::enttec::device::DmxDevice;
use campanile_firmware_link::fw102c::device::WheelDevice;
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use campanile_firmware_link::transport::serial;
use common::campanile;
use std::path::Path;
use std::time::Duration;

const TICK: Duration = Duration::from_millis(2);

/// A Pelco-D head that turns all the way round, as the example stations'
/// 0..359.99° pan says (the wire's −180° is its 180°).
fn round_head() -> PelcoConfig {
    PelcoConfig {
        speed: 90_000,
        pan_range: (-18_000, 17_999),
        ..PelcoConfig::default()
    }
}

#[test]
fn lists_serial_ports_and_cameras() {
    let out = campanile(&["devices"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines[0], "serial ports:");
    let cameras = lines.iter().position(|l| *l == "cameras:").expect("a cameras section");
    // Every listed port is a device node that exists.
    for port in &lines[1..cameras] {
        let p = port.trim();
        assert!(p == "(none found)" || Path::new(p).exists(), "{p}");
    }
    // GenICam cameras are listed through Aravis, or the build says it has no Aravis.
    assert!(
        lines.contains(&"GenICam cameras (Aravis):")
            || lines
                .iter()
                .any(|l| l.starts_with("note: built without the `aravis` feature")),
        "{stdout}"
    );
}

/// The three serial devices pass their suites over ptys; the V4L2 camera
/// is reported skipped in a build without the `v4l` feature (and tested
/// otherwise). A station whose wheel port does not exist fails, naming it.
#[test]
fn devices_test_runs_the_suites_over_pseudo_terminals() {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let _enter = rt.enter();
    let (head_master, head_slave) = serial::pty_pair().unwrap();
    let (wheel_master, wheel_slave) = serial::pty_pair().unwrap();
    let (lights_master, lights_slave) = serial::pty_pair().unwrap();
    let path = |s: &serial::SerialPort| serial::device_path(s).unwrap();
    let (head_path, wheel_path, lights_path) = (path(&head_slave), path(&wheel_slave), path(&lights_slave));
    let _emulators = (
        Emulator::spawn(PelcoDevice::new(round_head()), head_master, TICK),
        Emulator::spawn(WheelDevice::new(6), wheel_master, TICK),
        Emulator::spawn(DmxDevice::new(2718), lights_master, TICK),
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let real = std::fs::read_to_string(root.join("examples/real-station.ron")).unwrap();
    let station = real
        .replace("/dev/ttyUSB0", &head_path)
        .replace("/dev/ttyUSB1", &wheel_path)
        .replace("/dev/ttyUSB2", &lights_path);
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("pty-station.ron");
    std::fs::write(&file, &station).unwrap();

    let out = campanile(&[
        "devices",
        "test",
        "--station",
        file.to_str().unwrap(),
        "--move-limit-s",
        "10",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(stdout.contains(&format!("head (PelcoD on {head_path}):")), "{stdout}");
    assert!(
        stdout.contains(&format!("filter wheel (Fw102c on {wheel_path}):")),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!("lights (DmxEnttec on {lights_path}):")),
        "{stdout}"
    );
    // 6 head, 2 wheel and 2 lights checks, all passing.
    let serial_part = stdout.split("camera (").next().unwrap_or_default();
    assert!(!serial_part.contains("FAIL"), "{stdout}");
    let passes = serial_part
        .lines()
        .filter(|l| l.trim_start().starts_with("pass"))
        .count();
    assert_eq!(passes, 10, "{stdout}");
    // The camera is tested only when its driver is built (and then needs
    // a camera, which a build machine may not have).
    if !cfg!(feature = "v4l") {
        assert!(
            out.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("10 checks, 0 failed"), "{stdout}");
        assert!(stdout.contains("skipped: camera failure: this campanile was built without the V4L2 camera driver"));
    }

    // The wheel's port is gone: that device fails, the others still pass.
    let broken = station.replace(&wheel_path, "/dev/campanile-no-such-port");
    std::fs::write(&file, broken).unwrap();
    let out = campanile(&[
        "devices",
        "test",
        "--station",
        file.to_str().unwrap(),
        "--move-limit-s",
        "10",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("filter wheel (Fw102c on /dev/campanile-no-such-port):\n  FAIL  connect: I/O error on the device link: opening serial port /dev/campanile-no-such-port"),
        "{stdout}"
    );
    if !cfg!(feature = "v4l") {
        assert!(stdout.contains("9 checks, 1 failed"), "{stdout}");
    }
    drop((head_slave, wheel_slave, lights_slave));
}

#[test]
fn devices_test_on_the_simulated_station() {
    let out = campanile(&["devices", "test", "--station", "examples/sim-station.ron"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Head 6, wheel 2, lights 2, camera 3.
    assert!(stdout.contains("13 checks, 0 failed"), "{stdout}");
    assert!(stdout.contains("camera (Sim):"), "{stdout}");
}

#[test]
fn devices_test_refuses_a_bad_station() {
    let tmp = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let real = std::fs::read_to_string(root.join("examples/real-station.ron")).unwrap();
    let file = tmp.path().join("shared.ron");
    std::fs::write(&file, real.replace("/dev/ttyUSB1", "/dev/ttyUSB0")).unwrap();
    let out = campanile(&["devices", "test", "--station", file.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("the head and the filter wheel both use port \"/dev/ttyUSB0\""),
        "{stderr}"
    );
}

/// `examples/indi/station.ron` against a real `indiserver` running INDI's
/// CCD and filter-wheel simulators (Debian's indi-bin), its Pelco-D head on
/// a pseudo-terminal: every suite passes. `devices --indi` lists what the
/// server offers.
#[test]
fn devices_test_on_the_indi_station() {
    use campanile_capture::driver::indi::LocalServer;
    let server = LocalServer::start(&["indi_simulator_ccd", "indi_simulator_wheel"]).unwrap_or_else(|e| panic!("{e}"));
    let out = campanile(&["devices", "--indi", &server.address()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        stdout.contains("\"CCD Simulator\"  CCD, guider, filter wheel (indi_simulator_ccd)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("\"Filter Simulator\"  filter wheel (indi_simulator_wheel)"),
        "{stdout}"
    );

    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let _enter = rt.enter();
    let (head_master, head_slave) = serial::pty_pair().unwrap();
    let head_path = serial::device_path(&head_slave).unwrap();
    let _emulator = Emulator::spawn(PelcoDevice::new(round_head()), head_master, TICK);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let example = std::fs::read_to_string(root.join("examples/indi/station.ron")).unwrap();
    let station = example
        .replace("/dev/ttyUSB0", &head_path)
        .replace("127.0.0.1:7624", &server.address());
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("indi-station.ron");
    std::fs::write(&file, &station).unwrap();
    let out = campanile(&[
        "devices",
        "test",
        "--station",
        file.to_str().unwrap(),
        "--move-limit-s",
        "10",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let address = server.address();
    assert!(
        stdout.contains(&format!("filter wheel (INDI \"Filter Simulator\" on {address}):")),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!("camera (INDI \"CCD Simulator\" on {address}):")),
        "{stdout}"
    );
    // 6 head, 2 wheel and 3 camera checks.
    assert!(stdout.contains("11 checks, 0 failed"), "{stdout}");
    drop(head_slave);
}
