//! The camera trait: manual exposure and gain in, raw frames with the
//! settings the camera actually used out.
//!
//! Cameras round exposure times (a V4L2 driver takes them in 100 µs units,
//! a sensor in line times), so a [`Frame`] records both the exposure asked
//! for and the one the camera applied, as the session journal needs.

use super::{DeviceError, ExposureTime, FrameFile, Gain};
use campanile_process::camera::image::CodeImage;
use chrono::{DateTime, Utc};
use std::future::Future;

/// A closed range of exposure times and the step the camera rounds to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureRange {
    /// Shortest exposure.
    pub min: ExposureTime,
    /// Longest exposure.
    pub max: ExposureTime,
    /// The camera applies the nearest multiple of this step (within
    /// `min..=max`).
    pub step: ExposureTime,
}

impl ExposureRange {
    /// The exposure the camera applies for `requested`: the nearest
    /// multiple of the step, kept within `min..=max`; or
    /// [`DeviceError::OutOfRange`] if `requested` is outside the range.
    pub fn applied(&self, requested: ExposureTime) -> Result<ExposureTime, DeviceError> {
        let (lo, hi, s) = (self.min.seconds(), self.max.seconds(), self.step.seconds());
        let t = requested.seconds();
        if t < lo || t > hi {
            return Err(DeviceError::OutOfRange {
                what: "exposure (s)",
                requested: t,
                min: lo,
                max: hi,
            });
        }
        let rounded = if s > 0.0 { (t / s).round() * s } else { t };
        // Clamp back inside the range; a range whose ends are not multiples
        // of the step keeps its ends.
        Ok(ExposureTime::from_seconds(rounded.clamp(lo, hi)).unwrap_or(requested))
    }
}

/// The exposure times of a camera with a stepped shutter (a DSLR's
/// nominal ⅓-stop speeds, a gphoto2 `shutterspeed` list), shortest first.
///
/// Requests snap to the nearest entry in stops (log₂ t), so a plan's
/// 1/3 s lands on 0.3 s, not on 0.4 s, and an auto-bracket four stops
/// apart stays four stops apart within the table's rounding.
#[derive(Debug, Clone, PartialEq)]
pub struct ExposureTable(Vec<ExposureTime>);

impl ExposureTable {
    /// A table of `seconds` (any order; repeats dropped), or `None` if it
    /// holds no finite positive time.
    pub fn new(seconds: &[f64]) -> Option<Self> {
        let mut t: Vec<f64> = seconds.iter().copied().filter(|s| s.is_finite() && *s > 0.0).collect();
        t.sort_by(f64::total_cmp);
        t.dedup();
        let times: Vec<ExposureTime> = t.into_iter().filter_map(ExposureTime::from_seconds).collect();
        (!times.is_empty()).then_some(Self(times))
    }

    /// The times, shortest first.
    pub fn times(&self) -> &[ExposureTime] {
        &self.0
    }

    /// The index of the entry nearest `requested` in stops (the shorter of
    /// two equally near).
    pub fn nearest_index(&self, requested: ExposureTime) -> usize {
        let l = requested.seconds().log2();
        let mut best = 0;
        for (i, t) in self.0.iter().enumerate() {
            if (t.seconds().log2() - l).abs() < (self.0[best].seconds().log2() - l).abs() {
                best = i;
            }
        }
        best
    }

    /// The entry nearest `requested` in stops.
    pub fn nearest(&self, requested: ExposureTime) -> ExposureTime {
        self.0[self.nearest_index(requested)]
    }

    /// The notches a dial turns from the entry nearest `from` to the one
    /// nearest `to` (positive: longer), for cameras that take a notch at a
    /// time.
    pub fn notches(&self, from: ExposureTime, to: ExposureTime) -> isize {
        self.nearest_index(to) as isize - self.nearest_index(from) as isize
    }

    /// The range the table spans, with the step 0 (the table rounds).
    pub fn range(&self) -> ExposureRange {
        let (first, last) = (self.0[0], self.0[self.0.len() - 1]);
        ExposureRange {
            min: first,
            max: last,
            step: ExposureTime::default(),
        }
    }
}

