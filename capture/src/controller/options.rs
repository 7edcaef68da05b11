//! How a run behaves ([`RunOptions`]), what it reports ([`RunReport`]),
//! and how it tells a user interface about its progress ([`Progress`]).

use crate::schedule::{Occurrence, PlannedShot};
use std::time::Duration;

/// Tolerances and limits of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// An occurrence that starts more than this after its trigger has the
    /// frames taken more than this after their planned times (the trigger
    /// plus each shot's estimated start) journaled `late`, with `late_by_s`
    /// against the planned time.
    pub late_tolerance: Duration,
    /// An occurrence that cannot start within this of its trigger is
    /// recorded missed, shot by shot, with the reason.
    pub start_window: Duration,
    /// A device call (beyond the exposure itself) that takes longer than
    /// this is abandoned as hung.
    pub watchdog: Duration,
    /// How long to wait for the head to come to rest.
    pub settle_limit: Duration,
    /// Attempts to reconnect a dropped device, with doubling waits from
    /// `reconnect_backoff`.
    pub reconnect_attempts: u32,
    /// The first wait before reconnecting.
    pub reconnect_backoff: Duration,
    /// First guess of a metered exposure, seconds.
    pub meter_start_s: f64,
}

impl Default for RunOptions {
    /// Late beyond 60 s, missed beyond 30 min, 30 s watchdog, 60 s to
    /// settle, 8 reconnects from 1 s (about 4 min in all), metering from 10 ms.
    fn default() -> Self {
        Self {
            late_tolerance: Duration::from_secs(60),
            start_window: Duration::from_secs(30 * 60),
            watchdog: Duration::from_secs(30),
            settle_limit: Duration::from_secs(60),
            reconnect_attempts: 8,
            reconnect_backoff: Duration::from_secs(1),
            meter_start_s: 0.01,
        }
    }
}

/// An auto-bracket's outcome: how many frames it took to cover its target.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoBracketUse {
    /// The target, `"{occurrence}/s{step}/t{target}"`.
    pub target: String,
    /// Data frames taken.
    pub frames: usize,
    /// At most.
    pub max_frames: usize,
    /// Pixels left without a well-exposed frame (0 when covered).
    pub uncovered_pixels: usize,
}

/// What a run did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunReport {
    /// Frames journaled by this run.
    pub frames: usize,
    /// Of which `late`.
    pub late: usize,
    /// Shots journaled `missed` by this run.
    pub missed: usize,
    /// Shots already complete in the session, skipped.
    pub already_done: usize,
    /// Device calls retried after a failure.
    pub retries: usize,
    /// Devices reconnected.
    pub reconnects: usize,
    /// Sun frames retaken through a denser filter because the disc saturated.
    pub saturation_retakes: usize,
    /// Unstored test captures taken to meter exposures.
    pub metering_captures: usize,
    /// Auto-brackets, in order.
    pub auto_brackets: Vec<AutoBracketUse>,
    /// Why the run stopped early, if it did (e.g. the disk is full).
    pub stopped: Option<String>,
}

/// What became of one shot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShotOutcome {
    /// Journaled with its frame.
    Stored,
    /// Journaled with its frame, late.
    Late,
    /// Journaled missed.
    Missed,
    /// Complete from an earlier run.
    AlreadyDone,
    /// An auto-bracket frame the metered range did not need.
    NotNeeded,
}

/// Receives progress; every method does nothing by default.
pub trait Progress: Send {
    /// An occurrence begins (after waiting for its start).
    fn occurrence(&mut self, occurrence: &Occurrence) {
        let _ = occurrence;
    }
    /// A step begins, with its number of shots.
    fn step(&mut self, occurrence: &Occurrence, step: usize, kind: &str, shots: usize) {
        let _ = (occurrence, step, kind, shots);
    }
    /// A shot is settled.
    fn shot(&mut self, shot: &PlannedShot, outcome: ShotOutcome) {
        let _ = (shot, outcome);
    }
}

/// No progress display.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}
