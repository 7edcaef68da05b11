//! Auto-exposure that does not flap: exposures planned across the day from
//! a clear-sky model and damped from one scan to the next.
//!
//! All-sky software that meters every frame afresh makes consecutive
//! frames jump around (a cloud edge, the sun entering a tile), and a
//! metering that accepts a range of medians (here ±1 stop of gamma-2.2
//! codes, [`crate::controller::metering::ACCEPT`]) lets the exposure sit
//! anywhere in that range, jumping when it drifts out. Here each metered
//! target of a repeating session (a sky tile `sky/s1/t3`, the same tile
//! in every scan) keeps its exposure in log₂ seconds, `x`, from scan to
//! scan:
//!
//! 1. **Plan.** The exposure the previous scan chose, carried to this
//!    scan's sun by the clear-sky model (CIE clear sky per channel,
//!    `process::sky::Daylight::clear`, mean of the channels, at the
//!    tile's direction): `p = x₋₁ + log₂ L̂₋₁ − log₂ L̂` (exposure is
//!    inversely proportional to radiance). The metering starts from `2^p`,
//!    so it usually accepts its first test capture.
//! 2. **Measure.** The metering's *ideal* exposure `m` (the one that puts
//!    the last test capture's median code exactly at the target,
//!    [`crate::controller::Metering::ideal_s`]), not the accepted one, so
//!    that the measurement moves smoothly with the sky.
//! 3. **Damp.** Exponential smoothing toward the measurement, bounded:
//!    `x = x₋₁ + clamp(p + g (m − p) − x₋₁, −s, s)` with gain `g`
//!    ([`ExposureDamping::gain`], 0.5) and step `s`
//!    ([`ExposureDamping::max_step_stops`], 0.5 stop). So consecutive
//!    scans' exposures of a target differ by at most `s` stops, follow the
//!    model's smooth trend, and correct the model's error by half of it per
//!    scan: a monotone brightening sky gives monotone exposures.
//!
//! The first scan of a target, or one more than
//! [`ExposureDamping::memory`] after the previous (the next morning, a
//! long outage), uses the measurement as is. After a restart the memory is
//! recalled from the journal ([`ExposurePlan::recall`]). Targets that are
//! not sky directions (poses) have no model: `p = x₋₁`.

use std::collections::HashMap;
use std::time::Duration;

use campanile_process::sky::{Atmosphere, Daylight};
use chrono::{DateTime, Utc};

use crate::controller::Metering;
use crate::controller::aim::direction_deg;
use crate::schedule::{Occurrence, PlannedAim, PlannedExposure};
use crate::store::{SessionStore, Storage};

/// How exposures are damped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureDamping {
    /// The largest change of a target's exposure from one scan to the next, stops.
    pub max_step_stops: f64,
    /// The fraction of the model's error corrected per scan, in (0, 1].
    pub gain: f64,
    /// A previous scan older than this is forgotten.
    pub memory: Duration,
}

impl Default for ExposureDamping {
    /// Half a stop, gain 0.5, 90 minutes.
    fn default() -> Self {
        Self {
            max_step_stops: 0.5,
            gain: 0.5,
            memory: Duration::from_secs(90 * 60),
        }
    }
}

/// One exposure chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct ExposureChoice {
    /// The occurrence.
    pub occurrence: String,
    /// The target across scans, `{session}/s{step}/t{target}`.
    pub target: String,
    /// The occurrence's start.
    pub time: DateTime<Utc>,
    /// The metering's ideal exposure, seconds.
    pub measured_s: f64,
    /// The planned exposure (the previous one carried by the model), seconds.
    pub planned_s: Option<f64>,
    /// The exposure chosen, seconds.
    pub chosen_s: f64,
}

#[derive(Debug, Clone, Copy)]
struct Remembered {
    log2_s: f64,
    start: DateTime<Utc>,
    model_log2: Option<f64>,
}

/// The exposures of the targets of repeating sessions, scan to scan.
#[derive(Debug, Clone, Default)]
pub struct ExposurePlan {
    damping: ExposureDamping,
    memory: HashMap<String, Remembered>,
    choices: Vec<ExposureChoice>,
}

/// The target across scans: `{session}/s{step}/t{target}` of a target key
/// `{occurrence}/s{step}/t{target}`.
pub fn target_id(occurrence: &Occurrence, target: &str) -> String {
    match target.strip_prefix(occurrence.key.as_str()) {
        Some(rest) => format!("{}{rest}", occurrence.name),
        None => target.to_owned(),
    }
}

