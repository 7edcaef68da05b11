//! A GenICam machine-vision camera (GigE Vision, USB3 Vision) through
//! Aravis (cargo feature `aravis`; Debian's `libaravis-dev`, 0.8.26): manual
//! exposure in µs and gain, Mono, Bayer and RGB8 frames as RGB codes, the
//! exposure and gain read back from the camera, and the frame's time from
//! the buffer's timestamp.
//!
//! **Opening** ([`AravisCamera::open`]): the camera is found by Aravis's
//! device id (`Vendor-Serial`), physical id or address, as `campanile
//! devices` lists them. Aravis's fake camera, `"Fake_1"`, is reached by
//! enabling Aravis's `Fake` interface first (Aravis leaves it off). Then:
//! automatic exposure and gain off where the camera has them; triggers
//! cleared (free run) and continuous acquisition mode; the pixel format
//! set ([`genicam_format::choose`]: the configured one, or the deepest raw
//! one offered); the region set to the configured resolution, centred on
//! the sensor when the camera has offsets; `options.features` (Aravis's
//! `Name=Value` list) written last. Every setting is read back, and a
//! camera that keeps another pixel format or size is an error.
//!
//! **Each capture** checks exposure and gain against the camera's bounds
//! ([`DeviceError::OutOfRange`], nothing written), writes them with the
//! acquisition stopped, reads both back (the frame's `exposure_actual` and
//! `gain` are what the camera reports, not what was asked), drops the
//! buffers that arrived meanwhile, starts the acquisition, drops
//! [`AravisOptions::settle_frames`] frames (a camera may have frames in
//! flight exposed before the change), keeps the next and stops. No frame
//! within the exposure plus [`AravisOptions::frame_timeout`] is
//! [`DeviceError::Timeout`]; an incomplete buffer is a camera error.
//!
//! **Time.** `Frame::timestamp` is the buffer's *system timestamp* (the
//! host's clock, UTC, when Aravis received the frame; for the fake camera,
//! when it filled it) minus the exposure read back: the start of the
//! exposure if the frame is stamped as its exposure ends (readout time is
//! not known and not subtracted). It is never earlier than the host's clock
//! when the acquisition was started, since no exposure of the kept frame
//! began before that (the fake camera delivers frames at its frame rate
//! whatever the exposure, so without this bound a long exposure would date
//! its frame before the previous one). The buffer's own *timestamp* counts
//! the camera's clock from an unknown origin (for GigE Vision, ticks since
//! the camera was reset), so it is not a UTC time; it is logged with each
//! frame, not used. A buffer without a system timestamp takes the host's
//! clock when the acquisition started.
//!
//! **Gain** is in dB when the camera's `Gain` feature says so; otherwise
//! (`GainRaw`, a unitless `Gain`) its range is spread over the station's
//! configured dB range ([`GainScale`]). Exposure is GenICam's
//! `ExposureTime` or the older `ExposureTimeAbs` (the fake camera's), in
//! µs, through Aravis's camera API, which picks the one the camera has.
//!
//! glib objects cannot leave their thread: [`open`] runs the camera on its
//! own ([`ThreadedCamera`]).
//!
//! Not done: packed pixel formats (`Mono12p`, `Mono12Packed`) and YUV,
//! chunk data (the exposure as the frame's chunk says), the sensor's
//! temperature (`DeviceTemperature`), hardware triggers, binning.

use super::camera_thread::{BlockingCamera, ThreadedCamera};
use super::genicam_format::{self, ExposureScale, GainScale, GenicamFormat, GenicamLayout, to_rgb_codes};
use crate::device::{CameraInfo, CaptureSettings, DeviceError, Frame};
use aravis::glib;
use aravis::prelude::*;
use aravis::{Auto, Buffer, BufferStatus, Camera as ArvCamera, Stream};
use campanile_config::camera::{Camera as CameraConfig, DeviceRef};
use glib::prelude::Cast;
use std::time::Duration;

/// Settings beyond the station's camera config.
#[derive(Debug, Clone, PartialEq)]
pub struct AravisOptions {
    /// Frames dropped after the settings change, before the kept one.
    pub settle_frames: u32,
    /// How long to wait for a frame beyond its exposure.
    pub frame_timeout: Duration,
    /// Buffers queued on the stream.
    pub buffers: usize,
    /// GenICam features written after opening, in Aravis's syntax
    /// (`"AcquisitionFrameRate=30 BlackLevel=0"`); empty for none.
    pub features: String,
}

