//! One camera file of the folder: what its EXIF says about when, how and
//! with what it was taken (kamadak-exif, as `campanile hdr` reads exposure).

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use chrono::{FixedOffset, NaiveDate, NaiveDateTime};
use exif::{Exif, In, Tag, Value};

use super::error::ImportError;
use crate::device::FrameFormat;

/// A camera file's EXIF, as far as import uses it. Absent tags are `None`
/// except the capture time, without which a photograph cannot be placed.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraFile {
    /// The file.
    pub path: PathBuf,
    /// Its name in the folder.
    pub name: String,
    /// DateTimeOriginal with SubSecTimeOriginal, on the camera's clock.
    pub camera_time: NaiveDateTime,
    /// DateTimeOriginal as written (for the record).
    pub date_time_original: String,
    /// OffsetTimeOriginal, if the camera wrote one.
    pub offset_time_original: Option<FixedOffset>,
    /// ExposureTime, seconds.
    pub exposure_time_s: Option<f64>,
    /// FNumber.
    pub f_number: Option<f64>,
    /// ISO (PhotographicSensitivity).
    pub iso: Option<f64>,
    /// The camera: Make, Model and BodySerialNumber, as present.
    pub camera: String,
    /// FocalLength, mm.
    pub focal_length_mm: Option<f64>,
    /// FocalPlaneXResolution in pixels per mm (from its unit).
    pub focal_plane_px_per_mm: Option<f64>,
    /// FocalLengthIn35mmFilm, mm.
    pub focal_length_35mm: Option<f64>,
}

/// Reads `path`'s first bytes (a JPEG, else [`ImportError::NotJpeg`]) and
/// its EXIF block ([`ImportError::NoExif`] without one;
/// [`ImportError::Tag`] for an unusable DateTimeOriginal).
pub fn read_camera_file(path: &Path) -> Result<CameraFile, ImportError> {
    let read_err = |source| ImportError::Read {
        path: path.to_path_buf(),
        source,
    };
    let file = File::open(path).map_err(read_err)?;
    let mut reader = BufReader::new(file);
    let head = std::io::BufRead::fill_buf(&mut reader).map_err(read_err)?;
    if let Some(reason) = FrameFormat::Jpeg.signature_problem(head) {
        return Err(ImportError::NotJpeg {
            path: path.to_path_buf(),
            reason,
        });
    }
    let exif = match exif::Reader::new().read_from_container(&mut reader) {
        Ok(e) => e,
        Err(exif::Error::NotFound(_)) => {
            return Err(ImportError::NoExif {
                path: path.to_path_buf(),
            });
        }
        Err(exif::Error::Io(source)) => return Err(read_err(source)),
        Err(e) => {
            return Err(ImportError::Tag {
                path: path.to_path_buf(),
                tag: "block",
                value: format!("unreadable ({e})"),
                expected: "a readable EXIF block (TIFF structure)".into(),
            });
        }
    };
    from_exif(path, &exif)
}

fn ascii(exif: &Exif, tag: Tag) -> Option<String> {
    exif.get_field(tag, In::PRIMARY).and_then(|f| match &f.value {
        Value::Ascii(parts) => parts
            .first()
            .map(|s| String::from_utf8_lossy(s).trim_end_matches('\0').trim().to_string())
            .filter(|s| !s.is_empty()),
        _ => None,
    })
}

