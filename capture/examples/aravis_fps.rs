//! Captures per second through the GenICam driver from Aravis's fake
//! camera (in-process, `Fake_1`), each capture a full settings change and
//! frame as the controller asks for it (exposure and gain written and read
//! back, stale buffers dropped, acquisition started, one settle frame
//! dropped, the next kept and decoded, acquisition stopped).
//!
//! Usage: `cargo run --release -p campanile-capture --features aravis
//! --example aravis_fps -- [FRAMES] [WIDTH HEIGHT] [FORMAT] [SETTLE] [FEATURES]`;
//! defaults 50 frames of the fake's default 512 × 512 Mono8, one settle
//! frame, the fake's own 25 fps (`FEATURES` such as
//! `AcquisitionFramePeriod=1000` lifts it to 1000 fps).

use campanile_capture::device::{CaptureSettings, ExposureTime, Gain};
use campanile_capture::driver::aravis_camera::{AravisCamera, AravisOptions, FAKE_ID};
use campanile_capture::driver::camera_thread::BlockingCamera;
use campanile_config::camera::{CameraDriver, DeviceRef, Resolution};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.to_owned());
    let frames: usize = arg(0, "50").parse()?;
    let (width, height): (u32, u32) = (arg(1, "512").parse()?, arg(2, "512").parse()?);
    let format = arg(3, "Mono8");
    let settle_frames: u32 = arg(4, "1").parse()?;
    let features = arg(5, "");
    let station =
        campanile_config::load_station(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/aravis/station.ron"))?
            .value;
    let config = campanile_config::camera::Camera {
        driver: CameraDriver::Aravis,
        device: Some(DeviceRef::Aravis {
            id: FAKE_ID.into(),
            pixel_format: Some(format.clone()),
        }),
        resolution: Resolution { width, height },
        ..station.camera
    };
    let options = AravisOptions {
        settle_frames,
        features: features.clone(),
        ..AravisOptions::default()
    };
    let mut camera = AravisCamera::open(&config, options)?;
    let settings = CaptureSettings {
        exposure: ExposureTime::from_seconds(0.001).ok_or("exposure")?,
        gain: Gain::UNITY,
    };
    camera.capture(settings)?;
    let start = std::time::Instant::now();
    for _ in 0..frames {
        camera.capture(settings)?;
    }
    let s = start.elapsed().as_secs_f64();
    println!(
        "{frames} captures of {width}×{height} {format}, {settle_frames} settle frame(s), features {features:?}: {s:.3} s, {:.1} captures/s",
        frames as f64 / s
    );
    Ok(())
}