impl Default for AravisOptions {
    /// One settle frame, 5 s timeout, 4 buffers, no extra features.
    fn default() -> Self {
        Self {
            settle_frames: 1,
            frame_timeout: Duration::from_secs(5),
            buffers: 4,
            features: String::new(),
        }
    }
}

/// A GenICam camera found by Aravis, as `campanile devices` lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GenicamEntry {
    /// Aravis's device id (what `Aravis(id: …)` takes).
    pub id: String,
    /// Vendor.
    pub vendor: String,
    /// Model.
    pub model: String,
    /// Protocol: `GigEVision`, `USB3Vision` or `Fake`.
    pub protocol: String,
    /// Address (IP for GigE Vision), if any.
    pub address: String,
}

/// Aravis's fake camera's device id.
pub const FAKE_ID: &str = "Fake_1";

/// Held while this module touches Aravis's global device lists: Aravis
/// locks each call, but the strings `arv_get_device_id` and its siblings
/// return belong to the interfaces' lists, which the next update (by
/// `arv_update_device_list` or by opening a camera) frees. Code outside
/// this module that calls Aravis's system functions is not covered.
static SYSTEM: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn system_lock() -> std::sync::MutexGuard<'static, ()> {
    // A panic while listing leaves nothing half-done that matters here.
    SYSTEM.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Turn on Aravis's `Fake` interface (off by default), so that
/// [`FAKE_ID`] opens and [`list`] shows it.
pub fn enable_fake_interface() {
    let _guard = system_lock();
    // SAFETY: a NUL-terminated string that outlives the call; Aravis only
    // compares it with its interfaces' names and sets a flag (under
    // `SYSTEM`, against this module's other calls).
    unsafe { aravis_sys::arv_enable_interface(c"Fake".as_ptr()) }
}

/// The GenICam cameras Aravis finds (GigE Vision discovery waits about a
/// second for answers).
pub fn list() -> Vec<GenicamEntry> {
    let _guard = system_lock();
    // SAFETY: the list is updated and its strings copied under `SYSTEM`, so
    // no camera opened through this module frees them meanwhile.
    unsafe { aravis::get_device_list() }
        .into_iter()
        .map(|d| GenicamEntry {
            id: d.id.to_string_lossy().into_owned(),
            vendor: d.vendor.to_string_lossy().into_owned(),
            model: d.model.to_string_lossy().into_owned(),
            protocol: d.protocol.to_string_lossy().into_owned(),
            address: d.address.to_string_lossy().into_owned(),
        })
        .collect()
}

/// The id and wanted pixel format of a configured device, or a clear error.
fn device_id(device: Option<&DeviceRef>) -> Result<(String, Option<String>), DeviceError> {
    match device {
        Some(DeviceRef::Aravis { id, pixel_format }) => Ok((id.clone(), pixel_format.clone())),
        other => Err(DeviceError::Camera(format!(
            "the Aravis driver needs `device: Aravis(id: \"…\")`, not {other:?}"
        ))),
    }
}

/// Open the station's GenICam camera on its own thread, as a
/// [`Camera`](crate::device::Camera).
pub fn open(config: &CameraConfig, options: AravisOptions) -> Result<ThreadedCamera, DeviceError> {
    let (id, _) = device_id(config.device.as_ref())?;
    let config = config.clone();
    ThreadedCamera::spawn(&format!("GenICam camera {id}"), move || {
        AravisCamera::open(&config, options)
    })
}

/// How the gain is written and read.
#[derive(Debug, Clone, Copy, PartialEq)]
enum GainFeature {
    None,
    Float(&'static str),
    Integer(&'static str),
}

/// An open GenICam camera (blocking; see [`open`]).
pub struct AravisCamera {
    camera: ArvCamera,
    stream: Stream,
    name: String,
    layout: GenicamLayout,
    exposure: ExposureScale,
    gain_feature: GainFeature,
    gain: GainScale,
    info: CameraInfo,
    options: AravisOptions,
    sequence: u64,
}

impl std::fmt::Debug for AravisCamera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AravisCamera")
            .field("name", &self.name)
            .field("layout", &self.layout)
            .field("exposure", &self.exposure)
            .field("gain", &self.gain)
            .finish_non_exhaustive()
    }
}

fn fail(name: &str, what: &str, e: &glib::Error) -> DeviceError {
    DeviceError::Camera(format!("{name}: {what}: {e}"))
}

