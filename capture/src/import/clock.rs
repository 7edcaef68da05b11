//! The true time of a photograph: the camera's clock (EXIF
//! DateTimeOriginal with SubSecTimeOriginal), its offset from UTC
//! (OffsetTimeOriginal, else the one stated), less the stated error of
//! the camera's clock. A wrong time is a wrong sun, so nothing is assumed.

use chrono::{DateTime, FixedOffset, Utc};
use serde::Serialize;

use super::camera_file::CameraFile;
use super::error::ImportError;

/// What the user states about the camera's clock.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ClockSettings {
    /// The camera's clock minus the true time, seconds (`--clock-offset-s`;
    /// 0 for a clock checked right). Required.
    pub clock_offset_s: Option<f64>,
    /// The offset from UTC the camera's clock was set to
    /// (`--utc-offset`), for files without OffsetTimeOriginal.
    pub utc_offset: Option<FixedOffset>,
}

/// Where a photograph's UTC offset came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OffsetSource {
    /// The file's OffsetTimeOriginal.
    Exif,
    /// `--utc-offset`.
    Stated,
}

/// A photograph's time, corrected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueTime {
    /// The true time, UTC.
    pub utc: DateTime<Utc>,
    /// The offset the camera's clock ran on.
    pub utc_offset: FixedOffset,
    /// Where it came from.
    pub offset_from: OffsetSource,
}

impl ClockSettings {
    /// The stated clock offset, or the error that names the option.
    pub fn clock_offset(&self) -> Result<f64, ImportError> {
        match self.clock_offset_s {
            Some(s) if s.is_finite() => Ok(s),
            Some(s) => Err(ImportError::Option(format!(
                "--clock-offset-s {s}: expected a finite number of seconds"
            ))),
            None => Err(ImportError::Option(
                "--clock-offset-s is missing: state the camera clock's error (camera clock minus true time, seconds; \
                 0 if you checked it), e.g. from a photograph of a GPS or phone clock; a wrong time is a wrong sun"
                    .into(),
            )),
        }
    }

    /// `f`'s true time: its camera time at its UTC offset, less the clock
    /// offset. A file without OffsetTimeOriginal needs `--utc-offset`; a
    /// file whose offset differs from the one stated is refused.
    pub fn true_time(&self, f: &CameraFile) -> Result<TrueTime, ImportError> {
        let clock = self.clock_offset()?;
        let (offset, from) = match (f.offset_time_original, self.utc_offset) {
            (Some(file), Some(stated)) if file != stated => {
                return Err(ImportError::Tag {
                    path: f.path.clone(),
                    tag: "OffsetTimeOriginal",
                    value: file.to_string(),
                    expected: format!(
                        "the offset stated with --utc-offset ({stated}); drop --utc-offset to use the file's, \
                         or correct the camera's clock with --clock-offset-s"
                    ),
                });
            }
            (Some(file), _) => (file, OffsetSource::Exif),
            (None, Some(stated)) => (stated, OffsetSource::Stated),
            (None, None) => {
                return Err(ImportError::Tag {
                    path: f.path.clone(),
                    tag: "OffsetTimeOriginal",
                    value: "absent".into(),
                    expected: "the camera clock's offset from UTC: give it with --utc-offset +HH:MM \
                               (e.g. +02:00 for a camera set to central European summer time)"
                        .into(),
                });
            }
        };
        let local = f
            .camera_time
            .and_local_timezone(offset)
            .single()
            .ok_or_else(|| ImportError::Tag {
                path: f.path.clone(),
                tag: "DateTimeOriginal",
                value: f.date_time_original.clone(),
                expected: format!("a time that exists at UTC offset {offset}"),
            })?;
        let nanos = (clock * 1e9).round();
        if nanos.abs() > 1e18 {
            return Err(ImportError::Option(format!(
                "--clock-offset-s {clock}: expected an offset of less than 30 years"
            )));
        }
        let utc = local.with_timezone(&Utc) - chrono::Duration::nanoseconds(nanos as i64);
        Ok(TrueTime {
            utc,
            utc_offset: offset,
            offset_from: from,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn file(offset: Option<i32>) -> CameraFile {
        CameraFile {
            path: PathBuf::from("IMG_1.JPG"),
            name: "IMG_1.JPG".into(),
            camera_time: chrono::NaiveDate::from_ymd_opt(2017, 7, 13)
                .unwrap()
                .and_hms_milli_opt(15, 44, 47, 710)
                .unwrap(),
            date_time_original: "2017:07:13 15:44:47".into(),
            offset_time_original: offset.and_then(FixedOffset::east_opt),
            exposure_time_s: Some(13.0),
            f_number: None,
            iso: None,
            camera: "c".into(),
            focal_length_mm: None,
            focal_plane_px_per_mm: None,
            focal_length_35mm: None,
        }
    }

    #[test]
    fn the_true_time_is_the_camera_time_at_its_offset_less_the_clock_error() {
        let s = ClockSettings {
            clock_offset_s: Some(12.5),
            utc_offset: FixedOffset::east_opt(-7 * 3600),
        };
        let t = s.true_time(&file(None)).unwrap();
        // 15:44:47.710 at −07:00 is 22:44:47.710 UTC; the clock ran 12.5 s fast.
        assert_eq!(t.utc.to_rfc3339(), "2017-07-13T22:44:35.210+00:00");
        assert_eq!(t.offset_from, OffsetSource::Stated);
        // The file's own offset serves without --utc-offset.
        let s = ClockSettings {
            clock_offset_s: Some(0.0),
            utc_offset: None,
        };
        let t = s.true_time(&file(Some(7200))).unwrap();
        assert_eq!(t.utc.to_rfc3339(), "2017-07-13T13:44:47.710+00:00");
        assert_eq!(t.offset_from, OffsetSource::Exif);
    }

    #[test]
    fn a_missing_offset_or_clock_error_names_what_is_missing() {
        let none = ClockSettings {
            clock_offset_s: Some(0.0),
            utc_offset: None,
        };
        let e = none.true_time(&file(None)).unwrap_err().to_string();
        assert!(
            e.contains("IMG_1.JPG") && e.contains("OffsetTimeOriginal") && e.contains("--utc-offset"),
            "{e}"
        );
        let no_clock = ClockSettings {
            clock_offset_s: None,
            utc_offset: FixedOffset::east_opt(0),
        };
        let e = no_clock.true_time(&file(None)).unwrap_err().to_string();
        assert!(e.contains("--clock-offset-s is missing"), "{e}");
        let clash = ClockSettings {
            clock_offset_s: Some(0.0),
            utc_offset: FixedOffset::east_opt(3600),
        };
        let e = clash.true_time(&file(Some(7200))).unwrap_err().to_string();
        assert!(e.contains("+02:00") && e.contains("+01:00"), "{e}");
    }
}
