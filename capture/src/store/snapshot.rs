//! The session's snapshot: the plan, station and scene descriptions as
//! they were when the session began, and where its calibration came from.
//!
//! They are written once, at `create`, as `plan.ron`, `station.ron`,
//! `scene.ron` (if given) and `provenance.json`, and read back at
//! `resume`, so a resumed session runs the plan it started with whatever
//! has happened to the configuration files since.

use super::error::StoreError;
use super::storage::Storage;
use chrono::{DateTime, Utc};
use serde::{Deserialize, Serialize};
use std::io;
use std::path::Path;

/// File name of the plan snapshot.
pub const PLAN_FILE: &str = "plan.ron";
/// File name of the station snapshot.
pub const STATION_FILE: &str = "station.ron";
/// File name of the scene snapshot (present only if the session has one).
pub const SCENE_FILE: &str = "scene.ron";
/// File name of the provenance record.
pub const PROVENANCE_FILE: &str = "provenance.json";

/// A calibration input the session depends on, and its checksum.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CalibrationRef {
    /// What it is or where it lives (e.g. `response-2026-08-01.csv`).
    pub file: String,
    /// Its checksum, as the calibration tool wrote it.
    pub checksum: String,
}

/// Where a session came from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Provenance {
    /// The `campanile` version that created the session.
    pub campanile_version: String,
    /// When the session was created, UTC.
    pub created_utc: DateTime<Utc>,
    /// Calibration inputs (response curve, mount offset, …).
    pub calibration: Vec<CalibrationRef>,
    /// Where the descriptions were read from, so that a resumed session
    /// can resolve their relative paths (the scene's OBJ geometry, a
    /// response curve) without being given the files again. Absent in
    /// sessions written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sources: Option<SourcePaths>,
}

/// The files a session's descriptions came from, as absolute paths.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SourcePaths {
    /// The plan file.
    pub plan: std::path::PathBuf,
    /// The station file.
    pub station: std::path::PathBuf,
    /// The scene file, if the plan names one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<std::path::PathBuf>,
}

/// What a session is captured under, as text (the RON the user wrote).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Snapshot {
    /// The plan, RON.
    pub plan_ron: String,
    /// The station configuration, RON.
    pub station_ron: String,
    /// The scene description, RON, if any.
    pub scene_ron: Option<String>,
    /// Where the session came from.
    pub provenance: Provenance,
}

impl Snapshot {
    /// The files to write: (name, bytes), in order.
    pub(crate) fn files(&self) -> Vec<(&'static str, Vec<u8>)> {
        let mut files = vec![
            (PLAN_FILE, self.plan_ron.as_bytes().to_vec()),
            (STATION_FILE, self.station_ron.as_bytes().to_vec()),
        ];
        if let Some(scene) = &self.scene_ron {
            files.push((SCENE_FILE, scene.as_bytes().to_vec()));
        }
        // A plain struct of strings and a date serializes without failure.
        let mut provenance = serde_json::to_vec_pretty(&self.provenance).unwrap_or_default();
        provenance.push(b'\n');
        files.push((PROVENANCE_FILE, provenance));
        files
    }

    /// Read the snapshot of the session in `dir` without opening the
    /// session (nothing is repaired or changed).
    pub fn read_dir(dir: &Path) -> Result<Self, StoreError> {
        Self::read(&super::storage::FsStorage, dir)
    }

    /// Read the snapshot of the session in `dir`.
    pub(crate) fn read<S: Storage + ?Sized>(s: &S, dir: &Path) -> Result<Self, StoreError> {
        let text = |name: &str, required: bool| -> Result<Option<String>, StoreError> {
            let path = dir.join(name);
            match s.read(&path) {
                Ok(bytes) => String::from_utf8(bytes).map(Some).map_err(|e| StoreError::BadSnapshot {
                    path,
                    reason: format!("expected UTF-8 text: {e}"),
                }),
                Err(e) if e.kind() == io::ErrorKind::NotFound && !required => Ok(None),
                Err(e) if e.kind() == io::ErrorKind::NotFound => Err(StoreError::NotASession {
                    dir: dir.to_path_buf(),
                    missing: path,
                }),
                Err(source) => Err(StoreError::Io {
                    action: "reading",
                    path,
                    source,
                }),
            }
        };
        let required = |name| text(name, true).map(Option::unwrap_or_default);
        let plan_ron = required(PLAN_FILE)?;
        let station_ron = required(STATION_FILE)?;
        let scene_ron = text(SCENE_FILE, false)?;
        let provenance_json = required(PROVENANCE_FILE)?;
        let provenance = serde_json::from_str(&provenance_json).map_err(|e| StoreError::BadSnapshot {
            path: dir.join(PROVENANCE_FILE),
            reason: format!("expected campanile_version, created_utc and calibration: {e}"),
        })?;
        Ok(Self {
            plan_ron,
            station_ron,
            scene_ron,
            provenance,
        })
    }
}