impl AravisCamera {
    /// Open and set up the camera `config` names (on the calling thread).
    pub fn open(config: &CameraConfig, options: AravisOptions) -> Result<Self, DeviceError> {
        let (id, wanted_format) = device_id(config.device.as_ref())?;
        if id.starts_with("Fake") {
            enable_fake_interface();
        }
        let opened = {
            let _guard = system_lock();
            ArvCamera::new(Some(&id))
        };
        let camera = opened.map_err(|e| {
            DeviceError::Camera(format!(
                "no GenICam camera {id:?} ({e}); `campanile devices` lists the ones Aravis finds"
            ))
        })?;
        let vendor = camera.vendor_name().map(|s| s.to_string()).unwrap_or_default();
        let model = camera.model_name().map(|s| s.to_string()).unwrap_or_default();
        let name = format!("{vendor} {model} ({id})");
        let f = |what: &str| {
            let name = name.clone();
            let what = what.to_owned();
            move |e: glib::Error| fail(&name, &what, &e)
        };
        let available = |feature: &str| camera.is_feature_available(feature).unwrap_or(false);

        if camera.is_exposure_auto_available().unwrap_or(false) {
            camera
                .set_exposure_time_auto(Auto::Off)
                .map_err(f("cannot turn automatic exposure off"))?;
        }
        if camera.is_gain_auto_available().unwrap_or(false) {
            camera
                .set_gain_auto(Auto::Off)
                .map_err(f("cannot turn automatic gain off"))?;
        }
        if available("TriggerMode") {
            camera.clear_triggers().map_err(f("cannot clear its triggers"))?;
        }
        if available("AcquisitionMode") {
            camera
                .set_acquisition_mode(aravis::AcquisitionMode::Continuous)
                .map_err(f("cannot set continuous acquisition"))?;
        }

        // Pixel format.
        let offered: Vec<String> = camera
            .dup_available_pixel_formats_as_strings()
            .map_err(f("cannot list its pixel formats"))?
            .into_iter()
            .map(|s| s.to_string())
            .collect();
        let offered_refs: Vec<&str> = offered.iter().map(String::as_str).collect();
        let (format_name, format) = genicam_format::choose(&offered_refs, wanted_format.as_deref())
            .map_err(|why| DeviceError::Camera(format!("{name}: {why}")))?;
        camera
            .set_pixel_format_from_string(format_name)
            .map_err(f(&format!("cannot set pixel format {format_name}")))?;
        let got = camera
            .pixel_format_as_string()
            .map_err(f("cannot read its pixel format"))?;
        if GenicamFormat::from_name(&got) != Some(format) {
            return Err(DeviceError::Camera(format!(
                "{name}: asked for pixel format {format_name}, the camera keeps {got}"
            )));
        }
        if format.bits() != config.bit_depth {
            tracing::warn!(camera = %name, configured = config.bit_depth, delivered = format.bits(), format = %format_name, "the camera's frames have another bit depth than the station config says");
        }

        // Region: the configured size, centred when the camera has offsets.
        let (w, h) = (config.resolution.width as i32, config.resolution.height as i32);
        let (sw, sh) = camera.sensor_size().map_err(f("cannot read its sensor size"))?;
        if w > sw || h > sh {
            return Err(DeviceError::Camera(format!(
                "{name}: asked for {w}×{h}, the sensor is {sw}×{sh}; set the station's camera resolution to at most that"
            )));
        }
        let centred = |span: i32, size: i32, inc: Result<i32, glib::Error>| {
            let inc = inc.ok().filter(|i| *i > 0).unwrap_or(1);
            (span - size) / 2 / inc * inc
        };
        let (x, y) = if available("OffsetX") && available("OffsetY") {
            (
                centred(sw, w, camera.x_offset_increment()),
                centred(sh, h, camera.y_offset_increment()),
            )
        } else {
            (0, 0)
        };
        camera
            .set_region(x, y, w, h)
            .map_err(f(&format!("cannot set its region to {w}×{h} at ({x}, {y})")))?;
        let (_, _, gw, gh) = camera.region().map_err(f("cannot read its region"))?;
        if (gw, gh) != (w, h) {
            return Err(DeviceError::Camera(format!(
                "{name}: asked for {w}×{h}, the camera gives {gw}×{gh}; set the station's camera resolution to one it offers"
            )));
        }
        if !options.features.trim().is_empty() {
            camera
                .device()
                .ok_or_else(|| DeviceError::Camera(format!("{name}: has no device to write features to")))?
                .set_features_from_string(&options.features)
                .map_err(f(&format!("cannot write features {:?}", options.features)))?;
        }

        // Exposure.
        if !camera.is_exposure_time_available().unwrap_or(false) {
            return Err(DeviceError::Camera(format!(
                "{name}: has no ExposureTime (nor ExposureTimeAbs) feature, so manual exposure is impossible"
            )));
        }
        let (lo, hi) = camera
            .exposure_time_bounds()
            .map_err(f("cannot read its exposure bounds"))?;
        let exposure_feature = if available("ExposureTime") {
            "ExposureTime"
        } else {
            "ExposureTimeAbs"
        };
        let inc = camera.float_increment(exposure_feature).ok();
        let exposure = ExposureScale::new(lo, hi, inc).ok_or_else(|| {
            DeviceError::Camera(format!(
                "{name}: its exposure bounds {lo}..={hi} µs are not a range of times"
            ))
        })?;

        // Gain: the feature Aravis's camera API would use, and its unit.
        let device = camera.device();
        let node = |feature: &str| device.as_ref().and_then(|d| d.feature(feature));
        let gain_feature = ["Gain", "GainAbs", "GainRaw"]
            .into_iter()
            .filter(|g| available(g))
            .find_map(|g| {
                let n = node(g)?;
                if n.dynamic_cast_ref::<aravis::GcFloat>().is_some() {
                    Some(GainFeature::Float(g))
                } else if n.dynamic_cast_ref::<aravis::GcInteger>().is_some() {
                    Some(GainFeature::Integer(g))
                } else {
                    None
                }
            })
            .unwrap_or(GainFeature::None);
        let (cmin, cmax) = (config.gain.min_db, config.gain.max_db);
        let gain = match gain_feature {
            GainFeature::None => GainScale::Fixed { db: cmin },
            GainFeature::Float(g) => {
                let (gmin, gmax) = camera.float_bounds(g).map_err(f("cannot read its gain bounds"))?;
                let inc = camera.float_increment(g).unwrap_or(0.0);
                let unit = node(g)
                    .and_then(|n| n.dynamic_cast_ref::<aravis::GcFloat>().and_then(|x| x.unit()))
                    .map(|u| u.to_string())
                    .unwrap_or_default();
                GainScale::of_feature(&unit, gmin, gmax, inc, cmin, cmax)
            }
            GainFeature::Integer(g) => {
                let (gmin, gmax) = camera.integer_bounds(g).map_err(f("cannot read its gain bounds"))?;
                let inc = camera.integer_increment(g).unwrap_or(1);
                GainScale::of_feature("", gmin as f64, gmax as f64, inc as f64, cmin, cmax)
            }
        };

        let payload = camera.payload().map_err(f("cannot read its payload size"))? as usize;
        let stream = camera.create_stream().map_err(f("cannot open a stream"))?;
        for _ in 0..options.buffers.max(2) {
            stream.push_buffer(Buffer::new_allocate(payload));
        }
        let layout = GenicamLayout::packed(format, w as usize, h as usize);
        let info = CameraInfo {
            model: name.clone(),
            width: layout.width,
            height: layout.height,
            bits: format.bits(),
            exposure: exposure.range(),
            gain: gain.range(),
            exposure_table: None,
            // A machine-vision sensor's codes are linear.
            linear: true,
        };
        tracing::info!(camera = %name, format = %format_name, ?exposure, ?gain, ?gain_feature, "GenICam camera open");
        Ok(Self {
            camera,
            stream,
            name,
            layout,
            exposure,
            gain_feature,
            gain,
            info,
            options,
            sequence: 0,
        })
    }

