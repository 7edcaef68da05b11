//! The station's alert hook on a sky-condition change (`campanile station
//! run --process --on-condition-change CMD`): after each processed scan,
//! when the scan's `sky_condition` differs from the previous scan's of the
//! same day (as recomputed with the day so far; `unknown` before the
//! day's first computed condition), `CMD` runs through `sh -c` with
//!
//! | argument | environment variable | value |
//! | --- | --- | --- |
//! | `$1` | `CAMPANILE_SKY_CONDITION` | the new condition: `clear`, `partly-cloudy`, `cloudy` or `overcast` |
//! | `$2` | `CAMPANILE_PREVIOUS_SKY_CONDITION` | the previous scan's, or `unknown` |
//! | `$3` | `CAMPANILE_SCAN_TIME_UTC` | the scan's time, RFC 3339 UTC |
//! | `$4` | `CAMPANILE_OCCURRENCE` | the scan's occurrence id |
//! | `$5` | `CAMPANILE_CLOUD_COVER` | cloud cover, 0–1 |
//! | `$6` | `CAMPANILE_CLEAR_SKY_INDEX` | the sky's clear-sky index (empty if not computed) |
//! | `$7` | `CAMPANILE_DIRECT_CLEAR_SKY_INDEX` | the sun's (empty if not computed) |
//! | `$8` | `CAMPANILE_CLOUDS_NEAR_SUN_REGION` | `1`, `0`, or empty |
//!
//! A scan whose condition could not be computed changes nothing. The hook
//! never stops the station: a command that cannot start, exits non-zero
//! or outlives [`HOOK_TIMEOUT`] (then it is killed) is logged as a warning.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use campanile_process::sky_series::{Condition, SkySeries, day_of};

/// How long the hook may run before it is killed.
pub const HOOK_TIMEOUT: Duration = Duration::from_secs(30);

/// A change of condition at one scan.
#[derive(Debug, Clone, PartialEq)]
pub struct ConditionChange {
    /// The scan's condition.
    pub new: Condition,
    /// The previous scan's (same day), if computed.
    pub old: Option<Condition>,
    /// The scan's time.
    pub time_utc: chrono::DateTime<chrono::Utc>,
    /// The scan's occurrence id.
    pub occurrence: String,
    /// Cloud cover, 0–1.
    pub cloud_cover: f64,
    /// The sky's clear-sky index.
    pub clear_sky_index: Option<f64>,
    /// The sun's clear-sky index.
    pub direct_clear_sky_index: Option<f64>,
    /// Clouds in the sun's neighbourhood by the sky image.
    pub clouds_near_sun_region: Option<bool>,
}

impl ConditionChange {
    /// The change at `occurrence` in `series`, if its condition differs
    /// from the previous scan's of the same day.
    pub fn at(series: &SkySeries, occurrence: &str) -> Option<ConditionChange> {
        let i = series.scans.iter().position(|s| s.occurrence == occurrence)?;
        let scan = &series.scans[i];
        let cond = series.conditions.get(i)?;
        let new = cond.condition?;
        let day = day_of(scan);
        let old = (0..i)
            .rev()
            .find(|&j| day_of(&series.scans[j]) == day && series.conditions[j].condition.is_some())
            .and_then(|j| series.conditions[j].condition);
        (old != Some(new)).then(|| ConditionChange {
            new,
            old,
            time_utc: scan.time_utc,
            occurrence: scan.occurrence.clone(),
            cloud_cover: cond.cloud_cover.unwrap_or(f64::NAN),
            clear_sky_index: cond.clear_sky_index,
            direct_clear_sky_index: cond.direct_clear_sky_index,
            clouds_near_sun_region: cond.clouds_near_sun_region,
        })
    }