/// log₂ of the clear-sky model's radiance (mean of the channels) where
/// `target` of `occurrence` looks, with the sun at the occurrence's start;
/// `None` for a target that is not a sky direction or a dark model.
pub fn model_log2(occurrence: &Occurrence, target: &str) -> Option<f64> {
    let prefix = format!("{target}/");
    let shot = occurrence.shots.iter().find(|s| s.key.starts_with(&prefix))?;
    let PlannedAim::Sky {
        azimuth_deg,
        elevation_deg,
    } = shot.aim
    else {
        return None;
    };
    let sun = direction_deg(occurrence.sun.0, occurrence.sun.1);
    let daylight = Daylight::clear(sun, &Atmosphere::clear());
    let l = daylight.sky_radiance(direction_deg(azimuth_deg, elevation_deg));
    let mean = (l[0] + l[1] + l[2]) / 3.0;
    (mean.is_finite() && mean > 0.0).then(|| mean.log2())
}

impl ExposurePlan {
    /// A plan with no memory yet.
    pub fn new(damping: ExposureDamping) -> Self {
        Self {
            damping,
            memory: HashMap::new(),
            choices: Vec::new(),
        }
    }

    /// The damping in use.
    pub fn damping(&self) -> ExposureDamping {
        self.damping
    }

    fn remembered(&self, occurrence: &Occurrence, id: &str) -> Option<Remembered> {
        let r = *self.memory.get(id)?;
        let age = (occurrence.start - r.start).to_std().ok()?;
        (age <= self.damping.memory).then_some(r)
    }

    /// The planned exposure of `target` (log₂ s): the previous scan's,
    /// carried by the model; `None` without a recent previous scan.
    fn planned_log2(&self, occurrence: &Occurrence, target: &str) -> Option<(Remembered, f64)> {
        let r = self.remembered(occurrence, &target_id(occurrence, target))?;
        let shift = match (r.model_log2, model_log2(occurrence, target)) {
            (Some(before), Some(now)) => before - now,
            _ => 0.0,
        };
        Some((r, r.log2_s + shift))
    }

    /// Where the metering of `target` starts, seconds (the planned exposure).
    pub fn metering_start(&self, occurrence: &Occurrence, target: &str) -> Option<f64> {
        self.planned_log2(occurrence, target).map(|(_, p)| p.exp2())
    }

    /// The damped exposure of `target` given its metering, seconds (see
    /// the module documentation); remembered for the next scan.
    pub fn choose(&mut self, occurrence: &Occurrence, target: &str, metering: Metering) -> f64 {
        let measured = if metering.ideal_s.is_finite() && metering.ideal_s > 0.0 {
            metering.ideal_s
        } else {
            metering.accepted_s
        };
        let m = measured.log2();
        let planned = self.planned_log2(occurrence, target);
        let x = match planned {
            None => m,
            Some((last, p)) => {
                let want = p + self.damping.gain * (m - p);
                let s = self.damping.max_step_stops;
                last.log2_s + (want - last.log2_s).clamp(-s, s)
            }
        };
        let id = target_id(occurrence, target);
        self.memory.insert(
            id.clone(),
            Remembered {
                log2_s: x,
                start: occurrence.start,
                model_log2: model_log2(occurrence, target),
            },
        );
        self.choices.push(ExposureChoice {
            occurrence: occurrence.key.clone(),
            target: id,
            time: occurrence.start,
            measured_s: measured,
            planned_s: planned.map(|(_, p)| p.exp2()),
            chosen_s: x.exp2(),
        });
        x.exp2()
    }

    /// Remember the exposures `occurrence` journaled (its metered shots'
    /// requested exposure, less their stops), e.g. after a restart.
    pub fn recall<S: Storage>(&mut self, occurrence: &Occurrence, store: &SessionStore<S>) {
        for shot in &occurrence.shots {
            let PlannedExposure::Metered { stops } = shot.exposure else {
                continue;
            };
            let Some(frame) = store.frame_entry(&shot.key) else {
                continue;
            };
            let t = frame.meta.exposure_requested_s;
            if !(t.is_finite() && t > 0.0) {
                continue;
            }
            let target = shot.key.rsplit_once("/f").map_or(shot.key.as_str(), |(t, _)| t);
            let id = target_id(occurrence, target);
            if self.memory.get(&id).is_some_and(|r| r.start > occurrence.start) {
                continue;
            }
            self.memory.insert(
                id,
                Remembered {
                    log2_s: t.log2() - stops,
                    start: occurrence.start,
                    model_log2: model_log2(occurrence, target),
                },
            );
        }
    }