    fn read_gain(&self) -> Result<Option<f64>, glib::Error> {
        Ok(match self.gain_feature {
            GainFeature::None => None,
            GainFeature::Float(g) => Some(self.camera.float(g)?),
            GainFeature::Integer(g) => Some(self.camera.integer(g)? as f64),
        })
    }

    /// Drop the buffers waiting in the stream (frames of the old settings).
    fn drain(&self) {
        while let Some(b) = self.stream.try_pop_buffer() {
            self.stream.push_buffer(b);
        }
    }

    /// Start the acquisition, keep the frame after the settle frames, stop;
    /// with the host's clock when the acquisition started.
    fn grab(&self, exposure: Duration) -> Result<(Buffer, chrono::DateTime<chrono::Utc>), DeviceError> {
        let name = &self.name;
        self.drain();
        let started = chrono::Utc::now();
        self.camera
            .start_acquisition()
            .map_err(|e| fail(name, "cannot start the acquisition", &e))?;
        let wait = exposure + self.options.frame_timeout;
        let mut kept = None;
        for n in 0..=self.options.settle_frames {
            let Some(buffer) = self.stream.timeout_pop_buffer(wait.as_micros() as u64) else {
                kept = Some(Err(DeviceError::Timeout(format!("{name}: no frame within {wait:?}"))));
                break;
            };
            if buffer.status() != BufferStatus::Success {
                let status = buffer.status();
                self.stream.push_buffer(buffer);
                kept = Some(Err(DeviceError::Camera(format!(
                    "{name}: the frame arrived incomplete ({status:?})"
                ))));
                break;
            }
            if n == self.options.settle_frames {
                kept = Some(Ok(buffer));
            } else {
                self.stream.push_buffer(buffer);
            }
        }
        let stopped = self.camera.stop_acquisition();
        let buffer = kept.unwrap_or_else(|| Err(DeviceError::Camera(format!("{name}: no frame kept"))))?;
        if let Err(e) = stopped {
            self.stream.push_buffer(buffer);
            return Err(fail(name, "cannot stop the acquisition", &e));
        }
        Ok((buffer, started))
    }

