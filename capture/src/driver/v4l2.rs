//! A V4L2 camera (cargo feature `v4l`): manual exposure and gain through
//! V4L2 controls, raw (`Y16 `, `RGB3`, `GREY`) or YUV (`YUYV`) capture,
//! and the exposure the driver actually applied read back for each frame.
//!
//! Opening sets the configured resolution and the preferred format the
//! camera offers ([`pixel_format::choose`]), switches
//! `V4L2_CID_EXPOSURE_AUTO` to manual and auto gain off, and fails with a
//! clear error if the camera refuses manual exposure or has no absolute
//! exposure control. Each capture sets exposure and gain, reads them back,
//! starts a memory-mapped stream, drops [`V4l2Options::settle_frames`]
//! frames (a UVC camera's pipeline still holds frames exposed with the old
//! settings), and keeps the next.
//!
//! The camera lives on its own thread ([`ThreadedCamera`]); use
//! [`open`] to get it as a [`Camera`](crate::device::Camera).
//!
//! Not done: Bayer formats, MJPEG (lossy: refused), the sensor's
//! temperature, frame timestamps from the driver (the host clock at the
//! start of the capture is recorded).

use super::camera_thread::{BlockingCamera, ThreadedCamera};
use super::exposure_control::{
    CID_ANALOGUE_GAIN, CID_AUTOGAIN, CID_EXPOSURE_ABSOLUTE, CID_EXPOSURE_AUTO, CID_GAIN, ControlRange, EXPOSURE_MANUAL,
    GainMap, applied_exposure, control_error, exposure_note, exposure_range, exposure_units,
};
use super::pixel_format::{self, Layout, PixelFormat, YuvRange, to_rgb_codes};
use crate::device::{CameraInfo, CaptureSettings, DeviceError, Frame};
use campanile_config::camera::{Camera as CameraConfig, DeviceRef};
use std::io;
use std::time::Duration;
use v4l::buffer::Type;
use v4l::control::{Control, Description, Value};
use v4l::format::{FourCC, Quantization};
use v4l::io::mmap::Stream;
use v4l::io::traits::CaptureStream;
use v4l::video::Capture;
use v4l::{Device, Format};

/// Settings beyond the station's camera config.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct V4l2Options {
    /// Frames dropped after the settings change, before the kept one.
    pub settle_frames: u32,
    /// How long to wait for a frame beyond its exposure.
    pub frame_timeout: Duration,
}

impl Default for V4l2Options {
    /// Two settle frames, 5 s timeout.
    fn default() -> Self {
        Self {
            settle_frames: 2,
            frame_timeout: Duration::from_secs(5),
        }
    }
}

/// An open V4L2 camera (blocking; see [`open`]).
pub struct V4l2Camera {
    dev: Device,
    name: String,
    layout: Layout,
    exposure: ControlRange,
    gain: Option<(u32, GainMap)>,
    gain_map: GainMap,
    info: CameraInfo,
    options: V4l2Options,
    sequence: u64,
}

impl std::fmt::Debug for V4l2Camera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("V4l2Camera")
            .field("name", &self.name)
            .field("layout", &self.layout)
            .field("exposure", &self.exposure)
            .finish_non_exhaustive()
    }
}

/// Open the station's V4L2 camera on its own thread, as a
/// [`Camera`](crate::device::Camera).
pub fn open(config: &CameraConfig, options: V4l2Options) -> Result<ThreadedCamera, DeviceError> {
    let config = config.clone();
    let name = device_name(config.device.as_ref());
    ThreadedCamera::spawn(&name, move || V4l2Camera::open(&config, options))
}

fn device_name(device: Option<&DeviceRef>) -> String {
    match device {
        Some(DeviceRef::Path(p)) => p.clone(),
        Some(DeviceRef::Index(i)) => format!("/dev/video{i}"),
        // An INDI or GenICam device names no V4L2 node (the config refuses it here).
        None | Some(DeviceRef::Indi { .. } | DeviceRef::Aravis { .. }) => "/dev/video0".to_owned(),
    }
}

fn integer_range(d: &Description) -> ControlRange {
    ControlRange {
        min: d.minimum,
        max: d.maximum,
        step: i64::try_from(d.step).unwrap_or(1),
    }
}

