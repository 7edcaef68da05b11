//! A camera through nokhwa (cargo feature `nokhwa`, its V4L2 backend):
//! manual exposure and gain through nokhwa's camera controls, raw grey or
//! RGB or YUYV frames, the applied exposure read back.
//!
//! nokhwa's Linux backend exposes V4L2's controls, so the exposure is in
//! V4L2's 100 µs units and converted by [`super::exposure_control`], and
//! the gain is spread over the station's dB range as there. Its camera
//! cannot leave the thread that opened it: [`open`] runs it on its own
//! thread ([`ThreadedCamera`]).
//!
//! Not done: formats other than GRAY, RAWRGB and YUYV (MJPEG and NV12 are
//! refused), settle frames beyond one dropped frame, the sensor's temperature.

use super::camera_thread::{BlockingCamera, ThreadedCamera};
use super::exposure_control::{
    CID_EXPOSURE_AUTO, ControlRange, EXPOSURE_MANUAL, GainMap, applied_exposure, exposure_note, exposure_range,
    exposure_units,
};
use super::pixel_format::{Layout, PixelFormat, YuvRange, to_rgb_codes};
use crate::device::{CameraInfo, CaptureSettings, DeviceError, Frame};
use campanile_config::camera::{Camera as CameraConfig, DeviceRef};
use nokhwa::Camera as NokhwaDevice;
use nokhwa::utils::{
    CameraFormat, CameraIndex, ControlValueDescription, ControlValueSetter, FrameFormat, KnownCameraControl,
    RequestedFormat, RequestedFormatType,
};

/// The nokhwa index of a configured device: `Index(n)` as it is, a path
/// `/dev/videoN` as `N`, any other path by name.
pub fn camera_index(device: Option<&DeviceRef>) -> CameraIndex {
    match device {
        Some(DeviceRef::Index(i)) => CameraIndex::Index(*i),
        Some(DeviceRef::Path(p)) => match p.strip_prefix("/dev/video").and_then(|n| n.parse().ok()) {
            Some(n) => CameraIndex::Index(n),
            None => CameraIndex::String(p.clone()),
        },
        // An INDI or GenICam device names no V4L2 camera (the config refuses it here).
        None | Some(DeviceRef::Indi { .. } | DeviceRef::Aravis { .. }) => CameraIndex::Index(0),
    }
}

/// The buffer layout of a nokhwa frame format, if campanile takes it.
pub fn pixel_format(f: FrameFormat) -> Option<PixelFormat> {
    match f {
        FrameFormat::GRAY => Some(PixelFormat::Grey),
        FrameFormat::RAWRGB => Some(PixelFormat::Rgb24),
        FrameFormat::YUYV => Some(PixelFormat::Yuyv),
        FrameFormat::MJPEG | FrameFormat::NV12 | FrameFormat::RAWBGR => None,
    }
}

fn integer_range(d: &ControlValueDescription) -> Option<ControlRange> {
    match d {
        ControlValueDescription::IntegerRange { min, max, step, .. } => Some(ControlRange {
            min: *min,
            max: *max,
            step: *step,
        }),
        _ => None,
    }
}

fn integer(v: &ControlValueSetter) -> Option<i64> {
    match v {
        ControlValueSetter::Integer(i) | ControlValueSetter::EnumValue(i) => Some(*i),
        _ => None,
    }
}

/// An open nokhwa camera (blocking; see [`open`]).
pub struct NokhwaCamera {
    camera: NokhwaDevice,
    name: String,
    layout: Layout,
    exposure: ControlRange,
    gain: Option<GainMap>,
    gain_map: GainMap,
    info: CameraInfo,
    sequence: u64,
}

/// Open the station's camera through nokhwa on its own thread, as a
/// [`Camera`](crate::device::Camera).
pub fn open(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    let config = config.clone();
    let name = format!("nokhwa {}", camera_index(config.device.as_ref()));
    ThreadedCamera::spawn(&name, move || NokhwaCamera::open(&config))
}

