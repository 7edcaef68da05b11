//! The import record, `import.json` in the session: where every frame
//! came from, the clock offset and UTC offsets used and where they came
//! from, the exposure rule, the camera, and what was estimated rather than
//! measured (which `process` copies into its verdicts).

use serde::{Deserialize, Serialize};
use std::path::Path;

/// File name of the import record in a session directory.
pub const IMPORT_FILE: &str = "import.json";

/// Something the session's products rest on that was estimated or
/// stated, not measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// What: `camera`, `time`, `exposure`, `sky`.
    pub what: String,
    /// How it was had, in words.
    pub how: String,
    /// The products it bears on, by the first word of their names
    /// (`response`, `radiance`, `sun`, `sky`, `environment`, `pseudo-albedos`).
    pub affects: Vec<String>,
}

/// One imported frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportedFrameRecord {
    /// The camera file's name in the folder.
    pub file: String,
    /// Its journal key.
    pub key: String,
    /// EXIF DateTimeOriginal (camera clock, local).
    pub date_time_original: String,
    /// The true time used, UTC (RFC 3339).
    pub utc: String,
    /// The UTC offset applied and where it came from (`exif`, `stated`).
    pub utc_offset: String,
    /// Where the offset came from.
    pub utc_offset_from: String,
    /// Exposure time, seconds.
    pub exposure_time_s: f64,
    /// Where it came from (`EXIF ExposureTime` or the times file).
    pub exposure_time_from: String,
    /// ISO, if in EXIF.
    pub iso: Option<f64>,
    /// f-number, if in EXIF.
    pub f_number: Option<f64>,
    /// The effective time journaled as `exposure_actual_s`.
    pub effective_exposure_s: f64,
}

/// One imported bracket.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportedBracketRecord {
    /// Key prefix (`{occurrence}/s{step}/t{target}`).
    pub group: String,
    /// `view` or `sky`.
    pub purpose: String,
    /// The pose's name in the plan (a scene pose or one made for it).
    pub pose: String,
    /// Azimuth and elevation of the optical axis, degrees.
    pub azimuth_deg: f64,
    /// Elevation, degrees.
    pub elevation_deg: f64,
    /// Where the camera stood, metres, if given.
    pub position_m: Option<[f64; 3]>,
    /// The head's pan and tilt journaled, degrees: a sky bracket's, or a
    /// view's imported without a scene. `None` for a view with a scene
    /// (taken off the head: processing takes its scene pose as it is);
    /// earlier imports journaled one for every bracket.
    #[serde(default)]
    pub head_deg: Option<[f64; 2]>,
    /// A zoom photograph's focal length, pixels (taken at another focal
    /// length than the session's camera; journaled as `focal_px`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_px: Option<f64>,
    /// The poses-file entry (or `--sky` pattern) that gave it.
    pub from: String,
    /// Why the bracket began where it did.
    pub began: String,
    /// Its frames.
    pub frames: Vec<ImportedFrameRecord>,
}

/// The import record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportRecord {
    /// The folder imported.
    pub folder: String,
    /// The camera (EXIF Make, Model, BodySerialNumber).
    pub camera: String,
    /// The camera clock minus the true time, seconds, as stated.
    pub clock_offset_s: f64,
    /// Where the clock offset came from.
    pub clock_offset_from: String,
    /// The bracket gap allowed, seconds.
    pub bracket_gap_s: f64,
    /// How the journal's exposures relate to EXIF.
    pub exposure_rule: String,
    /// Reference ISO of the effective times, if the files carry ISO.
    pub reference_iso: Option<f64>,
    /// Reference f-number, if the files carry it.
    pub reference_f_number: Option<f64>,
    /// Where the station (camera, site) came from.
    pub station_from: String,
    /// The brackets, in time order.
    pub brackets: Vec<ImportedBracketRecord>,
    /// Lone frames left out (`--skip-single`), with why.
    pub skipped: Vec<String>,
    /// What the products rest on that was estimated or stated.
    pub estimated: Vec<Estimate>,
}

impl ImportRecord {
    /// The record of the session in `dir`, if it was imported; a record
    /// that does not parse is an error naming the file.
    pub fn read(dir: &Path) -> Result<Option<ImportRecord>, String> {
        let path = dir.join(IMPORT_FILE);
        match std::fs::read(&path) {
            Ok(bytes) => serde_json::from_slice(&bytes)
                .map(Some)
                .map_err(|e| format!("{}: not an import record: {e}", path.display())),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(format!("{}: cannot read: {e}", path.display())),
        }
    }

    /// The estimates bearing on a product named `product` (its first word).
    pub fn estimates_for<'a>(&'a self, product: &'a str) -> impl Iterator<Item = &'a Estimate> + 'a {
        let kind = product.split_whitespace().next().unwrap_or_default();
        self.estimated
            .iter()
            .filter(move |e| e.affects.iter().any(|a| a == kind))
    }
}
