//! The simulated scans' true surfaces on disk, beside the scan files, so
//! that tools outside Campanile (the segmentation peers of `bench/segment/`)
//! can score a segmentation against them. The scan files themselves stay as
//! a scanner makes them: no truth inside.
//!
//! # The format
//!
//! For a set of scans `SET` (`room`, `building`) written into a directory:
//!
//! - `SET.truth.json`, the index:
//!
//!   ```json
//!   {
//!     "surfaces": ["floor", "north-wall", ...],
//!     "unassigned": 4294967295,
//!     "scans": [
//!       {"name": "room-sw", "scan_file": "room-sw.ply", "points": 262144, "truth": "room-sw.truth"},
//!       ...
//!     ]
//!   }
//!   ```
//!
//!   `surfaces` are the scene's surface names; a label is an index into
//!   them. `scan_file` is the file (beside the index) that holds the scan:
//!   `NAME.ply`, or `SET.e57` where every scan is in one E57 file.
//! - `NAME.truth`, one per scan: `points` labels, each a little-endian
//!   `u32`, in the order the scan file lists its points (the PLY vertex
//!   order; the E57 point order). A label is the index of the point's true
//!   surface, or `unassigned` (`u32::MAX`, [`UNASSIGNED`]) for a point on
//!   no surface (a mixed pixel). The file is exactly `4 × points` bytes.

use std::path::{Path, PathBuf};

use campanile_scan::segmentation::{Segmentation, UNASSIGNED};
use serde::{Deserialize, Serialize};

use super::range_scanner::{RangeScans, ScanFileFormat};

/// Why the truth could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum TruthFileError {
    /// A file could not be written or read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// A file does not hold what the format says.
    #[error("{path}: {field}: found {found}, expected {expected}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// The field or part of the file.
        field: String,
        /// What was found.
        found: String,
        /// What was expected.
        expected: String,
    },
}

/// One scan's entry in the index.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TruthScan {
    /// The scan's name (the scanner pose's).
    pub name: String,
    /// The file that holds the scan, beside the index.
    pub scan_file: String,
    /// Its number of points.
    pub points: usize,
    /// The file of its labels, beside the index.
    pub truth: String,
}

/// `SET.truth.json`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TruthIndex {
    /// The true surfaces' names.
    pub surfaces: Vec<String>,
    /// The label of a point on no surface (`u32::MAX`).
    pub unassigned: u32,
    /// The scans, in the order written.
    pub scans: Vec<TruthScan>,
}

/// Writes the truth of `scans`, written by
/// [`super::range_scanner::write_scans`] into `dir` as `set` in `format`:
/// `SET.truth.json` and one `NAME.truth` per scan. Returns the index's
/// path.
pub fn write_truth(
    dir: &Path,
    set: &str,
    scans: &RangeScans,
    format: ScanFileFormat,
) -> Result<PathBuf, TruthFileError> {
    let io = |path: &Path, e: &dyn std::fmt::Display| TruthFileError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let mut entries = Vec::with_capacity(scans.scans.len());
    for (scan, labels) in scans.scans.iter().zip(&scans.truth.labels) {
        let truth = format!("{}.truth", scan.name);
        let bytes: Vec<u8> = labels.iter().flat_map(|l| l.to_le_bytes()).collect();
        let path = dir.join(&truth);
        std::fs::write(&path, bytes).map_err(|e| io(&path, &e))?;
        entries.push(TruthScan {
            name: scan.name.clone(),
            scan_file: match format {
                ScanFileFormat::Ply => format!("{}.ply", scan.name),
                ScanFileFormat::E57 => format!("{set}.e57"),
            },
            points: labels.len(),
            truth,
        });
    }
    let index = TruthIndex {
        surfaces: scans.truth.names.clone(),
        unassigned: UNASSIGNED,
        scans: entries,
    };
    let path = dir.join(format!("{set}.truth.json"));
    let text = serde_json::to_string_pretty(&index).map_err(|e| io(&path, &e))?;
    std::fs::write(&path, text).map_err(|e| io(&path, &e))?;
    Ok(path)
}