impl NokhwaCamera {
    /// Open and set up the camera `config` names (on the calling thread).
    pub fn open(config: &CameraConfig) -> Result<Self, DeviceError> {
        let index = camera_index(config.device.as_ref());
        let name = format!("camera {index}");
        let fail = |what: &str, e: &dyn std::fmt::Display| DeviceError::Camera(format!("{name}: {what}: {e}"));
        let (w, h) = (config.resolution.width, config.resolution.height);
        let wanted = [FrameFormat::GRAY, FrameFormat::RAWRGB, FrameFormat::YUYV];
        let request = RequestedFormat::with_formats(
            RequestedFormatType::Closest(CameraFormat::new_from(w, h, FrameFormat::YUYV, 30)),
            &wanted,
        );
        let mut camera = NokhwaDevice::new(index.clone(), request).map_err(|e| fail("cannot open it", &e))?;
        let got = camera.camera_format();
        let Some(format) = pixel_format(got.format()) else {
            return Err(DeviceError::Camera(format!(
                "{name}: gives {} frames; campanile needs GRAY, RAWRGB or YUYV",
                got.format()
            )));
        };
        if (got.resolution().width(), got.resolution().height()) != (w, h) {
            return Err(DeviceError::Camera(format!(
                "{name}: asked for {w}×{h}, the camera gives {}; set the station's camera resolution to one it offers",
                got.resolution()
            )));
        }
        let layout = Layout {
            format,
            width: w as usize,
            height: h as usize,
            stride: format.row_bytes(w as usize),
            bits: 8,
            range: YuvRange::Limited,
        };
        let refused = |e: &dyn std::fmt::Display| {
            DeviceError::Camera(format!(
                "{name}: refuses manual exposure (setting V4L2_CID_EXPOSURE_AUTO to manual failed: {e})"
            ))
        };
        camera
            .set_camera_control(
                KnownCameraControl::Other(u128::from(CID_EXPOSURE_AUTO)),
                ControlValueSetter::Integer(EXPOSURE_MANUAL),
            )
            .map_err(|e| refused(&e))?;
        let exposure_control = camera
            .camera_control(KnownCameraControl::Exposure)
            .map_err(|e| fail("has no exposure control, so manual exposure is impossible", &e))?;
        let exposure = integer_range(exposure_control.description()).ok_or_else(|| {
            DeviceError::Camera(format!(
                "{name}: its exposure control is not an integer range ({:?})",
                exposure_control.description()
            ))
        })?;
        let gain = camera
            .camera_control(KnownCameraControl::Gain)
            .ok()
            .and_then(|c| integer_range(c.description()))
            .map(|control| GainMap {
                control,
                min_db: config.gain.min_db,
                max_db: config.gain.max_db,
            });
        let gain_map = gain.unwrap_or(GainMap {
            control: ControlRange {
                min: 0,
                max: 0,
                step: 1,
            },
            min_db: config.gain.min_db,
            max_db: config.gain.min_db,
        });
        let exposure_limits = exposure_range(&exposure)
            .ok_or_else(|| DeviceError::Camera(format!("{name}: exposure control range {exposure:?} is empty")))?;
        camera.open_stream().map_err(|e| fail("cannot start streaming", &e))?;
        let info = CameraInfo {
            model: format!("{} ({name})", camera.info().human_name()),
            width: layout.width,
            height: layout.height,
            bits: 8,
            exposure: exposure_limits,
            gain: gain_map.range(),
            exposure_table: None,
            linear: false,
        };
        Ok(Self {
            camera,
            name,
            layout,
            exposure,
            gain,
            gain_map,
            info,
            sequence: 0,
        })
    }
}

impl BlockingCamera for NokhwaCamera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let name = self.name.clone();
        let fail = |what: &str, e: &dyn std::fmt::Display| DeviceError::Camera(format!("{name}: {what}: {e}"));
        let units = exposure_units(settings.exposure, &self.exposure)?;
        self.camera
            .set_camera_control(KnownCameraControl::Exposure, ControlValueSetter::Integer(units))
            .map_err(|e| fail("cannot set the exposure", &e))?;
        let gain_value = self.gain_map.value(settings.gain)?;
        if self.gain.is_some() {
            self.camera
                .set_camera_control(KnownCameraControl::Gain, ControlValueSetter::Integer(gain_value))
                .map_err(|e| fail("cannot set the gain", &e))?;
        }
        let read_back = self
            .camera
            .camera_control(KnownCameraControl::Exposure)
            .ok()
            .and_then(|c| integer(&c.value()))
            .unwrap_or(0);
        if let Some(note) = exposure_note(settings.exposure, units, read_back) {
            tracing::info!(camera = %name, "{note}");
        }
        let actual = applied_exposure(units, read_back);
        let timestamp = chrono::Utc::now();
        // One frame still carries the old settings; keep the next.
        self.camera.frame().map_err(|e| fail("reading a frame", &e))?;
        let buffer = self.camera.frame().map_err(|e| fail("reading a frame", &e))?;
        let data =
            to_rgb_codes(buffer.buffer(), &self.layout).map_err(|e| DeviceError::Camera(format!("{name}: {e}")))?;
        let sequence = self.sequence;
        self.sequence += 1;
        Ok(Frame {
            width: self.layout.width,
            height: self.layout.height,
            bits: 8,
            data,
            exposure_requested: settings.exposure,
            exposure_actual: actual,
            gain: self.gain_map.gain(gain_value),
            sequence,
            timestamp,
            temperature_c: None,
            file: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn device_references_become_nokhwa_indices() {
        assert_eq!(
            camera_index(Some(&DeviceRef::Path("/dev/video3".into()))),
            CameraIndex::Index(3)
        );
        assert_eq!(camera_index(Some(&DeviceRef::Index(1))), CameraIndex::Index(1));
        assert_eq!(
            camera_index(Some(&DeviceRef::Path("/dev/v4l/by-id/usb-cam".into()))),
            CameraIndex::String("/dev/v4l/by-id/usb-cam".into())
        );
        assert_eq!(pixel_format(FrameFormat::YUYV), Some(PixelFormat::Yuyv));
        assert_eq!(pixel_format(FrameFormat::MJPEG), None);
    }
}
