//! Issue 3, "Real tty": each protocol's command set through a real
//! pseudo-terminal. The emulator runs on the controlling end; the host
//! driver opens the device end by path with the `serialport` crate (through
//! tokio-serial), exactly as it would open a USB-serial adapter.
//!
//! These use real time (a pty is real I/O); each takes well under a second.

use campanile_firmware_link::emulator::Emulator;
use campanile_firmware_link::firmware::Firmware;
use campanile_firmware_link::transport::serial::{self, SerialPort};
use std::time::Duration;

/// Start `firmware` behind a pty; returns the emulator and the host's port.
fn behind_pty<F>(firmware: F) -> (Emulator<F>, SerialPort)
where
    F: Firmware + Send + 'static,
    F::Effect: Send + 'static,
{
    let (controller, device_end) = serial::pty_pair().expect("pty pair");
    let path = serial::device_path(&device_end).expect("pty path");
    assert!(path.starts_with("/dev/"), "{path}");
    let host = serial::open(&path, 115_200).expect("reopen the pty by path");
    drop(device_end);
    let emulator = Emulator::spawn(firmware, controller, Duration::from_millis(2));
    (emulator, host)
}

#[tokio::test]
async fn campanile_link_over_a_pty() {
    use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
    use campanile_firmware_link::link::host::{LinkClient, RetryPolicy};
    let cfg = DeviceConfig {
        speed: 10_000_000,
        ..DeviceConfig::default()
    };
    let (emu, port) = behind_pty(LinkDevice::new(cfg));
    let mut c = LinkClient::new(port, RetryPolicy::default(), 77);
    let info = c.info().await.unwrap();
    assert_eq!((info.pan_min, info.tilt_max), (cfg.pan_range.0, cfg.tilt_range.1));
    c.move_to(1_000_000, 500_000).await.unwrap();
    let s = c
        .wait_idle(Duration::from_millis(10), Duration::from_secs(3))
        .await
        .unwrap();
    assert_eq!((s.pan, s.tilt), (1_000_000, 500_000));
    let s = c.move_by(-250_000, 0).await.unwrap();
    assert_eq!(s.target_pan, 750_000);
    assert!(c.move_to(0, 2_000_000).await.is_err());
    c.stop().await.unwrap();
    c.set_motion(10_000_000, 1_000_000).await.unwrap();
    assert_eq!(c.select_filter(5).await.unwrap().slot, 5);
    assert_eq!(c.filter().await.unwrap().slot, 5);
    assert_eq!(c.set_light(0, 65_535).await.unwrap().levels[0], 65_535);
    assert_eq!(c.lights().await.unwrap().levels[0], 65_535);
    c.all_lights_off().await.unwrap();
    c.heartbeat().await.unwrap();
    c.home().await.unwrap();
    let s = c
        .wait_idle(Duration::from_millis(10), Duration::from_secs(3))
        .await
        .unwrap();
    assert_eq!((s.pan, s.tilt), (0, 0));
    assert_eq!(emu.firmware().filter_slot(), 5);
    assert_eq!(emu.firmware().light_levels(), &[0, 0, 0, 0]);
}

#[tokio::test]
async fn pelco_d_over_a_pty() {
    use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
    use campanile_firmware_link::pelco_d::host::PelcoD;
    let cfg = PelcoConfig {
        speed: 90_000,
        ..PelcoConfig::default()
    };
    let (emu, port) = behind_pty(PelcoDevice::new(cfg));
    let mut h = PelcoD::new(port, 1, Duration::from_millis(200), 3);
    h.goto(4500, -1000).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(h.pan().await.unwrap(), 4500);
    assert_eq!(h.tilt().await.unwrap(), -1000);
    h.set_preset(2).await.unwrap();
    h.goto(0, 0).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(h.pan().await.unwrap(), 0);
    h.go_to_preset(2).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!((h.pan().await.unwrap(), h.tilt().await.unwrap()), (4500, -1000));
    h.goto(-9000, 0).await.unwrap();
    h.stop().await.unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;
    let p = h.pan().await.unwrap();
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert_eq!(h.pan().await.unwrap(), p, "stopped head stays put");
    assert_eq!(emu.firmware().position().0, p);
    assert!(h.goto(40_000, 0).await.is_err());
}

