//! Exposure metadata of image files (EXIF): exposure time, f-number, ISO,
//! orientation and camera, and the relative exposure of a bracket's frames.
//!
//! A frame's sensor exposure is proportional to `t · S / N²` (time `t`,
//! ISO speed `S`, f-number `N`): the aperture's area goes as `1/N²` and ISO
//! is a gain on the same signal. So a bracket that varies aperture or ISO
//! instead of time is merged by giving each frame the **effective time**
//!
//! ```text
//! t_eff = t · (S / S₀) · (N₀ / N)²
//! ```
//!
//! relative to the first frame's `S₀` and `N₀` (so a bracket that varies only
//! the time keeps its times exactly). hdrgen, pfstools and Luminance HDR use
//! the same relation. A field that some frames carry and others do not is an
//! error, not a guess.

use std::fs::File;
use std::io::{BufRead, BufReader, Cursor, Seek};
use std::path::{Path, PathBuf};

use exif::{In, Reader, Tag, Value};

use super::HdrError;

/// EXIF orientation (tag 0x0112): how the stored pixels must be turned to
/// be seen upright.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Orientation {
    /// 1: as stored.
    #[default]
    Upright,
    /// 2: mirrored left–right.
    MirrorHorizontal,
    /// 3: turned 180°.
    Rotate180,
    /// 4: mirrored top–bottom.
    MirrorVertical,
    /// 5: mirrored about the main diagonal (rows become columns).
    Transpose,
    /// 6: to be turned 90° clockwise.
    Rotate90Clockwise,
    /// 7: mirrored about the anti-diagonal.
    Transverse,
    /// 8: to be turned 90° counter-clockwise.
    Rotate90CounterClockwise,
}

impl Orientation {
    /// The orientation of EXIF value `v` (1–8).
    pub fn from_exif(v: u32) -> Option<Self> {
        Some(match v {
            1 => Self::Upright,
            2 => Self::MirrorHorizontal,
            3 => Self::Rotate180,
            4 => Self::MirrorVertical,
            5 => Self::Transpose,
            6 => Self::Rotate90Clockwise,
            7 => Self::Transverse,
            8 => Self::Rotate90CounterClockwise,
            _ => return None,
        })
    }

    /// Whether turning swaps width and height.
    pub fn swaps_axes(self) -> bool {
        matches!(
            self,
            Self::Transpose | Self::Rotate90Clockwise | Self::Transverse | Self::Rotate90CounterClockwise
        )
    }

    /// The stored pixel `(x, y)` that lands at upright pixel `(xo, yo)`, for a
    /// stored image of `w × h`.
    pub fn source_of(self, xo: usize, yo: usize, w: usize, h: usize) -> (usize, usize) {
        match self {
            Self::Upright => (xo, yo),
            Self::MirrorHorizontal => (w - 1 - xo, yo),
            Self::Rotate180 => (w - 1 - xo, h - 1 - yo),
            Self::MirrorVertical => (xo, h - 1 - yo),
            Self::Transpose => (yo, xo),
            Self::Rotate90Clockwise => (yo, h - 1 - xo),
            Self::Transverse => (w - 1 - yo, h - 1 - xo),
            Self::Rotate90CounterClockwise => (w - 1 - yo, xo),
        }
    }
}

/// What a file's EXIF block says about its exposure. Absent fields are `None`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExposureMetadata {
    /// ExposureTime (0x829A), seconds.
    pub exposure_time_s: Option<f64>,
    /// FNumber (0x829D).
    pub f_number: Option<f64>,
    /// PhotographicSensitivity (0x8827, "ISOSpeedRatings").
    pub iso: Option<f64>,
    /// Orientation (0x0112); upright when absent.
    pub orientation: Orientation,
    /// Make and Model, when present.
    pub camera: Option<String>,
}