    /// Every exposure chosen by this run, in order.
    pub fn choices(&self) -> &[ExposureChoice] {
        &self.choices
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schedule::{FilterChoice, PlannedShot, ShotKind};
    use chrono::{TimeDelta, TimeZone};

    fn scan(n: i64, sun_el: f64) -> Occurrence {
        let key = format!("sky@2026-06-21#{n}");
        Occurrence {
            key: key.clone(),
            session: 0,
            name: "sky".to_owned(),
            held_out: false,
            start: Utc.with_ymd_and_hms(2026, 6, 21, 14, 0, 0).unwrap() + TimeDelta::minutes(10 * n),
            sun: (90.0, sun_el),
            shots: vec![PlannedShot {
                key: format!("{key}/s1/t0/f1"),
                step: 1,
                kind: ShotKind::Data,
                aim: PlannedAim::Sky {
                    azimuth_deg: 270.0,
                    elevation_deg: 30.0,
                },
                exposure: PlannedExposure::Metered { stops: 0.0 },
                filter: FilterChoice::None,
                lights: None,
                promised: true,
            }],
            estimated_duration: Duration::ZERO,
        }
    }

    fn metering(s: f64) -> Metering {
        Metering {
            accepted_s: s,
            ideal_s: s,
            captures: 1,
        }
    }

    #[test]
    fn a_jump_in_the_measurement_is_taken_half_a_stop_per_scan() {
        let mut plan = ExposurePlan::new(ExposureDamping::default());
        // Same sun: the model predicts no change.
        let a = scan(1, 30.0);
        let target = format!("{}/s1/t0", a.key);
        assert_eq!(plan.metering_start(&a, &target), None);
        let x0 = plan.choose(&a, &target, metering(0.01));
        assert!((x0 - 0.01).abs() < 1e-12, "first scan takes the measurement: {x0}");
        // The measurement jumps 3 stops brighter (shorter) and stays there.
        let mut x = x0;
        let mut steps = Vec::new();
        for n in 2..14 {
            let o = scan(n, 30.0);
            let t = format!("{}/s1/t0", o.key);
            let start = plan.metering_start(&o, &t).expect("a recent scan");
            assert!(
                (start - x).abs() < 1e-12 * x,
                "metering starts at the previous exposure"
            );
            let next = plan.choose(&o, &t, metering(0.01 / 8.0));
            steps.push((next / x).log2());
            x = next;
        }
        // Bounded steps of at most 0.5 stop, all in one direction, halving the
        // rest of the way once within a stop: −0.5 × 5, then −0.25, −0.125, … to −3 stops.
        for s in &steps {
            assert!(*s <= 1e-12 && *s >= -0.5 - 1e-12, "{steps:?}");
        }
        assert!((steps[0] + 0.5).abs() < 1e-9, "{steps:?}");
        assert!(((x / 0.01).log2() + 3.0).abs() < 0.05, "{}", (x / 0.01).log2());
    }

    #[test]
    fn the_model_carries_the_exposure_as_the_sun_rises_and_memory_expires() {
        let mut plan = ExposurePlan::new(ExposureDamping::default());
        let a = scan(1, 10.0);
        let ta = format!("{}/s1/t0", a.key);
        plan.choose(&a, &ta, metering(0.02));
        let b = scan(2, 12.0);
        let tb = format!("{}/s1/t0", b.key);
        let predicted = (model_log2(&a, &ta).unwrap() - model_log2(&b, &tb).unwrap()).exp2() * 0.02;
        let start = plan.metering_start(&b, &tb).unwrap();
        assert!((start / predicted - 1.0).abs() < 1e-9, "{start} vs {predicted}");
        // A brighter sky asks for a shorter exposure.
        assert!(start < 0.02);
        // The measurement equals the plan: the plan is chosen.
        let x = plan.choose(&b, &tb, metering(start));
        assert!((x / start - 1.0).abs() < 1e-9);
        // Ten hours later the memory is gone.
        let mut late = scan(62, 12.0);
        late.key = "sky@2026-06-22#1".into();
        let tl = format!("{}/s1/t0", late.key);
        assert_eq!(plan.metering_start(&late, &tl), None);
        assert_eq!(target_id(&late, &tl), "sky/s1/t0");
    }
}