    /// The frame's codes from `buffer`, checked against the layout.
    fn decode(&self, buffer: &Buffer) -> Result<Vec<u16>, DeviceError> {
        let name = &self.name;
        let (w, h) = (buffer.image_width() as usize, buffer.image_height() as usize);
        let code = buffer.image_pixel_format().raw();
        if (w, h) != (self.layout.width, self.layout.height) || code != self.layout.format.pfnc() {
            return Err(DeviceError::Camera(format!(
                "{name}: a {w}×{h} frame in pixel format 0x{code:08X} arrived, {}×{} {} (0x{:08X}) was set",
                self.layout.width,
                self.layout.height,
                self.layout.format.name(),
                self.layout.format.pfnc()
            )));
        }
        let (x_padding, _) = buffer.image_padding();
        let layout = GenicamLayout {
            stride: self.layout.stride + x_padding.max(0) as usize,
            ..self.layout
        };
        to_rgb_codes(&buffer.image_data(), &layout).map_err(|e| DeviceError::Camera(format!("{name}: {e}")))
    }
}

impl BlockingCamera for AravisCamera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let name = self.name.clone();
        // Both checked before anything is written.
        let exposure_us = self.exposure.value(settings.exposure)?;
        let gain_value = self.gain.value(settings.gain)?;
        let sequence = self.sequence;
        self.sequence += 1;
        self.camera
            .set_exposure_time(exposure_us)
            .map_err(|e| fail(&name, &format!("cannot set the exposure to {exposure_us} µs"), &e))?;
        match (self.gain_feature, gain_value) {
            (GainFeature::Float(g), Some(v)) => self.camera.set_float(g, v),
            (GainFeature::Integer(g), Some(v)) => self.camera.set_integer(g, v.round() as i64),
            _ => Ok(()),
        }
        .map_err(|e| fail(&name, "cannot set the gain", &e))?;
        let read_us = self
            .camera
            .exposure_time()
            .map_err(|e| fail(&name, "cannot read the exposure back", &e))?;
        let actual = ExposureScale::time(read_us).ok_or_else(|| {
            DeviceError::Camera(format!(
                "{name}: reports an exposure of {read_us} µs after {exposure_us} µs was set"
            ))
        })?;
        if (read_us - exposure_us).abs() > self.exposure.inc_us {
            tracing::info!(camera = %name, "camera applied {read_us} µs for {exposure_us} µs asked");
        }
        let gain_read = self
            .read_gain()
            .map_err(|e| fail(&name, "cannot read the gain back", &e))?;
        let (buffer, started) = self.grab(actual.duration())?;
        let decoded = self.decode(&buffer);
        let (system_ns, camera_ns, frame_id) = (buffer.system_timestamp(), buffer.timestamp(), buffer.frame_id());
        self.stream.push_buffer(buffer);
        let data = decoded?;
        let timestamp = match i64::try_from(system_ns) {
            Ok(ns) if ns > 0 => (chrono::DateTime::from_timestamp_nanos(ns)
                - chrono::Duration::from_std(actual.duration()).unwrap_or_default())
            .max(started),
            _ => started,
        };
        tracing::debug!(camera = %name, frame_id, camera_timestamp_ns = camera_ns, system_timestamp_ns = system_ns, "GenICam frame");
        Ok(Frame {
            width: self.layout.width,
            height: self.layout.height,
            bits: self.layout.format.bits(),
            data,
            exposure_requested: settings.exposure,
            exposure_actual: actual,
            gain: self.gain.gain(gain_read),
            sequence,
            timestamp,
            temperature_c: None,
            file: None,
        })
    }
}

impl Drop for AravisCamera {
    fn drop(&mut self) {
        // A camera left acquiring keeps streaming to nobody.
        let _ = self.camera.stop_acquisition();
    }
}