/// Reads the EXIF block of `path` (JPEG, TIFF, PNG, HEIF, WebP). A file
/// with no EXIF gives all fields absent; an EXIF block that cannot be
/// parsed, or a field with an impossible value (a time ≤ 0, an orientation
/// outside 1–8), is an error naming the file and the field.
pub fn read_exposure_metadata(path: &Path) -> Result<ExposureMetadata, HdrError> {
    let file = File::open(path).map_err(|cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    exposure_metadata_from(path, &mut BufReader::new(file))
}

/// [`read_exposure_metadata`] on a file's bytes already in memory (a frame
/// a camera delivered); `path` names it in errors.
pub fn read_exposure_metadata_bytes(path: &Path, bytes: &[u8]) -> Result<ExposureMetadata, HdrError> {
    exposure_metadata_from(path, &mut Cursor::new(bytes))
}

fn exposure_metadata_from<R: BufRead + Seek>(path: &Path, reader: &mut R) -> Result<ExposureMetadata, HdrError> {
    let exif = match Reader::new().read_from_container(reader) {
        Ok(e) => e,
        Err(exif::Error::NotFound(_)) => return Ok(ExposureMetadata::default()),
        Err(exif::Error::Io(cause)) => {
            return Err(HdrError::Io {
                path: path.to_path_buf(),
                cause,
            });
        }
        // An image format kamadak-exif does not parse (e.g. a bare PGM) carries no EXIF.
        Err(exif::Error::InvalidFormat(what)) if what.contains("Unknown image format") => {
            return Ok(ExposureMetadata::default());
        }
        Err(e) => {
            return Err(HdrError::Exif {
                path: path.to_path_buf(),
                what: format!("unreadable EXIF block: {e}"),
            });
        }
    };
    let bad = |what: String| HdrError::Exif {
        path: path.to_path_buf(),
        what,
    };
    let number = |tag: Tag| -> Result<Option<f64>, HdrError> {
        let Some(field) = exif.get_field(tag, In::PRIMARY) else {
            return Ok(None);
        };
        let v = match &field.value {
            Value::Rational(r) if !r.is_empty() => r[0].to_f64(),
            Value::SRational(r) if !r.is_empty() => r[0].to_f64(),
            Value::Float(f) if !f.is_empty() => f64::from(f[0]),
            Value::Double(f) if !f.is_empty() => f[0],
            other => match other.get_uint(0) {
                Some(u) => f64::from(u),
                None => return Err(bad(format!("{tag} is {other:?}: expected a number"))),
            },
        };
        if v.is_finite() && v > 0.0 {
            Ok(Some(v))
        } else {
            Err(bad(format!("{tag} is {v}: expected a number > 0")))
        }
    };
    let orientation = match exif.get_field(Tag::Orientation, In::PRIMARY) {
        None => Orientation::Upright,
        Some(f) => {
            let v = f.value.get_uint(0);
            v.and_then(Orientation::from_exif)
                .ok_or_else(|| bad(format!("Orientation is {v:?}: expected 1 to 8")))?
        }
    };
    let text = |tag: Tag| {
        exif.get_field(tag, In::PRIMARY).and_then(|f| match &f.value {
            Value::Ascii(parts) => parts
                .first()
                .map(|s| String::from_utf8_lossy(s).trim_end_matches('\0').trim().to_string()),
            _ => None,
        })
    };
    let camera = match (text(Tag::Make), text(Tag::Model)) {
        (Some(make), Some(model)) if model.starts_with(&make) => Some(model),
        (Some(make), Some(model)) => Some(format!("{make} {model}")),
        (a, b) => a.or(b),
    }
    .filter(|s| !s.is_empty());
    Ok(ExposureMetadata {
        exposure_time_s: number(Tag::ExposureTime)?,
        f_number: number(Tag::FNumber)?,
        iso: number(Tag::PhotographicSensitivity)?,
        orientation,
        camera,
    })
}

/// The effective exposure times `t · (S/S₀) · (N₀/N)²` of a bracket's frames
/// (module doc), from each file's metadata. Every frame needs an exposure
/// time; f-number and ISO count when every frame has them, are ignored when
/// none has, and are an error when only some have.
pub fn effective_times(frames: &[(PathBuf, ExposureMetadata)]) -> Result<Vec<f64>, HdrError> {
    let mut times = Vec::with_capacity(frames.len());
    for (path, m) in frames {
        times.push(m.exposure_time_s.ok_or_else(|| HdrError::Exif {
            path: path.clone(),
            what: "no ExposureTime in the file's EXIF: give the times with --times or --list".into(),
        })?);
    }
    for (name, get) in [
        (
            "FNumber",
            (|m: &ExposureMetadata| m.f_number) as fn(&ExposureMetadata) -> Option<f64>,
        ),
        ("ISO (PhotographicSensitivity)", |m: &ExposureMetadata| m.iso),
    ] {
        let with = frames.iter().filter(|(_, m)| get(m).is_some()).count();
        if with == 0 {
            continue;
        }
        if let Some((path, _)) = frames.iter().find(|(_, m)| get(m).is_none()) {
            let other = frames.iter().find(|(_, m)| get(m).is_some()).map(|(p, _)| p);
            return Err(HdrError::Exif {
                path: path.clone(),
                what: format!(
                    "no {name}, though {} has one: the frames' relative exposure cannot be known; \
                     give the times with --times or --list",
                    other.map_or_else(String::new, |p| p.display().to_string())
                ),
            });
        }
        let reference = get(&frames[0].1).expect("every frame has it");
        for (t, (_, m)) in times.iter_mut().zip(frames) {
            let v = get(m).expect("every frame has it");
            *t *= if name == "FNumber" {
                (reference / v).powi(2)
            } else {
                v / reference
            };
        }
    }
    Ok(times)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta(t: Option<f64>, n: Option<f64>, iso: Option<f64>) -> ExposureMetadata {
        ExposureMetadata {
            exposure_time_s: t,
            f_number: n,
            iso,
            ..Default::default()
        }
    }

    #[test]
    fn effective_time_is_t_iso_over_n_squared() {
        let f = |m| (PathBuf::from("x.jpg"), m);
        // Time-only bracket: the times unchanged.
        let t = effective_times(&[f(meta(Some(0.01), None, None)), f(meta(Some(0.04), None, None))]).unwrap();
        assert_eq!(t, vec![0.01, 0.04]);
        // Same time, f/8 → f/4 is 4× the light, ISO 100 → 400 another 4×.
        let t = effective_times(&[
            f(meta(Some(0.01), Some(8.0), Some(100.0))),
            f(meta(Some(0.01), Some(4.0), Some(100.0))),
            f(meta(Some(0.01), Some(8.0), Some(400.0))),
        ])
        .unwrap();
        for (got, want) in t.iter().zip([0.01, 0.04, 0.04]) {
            assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn missing_fields_name_the_file() {
        let e = effective_times(&[
            (PathBuf::from("a.jpg"), meta(Some(0.01), None, None)),
            (PathBuf::from("b.jpg"), meta(None, None, None)),
        ])
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("b.jpg") && e.contains("ExposureTime") && e.contains("--times"),
            "{e}"
        );
        let e = effective_times(&[
            (PathBuf::from("a.jpg"), meta(Some(0.01), Some(4.0), None)),
            (PathBuf::from("b.jpg"), meta(Some(0.02), None, None)),
        ])
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("b.jpg") && e.contains("FNumber") && e.contains("a.jpg"),
            "{e}"
        );
    }

    #[test]
    fn orientation_maps_corners() {
        // A 3×2 stored image; where does its stored top-left pixel (0, 0) land?
        let (w, h) = (3, 2);
        let landing = |o: Orientation| {
            let (wo, ho) = if o.swaps_axes() { (h, w) } else { (w, h) };
            (0..ho)
                .flat_map(|y| (0..wo).map(move |x| (x, y)))
                .find(|&(x, y)| o.source_of(x, y, w, h) == (0, 0))
                .unwrap()
        };
        assert_eq!(landing(Orientation::Upright), (0, 0));
        assert_eq!(landing(Orientation::MirrorHorizontal), (2, 0));
        assert_eq!(landing(Orientation::Rotate180), (2, 1));
        assert_eq!(landing(Orientation::MirrorVertical), (0, 1));
        assert_eq!(landing(Orientation::Transpose), (0, 0));
        // Turned 90° clockwise, the top-left corner goes to the top-right.
        assert_eq!(landing(Orientation::Rotate90Clockwise), (1, 0));
        assert_eq!(landing(Orientation::Transverse), (1, 2));
        assert_eq!(landing(Orientation::Rotate90CounterClockwise), (0, 2));
    }
}
