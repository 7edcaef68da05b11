//! Manual exposure and gain through V4L2 integer controls: the control
//! IDs, the conversion of an exposure time to V4L2's 100 µs units and of
//! a gain in dB to a control value, the read-back of what the camera
//! applied, and the meaning of the errors `VIDIOC_S_EXT_CTRLS` returns.
//!
//! Pure arithmetic, so that it is tested without a camera; the V4L2 and
//! nokhwa drivers call it.
//!
//! **Exposure.** `V4L2_CID_EXPOSURE_ABSOLUTE` counts 100 µs units; the
//! driver rounds a request to the control's step within its range, and a
//! sensor may round again to its line time, so the value is read back
//! after setting it and the read-back is what the journal records.
//!
//! **Gain.** V4L2 gives gain no unit: `V4L2_CID_GAIN` (or
//! `V4L2_CID_ANALOGUE_GAIN`) runs over a device-specific integer range.
//! [`GainMap`] spreads the station's configured dB range linearly over the
//! control's range (min ↔ `min_db`, max ↔ `max_db`); a camera whose
//! control is not linear in dB needs its configured range calibrated.

use crate::device::{DeviceError, ExposureRange, ExposureTime, Gain, GainRange};
use std::io;

/// `V4L2_CID_EXPOSURE_AUTO` (menu: 0 auto, 1 manual, 2 shutter priority,
/// 3 aperture priority).
pub const CID_EXPOSURE_AUTO: u32 = 0x009a_0901;
/// `V4L2_CID_EXPOSURE_ABSOLUTE`, in 100 µs units.
pub const CID_EXPOSURE_ABSOLUTE: u32 = 0x009a_0902;
/// `V4L2_CID_GAIN`.
pub const CID_GAIN: u32 = 0x0098_0913;
/// `V4L2_CID_ANALOGUE_GAIN`.
pub const CID_ANALOGUE_GAIN: u32 = 0x009e_0903;
/// `V4L2_CID_AUTOGAIN` (boolean).
pub const CID_AUTOGAIN: u32 = 0x0098_0912;
/// `V4L2_EXPOSURE_MANUAL`, the manual entry of `V4L2_CID_EXPOSURE_AUTO`.
pub const EXPOSURE_MANUAL: i64 = 1;
/// Seconds per unit of `V4L2_CID_EXPOSURE_ABSOLUTE`.
pub const EXPOSURE_UNIT_S: f64 = 1e-4;

/// An integer control's range as the driver reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControlRange {
    /// Lowest value.
    pub min: i64,
    /// Highest value.
    pub max: i64,
    /// Values are `min + k · step` (a step of 0 is taken as 1).
    pub step: i64,
}

impl ControlRange {
    fn step(&self) -> i64 {
        self.step.max(1)
    }

    /// The allowed value nearest `v` (which must lie within the range).
    pub fn nearest(&self, v: f64) -> i64 {
        let s = self.step() as f64;
        let k = ((v - self.min as f64) / s).round();
        let snapped = self.min as f64 + k * s;
        // The highest allowed value is the last multiple of the step.
        let top = self.min + (self.max - self.min) / self.step() * self.step();
        (snapped as i64).clamp(self.min, top)
    }
}

/// The exposure range a control offers, as the [`Camera`](crate::device::Camera)
/// trait states it (a minimum of 0 units is taken as one unit).
pub fn exposure_range(control: &ControlRange) -> Option<ExposureRange> {
    Some(ExposureRange {
        min: ExposureTime::from_seconds(control.min.max(1) as f64 * EXPOSURE_UNIT_S)?,
        max: ExposureTime::from_seconds(control.max.max(1) as f64 * EXPOSURE_UNIT_S)?,
        step: ExposureTime::from_seconds(control.step() as f64 * EXPOSURE_UNIT_S)?,
    })
}

/// The control value for `requested`: the nearest allowed value, or
/// [`DeviceError::OutOfRange`] (in seconds) if `requested` lies beyond
/// half a step outside the control's range.
pub fn exposure_units(requested: ExposureTime, control: &ControlRange) -> Result<i64, DeviceError> {
    let u = requested.seconds() / EXPOSURE_UNIT_S;
    let half = control.step() as f64 / 2.0;
    let (lo, hi) = (control.min.max(1) as f64, control.max as f64);
    if u < lo - half || u > hi + half {
        return Err(DeviceError::OutOfRange {
            what: "exposure (s)",
            requested: requested.seconds(),
            min: lo * EXPOSURE_UNIT_S,
            max: hi * EXPOSURE_UNIT_S,
        });
    }
    Ok(control.nearest(u).max(1))
}

