//! The journal: one JSON object per line (`journal.jsonl`), appended once
//! per shot, never rewritten except to cut back a torn last line.
//!
//! Each line has a `status`:
//! - `done`: a frame taken on time, with its file, CRC-32C, size, bit
//!   depth, camera sequence number and [`FrameMeta`];
//! - `late`: the same, for a frame taken late (`meta.late_by_s` says by
//!   how much);
//! - `missed`: a shot not taken, with the time and the reason;
//! - `pruned`: raw frames deleted on purpose (an unattended station's
//!   storage budget, once their processed products exist), with the keys,
//!   the bytes freed and the reason; those frames are intentionally gone,
//!   not damaged, and their shots stay complete;
//! - `outage`: a device that was down, from `start` (its first failed
//!   call) to `end` (its first answer after coming back).
//!
//! A line is written whole (one `write_all` of the line and its `\n`) and
//! fsynced before the next shot; a crash can only leave a torn *last*
//! line without its `\n`, which [`parse_journal`] sets apart.

use super::error::StoreError;
use crate::device::FrameFormat;
use chrono::{DateTime, Utc};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What a shot was for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShotKind {
    /// A frame for the science.
    Data,
    /// A metering shot (to choose a bracket).
    Metering,
    /// A shot to centre the head on a target (e.g. the sun).
    Centering,
}

/// A head pose in degrees, as journaled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseDeg {
    /// Pan, degrees.
    pub pan_deg: f64,
    /// Tilt, degrees.
    pub tilt_deg: f64,
}

impl From<crate::device::Pose> for PoseDeg {
    fn from(p: crate::device::Pose) -> Self {
        Self {
            pan_deg: p.pan.degrees(),
            tilt_deg: p.tilt.degrees(),
        }
    }
}

/// One light channel's level, as journaled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LightLevel {
    /// Channel, 0-based.
    pub channel: u16,
    /// Fraction of full output, 0..=1.
    pub level: f64,
}

/// What the controller knows about a shot, journaled with its frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameMeta {
    /// When the shot was taken, UTC.
    pub time: DateTime<Utc>,
    /// What the shot was for.
    pub kind: ShotKind,
    /// Head pose asked for, if the head was used.
    pub pose_requested: Option<PoseDeg>,
    /// Head pose the head reported reaching.
    pub pose_reached: Option<PoseDeg>,
    /// Exposure time asked for, seconds.
    pub exposure_requested_s: f64,
    /// Exposure time the camera applied, seconds.
    pub exposure_actual_s: f64,
    /// Gain applied, dB.
    pub gain_db: f64,
    /// The filter in place (slot name), if a wheel was used.
    pub filter: Option<String>,
    /// Light levels, if lights were used.
    pub lights: Option<Vec<LightLevel>>,
    /// Sensor temperature, °C, if known.
    pub temperature_c: Option<f64>,
    /// How late the shot was taken, seconds; `Some` makes the journal line
    /// `late`.
    pub late_by_s: Option<f64>,
    /// Free-form notes (e.g. "late by 12 s: head stalled").
    pub notes: Vec<String>,
    /// The camera's own report with the frame, when it sent one: its FITS
    /// header's valued cards as `KEYWORD = value` (an INDI camera's
    /// `EXPTIME`, `DATE-OBS`, `CCD-TEMP`, `INSTRUME`, …).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub camera_report: Vec<String>,
    /// The lens's focal length for this frame, pixels at the frame's size,
    /// when it is not the station camera's: a zoom photograph (thesis
    /// §5.6.4), such as `session import` writes for photographs taken at
    /// another focal length than the session's camera. Processing takes
    /// such a frame as an undistorted pinhole of this focal length centred
    /// on the frame. `None`: the station camera's intrinsics.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_px: Option<f64>,
}

/// The header cards of a frame the camera delivered as FITS.
fn camera_report(frame: &crate::device::Frame) -> Vec<String> {
    match &frame.file {
        Some(f) if f.format == crate::device::FrameFormat::Fits => {
            campanile_process::hdr::fits_file::read_header(&f.bytes, "frame")
                .map(|(cards, _)| {
                    cards
                        .into_iter()
                        .map(|c| format!("{} = {}", c.keyword, c.value))
                        .collect()
                })
                .unwrap_or_default()
        }
        _ => Vec::new(),
    }
}