    /// The hook's arguments `$1` … `$8`, with their environment variable names.
    pub fn arguments(&self) -> Vec<(&'static str, String)> {
        let num = |v: Option<f64>| v.filter(|v| v.is_finite()).map_or(String::new(), |v| format!("{v:.4}"));
        vec![
            ("CAMPANILE_SKY_CONDITION", self.new.as_str().to_owned()),
            (
                "CAMPANILE_PREVIOUS_SKY_CONDITION",
                self.old.map_or("unknown", Condition::as_str).to_owned(),
            ),
            (
                "CAMPANILE_SCAN_TIME_UTC",
                self.time_utc.to_rfc3339_opts(chrono::SecondsFormat::Millis, true),
            ),
            ("CAMPANILE_OCCURRENCE", self.occurrence.clone()),
            ("CAMPANILE_CLOUD_COVER", num(Some(self.cloud_cover))),
            ("CAMPANILE_CLEAR_SKY_INDEX", num(self.clear_sky_index)),
            ("CAMPANILE_DIRECT_CLEAR_SKY_INDEX", num(self.direct_clear_sky_index)),
            (
                "CAMPANILE_CLOUDS_NEAR_SUN_REGION",
                self.clouds_near_sun_region
                    .map_or(String::new(), |b| u8::from(b).to_string()),
            ),
        ]
    }
}

/// The command run on a change (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct ConditionHook {
    /// The shell command.
    pub command: String,
    /// How long it may run.
    pub timeout: Duration,
}

impl ConditionHook {
    /// A hook running `command` with [`HOOK_TIMEOUT`].
    pub fn new(command: impl Into<String>) -> ConditionHook {
        ConditionHook {
            command: command.into(),
            timeout: HOOK_TIMEOUT,
        }
    }