/// What the camera applied, from the value read back after setting
/// `sent`: the read-back is the truth. A read-back of zero or less (a
/// camera that reports nothing useful) falls back to what was sent.
pub fn applied_exposure(sent: i64, read_back: i64) -> ExposureTime {
    let units = if read_back > 0 { read_back } else { sent.max(1) };
    ExposureTime::from_seconds(units as f64 * EXPOSURE_UNIT_S).unwrap_or_else(|| {
        // `units` ≥ 1, so this is never reached; 100 µs is the safe answer.
        ExposureTime::from_seconds(EXPOSURE_UNIT_S).unwrap_or_default()
    })
}

/// A note for the journal when the camera applied another exposure than
/// the control value sent (beyond the driver's own rounding to the step).
pub fn exposure_note(requested: ExposureTime, sent: i64, read_back: i64) -> Option<String> {
    (read_back > 0 && read_back != sent).then(|| {
        format!(
            "camera applied {} s for {} s asked (sent {sent} × 100 µs, read back {read_back})",
            read_back as f64 * EXPOSURE_UNIT_S,
            requested.seconds()
        )
    })
}

/// A gain control spread linearly over the station's dB range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainMap {
    /// The control's range.
    pub control: ControlRange,
    /// dB at the control's minimum.
    pub min_db: f64,
    /// dB at the control's maximum.
    pub max_db: f64,
}

impl GainMap {
    fn db_per_value(&self) -> f64 {
        let span = (self.control.max - self.control.min) as f64;
        if span > 0.0 {
            (self.max_db - self.min_db) / span
        } else {
            0.0
        }
    }

    /// The range as the camera trait states it.
    pub fn range(&self) -> GainRange {
        GainRange {
            min: Gain::from_db(self.min_db).unwrap_or(Gain::UNITY),
            max: Gain::from_db(self.max_db).unwrap_or(Gain::UNITY),
            step_db: self.db_per_value() * self.control.step() as f64,
        }
    }

    /// The control value nearest `gain`, or [`DeviceError::OutOfRange`].
    pub fn value(&self, gain: Gain) -> Result<i64, DeviceError> {
        let g = gain.db();
        let tol = 1e-9 * (1.0 + self.max_db.abs());
        if !(self.min_db - tol..=self.max_db + tol).contains(&g) {
            return Err(DeviceError::OutOfRange {
                what: "gain (dB)",
                requested: g,
                min: self.min_db,
                max: self.max_db,
            });
        }
        let k = self.db_per_value();
        let v = if k > 0.0 {
            self.control.min as f64 + (g - self.min_db) / k
        } else {
            self.control.min as f64
        };
        Ok(self.control.nearest(v))
    }

    /// The gain of a control value (as read back).
    pub fn gain(&self, value: i64) -> Gain {
        Gain::from_db(self.min_db + (value - self.control.min) as f64 * self.db_per_value()).unwrap_or(Gain::UNITY)
    }
}