impl FrameMeta {
    /// Metadata filled from what the camera reported with `frame` (time,
    /// exposures, gain, temperature); pose, filter, lights, lateness and
    /// notes are left empty for the caller.
    pub fn from_frame(frame: &crate::device::Frame, kind: ShotKind) -> Self {
        Self {
            time: frame.timestamp,
            kind,
            pose_requested: None,
            pose_reached: None,
            exposure_requested_s: frame.exposure_requested.seconds(),
            exposure_actual_s: frame.exposure_actual.seconds(),
            gain_db: frame.gain.db(),
            filter: None,
            lights: None,
            temperature_c: frame.temperature_c,
            late_by_s: None,
            notes: Vec::new(),
            camera_report: camera_report(frame),
            focal_px: None,
        }
    }

    /// Check that every number can be journaled and read back (JSON has
    /// no NaN or infinity) and lies in its range; the problem, if any.
    pub fn problem(&self) -> Option<String> {
        let finite = |name: &str, v: f64| (!v.is_finite()).then(|| format!("{name} is {v}, not a finite number"));
        let positive =
            |name: &str, v: f64| (!(v.is_finite() && v > 0.0)).then(|| format!("{name} is {v}, expected > 0 s"));
        let poses = [
            ("pose_requested", self.pose_requested),
            ("pose_reached", self.pose_reached),
        ];
        positive("exposure_requested_s", self.exposure_requested_s)
            .or_else(|| positive("exposure_actual_s", self.exposure_actual_s))
            .or_else(|| finite("gain_db", self.gain_db))
            .or_else(|| self.temperature_c.and_then(|t| finite("temperature_c", t)))
            .or_else(|| {
                self.focal_px.and_then(|f| {
                    (!(f.is_finite() && f > 0.0)).then(|| format!("focal_px is {f}, expected > 0 pixels"))
                })
            })
            .or_else(|| {
                self.late_by_s
                    .and_then(|l| (!(l.is_finite() && l >= 0.0)).then(|| format!("late_by_s is {l}, expected ≥ 0")))
            })
            .or_else(|| {
                poses.iter().find_map(|(name, p)| {
                    p.and_then(|p| {
                        finite(&format!("{name}.pan_deg"), p.pan_deg)
                            .or(finite(&format!("{name}.tilt_deg"), p.tilt_deg))
                    })
                })
            })
            .or_else(|| {
                self.lights.iter().flatten().find_map(|l| {
                    (!(0.0..=1.0).contains(&l.level))
                        .then(|| format!("light {} level is {}, expected 0..=1", l.channel, l.level))
                })
            })
    }
}

/// A journaled frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameEntry {
    /// The scheduler's key for the shot.
    pub key: String,
    /// The frame file, relative to the session directory
    /// (`frames/….png`, `….jpg`, `….dng`).
    pub file: String,
    /// The file's format. Journals from before the field read as PNG.
    #[serde(default)]
    pub format: FrameFormat,
    /// CRC-32C of the file's bytes.
    pub crc32c: u32,
    /// Size of the file, bytes.
    pub bytes: u64,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Significant bits per sample: the stored codes lie in
    /// `0..=2^bits − 1` (unscaled). For a camera's file, the bits of the
    /// codes the camera reported with it (the file's own depth is the
    /// file's).
    pub bits: u8,
    /// The camera's frame counter.
    pub sequence: u64,
    /// What the controller knew about the shot.
    pub meta: FrameMeta,
}

/// A shot that was not taken.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissedEntry {
    /// The scheduler's key for the shot.
    pub key: String,
    /// When it was given up, UTC.
    pub time: DateTime<Utc>,
    /// Why (e.g. "sun behind cloud", "head did not reach pose").
    pub reason: String,
}

/// Raw frames deleted on purpose (e.g. to stay within a storage budget).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrunedEntry {
    /// When they were deleted, UTC.
    pub time: DateTime<Utc>,
    /// The shot keys whose frames were deleted (each completed earlier).
    pub keys: Vec<String>,
    /// Bytes freed (the journaled sizes of their files).
    pub bytes: u64,
    /// Why, e.g. "storage budget 2000000 bytes exceeded; products exist".
    pub reason: String,
}