#[tokio::test]
async fn flir_ptu_over_a_pty() {
    use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
    use campanile_firmware_link::flir_ptu::host::{Answer, Ptu};
    use campanile_firmware_link::flir_ptu::{Axis, Command, Query, Setting, Unsolicited};
    let cfg = PtuConfig {
        speed: 20_000,
        ..PtuConfig::default()
    };
    let (emu, port) = behind_pty(PtuDevice::new(cfg));
    let mut p = Ptu::new(port, Duration::from_millis(500));
    p.init().await.unwrap();
    assert_eq!(p.get(Axis::Pan, Query::Min).await.unwrap(), -3090);
    assert_eq!(p.get(Axis::Pan, Query::Max).await.unwrap(), 3090);
    assert_eq!(p.get(Axis::Tilt, Query::Min).await.unwrap(), -907);
    assert_eq!(p.get(Axis::Tilt, Query::Max).await.unwrap(), 604);
    assert_eq!(p.resolution_milli_arcsec(Axis::Pan).await.unwrap(), 185_142);
    p.set(Axis::Pan, Setting::Speed, 20_000).await.unwrap();
    assert_eq!(p.get(Axis::Pan, Query::Speed).await.unwrap(), 20_000);
    p.set(Axis::Pan, Setting::Acceleration, 3000).await.unwrap();
    assert_eq!(p.get(Axis::Pan, Query::Acceleration).await.unwrap(), 3000);
    p.set(Axis::Pan, Setting::Position, -2500).await.unwrap();
    p.set(Axis::Tilt, Setting::Position, 300).await.unwrap();
    p.await_motion(Duration::from_secs(2)).await.unwrap();
    assert_eq!(p.get(Axis::Pan, Query::Position).await.unwrap(), -2500);
    assert_eq!(p.get(Axis::Tilt, Query::Position).await.unwrap(), 300);
    p.set(Axis::Pan, Setting::Offset, 500).await.unwrap();
    p.await_motion(Duration::from_secs(2)).await.unwrap();
    assert_eq!(p.get(Axis::Pan, Query::Position).await.unwrap(), -2000);
    assert!(p.set(Axis::Pan, Setting::Position, 3200).await.is_err());
    p.halt().await.unwrap();
    // Limits off: the tilt runs into its stop and "!T" arrives between replies.
    assert_eq!(p.command(Command::LimitsOff).await.unwrap(), Answer::Ack);
    p.set(Axis::Tilt, Setting::Position, 5000).await.unwrap();
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert_eq!(p.get(Axis::Tilt, Query::Position).await.unwrap(), 604);
    assert_eq!(p.take_events(), [Unsolicited::TiltLimit]);
    assert_eq!(emu.firmware().position(), (-2000, 604));
}

#[tokio::test]
async fn enttec_dmx_usb_pro_over_a_pty() {
    use campanile_firmware_link::enttec::device::DmxDevice;
    use campanile_firmware_link::enttec::host::DmxUsbPro;
    let (emu, port) = behind_pty(DmxDevice::new(20_241_122));
    let mut w = DmxUsbPro::new(port, 8, Duration::from_millis(500));
    assert_eq!(w.serial_number().await.unwrap(), 20_241_122);
    let params = w.parameters().await.unwrap();
    assert_eq!((params.firmware, params.rate), (0x0144, 40));
    w.set_level(1, 255).await.unwrap();
    w.set_level(3, 128).await.unwrap();
    assert!(w.set_level(25, 1).await.is_err());
    // The serial number round trip orders the earlier writes.
    w.serial_number().await.unwrap();
    assert_eq!(&emu.firmware().universe()[..4], &[255, 0, 128, 0]);
    w.blackout().await.unwrap();
    w.serial_number().await.unwrap();
    assert!(emu.firmware().universe().iter().all(|&l| l == 0));
    assert_eq!(emu.firmware().frames, 3);
}

#[tokio::test]
async fn fw102c_over_a_pty() {
    use campanile_firmware_link::fw102c::device::WheelDevice;
    use campanile_firmware_link::fw102c::host::Fw102c;
    let (emu, port) = behind_pty(WheelDevice::new(6));
    let mut w = Fw102c::new(port, Duration::from_millis(500));
    assert_eq!(w.count().await.unwrap(), 6);
    assert!(w.identify().await.unwrap().contains("FW102C"));
    w.set_position(4).await.unwrap();
    assert_eq!(w.position().await.unwrap(), 4);
    assert!(w.set_position(7).await.is_err());
    assert_eq!(w.position().await.unwrap(), 4);
    assert_eq!(emu.firmware().position(), 4);
}
