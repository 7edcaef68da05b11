//! The station's [`Supervisor`] of each scan: the stop handle, the damped
//! exposure plan, and device health in the heartbeat.

use chrono::{DateTime, Utc};

use super::exposure_plan::ExposurePlan;
use super::heartbeat::Beat;
use super::outage::DeviceState;
use super::stop::StopHandle;
use crate::controller::{DeviceKind, Metering, Supervisor};
use crate::device::DeviceError;
use crate::schedule::Occurrence;

/// Supervises one scan for the station.
pub struct StationSupervisor<'a> {
    /// Stops the scan between shots when asked.
    pub stop: &'a StopHandle,
    /// Seeds and damps metered exposures.
    pub exposure: &'a mut ExposurePlan,
    /// Device health, in the heartbeat.
    pub beat: &'a Beat,
}

impl Supervisor for StationSupervisor<'_> {
    fn stop_requested(&self) -> bool {
        self.stop.is_requested()
    }

    fn metering_start(&mut self, occurrence: &Occurrence, target: &str) -> Option<f64> {
        self.exposure.metering_start(occurrence, target)
    }

    fn metered_exposure(&mut self, occurrence: &Occurrence, target: &str, metering: Metering) -> f64 {
        self.exposure.choose(occurrence, target, metering)
    }

    fn device_failed(&mut self, device: DeviceKind, time: DateTime<Utc>, error: &DeviceError) {
        let message = error.to_string();
        self.beat.update(time, |_, h| h.failed(device, time, &message));
    }

    fn journals_outages(&self) -> bool {
        // The station journals outages itself: it probes its devices
        // between scans too (`journal_outages`).
        false
    }

    fn device_answered(&mut self, device: DeviceKind, time: DateTime<Utc>) {
        // Rewrite the heartbeat only when the device's state changes.
        let changed = self.beat.health(|h| {
            let was_up = matches!(h.state(device), DeviceState::Up { .. });
            h.answered(device, time);
            !was_up
        });
        if changed {
            self.beat.update(time, |_, _| ());
        }
    }
}