fn number(exif: &Exif, tag: Tag) -> Option<f64> {
    let field = exif.get_field(tag, In::PRIMARY)?;
    let v = match &field.value {
        Value::Rational(r) if !r.is_empty() => r[0].to_f64(),
        Value::SRational(r) if !r.is_empty() => r[0].to_f64(),
        Value::Float(f) if !f.is_empty() => f64::from(f[0]),
        Value::Double(f) if !f.is_empty() => f[0],
        other => f64::from(other.get_uint(0)?),
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

fn from_exif(path: &Path, exif: &Exif) -> Result<CameraFile, ImportError> {
    let tag_err = |tag: &'static str, value: String, expected: &str| ImportError::Tag {
        path: path.to_path_buf(),
        tag,
        value,
        expected: expected.to_owned(),
    };
    let original = ascii(exif, Tag::DateTimeOriginal).ok_or_else(|| {
        tag_err(
            "DateTimeOriginal",
            "absent".into(),
            "the time the photograph was taken, \"YYYY:MM:DD HH:MM:SS\" (a wrong time is a wrong sun; import the camera's original files)",
        )
    })?;
    let bad_time = || {
        tag_err(
            "DateTimeOriginal",
            format!("{original:?}"),
            "a date and time \"YYYY:MM:DD HH:MM:SS\"",
        )
    };
    let dt = exif::DateTime::from_ascii(original.as_bytes()).map_err(|_| bad_time())?;
    let mut camera_time = NaiveDate::from_ymd_opt(i32::from(dt.year), u32::from(dt.month), u32::from(dt.day))
        .and_then(|d| d.and_hms_opt(u32::from(dt.hour), u32::from(dt.minute), u32::from(dt.second)))
        .ok_or_else(bad_time)?;
    if let Some(sub) = ascii(exif, Tag::SubSecTimeOriginal) {
        let digits: String = sub.chars().take_while(char::is_ascii_digit).take(9).collect();
        if digits.is_empty() {
            return Err(tag_err(
                "SubSecTimeOriginal",
                format!("{sub:?}"),
                "decimal digits of a second, e.g. \"71\"",
            ));
        }
        let nanos: u32 = format!("{digits:0<9}").parse().map_err(|_| bad_time())?;
        camera_time += chrono::Duration::nanoseconds(i64::from(nanos));
    }
    let offset_time_original = match ascii(exif, Tag::OffsetTimeOriginal) {
        None => None,
        Some(text) => Some(parse_utc_offset(&text).ok_or_else(|| {
            tag_err(
                "OffsetTimeOriginal",
                format!("{text:?}"),
                "an offset from UTC \"+HH:MM\" or \"-HH:MM\"",
            )
        })?),
    };
    let camera = [Tag::Make, Tag::Model, Tag::BodySerialNumber]
        .into_iter()
        .filter_map(|t| ascii(exif, t))
        .fold(String::new(), |acc, part| {
            if acc.is_empty() {
                part
            } else if part.starts_with(&acc) {
                // Canon writes Make "Canon", Model "Canon EOS 5D Mark II".
                part
            } else {
                format!("{acc} {part}")
            }
        });
    let px_per_mm = number(exif, Tag::FocalPlaneXResolution).and_then(|r| {
        let unit_mm = match exif
            .get_field(Tag::FocalPlaneResolutionUnit, In::PRIMARY)
            .and_then(|f| f.value.get_uint(0))
        {
            None | Some(2) => 25.4,
            Some(3) => 10.0,
            Some(4) => 1.0,
            Some(_) => return None,
        };
        Some(r / unit_mm)
    });
    Ok(CameraFile {
        path: path.to_path_buf(),
        name: path
            .file_name()
            .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned()),
        camera_time,
        date_time_original: original,
        offset_time_original,
        exposure_time_s: number(exif, Tag::ExposureTime),
        f_number: number(exif, Tag::FNumber),
        iso: number(exif, Tag::PhotographicSensitivity),
        camera: if camera.is_empty() {
            "unknown camera".to_owned()
        } else {
            camera
        },
        focal_length_mm: number(exif, Tag::FocalLength),
        focal_plane_px_per_mm: px_per_mm,
        focal_length_35mm: number(exif, Tag::FocalLengthIn35mmFilm),
    })
}

/// Parses an offset from UTC, `+HH:MM`, `-HH:MM` (or `Z`, `UTC`).
pub fn parse_utc_offset(text: &str) -> Option<FixedOffset> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("z") || t.eq_ignore_ascii_case("utc") {
        return FixedOffset::east_opt(0);
    }
    let (sign, rest) = match t.as_bytes().first()? {
        b'+' => (1, &t[1..]),
        b'-' => (-1, &t[1..]),
        _ => return None,
    };
    let (h, m) = rest.split_once(':')?;
    if h.len() != 2 || m.len() != 2 {
        return None;
    }
    let (h, m): (i32, i32) = (h.parse().ok()?, m.parse().ok()?);
    if h > 14 || m > 59 {
        return None;
    }
    FixedOffset::east_opt(sign * (h * 3600 + m * 60))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_offsets_parse_and_refuse_garbage() {
        assert_eq!(parse_utc_offset("+02:00"), FixedOffset::east_opt(7200));
        assert_eq!(parse_utc_offset("-07:30"), FixedOffset::east_opt(-27000));
        assert_eq!(parse_utc_offset("Z"), FixedOffset::east_opt(0));
        for bad in ["02:00", "+2:00", "+15:00", "+02:60", "", "+0200"] {
            assert_eq!(parse_utc_offset(bad), None, "{bad:?}");
        }
    }

    /// The committed EOS 5D Mark II fixture: the values exiftool prints.
    #[test]
    fn a_real_canon_file_reads_as_exiftool_says() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../validation/hdr/fixtures/radiantlab-eos/IMG_6955.JPG");
        let f = read_camera_file(&path).unwrap();
        assert_eq!(f.date_time_original, "2017:07:13 15:44:47");
        assert_eq!(f.camera_time.to_string(), "2017-07-13 15:44:47.710");
        assert_eq!(f.offset_time_original, None);
        assert_eq!(f.exposure_time_s, Some(13.0));
        assert_eq!(f.f_number, Some(5.6));
        assert_eq!(f.iso, Some(100.0));
        assert_eq!(f.camera, "Canon EOS 5D Mark II");
        assert_eq!(f.focal_length_mm, Some(8.0));
        // 3849.211789 px per inch.
        assert!((f.focal_plane_px_per_mm.unwrap() - 3849.211789 / 25.4).abs() < 1e-3);
    }
}
