//! Device health: which devices are up or down, since when, and the
//! outages that have ended (to journal as `outage` lines).
//!
//! A device goes down at its first failed call (a controller call or a
//! station probe) and comes back at its first answer after that; the
//! outage journaled is `[first failure, first answer]`. How close that is
//! to the truth depends on how often the device is asked: the station
//! probes an idle device every [`super::StationOptions::health_interval`]
//! and a down one with backoff ([`super::StationOptions::probe_backoff`]),
//! so both ends are late by at most about one of those waits.

use chrono::{DateTime, Utc};
use serde::{Deserialize, Serialize};

use crate::controller::DeviceKind;

/// The devices a station watches, in heartbeat order.
pub const WATCHED: [DeviceKind; 4] = [
    DeviceKind::Camera,
    DeviceKind::Head,
    DeviceKind::Wheel,
    DeviceKind::Lights,
];

/// A device's state as the station last saw it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "lowercase")]
pub enum DeviceState {
    /// Not asked yet in this run.
    Unknown,
    /// Answered at `last_answer`.
    Up {
        /// Its last answer, UTC.
        last_answer: DateTime<Utc>,
    },
    /// Failing since `since`.
    Down {
        /// Its first failed call, UTC.
        since: DateTime<Utc>,
        /// The last failure.
        error: String,
        /// Probes that failed since.
        probes: u32,
    },
}

/// An outage that has ended.
#[derive(Debug, Clone, PartialEq)]
pub struct EndedOutage {
    /// The device.
    pub device: DeviceKind,
    /// Its first failed call.
    pub start: DateTime<Utc>,
    /// Its first answer after.
    pub end: DateTime<Utc>,
}

/// Every watched device's state, and the outages ended but not journaled.
#[derive(Debug, Clone)]
pub struct DeviceHealth {
    states: [(DeviceKind, DeviceState); 4],
    ended: Vec<EndedOutage>,
}

impl Default for DeviceHealth {
    fn default() -> Self {
        Self {
            states: WATCHED.map(|k| (k, DeviceState::Unknown)),
            ended: Vec::new(),
        }
    }
}

impl DeviceHealth {
    fn slot(&mut self, device: DeviceKind) -> &mut DeviceState {
        let i = WATCHED.iter().position(|&k| k == device).unwrap_or(0);
        &mut self.states[i].1
    }

    /// A call to `device` failed at `time`: it is down from then (or
    /// still down; one more failed probe).
    pub fn failed(&mut self, device: DeviceKind, time: DateTime<Utc>, error: &str) {
        let state = self.slot(device);
        match state {
            DeviceState::Down { error: e, probes, .. } => {
                *e = error.to_owned();
                *probes += 1;
            }
            _ => {
                tracing::warn!(device = %device, %time, error, "device down");
                *state = DeviceState::Down {
                    since: time,
                    error: error.to_owned(),
                    probes: 0,
                };
            }
        }
    }

    /// `device` answered at `time`; if it was down, its outage ends.
    pub fn answered(&mut self, device: DeviceKind, time: DateTime<Utc>) {
        let state = self.slot(device);
        if let DeviceState::Down { since, .. } = state {
            let start = *since;
            tracing::info!(device = %device, %start, end = %time, "device back after an outage");
            self.ended.push(EndedOutage {
                device,
                start,
                end: time,
            });
        }
        *self.slot(device) = DeviceState::Up { last_answer: time };
    }

    /// The state of `device`.
    pub fn state(&self, device: DeviceKind) -> &DeviceState {
        let i = WATCHED.iter().position(|&k| k == device).unwrap_or(0);
        &self.states[i].1
    }

    /// Since when `device` is down, if it is.
    pub fn down_since(&self, device: DeviceKind) -> Option<DateTime<Utc>> {
        match self.state(device) {
            DeviceState::Down { since, .. } => Some(*since),
            _ => None,
        }
    }

    /// Failed probes of `device` since it went down (0 if up).
    pub fn failed_probes(&self, device: DeviceKind) -> u32 {
        match self.state(device) {
            DeviceState::Down { probes, .. } => *probes,
            _ => 0,
        }
    }

    /// Every device's state, in [`WATCHED`] order.
    pub fn states(&self) -> impl Iterator<Item = (DeviceKind, &DeviceState)> {
        self.states.iter().map(|(k, s)| (*k, s))
    }

    /// The outages ended since the last call, to journal.
    pub fn take_ended(&mut self) -> Vec<EndedOutage> {
        std::mem::take(&mut self.ended)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::TimeZone;

    #[test]
    fn an_outage_runs_from_the_first_failure_to_the_first_answer() {
        let t = |m: u32| Utc.with_ymd_and_hms(2026, 6, 22, 18, m, 0).unwrap();
        let mut h = DeviceHealth::default();
        h.answered(DeviceKind::Head, t(0));
        assert!(h.take_ended().is_empty());
        h.failed(DeviceKind::Head, t(5), "link closed");
        h.failed(DeviceKind::Head, t(6), "port absent");
        h.failed(DeviceKind::Head, t(7), "port absent");
        assert_eq!(h.down_since(DeviceKind::Head), Some(t(5)));
        assert_eq!(h.failed_probes(DeviceKind::Head), 2);
        assert_eq!(h.down_since(DeviceKind::Wheel), None);
        h.answered(DeviceKind::Head, t(35));
        h.answered(DeviceKind::Head, t(36));
        assert_eq!(
            h.take_ended(),
            vec![EndedOutage {
                device: DeviceKind::Head,
                start: t(5),
                end: t(35)
            }]
        );
        assert!(h.take_ended().is_empty());
        assert_eq!(h.state(DeviceKind::Head), &DeviceState::Up { last_answer: t(36) });
    }
}