/// A closed range of gains and the step the camera rounds to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainRange {
    /// Lowest gain.
    pub min: Gain,
    /// Highest gain.
    pub max: Gain,
    /// The camera applies the nearest multiple of this step, in dB (0:
    /// continuous).
    pub step_db: f64,
}

impl GainRange {
    /// The gain the camera applies for `requested`, or
    /// [`DeviceError::OutOfRange`].
    pub fn applied(&self, requested: Gain) -> Result<Gain, DeviceError> {
        let (lo, hi, g) = (self.min.db(), self.max.db(), requested.db());
        if g < lo || g > hi {
            return Err(DeviceError::OutOfRange {
                what: "gain (dB)",
                requested: g,
                min: lo,
                max: hi,
            });
        }
        let rounded = if self.step_db > 0.0 {
            (g / self.step_db).round() * self.step_db
        } else {
            g
        };
        Ok(Gain::from_db(rounded.clamp(lo, hi)).unwrap_or(requested))
    }
}

/// What a camera is and what it accepts (known after opening it).
#[derive(Debug, Clone, PartialEq)]
pub struct CameraInfo {
    /// Model or driver name, for the journal.
    pub model: String,
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Significant bits per sample of raw frames (8 to 16).
    pub bits: u8,
    /// Exposure times it accepts.
    pub exposure: ExposureRange,
    /// Gains it accepts.
    pub gain: GainRange,
    /// The exposure times a stepped shutter offers (`None`: any time in
    /// `exposure`, rounded to its step).
    pub exposure_table: Option<ExposureTable>,
    /// Its codes are proportional to exposure (an astro camera's FITS
    /// frames, a machine-vision sensor's), not through a response curve:
    /// the controller meters them as such.
    pub linear: bool,
}

impl CameraInfo {
    /// The exposure the camera applies for `requested`: range-checked, then
    /// snapped to the table's nearest entry if the shutter is stepped, else
    /// rounded to the range's step ([`ExposureRange::applied`]).
    pub fn exposure_applied(&self, requested: ExposureTime) -> Result<ExposureTime, DeviceError> {
        let rounded = self.exposure.applied(requested)?;
        Ok(match &self.exposure_table {
            Some(table) => table.nearest(requested),
            None => rounded,
        })
    }
}

/// Settings for one frame (all manual: no auto-exposure).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaptureSettings {
    /// Exposure time asked for.
    pub exposure: ExposureTime,
    /// Analogue gain asked for.
    pub gain: Gain,
}

/// One raw frame and the metadata the camera reported with it.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Significant bits per sample: codes lie in `0..=2^bits − 1`.
    pub bits: u8,
    /// Interleaved RGB codes (`[r, g, b, r, g, b, …]`, row-major),
    /// `width · height · 3` of them.
    pub data: Vec<u16>,
    /// Exposure time asked for.
    pub exposure_requested: ExposureTime,
    /// Exposure time the camera applied (rounded to its step).
    pub exposure_actual: ExposureTime,
    /// Gain the camera applied.
    pub gain: Gain,
    /// The camera's frame counter (consecutive for consecutive captures,
    /// counting failed ones).
    pub sequence: u64,
    /// When the exposure started, UTC.
    pub timestamp: DateTime<Utc>,
    /// Sensor temperature in °C, if the camera reports one.
    pub temperature_c: Option<f64>,
    /// The file the camera delivered the frame as (JPEG, RAW), if it
    /// delivered one: the session store keeps it byte for byte and
    /// processing decodes it, while `data` serves the controller's metering
    /// and centering. `None`: the store encodes `data` as a 16-bit PNG.
    pub file: Option<FrameFile>,
}

impl Frame {
    /// The codes as a [`CodeImage`] for the processing crate, labelled with
    /// the sequence number and actual exposure.
    pub fn to_code_image(&self) -> CodeImage {
        CodeImage {
            width: self.width,
            height: self.height,
            bits: self.bits,
            data: self.data.clone(),
            label: format!(
                "frame {} ({} s, {} dB)",
                self.sequence,
                self.exposure_actual.seconds(),
                self.gain.db()
            ),
        }
    }
}

