//! A caller that supervises a run ([`Supervisor`]): it may stop the run
//! between shots, seed and damp metered exposures from one occurrence to
//! the next, and hears of every device call that fails or answers (so it
//! can tell when a device went down and came back). The unattended
//! station ([`crate::unattended`]) is one; [`Unsupervised`] does nothing.

use chrono::{DateTime, Utc};

use super::rig::DeviceKind;
use crate::device::DeviceError;
use crate::schedule::Occurrence;

/// What a metering of one target found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metering {
    /// The exposure the metering loop accepted, seconds (its median code
    /// within [`super::metering::ACCEPT`]).
    pub accepted_s: f64,
    /// The exposure that would put the last test capture's median exactly
    /// at [`super::metering::TARGET_FRACTION`], seconds (`t · (target /
    /// median)^γ`, γ = [`super::metering::ASSUMED_GAMMA`]); equal to
    /// `accepted_s` when the last capture was black or white.
    pub ideal_s: f64,
    /// Test captures taken.
    pub captures: usize,
}

/// Steers and watches a run; every method has a neutral default.
pub trait Supervisor: Send {
    /// Whether to stop before the next shot (checked before every
    /// occurrence and every shot: a stop lands on a frame boundary, with
    /// the journal complete up to the last frame).
    fn stop_requested(&self) -> bool {
        false
    }

    /// The first exposure to try when metering `target` (`"{occurrence}/s{step}/t{target}"`)
    /// of `occurrence`, seconds; `None` starts from
    /// [`RunOptions::meter_start_s`](super::RunOptions::meter_start_s).
    fn metering_start(&mut self, occurrence: &Occurrence, target: &str) -> Option<f64> {
        let _ = (occurrence, target);
        None
    }

    /// The exposure to use for `target`, given its metering (seconds;
    /// clamped to the camera's range by the caller). The default is the
    /// accepted exposure.
    fn metered_exposure(&mut self, occurrence: &Occurrence, target: &str, metering: Metering) -> f64 {
        let _ = (occurrence, target);
        metering.accepted_s
    }

    /// A call to `device` failed at `time` (after the watchdog, if it hung).
    fn device_failed(&mut self, device: DeviceKind, time: DateTime<Utc>, error: &DeviceError) {
        let _ = (device, time, error);
    }

    /// A call to `device` answered at `time`.
    fn device_answered(&mut self, device: DeviceKind, time: DateTime<Utc>) {
        let _ = (device, time);
    }

    /// Whether the controller journals device outages (`outage` lines,
    /// from a device's first failed call to its first answer after, or to
    /// the run's end). A supervisor that also watches the devices between
    /// runs (the unattended station) journals them itself and says no.
    fn journals_outages(&self) -> bool {
        true
    }
}

/// No supervision: the run goes to its end, metering starts from
/// [`RunOptions::meter_start_s`](super::RunOptions::meter_start_s) and
/// uses the accepted exposure.
#[derive(Debug, Clone, Copy, Default)]
pub struct Unsupervised;

impl Supervisor for Unsupervised {}
