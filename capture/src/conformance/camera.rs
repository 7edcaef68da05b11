//! Conformance suite for any [`Camera`]: the frames have the stated size
//! and depth, and the exposure the camera reports applying is within one
//! step of the one asked for (for a stepped shutter, within ⅙ stop of its
//! table's entry), at a short and a longer exposure.

use super::Report;
use crate::device::{Camera, CaptureSettings, ExposureTime};

fn check_frame(
    info: &crate::device::CameraInfo,
    frame: &crate::device::Frame,
    asked: ExposureTime,
) -> Result<(), String> {
    if (frame.width, frame.height) != (info.width, info.height) {
        return Err(format!(
            "frame is {}×{}, the camera states {}×{}",
            frame.width, frame.height, info.width, info.height
        ));
    }
    if frame.data.len() != frame.width * frame.height * 3 {
        return Err(format!(
            "frame holds {} codes for {}×{}×3",
            frame.data.len(),
            frame.width,
            frame.height
        ));
    }
    let top = (1u32 << frame.bits.min(16)) - 1;
    if let Some(v) = frame.data.iter().find(|&&v| u32::from(v) > top) {
        return Err(format!("code {v} exceeds {} bits", frame.bits));
    }
    if info.exposure_table.is_some() {
        // A stepped shutter: the table's entry nearest in stops, as the
        // camera reports it (nominal speeds), within a sixth of a stop.
        let expected = info
            .exposure_applied(asked)
            .map_err(|e| format!("asked {} s: {e}", asked.seconds()))?;
        let stops = (frame.exposure_actual.seconds() / expected.seconds()).log2();
        if stops.abs() > 1.0 / 6.0 {
            return Err(format!(
                "asked {} s, the camera's table gives {} s, the camera reports {} s applied ({stops:+.2} stops)",
                asked.seconds(),
                expected.seconds(),
                frame.exposure_actual.seconds()
            ));
        }
        return Ok(());
    }
    let step = info.exposure.step.seconds().max(1e-9);
    let off = (frame.exposure_actual.seconds() - asked.seconds()).abs();
    if off > step * 1.01 {
        return Err(format!(
            "asked {} s, the camera reports {} s applied (more than its {:.3e} s step away)",
            asked.seconds(),
            frame.exposure_actual.seconds(),
            step
        ));
    }
    Ok(())
}

async fn check_exposure<C: Camera>(camera: &mut C, factor: f64) -> Result<(), String> {
    let info = camera.info();
    let (lo, hi) = (info.exposure.min.seconds(), info.exposure.max.seconds());
    let t = (lo * factor).min(hi).max(lo);
    let asked = ExposureTime::from_seconds(t).ok_or_else(|| format!("exposure {t} s"))?;
    let frame = camera
        .capture(CaptureSettings {
            exposure: asked,
            gain: info.gain.min,
        })
        .await
        .map_err(|e| format!("capture at {t} s: {e}"))?;
    check_frame(&info, &frame, asked)
}

async fn check_out_of_range<C: Camera>(camera: &mut C) -> Result<(), String> {
    let info = camera.info();
    let too_long = ExposureTime::from_seconds(info.exposure.max.seconds() * 2.0).ok_or("twice the longest")?;
    match camera
        .capture(CaptureSettings {
            exposure: too_long,
            gain: info.gain.min,
        })
        .await
    {
        Err(crate::device::DeviceError::OutOfRange { .. }) => Ok(()),
        Ok(_) => Err(format!(
            "{} s, twice the longest exposure, was taken",
            too_long.seconds()
        )),
        Err(e) => Err(format!("twice the longest exposure: expected OutOfRange, got {e}")),
    }
}

/// Run every check on `camera`.
pub async fn run<C: Camera>(camera: &mut C) -> Report {
    let mut r = Report::default();
    r.record(
        "short exposure: frame size, depth, applied exposure",
        check_exposure(camera, 10.0).await,
    );
    r.record(
        "longer exposure: frame size, depth, applied exposure",
        check_exposure(camera, 300.0).await,
    );
    r.record(
        "out of range: refused with OutOfRange",
        check_out_of_range(camera).await,
    );
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{CameraInfo, DeviceError, ExposureRange, Frame, GainRange};

    /// Rounds exposures to 100 µs, or (when `lies`) reports twice what it applied.
    struct Stepped {
        lies: bool,
    }

    impl Camera for Stepped {
        fn info(&self) -> CameraInfo {
            CameraInfo {
                model: "stepped".into(),
                width: 4,
                height: 2,
                bits: 10,
                exposure: ExposureRange {
                    min: ExposureTime::from_micros(100).unwrap(),
                    max: ExposureTime::from_seconds(1.0).unwrap(),
                    step: ExposureTime::from_micros(100).unwrap(),
                },
                gain: GainRange {
                    min: crate::device::Gain::UNITY,
                    max: crate::device::Gain::UNITY,
                    step_db: 0.0,
                },
                exposure_table: None,
                linear: false,
            }
        }

        async fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
            let applied = self.info().exposure_applied(settings.exposure)?;
            let reported = if self.lies {
                ExposureTime::from_seconds(applied.seconds() * 2.0).unwrap()
            } else {
                applied
            };
            Ok(Frame {
                width: 4,
                height: 2,
                bits: 10,
                data: vec![1023; 24],
                exposure_requested: settings.exposure,
                exposure_actual: reported,
                gain: settings.gain,
                sequence: 0,
                timestamp: chrono::DateTime::default(),
                temperature_c: None,
                file: None,
            })
        }
    }

    #[tokio::test]
    async fn an_honest_camera_passes_and_a_misreporting_one_fails() {
        let report = run(&mut Stepped { lies: false }).await;
        assert!(report.passed(), "{report}");
        let report = run(&mut Stepped { lies: true }).await;
        // 1 ms asked, 2 ms reported: one step is 0.1 ms.
        assert_eq!(
            report.checks[0].failure.as_deref(),
            Some("asked 0.001 s, the camera reports 0.002 s applied (more than its 1.000e-4 s step away)")
        );
        assert!(report.checks[2].failure.is_none());
    }
}