/// Reads a truth index and its label files: the index, and every scan's
/// labels as a [`Segmentation`] (scans in the index's order). Refuses a
/// label file of the wrong length and a label that is neither a surface nor
/// `unassigned`.
pub fn read_truth(index_path: &Path) -> Result<(TruthIndex, Segmentation), TruthFileError> {
    let io = |path: &Path, e: &dyn std::fmt::Display| TruthFileError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let text = std::fs::read_to_string(index_path).map_err(|e| io(index_path, &e))?;
    let index: TruthIndex = serde_json::from_str(&text).map_err(|e| TruthFileError::Malformed {
        path: index_path.to_path_buf(),
        field: format!("line {} column {}", e.line(), e.column()),
        found: e.to_string(),
        expected: "the truth index (surfaces, unassigned, scans)".into(),
    })?;
    let malformed = |path: &Path, field: String, found: String, expected: String| TruthFileError::Malformed {
        path: path.to_path_buf(),
        field,
        found,
        expected,
    };
    if index.unassigned != UNASSIGNED {
        return Err(malformed(
            index_path,
            "unassigned".into(),
            index.unassigned.to_string(),
            UNASSIGNED.to_string(),
        ));
    }
    let dir = index_path.parent().unwrap_or(Path::new("."));
    let mut labels = Vec::with_capacity(index.scans.len());
    for scan in &index.scans {
        let path = dir.join(&scan.truth);
        let bytes = std::fs::read(&path).map_err(|e| io(&path, &e))?;
        if bytes.len() != 4 * scan.points {
            return Err(malformed(
                &path,
                "length".into(),
                format!("{} bytes", bytes.len()),
                format!(
                    "4 × {} points = {} bytes (index {})",
                    scan.points,
                    4 * scan.points,
                    scan.name
                ),
            ));
        }
        let scan_labels: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        if let Some((p, l)) = scan_labels
            .iter()
            .enumerate()
            .find(|&(_, &l)| l != UNASSIGNED && l as usize >= index.surfaces.len())
        {
            return Err(malformed(
                &path,
                format!("label of point {p}"),
                l.to_string(),
                format!("a surface index below {} or {UNASSIGNED}", index.surfaces.len()),
            ));
        }
        labels.push(scan_labels);
    }
    let names = index.surfaces.clone();
    Ok((index, Segmentation { labels, names }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::range_scanner::{ScannerSettings, room_poses, room_scene, scan_scene, write_scans};

    #[test]
    fn the_truth_reads_back_beside_scans_that_read_back_in_the_same_order() {
        let mut settings = ScannerSettings::new(24, 48);
        settings.mixed_pixel_probability = 1.0;
        let poses: Vec<_> = room_poses().into_iter().take(2).collect();
        let scans = scan_scene(&room_scene().unwrap(), &poses, &settings).unwrap();
        let dir = tempfile::tempdir().unwrap();
        for format in [ScanFileFormat::Ply, ScanFileFormat::E57] {
            let files = write_scans(dir.path(), "room", &scans, format).unwrap();
            let index_path = write_truth(dir.path(), "room", &scans, format).unwrap();
            let (index, truth) = read_truth(&index_path).unwrap();
            assert_eq!(truth, scans.truth);
            assert_eq!(index.scans.len(), 2);
            // Mixed pixels (every edge beam here) are written as u32::MAX.
            let unassigned = truth.labels.iter().flatten().filter(|&&l| l == UNASSIGNED).count();
            assert_eq!(unassigned, scans.counts.iter().map(|c| c.mixed).sum::<usize>());
            assert!(unassigned > 0);
            // Each entry names the file that holds its scan, with as many
            // points as labels, in the same order: a floor label is on a
            // point at z = 0 (within 5σ of the 3 mm noise) in the file.
            let floor = truth.names.iter().position(|n| n == "floor").unwrap() as u32;
            for (entry, labels) in index.scans.iter().zip(&truth.labels) {
                let file = dir.path().join(&entry.scan_file);
                assert!(files.contains(&file), "{}", file.display());
                let scan = campanile_scan::read::read_scan(&file)
                    .unwrap()
                    .into_iter()
                    .find(|s| s.name == entry.name)
                    .unwrap();
                assert_eq!(scan.len(), labels.len());
                let on_floor = labels.iter().filter(|&&l| l == floor).count();
                assert!(on_floor > 50, "{on_floor}");
                for (p, _) in scan.positions.iter().zip(labels).filter(|&(_, &l)| l == floor) {
                    assert!(p.z.abs() < 0.015, "{p}");
                }
            }
        }
    }

    #[test]
    fn a_short_label_file_and_a_label_beyond_the_surfaces_are_refused_by_name() {
        let mut settings = ScannerSettings::new(6, 12);
        settings.elevation_deg = (-60.0, 60.0);
        let poses: Vec<_> = room_poses().into_iter().take(1).collect();
        let scans = scan_scene(&room_scene().unwrap(), &poses, &settings).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let index_path = write_truth(dir.path(), "room", &scans, ScanFileFormat::Ply).unwrap();
        let labels = dir.path().join("room-sw.truth");
        let mut bytes = std::fs::read(&labels).unwrap();
        let points = bytes.len() / 4;
        bytes.truncate(bytes.len() - 4);
        std::fs::write(&labels, &bytes).unwrap();
        let e = read_truth(&index_path).unwrap_err();
        let expected = format!("found {} bytes, expected 4 × {points} points", 4 * (points - 1));
        assert!(e.to_string().contains(&expected), "{e}");
        assert!(e.to_string().contains("room-sw.truth"), "{e}");
        bytes.extend(1000u32.to_le_bytes());
        std::fs::write(&labels, &bytes).unwrap();
        let e = read_truth(&index_path).unwrap_err();
        assert!(
            matches!(&e, TruthFileError::Malformed { field, found, .. } if *field == format!("label of point {}", points - 1) && found == "1000"),
            "{e}"
        );
    }
}