/// A device that was down.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutageEntry {
    /// The device: `camera`, `head`, `filter wheel` or `lights`.
    pub device: String,
    /// Its first failed call, UTC.
    pub start: DateTime<Utc>,
    /// Its first answer after coming back, UTC; or, when `open`, when the
    /// run stopped with the device still down.
    pub end: DateTime<Utc>,
    /// The run stopped (or ended) while the device was still down: `end`
    /// is the stop, not the device's return.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub open: bool,
}

/// One journal line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "lowercase")]
pub enum JournalEntry {
    /// A frame taken on time.
    Done(FrameEntry),
    /// A frame taken late.
    Late(FrameEntry),
    /// A shot not taken.
    Missed(MissedEntry),
    /// Frames deleted on purpose.
    Pruned(PrunedEntry),
    /// A device outage.
    Outage(OutageEntry),
}

impl JournalEntry {
    /// The shot's key; empty for the lines about no single shot
    /// (`pruned`, `outage`).
    pub fn key(&self) -> &str {
        match self {
            JournalEntry::Done(f) | JournalEntry::Late(f) => &f.key,
            JournalEntry::Missed(m) => &m.key,
            JournalEntry::Pruned(_) | JournalEntry::Outage(_) => "",
        }
    }

    /// The frame, unless the line is not about a taken frame.
    pub fn frame(&self) -> Option<&FrameEntry> {
        match self {
            JournalEntry::Done(f) | JournalEntry::Late(f) => Some(f),
            JournalEntry::Missed(_) | JournalEntry::Pruned(_) | JournalEntry::Outage(_) => None,
        }
    }

    /// When the line's event happened (a frame's time, a miss, a
    /// pruning, an outage's end).
    pub fn time(&self) -> DateTime<Utc> {
        match self {
            JournalEntry::Done(f) | JournalEntry::Late(f) => f.meta.time,
            JournalEntry::Missed(m) => m.time,
            JournalEntry::Pruned(p) => p.time,
            JournalEntry::Outage(o) => o.end,
        }
    }

    /// The line as written: compact JSON and `\n`.
    pub fn to_line(&self) -> Vec<u8> {
        // Serializing these plain structs cannot fail (string keys, no
        // maps with non-string keys); fall back to an empty object rather
        // than panic.
        let mut line = serde_json::to_vec(self).unwrap_or_else(|_| b"{}".to_vec());
        line.push(b'\n');
        line
    }
}

/// A journal as read back.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedJournal {
    /// The complete lines, in order.
    pub entries: Vec<JournalEntry>,
    /// Bytes up to and including the last `\n`.
    pub complete_len: u64,
    /// Bytes after it: a line torn by a crash mid-append (0 if none).
    pub torn_len: u64,
}

/// Read a journal's bytes. A last line without its `\n` is torn (counted,
/// not parsed); any complete line that is not a journal entry is
/// [`StoreError::JournalCorrupt`] naming its line number.
pub fn parse_journal(path: &Path, bytes: &[u8]) -> Result<ParsedJournal, StoreError> {
    let complete_len = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let mut entries = Vec::new();
    for (i, piece) in bytes[..complete_len].split_inclusive(|&b| b == b'\n').enumerate() {
        let n = i + 1;
        let line = piece.strip_suffix(b"\n").unwrap_or(piece);
        if line.is_empty() {
            return Err(StoreError::JournalCorrupt {
                path: path.to_path_buf(),
                line: n,
                reason: "empty line (expected a JSON journal entry)".into(),
            });
        }
        let entry = serde_json::from_slice::<JournalEntry>(line).map_err(|e| StoreError::JournalCorrupt {
            path: path.to_path_buf(),
            line: n,
            reason: format!("expected a JSON journal entry with status done, late, missed, pruned or outage: {e}"),
        })?;
        entries.push(entry);
    }
    Ok(ParsedJournal {
        entries,
        complete_len: complete_len as u64,
        torn_len: (bytes.len() - complete_len) as u64,
    })
}