impl V4l2Camera {
    /// Open and set up the camera `config` names (on the calling thread).
    pub fn open(config: &CameraConfig, options: V4l2Options) -> Result<Self, DeviceError> {
        let name = device_name(config.device.as_ref());
        let failed = |what: &str, e: io::Error| DeviceError::Camera(format!("{name}: {what}: {e}"));
        let dev = Device::with_path(&name).map_err(|e| failed("cannot open the camera", e))?;
        let offered: Vec<[u8; 4]> = dev
            .enum_formats()
            .map_err(|e| failed("cannot list its formats", e))?
            .iter()
            .map(|d| d.fourcc.repr)
            .collect();
        let Some(format) = pixel_format::choose(&offered) else {
            let list: Vec<String> = offered
                .iter()
                .map(|f| String::from_utf8_lossy(f).into_owned())
                .collect();
            return Err(DeviceError::Camera(format!(
                "{name}: offers only {}; campanile needs raw frames (Y16, RGB3, GREY) or YUYV (lossy formats such as MJPG are refused)",
                list.join(", ")
            )));
        };
        let (w, h) = (config.resolution.width, config.resolution.height);
        let asked = Format::new(w, h, FourCC::new(&format.fourcc()));
        let got = dev.set_format(&asked).map_err(|e| failed("cannot set the format", e))?;
        if (got.width, got.height) != (w, h) || got.fourcc.repr != format.fourcc() {
            return Err(DeviceError::Camera(format!(
                "{name}: asked for {w}×{h} {}, the camera gives {}×{} {}; set the station's camera resolution to one it offers",
                String::from_utf8_lossy(&format.fourcc()),
                got.width,
                got.height,
                String::from_utf8_lossy(&got.fourcc.repr)
            )));
        }
        let bits = if format == PixelFormat::Y16 {
            config.bit_depth
        } else {
            8
        };
        if bits != config.bit_depth {
            tracing::warn!(camera = %name, configured = config.bit_depth, delivered = bits, format = ?format, "the camera's frames have another bit depth than the station config says");
        }
        let layout = Layout {
            format,
            width: w as usize,
            height: h as usize,
            stride: (got.stride as usize).max(format.row_bytes(w as usize)),
            bits,
            range: match got.quantization {
                Quantization::FullRange => YuvRange::Full,
                _ => YuvRange::Limited,
            },
        };
        let controls = dev
            .query_controls()
            .map_err(|e| failed("cannot list its controls", e))?;
        let find = |id: u32| controls.iter().find(|c| c.id == id);
        let exposure = find(CID_EXPOSURE_ABSOLUTE).map(integer_range).ok_or_else(|| {
            DeviceError::Camera(format!(
                "{name}: has no absolute exposure control (V4L2_CID_EXPOSURE_ABSOLUTE), so manual exposure is impossible"
            ))
        })?;
        if find(CID_EXPOSURE_AUTO).is_some() {
            set(&dev, CID_EXPOSURE_AUTO, EXPOSURE_MANUAL).map_err(|e| control_error(&name, "manual exposure", &e))?;
            let mode = get(&dev, CID_EXPOSURE_AUTO).map_err(|e| control_error(&name, "manual exposure", &e))?;
            if mode != EXPOSURE_MANUAL {
                return Err(DeviceError::Camera(format!(
                    "{name}: refuses manual exposure (V4L2_CID_EXPOSURE_AUTO reads {mode} after setting {EXPOSURE_MANUAL}, manual)"
                )));
            }
        }
        if find(CID_AUTOGAIN).is_some() {
            set(&dev, CID_AUTOGAIN, 0).map_err(|e| control_error(&name, "auto gain off", &e))?;
        }
        let gain = [CID_ANALOGUE_GAIN, CID_GAIN].into_iter().find_map(|id| {
            find(id).map(|d| {
                (
                    id,
                    GainMap {
                        control: integer_range(d),
                        min_db: config.gain.min_db,
                        max_db: config.gain.max_db,
                    },
                )
            })
        });
        // Without a gain control, the gain is fixed at the configured minimum.
        let gain_map = gain.map_or(
            GainMap {
                control: ControlRange {
                    min: 0,
                    max: 0,
                    step: 1,
                },
                min_db: config.gain.min_db,
                max_db: config.gain.min_db,
            },
            |(_, g)| g,
        );
        let exposure_limits = exposure_range(&exposure)
            .ok_or_else(|| DeviceError::Camera(format!("{name}: exposure control range {exposure:?} is empty")))?;
        let caps = dev.query_caps().map_err(|e| failed("cannot query it", e))?;
        let info = CameraInfo {
            model: format!("{} ({}, {})", caps.card, caps.driver, name),
            width: layout.width,
            height: layout.height,
            bits,
            exposure: exposure_limits,
            gain: gain_map.range(),
            exposure_table: None,
            linear: false,
        };
        tracing::info!(camera = %info.model, format = ?format, ?exposure, "V4L2 camera open, manual exposure");
        Ok(Self {
            dev,
            name,
            layout,
            exposure,
            gain,
            gain_map,
            info,
            options,
            sequence: 0,
        })
    }