/// The device error for a failed control ioctl, saying what it means for
/// `what` (e.g. "manual exposure") on `device`.
pub fn control_error(device: &str, what: &str, err: &io::Error) -> DeviceError {
    let meaning = match err.raw_os_error() {
        // EACCES, EPERM: read-only, or locked while another control
        // (auto exposure) is on.
        Some(13 | 1) => "the camera refuses it (the control is read-only or locked by an automatic mode)",
        // EINVAL, ENOTTY: no such control, or a value it does not take.
        Some(22 | 25) => "the camera does not offer it (no such control, or the value is not accepted)",
        // EBUSY.
        Some(16) => "the camera is busy (another program may be using it)",
        // ERANGE.
        Some(34) => "the value is outside what the camera accepts",
        // ENODEV, EIO: unplugged or failing.
        Some(19 | 5) => "the camera has gone (unplugged or failing)",
        _ => "the camera failed the request",
    };
    DeviceError::Camera(format!("{device}: cannot set {what}: {meaning} ({err})"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(s: f64) -> ExposureTime {
        ExposureTime::from_seconds(s).unwrap()
    }

    /// A typical UVC webcam: 3..2047 units (0.3 ms to 0.2047 s), step 1.
    const UVC: ControlRange = ControlRange {
        min: 3,
        max: 2047,
        step: 1,
    };

    #[test]
    fn exposures_round_to_the_control_step() {
        // 1/60 s = 166.67 units → 167 (16.7 ms).
        assert_eq!(exposure_units(e(1.0 / 60.0), &UVC).unwrap(), 167);
        assert_eq!(exposure_units(e(0.1), &UVC).unwrap(), 1000);
        // A step of 10 units from 5: 5, 15, 25, …; 0.0131 s = 131 → 135.
        let coarse = ControlRange {
            min: 5,
            max: 1000,
            step: 10,
        };
        assert_eq!(exposure_units(e(0.0131), &coarse).unwrap(), 135);
        // The top is the last reachable multiple: 1000 is not, 995 is.
        assert_eq!(exposure_units(e(0.1), &coarse).unwrap(), 995);
        // Within half a step of the ends: the end; beyond: an error in seconds.
        assert_eq!(exposure_units(e(0.000_26), &UVC).unwrap(), 3);
        match exposure_units(e(0.5), &UVC) {
            Err(DeviceError::OutOfRange {
                requested, min, max, ..
            }) => {
                assert_eq!(requested, 0.5);
                assert!((min - 0.0003).abs() < 1e-12 && (max - 0.2047).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        let r = exposure_range(&UVC).unwrap();
        assert!((r.min.seconds() - 3e-4).abs() < 1e-15 && (r.max.seconds() - 0.2047).abs() < 1e-12);
        assert!((r.step.seconds() - 1e-4).abs() < 1e-15);
    }

    /// A sensor that rounds to its line time: 167 units sent, 166 read
    /// back; the frame records 16.6 ms and the journal says why.
    #[test]
    fn the_read_back_exposure_is_what_is_recorded() {
        assert!((applied_exposure(167, 166).seconds() - 0.0166).abs() < 1e-12);
        assert!((applied_exposure(167, 0).seconds() - 0.0167).abs() < 1e-12);
        let note = exposure_note(e(1.0 / 60.0), 167, 166).unwrap();
        assert!(note.starts_with("camera applied 0.0166 s for 0.016666"), "{note}");
        assert_eq!(exposure_note(e(0.1), 1000, 1000), None);
    }

    #[test]
    fn gain_spreads_the_configured_db_over_the_control() {
        // Control 0..=240 over 0..=24 dB: 0.1 dB per value.
        let g = GainMap {
            control: ControlRange {
                min: 0,
                max: 240,
                step: 1,
            },
            min_db: 0.0,
            max_db: 24.0,
        };
        assert_eq!(g.value(Gain::from_db(6.04).unwrap()).unwrap(), 60);
        assert!((g.gain(60).db() - 6.0).abs() < 1e-12);
        assert!((g.range().step_db - 0.1).abs() < 1e-12);
        assert_eq!(g.value(Gain::UNITY).unwrap(), 0);
        assert_eq!(g.value(Gain::from_db(24.0).unwrap()).unwrap(), 240);
        assert!(matches!(
            g.value(Gain::from_db(30.0).unwrap()),
            Err(DeviceError::OutOfRange { .. })
        ));
        // A control with one value: every gain in range maps to it.
        let fixed = GainMap {
            control: ControlRange {
                min: 16,
                max: 16,
                step: 1,
            },
            min_db: 0.0,
            max_db: 0.0,
        };
        assert_eq!(fixed.value(Gain::UNITY).unwrap(), 16);
        assert_eq!(fixed.gain(16).db(), 0.0);
    }

    #[test]
    fn control_errors_say_what_they_mean() {
        let refused = control_error("/dev/video0", "manual exposure", &io::Error::from_raw_os_error(13));
        assert_eq!(
            refused.to_string(),
            format!(
                "camera failure: /dev/video0: cannot set manual exposure: the camera refuses it (the control is read-only or locked by an automatic mode) ({})",
                io::Error::from_raw_os_error(13)
            )
        );
        let missing = control_error("/dev/video0", "gain", &io::Error::from_raw_os_error(22));
        assert!(missing.to_string().contains("does not offer it"), "{missing}");
        let gone = control_error("/dev/video0", "exposure", &io::Error::from_raw_os_error(19));
        assert!(gone.to_string().contains("has gone"), "{gone}");
    }
}
