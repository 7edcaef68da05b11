//! The gphoto2 camera driver (feature `gphoto2`, Debian `libgphoto2-dev`,
//! which `.ci/run` installs): the choice of camera among those detected,
//! and that opening with no camera attached is a clear error. An
//! integration test, so that CI's driver step builds only this crate's
//! targets (see `.ci/run`).

use campanile_capture::device::DeviceError;
use campanile_capture::driver::gphoto2_camera::{Gphoto2Tether, open, pick};
use campanile_config::camera::DeviceRef;
use gphoto2::list::CameraDescriptor;

fn descriptors() -> Vec<CameraDescriptor> {
    vec![
        CameraDescriptor {
            model: "Canon EOS 5D Mark II".into(),
            port: "usb:001,004".into(),
        },
        CameraDescriptor {
            model: "Nikon DSC D7000".into(),
            port: "usb:001,007".into(),
        },
    ]
}

#[test]
fn the_device_picks_by_port_model_or_index() {
    let found = descriptors();
    assert_eq!(pick(&found, None).unwrap().model, "Canon EOS 5D Mark II");
    let by_port = pick(&found, Some(&DeviceRef::Path("usb:001,007".into()))).unwrap();
    assert_eq!(by_port.model, "Nikon DSC D7000");
    let by_model = pick(&found, Some(&DeviceRef::Path("Nikon DSC D7000".into()))).unwrap();
    assert_eq!(by_model.port, "usb:001,007");
    assert_eq!(pick(&found, Some(&DeviceRef::Index(1))).unwrap().port, "usb:001,007");
    let err = pick(&found, Some(&DeviceRef::Index(2))).unwrap_err().to_string();
    assert!(
        err.contains("camera number 2") && err.contains("Nikon DSC D7000 at usb:001,007"),
        "{err}"
    );
    let err = pick(&[], None).unwrap_err().to_string();
    assert!(
        err.starts_with("camera failure: gphoto2 finds no camera (cameras found: none); check") && err.contains("PTP"),
        "{err}"
    );
}

/// No camera is attached where the tests run: opening is a clear error,
/// not a panic, whether the camera is asked for by default, port or
/// model.
#[test]
fn opening_with_no_camera_attached_is_a_clear_error() {
    let station = campanile_config::load_station(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/real-station.ron"),
    )
    .unwrap()
    .value;
    let mut cfg = station.camera.clone();
    cfg.driver = campanile_config::camera::CameraDriver::Gphoto2;
    for device in [
        None,
        Some(DeviceRef::Path("usb:999,999".into())),
        Some(DeviceRef::Path("Canon EOS 5D Mark II".into())),
    ] {
        cfg.device = device.clone();
        let err = Gphoto2Tether::open(cfg.device.as_ref()).unwrap_err();
        assert!(matches!(err, DeviceError::Camera(_)), "{device:?}: {err:?}");
        let msg = err.to_string();
        assert!(
            msg.starts_with("camera failure: gphoto2 finds no camera"),
            "{device:?}: {msg}"
        );
        assert!(msg.contains("(cameras found: none)"), "{device:?}: {msg}");
        if let Some(DeviceRef::Path(p)) = &device {
            assert!(msg.contains(&format!("matching {p} ")), "{device:?}: {msg}");
        }
        // Through the camera thread too.
        let err = open(&cfg).unwrap_err().to_string();
        assert_eq!(err, msg, "{device:?}");
    }
}
