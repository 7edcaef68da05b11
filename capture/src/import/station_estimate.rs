//! A station description for photographs taken without a station: the
//! camera's intrinsics estimated from EXIF (focal length and the focal
//! plane's pixel pitch, else the 35 mm equivalent focal length), the
//! principal point at the image centre, no distortion and no falloff,
//! and a level "head" whose pan is the azimuth and tilt the elevation, at
//! the site given on the command line. Each estimate is written beside
//! its value in the file and listed in the import record, so that the
//! verdicts can say the camera was estimated, not calibrated.

use campanile_config::Station;
use campanile_config::source::SourceFile;
use campanile_config::validate::{Validate, Validator};
use std::path::Path;

use super::camera_file::CameraFile;
use super::error::ImportError;

/// The site of a session, given on the command line (`--site LAT,LON[,ELEV_M]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiteGiven {
    /// Latitude, degrees north.
    pub latitude_deg: f64,
    /// Longitude, degrees east.
    pub longitude_deg: f64,
    /// Elevation, metres.
    pub elevation_m: f64,
}

impl std::str::FromStr for SiteGiven {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let num = |i: usize, what: &str, lo: f64, hi: f64| -> Result<f64, String> {
            let t = parts[i];
            let v: f64 = t.parse().map_err(|_| format!("{what} {t:?}: expected a number"))?;
            if (lo..=hi).contains(&v) {
                Ok(v)
            } else {
                Err(format!("{what} {v}: expected {lo} to {hi}"))
            }
        };
        if !(2..=3).contains(&parts.len()) {
            return Err(format!(
                "{s:?}: expected LAT,LON or LAT,LON,ELEVATION_M (degrees north, degrees east, metres)"
            ));
        }
        Ok(SiteGiven {
            latitude_deg: num(0, "latitude", -90.0, 90.0)?,
            longitude_deg: num(1, "longitude", -180.0, 180.0)?,
            elevation_m: if parts.len() == 3 {
                num(2, "elevation", -500.0, 9000.0)?
            } else {
                0.0
            },
        })
    }
}

/// A station estimated for `file`'s camera at an upright image size of
/// `width` × `height`: the RON text (with the estimates in comments) and
/// the estimates in words.
pub fn estimate_station(
    file: &CameraFile,
    width: usize,
    height: usize,
    site: &SiteGiven,
    exposures_s: (f64, f64),
) -> Result<(String, Vec<String>), ImportError> {
    let (focal_px, how) = match (file.focal_length_mm, file.focal_plane_px_per_mm, file.focal_length_35mm) {
        (Some(f), Some(px_mm), _) => (
            f * px_mm,
            format!(
                "focal length {:.1} px estimated from EXIF FocalLength {f} mm × FocalPlaneXResolution {:.2} px/mm ({})",
                f * px_mm,
                px_mm,
                file.name
            ),
        ),
        (_, _, Some(f35)) => {
            let diagonal = (width as f64).hypot(height as f64);
            let f_px = f35 * diagonal / 36.0f64.hypot(24.0);
            (
                f_px,
                format!(
                    "focal length {f_px:.1} px estimated from EXIF FocalLengthIn35mmFilm {f35} mm over the image diagonal ({})",
                    file.name
                ),
            )
        }
        _ => {
            return Err(ImportError::Tag {
                path: file.path.clone(),
                tag: "FocalLength",
                value: format!(
                    "{:?} mm with FocalPlaneXResolution {:?} px/mm and FocalLengthIn35mmFilm {:?}",
                    file.focal_length_mm, file.focal_plane_px_per_mm, file.focal_length_35mm
                ),
                expected: "FocalLength with FocalPlaneXResolution, or FocalLengthIn35mmFilm, to estimate the camera; \
                           or give the calibrated camera with --station"
                    .into(),
            });
        }
    };
    let notes = vec![
        how.clone(),
        format!(
            "principal point assumed at the image centre ({:.1}, {:.1}) px",
            width as f64 / 2.0,
            height as f64 / 2.0
        ),
        "lens distortion and falloff assumed zero (not calibrated)".to_owned(),
        "air pressure 1013.25 mbar and temperature 15 °C assumed (refraction only)".to_owned(),
    ];
    let (min_s, max_s) = exposures_s;
    let text = format!(
        r#"// Estimated by `campanile session import` from the photographs' EXIF:
// nothing here was calibrated. Replace it with a calibrated station
// (`--station`) where you have one.
Station(
    name: {name:?},
    site: (
        name: "imported photographs",
        latitude_deg: {lat},
        longitude_deg: {lon},
        elevation_m: {elev},
        pressure_mbar: 1013.25, // assumed (refraction only)
        temperature_c: 15.0,    // assumed (refraction only)
        time_zone: "UTC",
    ),
    camera: (
        driver: V4l,                // no device: the frames were imported
        device: Some(Index(0)),
        resolution: (width: {width}, height: {height}),
        intrinsics: (
            focal: Pixels({focal_px}), // {how}
            principal_point_px: None,  // assumed: the image centre
            distortion: (0.0, 0.0),    // assumed: not calibrated
            falloff: (0.0, 0.0),       // assumed: not calibrated
        ),
        bit_depth: 8,
        exposure: (min_s: {min_s}, max_s: {max_s}),
        gain: (min_db: 0.0, max_db: 0.0),
    ),
    // A level tripod: pan is the azimuth, tilt the elevation.
    head: (
        protocol: CampanileLink,
        link: (port: "none", baud: 9600),
        address: 1,
        limits: (pan_min_deg: -180.0, pan_max_deg: 180.0, tilt_min_deg: -90.0, tilt_max_deg: 90.0),
        dynamics: (pan_speed_deg_s: 30.0, tilt_speed_deg_s: 30.0, acceleration_deg_s2: 60.0, settle_s: 0.0),
        mount: (pan_zero_azimuth_deg: 0.0, tilt_zero_deg: 0.0, level_roll_deg: 0.0, level_pitch_deg: 0.0),
    ),
)
"#,
        name = format!("hand-taken: {}", file.camera),
        lat = site.latitude_deg,
        lon = site.longitude_deg,
        elev = site.elevation_m,
    );
    check_station_text(Path::new("station.ron"), &text)?;
    Ok((text, notes))
}

/// Parses and validates a station's text (`path` names it in errors).
pub fn check_station_text(path: &Path, text: &str) -> Result<Station, ImportError> {
    let source = SourceFile::from_text(path, text.to_owned());
    let station: Station = source.parse().map_err(|e| ImportError::Description(e.to_string()))?;
    let mut v = Validator::new(".");
    station.validate(&mut v);
    let issues = v.into_issues();
    if let Some(i) = issues.first() {
        return Err(ImportError::Description(format!(
            "{}: field {}: found {}; expected {}",
            path.display(),
            i.path,
            i.value,
            i.expected
        )));
    }
    Ok(station)
}