    fn grab(&mut self, exposure: Duration) -> Result<Vec<u8>, DeviceError> {
        let mut stream = Stream::with_buffers(&self.dev, Type::VideoCapture, 4)
            .map_err(|e| DeviceError::Camera(format!("{}: cannot start streaming: {e}", self.name)))?;
        stream.set_timeout(exposure + self.options.frame_timeout);
        for n in 0..=self.options.settle_frames {
            let (buf, meta) = stream.next().map_err(|e| {
                if e.kind() == io::ErrorKind::TimedOut {
                    DeviceError::Timeout(format!(
                        "{}: no frame within {:?}",
                        self.name,
                        exposure + self.options.frame_timeout
                    ))
                } else {
                    DeviceError::Camera(format!("{}: reading a frame: {e}", self.name))
                }
            })?;
            if n == self.options.settle_frames {
                let used = (meta.bytesused as usize).min(buf.len());
                return Ok(buf[..used].to_vec());
            }
        }
        Err(DeviceError::Camera(format!("{}: no frame kept", self.name)))
    }
}

fn set(dev: &Device, id: u32, value: i64) -> io::Result<()> {
    dev.set_control(Control {
        id,
        value: Value::Integer(value),
    })
}

fn get(dev: &Device, id: u32) -> io::Result<i64> {
    match dev.control(id)?.value {
        Value::Integer(v) => Ok(v),
        Value::Boolean(b) => Ok(i64::from(b)),
        _ => Err(io::Error::new(io::ErrorKind::InvalidData, "not an integer control")),
    }
}

impl BlockingCamera for V4l2Camera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let name = self.name.clone();
        let units = exposure_units(settings.exposure, &self.exposure)?;
        set(&self.dev, CID_EXPOSURE_ABSOLUTE, units).map_err(|e| control_error(&name, "the exposure", &e))?;
        let gain_value = self.gain_map.value(settings.gain)?;
        if let Some((id, _)) = self.gain {
            set(&self.dev, id, gain_value).map_err(|e| control_error(&name, "the gain", &e))?;
        }
        let read_back = get(&self.dev, CID_EXPOSURE_ABSOLUTE).map_err(|e| control_error(&name, "the exposure", &e))?;
        let gain_read = match self.gain {
            Some((id, _)) => get(&self.dev, id).map_err(|e| control_error(&name, "the gain", &e))?,
            None => gain_value,
        };
        if let Some(note) = exposure_note(settings.exposure, units, read_back) {
            tracing::info!(camera = %name, "{note}");
        }
        let actual = applied_exposure(units, read_back);
        let timestamp = chrono::Utc::now();
        let buf = self.grab(actual.duration())?;
        let data = to_rgb_codes(&buf, &self.layout).map_err(|e| DeviceError::Camera(format!("{name}: {e}")))?;
        let sequence = self.sequence;
        self.sequence += 1;
        Ok(Frame {
            width: self.layout.width,
            height: self.layout.height,
            bits: self.layout.bits,
            data,
            exposure_requested: settings.exposure,
            exposure_actual: actual,
            gain: self.gain_map.gain(gain_read),
            sequence,
            timestamp,
            temperature_c: None,
            file: None,
        })
    }
}