    /// Runs the command for `change`; `Err` says why it failed (the
    /// caller logs it and goes on).
    pub fn run(&self, change: &ConditionChange) -> Result<(), String> {
        let args = change.arguments();
        let mut cmd = Command::new("sh");
        cmd.arg("-c")
            .arg(format!("{} \"$@\"", self.command))
            .arg("campanile-condition-hook")
            .args(args.iter().map(|(_, v)| v))
            .stdin(Stdio::null());
        for (k, v) in &args {
            cmd.env(k, v);
        }
        let mut child = cmd
            .spawn()
            .map_err(|e| format!("--on-condition-change {:?}: cannot start: {e}", self.command))?;
        let started = Instant::now();
        loop {
            match child.try_wait() {
                Ok(Some(status)) if status.success() => return Ok(()),
                Ok(Some(status)) => {
                    return Err(format!("--on-condition-change {:?}: {status}", self.command));
                }
                Ok(None) if started.elapsed() > self.timeout => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(format!(
                        "--on-condition-change {:?}: still running after {} s, killed",
                        self.command,
                        self.timeout.as_secs_f64()
                    ));
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(20)),
                Err(e) => return Err(format!("--on-condition-change {:?}: {e}", self.command)),
            }
        }
    }

    /// Runs the hook if `occurrence` changed the condition in `series`;
    /// a failure is logged as a warning, never returned.
    pub fn on_scan(&self, series: &SkySeries, occurrence: &str) -> Option<ConditionChange> {
        let change = ConditionChange::at(series, occurrence)?;
        tracing::info!(
            scan = %occurrence,
            "sky condition {} → {} (cloud cover {:.2})",
            change.old.map_or("unknown", Condition::as_str),
            change.new,
            change.cloud_cover
        );
        if let Err(why) = self.run(&change) {
            tracing::warn!(scan = %occurrence, "{why}");
        }
        Some(change)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_process::sky_series::{MeridianProfile, QualityFlags, ScanProducts, SkyCondition, SkyRegions};

    fn scan(n: usize, date: &str) -> ScanProducts {
        ScanProducts {
            occurrence: format!("sky@{date}#{n}"),
            time_utc: format!("{date}T12:{n:02}:00Z").parse().unwrap(),
            sun_zenith_deg: 40.0,
            sun_azimuth_deg: 180.0,
            sun: None,
            sky: None,
            profile: MeridianProfile {
                signed_zenith_deg: Vec::new(),
                measured: Vec::new(),
                pixels: Vec::new(),
                fitted: None,
            },
            regions: SkyRegions::default(),
            quality: QualityFlags::judge(None, None),
            notes: Vec::new(),
        }
    }

    fn cond(c: Option<Condition>, cover: f64) -> SkyCondition {
        SkyCondition {
            clear_sky_index: c.map(|_| 1.0 + cover),
            direct_clear_sky_index: Some(0.5),
            cloud_cover: c.map(|_| cover),
            clouds_near_sun_region: c.map(|_| cover > 0.5),
            condition: c,
            ..SkyCondition::default()
        }
    }

    /// Clear, clear, (not computed), cloudy on one day; clear on the next.
    fn series() -> SkySeries {
        let d = "2026-06-21";
        SkySeries {
            scans: vec![scan(1, d), scan(2, d), scan(3, d), scan(4, d), scan(1, "2026-06-22")],
            days: Vec::new(),
            conditions: vec![
                cond(Some(Condition::Clear), 0.0),
                cond(Some(Condition::Clear), 0.1),
                cond(None, 0.0),
                cond(Some(Condition::Cloudy), 0.75),
                cond(Some(Condition::Clear), 0.0),
            ],
        }
    }

    #[test]
    fn a_change_is_found_only_where_the_condition_changes() {
        let s = series();
        let first = ConditionChange::at(&s, "sky@2026-06-21#1").unwrap();
        assert_eq!((first.new, first.old), (Condition::Clear, None));
        assert_eq!(ConditionChange::at(&s, "sky@2026-06-21#2"), None);
        assert_eq!(ConditionChange::at(&s, "sky@2026-06-21#3"), None);
        // The scan without a condition is skipped: clear → cloudy.
        let change = ConditionChange::at(&s, "sky@2026-06-21#4").unwrap();
        assert_eq!((change.new, change.old), (Condition::Cloudy, Some(Condition::Clear)));
        // A new day starts from unknown.
        let next = ConditionChange::at(&s, "sky@2026-06-22#1").unwrap();
        assert_eq!(next.old, None);
        assert_eq!(ConditionChange::at(&s, "nothing"), None);
    }

    #[test]
    fn the_hook_gets_its_arguments_and_a_failure_is_reported_not_raised() {
        let tmp = tempfile::tempdir().unwrap();
        let log = tmp.path().join("hook.log");
        let script = tmp.path().join("hook.sh");
        std::fs::write(
            &script,
            format!(
                "printf '%s|' \"$@\" >> '{0}'\necho \"$#|$CAMPANILE_SKY_CONDITION|$CAMPANILE_PREVIOUS_SKY_CONDITION|$CAMPANILE_CLOUD_COVER\" >> '{0}'\n",
                log.display()
            ),
        )
        .unwrap();
        let hook = ConditionHook::new(format!("sh '{}'", script.display()));
        let s = series();
        // No change: the command does not run.
        assert_eq!(hook.on_scan(&s, "sky@2026-06-21#2"), None);
        assert!(!log.exists());
        // A change: it runs once with the eight arguments and the environment.
        assert!(hook.on_scan(&s, "sky@2026-06-21#4").is_some());
        let text = std::fs::read_to_string(&log).unwrap();
        assert_eq!(
            text,
            "cloudy|clear|2026-06-21T12:04:00.000Z|sky@2026-06-21#4|0.7500|1.7500|0.5000|1|8|cloudy|clear|0.7500\n"
        );
        // A failing command and a hanging one: errors with the reason, and on_scan goes on.
        let failing = ConditionHook::new("exit 3;");
        let change = ConditionChange::at(&s, "sky@2026-06-21#4").unwrap();
        let why = failing.run(&change).unwrap_err();
        assert!(why.contains("exit status: 3"), "{why}");
        assert!(failing.on_scan(&s, "sky@2026-06-21#4").is_some());
        let hanging = ConditionHook {
            command: "exec sleep 5;".into(),
            timeout: Duration::from_millis(200),
        };
        let started = Instant::now();
        let why = hanging.run(&change).unwrap_err();
        assert!(why.contains("killed"), "{why}");
        assert!(started.elapsed() < Duration::from_secs(3));
    }
}