/// A camera with manual exposure and gain.
///
/// [`Camera::capture`] takes one frame and returns once it is read out:
/// the call lasts at least the exposure time. Settings outside
/// [`Camera::info`]'s ranges fail with [`DeviceError::OutOfRange`]; a frame
/// that never arrives fails with [`DeviceError::Timeout`]; a camera that
/// reports an error fails with [`DeviceError::Camera`].
pub trait Camera: Send {
    /// Resolution, bit depth, exposure and gain ranges (known after opening).
    fn info(&self) -> CameraInfo;

    /// Take one frame with `settings`.
    fn capture(&mut self, settings: CaptureSettings) -> impl Future<Output = Result<Frame, DeviceError>> + Send;

    /// Open the camera's link anew after a capture failed with
    /// [`DeviceError::Link`] (one attempt; the caller backs off between
    /// attempts). Cameras with no link to lose do nothing.
    fn reconnect(&mut self) -> impl Future<Output = Result<(), DeviceError>> + Send {
        std::future::ready(Ok(()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range() -> ExposureRange {
        ExposureRange {
            min: ExposureTime::from_micros(10).unwrap(),
            max: ExposureTime::from_seconds(30.0).unwrap(),
            step: ExposureTime::from_micros(10).unwrap(),
        }
    }

    #[test]
    fn exposure_is_rounded_to_the_step_and_range_checked() {
        let r = range();
        let e = |s| ExposureTime::from_seconds(s).unwrap();
        // 1/3 s → 333 330 µs (nearest 10 µs).
        assert!((r.applied(e(1.0 / 3.0)).unwrap().seconds() - 0.333_33).abs() < 1e-12);
        assert!((r.applied(e(0.012_345)).unwrap().seconds() - 0.012_35).abs() < 1e-12);
        assert!(matches!(r.applied(e(31.0)), Err(DeviceError::OutOfRange { .. })));
        assert!(matches!(r.applied(e(1e-6)), Err(DeviceError::OutOfRange { .. })));
    }

    #[test]
    fn a_stepped_shutter_snaps_to_its_nearest_nominal_in_stops() {
        let table = ExposureTable::new(campanile_config::shutter::ShutterSteps::Thirds.series().unwrap()).unwrap();
        let info = CameraInfo {
            model: "dslr".into(),
            width: 2,
            height: 2,
            bits: 14,
            exposure: table.range(),
            gain: GainRange {
                min: Gain::UNITY,
                max: Gain::UNITY,
                step_db: 0.0,
            },
            exposure_table: Some(table.clone()),
            linear: false,
        };
        let e = |s| ExposureTime::from_seconds(s).unwrap();
        let snapped = |s| info.exposure_applied(e(s)).unwrap().seconds();
        // 1/3 s: 0.3 s is 0.152 stop away, 0.4 s 0.263 stop.
        assert_eq!(snapped(1.0 / 3.0), 0.3);
        // 1/128 s (2^-7) is the nominal 1/125 s.
        assert_eq!(snapped(1.0 / 128.0), 1.0 / 125.0);
        // Four stops down from 1/60 s: 1/960 s → 1/1000 s.
        assert_eq!(snapped(1.0 / 960.0), 1.0 / 1000.0);
        assert_eq!(snapped(30.0), 30.0);
        assert!(matches!(
            info.exposure_applied(e(31.0)),
            Err(DeviceError::OutOfRange { .. })
        ));
        // From 1/125 s to 1/60 s is three notches; back is −3; 4 stops is 12.
        assert_eq!(table.notches(e(1.0 / 125.0), e(1.0 / 60.0)), 3);
        assert_eq!(table.notches(e(1.0 / 60.0), e(1.0 / 125.0)), -3);
        assert_eq!(table.notches(e(1.0 / 1000.0), e(1.0 / 60.0)), 12);
        assert_eq!(ExposureTable::new(&[f64::NAN, -1.0, 0.0]), None);
        assert_eq!(ExposureTable::new(&[0.5, 0.25, 0.5]).unwrap().times().len(), 2);
    }

    #[test]
    fn gain_is_range_checked() {
        let g = GainRange {
            min: Gain::UNITY,
            max: Gain::from_db(24.0).unwrap(),
            step_db: 0.1,
        };
        assert!((g.applied(Gain::from_db(6.04).unwrap()).unwrap().db() - 6.0).abs() < 1e-12);
        assert!(matches!(
            g.applied(Gain::from_db(30.0).unwrap()),
            Err(DeviceError::OutOfRange { .. })
        ));
    }
}
