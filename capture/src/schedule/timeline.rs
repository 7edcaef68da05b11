//! The timeline: every occurrence of every session over the plan's days,
//! with its start, the sun at that moment, its shots and its estimated
//! duration, and everything the plan will not cover. A pure function of the
//! plan, the station, the scene and the calendar: no devices, no clock.

use std::fmt;
use std::time::Duration;

use campanile_config::plan::{Plan, Repeat, Step, Trigger};
use campanile_config::station::Station;
use chrono::{DateTime, Days, NaiveDate, TimeDelta, Utc};
use serde::{Deserialize, Serialize};

use super::duration;
use super::error::ScheduleError;
use super::expand::Expansion;
use super::field_of_view::FieldOfView;
use super::scene_geometry::SceneGeometry;
use super::shot::{PlannedAim, PlannedShot, ShotKind};
use super::sun_track::SunTrack;
use super::trigger::{Firing, fire};

/// How far to simulate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TimelineOptions {
    /// Only the first `days` plan days from `start_date` (all of them when
    /// `None`). Occurrences on later days are left out, not reported.
    pub days: Option<u32>,
}

/// One run of a session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Occurrence {
    /// Stable id: `"{session}@{plan day}"`, plus `"#{n}"` (from 1) for the
    /// starts of an `Every` repeat, e.g. `"morning@2026-08-28"`.
    pub key: String,
    /// Index of the session in the plan.
    pub session: usize,
    /// The session's name.
    pub name: String,
    /// Held out from fitting (thesis §5.6).
    pub held_out: bool,
    /// When it starts.
    pub start: DateTime<Utc>,
    /// The sun's apparent `(azimuth_deg, elevation_deg)` at the start.
    pub sun: (f64, f64),
    /// The shots, in the order they are taken.
    pub shots: Vec<PlannedShot>,
    /// The estimated duration (see [`super::duration`]).
    pub estimated_duration: Duration,
}

impl Occurrence {
    /// Frames of `kind`: `(promised, at most)`.
    pub fn count(&self, kind: ShotKind) -> (usize, usize) {
        let of_kind = self.shots.iter().filter(|s| s.kind == kind);
        (of_kind.clone().filter(|s| s.promised).count(), of_kind.count())
    }

    /// Frames the plan promises.
    pub fn frames_promised(&self) -> usize {
        self.shots.iter().filter(|s| s.promised).count()
    }

    /// Frames it may take at most (auto-brackets in full).
    pub fn frames_at_most(&self) -> usize {
        self.shots.len()
    }

    /// The estimated end.
    pub fn estimated_end(&self) -> DateTime<Utc> {
        self.start + TimeDelta::milliseconds(self.estimated_duration.as_millis().min(i64::MAX as u128) as i64)
    }
}

/// Something the plan will not cover.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Uncovered {
    /// A session's trigger does not fire on a plan day, so it does not run.
    TriggerNeverFires {
        /// The session.
        session: String,
        /// The plan day.
        date: NaiveDate,
        /// Why, e.g. "the sun never reaches 80° on 2026-08-28 (highest 64.2°)".
        reason: String,
    },
    /// An occurrence is due before the one before it is estimated to end:
    /// it would start late.
    Overlap {
        /// The occurrence still running.
        earlier: String,
        /// The occurrence that would start late.
        later: String,
        /// By how much, seconds.
        late_by_s: f64,
    },
    /// Shots of a step aim where the head cannot reach; they stay in the
    /// plan (the controller records them as missed).
    Unreachable {
        /// The occurrence.
        occurrence: String,
        /// The step's index.
        step: usize,
        /// The kind of step.
        step_kind: String,
        /// How many of its shots.
        shots: usize,
        /// Out of.
        of: usize,
        /// The first such aim.
        example: String,
    },
    /// A sun shot is due while the sun is below the horizon.
    SunBelowHorizon {
        /// The occurrence.
        occurrence: String,
        /// The step's index.
        step: usize,
        /// The sun's elevation at the occurrence's start, degrees.
        elevation_deg: f64,
    },
    /// An outdoor plan (one with sun shots) never photographs this surface
    /// of its scene while it is sunlit.
    FaceNeverSunlit {
        /// The surface.
        face: String,
    },
}

impl fmt::Display for Uncovered {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Uncovered::TriggerNeverFires { session, reason, .. } => write!(f, "session {session:?}: {reason}"),
            Uncovered::Overlap {
                earlier,
                later,
                late_by_s,
            } => write!(
                f,
                "{later} is due {late_by_s:.0} s before {earlier} is estimated to end: it would start late"
            ),
            Uncovered::Unreachable {
                occurrence,
                step,
                step_kind,
                shots,
                of,
                example,
            } => write!(
                f,
                "{occurrence}, step {step} ({step_kind}): {shots} of {of} shots aim where the head cannot reach (e.g. {example})"
            ),
            Uncovered::SunBelowHorizon {
                occurrence,
                step,
                elevation_deg,
            } => write!(
                f,
                "{occurrence}, step {step} (sun shot): the sun is below the horizon ({elevation_deg:.1}°) at the start"
            ),
            Uncovered::FaceNeverSunlit { face } => write!(
                f,
                "face {face:?} is not sunlit at the start of any occurrence (self-shadowing not considered)"
            ),
        }
    }
}

impl Uncovered {
    /// A warning, not a fault of the plan: every shot is taken as planned,
    /// but the products will lack something. A face never sunlit at the
    /// plan's times (the north face of a tower on a short summer plan)
    /// is one: its sun reflectance is not measured, and the processing
    /// says so and fills it (sky-only environment regions, face ratios);
    /// a plan cannot always avoid it.
    pub fn is_warning(&self) -> bool {
        matches!(self, Uncovered::FaceNeverSunlit { .. })
    }
}

/// The plan simulated forward.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Timeline {
    /// Every occurrence, by start time (then session order).
    pub occurrences: Vec<Occurrence>,
    /// Everything the plan will not cover.
    pub uncovered: Vec<Uncovered>,
}

impl Timeline {
    /// Frames the plan promises, exactly.
    pub fn frames_promised(&self) -> usize {
        self.occurrences.iter().map(Occurrence::frames_promised).sum()
    }

    /// Frames it may take at most (auto-brackets in full).
    pub fn frames_at_most(&self) -> usize {
        self.occurrences.iter().map(Occurrence::frames_at_most).sum()
    }

    /// The total estimated duration.
    pub fn estimated_duration(&self) -> Duration {
        self.occurrences.iter().map(|o| o.estimated_duration).sum()
    }

    /// Whether everything is covered: nothing uncovered but warnings (see
    /// [`Uncovered::is_warning`]).
    pub fn is_covered(&self) -> bool {
        self.uncovered.iter().all(Uncovered::is_warning)
    }
}

/// The days a session runs on, as offsets from the plan's start date.
fn session_days(trigger: &Trigger, repeat: &Repeat) -> std::ops::Range<u64> {
    let first = match trigger {
        Trigger::Clock { day, .. } => u64::from(*day),
        _ => 0,
    };
    let count = match repeat {
        Repeat::Once => 1,
        Repeat::Daily { days } | Repeat::Every { days, .. } => u64::from(*days),
    };
    first..first + count
}

/// Simulates `plan` on `station` (and its `scene`, needed for poses and
/// face triggers): when every session runs, what it shoots and how long it
/// takes, and what will not be covered. Deterministic; reads no clock.
///
/// Day `d` of the plan is `start_date + d`; see [`trigger`](super::trigger)
/// for when each kind of trigger fires on a day, and
/// [`expand`](super::expand) for the shots of each step. Repeats:
/// `Once` runs on day 0 (plus a `Clock` trigger's `day`); `Daily { days }`
/// on `days` consecutive days; `Every { interval_min, while_sun_above_deg,
/// days }` on each of `days` days from the trigger every `interval_min`,
/// while the sun at a start is at or above `while_sun_above_deg` and for at
/// most 24 h after the day's trigger.
pub fn timeline(
    plan: &Plan,
    station: &Station,
    scene: Option<&SceneGeometry>,
    options: &TimelineOptions,
) -> Result<Timeline, ScheduleError> {
    let track = SunTrack::new(&station.site);
    let fov = FieldOfView::of_camera(&station.camera);
    let mut occurrences = Vec::new();
    let mut uncovered = Vec::new();
    for (index, session) in plan.sessions.iter().enumerate() {
        let face = match &session.trigger {
            Trigger::Face { face, .. } => {
                Some(
                    scene
                        .and_then(|g| g.surface(face))
                        .ok_or_else(|| ScheduleError::Unknown {
                            session: session.name.clone(),
                            what: "surface",
                            name: face.clone(),
                            place: match scene {
                                Some(g) => format!("a surface of scene {:?}", g.scene.name),
                                None => "available: the plan has no scene".to_owned(),
                            },
                        })?,
                )
            }
            _ => None,
        };
        let expansion = Expansion {
            station,
            scene,
            fov,
            session: &session.name,
        };
        for day in session_days(&session.trigger, &session.repeat) {
            if options.days.is_some_and(|n| day >= u64::from(n)) {
                break;
            }
            let date = plan
                .start_date
                .checked_add_days(Days::new(day))
                .ok_or(ScheduleError::Date {
                    date: plan.start_date,
                    days: day,
                })?;
            let first = match fire(&session.trigger, date, &track, face)? {
                Firing::At(t) => t,
                Firing::Never(reason) => {
                    uncovered.push(Uncovered::TriggerNeverFires {
                        session: session.name.clone(),
                        date,
                        reason,
                    });
                    continue;
                }
            };
            let starts: Vec<(String, DateTime<Utc>)> = match &session.repeat {
                Repeat::Once | Repeat::Daily { .. } => vec![(format!("{}@{date}", session.name), first)],
                Repeat::Every {
                    interval_min,
                    while_sun_above_deg,
                    ..
                } => {
                    let step = TimeDelta::milliseconds((interval_min * 60_000.0).round().max(1.0) as i64);
                    let mut starts = Vec::new();
                    let mut t = first;
                    while t < first + TimeDelta::hours(24) {
                        if let Some(limit) = while_sun_above_deg {
                            let el = track.position(t)?.elevation_rad().to_degrees();
                            if el < *limit {
                                if starts.is_empty() {
                                    uncovered.push(Uncovered::TriggerNeverFires {
                                        session: session.name.clone(),
                                        date,
                                        reason: format!(
                                            "the sun is at {el:.1}°, below {limit}°, when the trigger fires on {date} ({})",
                                            first.format("%H:%M:%S UTC")
                                        ),
                                    });
                                }
                                break;
                            }
                        }
                        starts.push((format!("{}@{date}#{}", session.name, starts.len() + 1), t));
                        t += step;
                    }
                    starts
                }
            };
            for (key, start) in starts {
                let p = track.position(start)?;
                let sun = (p.azimuth_rad.to_degrees(), p.elevation_rad().to_degrees());
                let mut shots = Vec::new();
                for (k, step) in session.steps.iter().enumerate() {
                    let step_shots = expansion.step_shots(&key, k, step, sun)?;
                    check_step(&key, k, step, &step_shots, station, sun, &mut uncovered);
                    shots.extend(step_shots);
                }
                let estimated_duration = duration::estimate(&shots, station, sun);
                occurrences.push(Occurrence {
                    key,
                    session: index,
                    name: session.name.clone(),
                    held_out: session.held_out,
                    start,
                    sun,
                    shots,
                    estimated_duration,
                });
            }
        }
    }
    occurrences.sort_by(|a, b| a.start.cmp(&b.start).then(a.session.cmp(&b.session)));
    let mut running: Option<(&Occurrence, DateTime<Utc>)> = None;
    for o in &occurrences {
        if let Some((earlier, end)) = running
            && o.start < end
        {
            uncovered.push(Uncovered::Overlap {
                earlier: earlier.key.clone(),
                later: o.key.clone(),
                late_by_s: (end - o.start).num_milliseconds() as f64 / 1000.0,
            });
        }
        let end = o.estimated_end();
        if running.is_none_or(|(_, e)| end > e) {
            running = Some((o, end));
        }
    }
    let outdoor = plan
        .sessions
        .iter()
        .any(|s| s.steps.iter().any(|st| matches!(st, Step::SunShot { .. })));
    if let Some(g) = scene
        && outdoor
        && !occurrences.is_empty()
    {
        for surface in g.surfaces.iter().filter(|s| s.normal.is_some()) {
            let lit = occurrences.iter().any(|o| {
                let d = super::tiling::direction(o.sun.0.to_radians(), o.sun.1.to_radians());
                surface.is_sunlit(d, o.sun.1.to_radians())
            });
            if !lit {
                uncovered.push(Uncovered::FaceNeverSunlit {
                    face: surface.name.clone(),
                });
            }
        }
    }
    Ok(Timeline { occurrences, uncovered })
}

/// Reports a step's shots the head cannot reach, and sun shots with the sun down.
fn check_step(
    key: &str,
    index: usize,
    step: &Step,
    shots: &[PlannedShot],
    station: &Station,
    sun: (f64, f64),
    uncovered: &mut Vec<Uncovered>,
) {
    if matches!(step, Step::SunShot { .. }) && sun.1 < 0.0 {
        uncovered.push(Uncovered::SunBelowHorizon {
            occurrence: key.to_owned(),
            step: index,
            elevation_deg: sun.1,
        });
        return;
    }
    let unreachable: Vec<&PlannedShot> = shots
        .iter()
        .filter(|s| s.aim.head_angles(&station.head, sun).is_none())
        .collect();
    if let Some(first) = unreachable.first() {
        let example = match first.aim {
            PlannedAim::Sun => format!("the sun at azimuth {:.1}°, elevation {:.1}°", sun.0, sun.1),
            ref aim => aim.describe(),
        };
        uncovered.push(Uncovered::Unreachable {
            occurrence: key.to_owned(),
            step: index,
            step_kind: step.kind().to_owned(),
            shots: unreachable.len(),
            of: shots.len(),
            example,
        });
    }
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;
    use crate::schedule::tiling::{band_rows, ring_tiles, sky_rows};
    use campanile_config::Document;
    use campanile_process::sun::{SolarDay, solar_day};

    fn examples() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
    }

    fn station() -> Station {
        campanile_config::load_station(&examples().join("sim-station.ron"))
            .expect("valid example station")
            .value
    }

    fn example_plan(name: &str) -> (Plan, Option<SceneGeometry>) {
        let loaded = campanile_config::load_plan(&examples().join(name)).expect("valid example plan");
        let scene = loaded
            .scene
            .map(|s| SceneGeometry::load(&s.value, &s.source.base_dir()).expect("OBJ"));
        (loaded.plan.value, scene)
    }

    /// A plan from RON text (no scene).
    fn plan(text: &str) -> Plan {
        match campanile_config::load_text(Path::new("test-plan.ron"), text.to_owned()) {
            Ok(Document::Plan(p)) => p.plan.value,
            Ok(_) => panic!("not a plan"),
            Err(e) => panic!("{e}"),
        }
    }

    fn elevation_deg(station: &Station, t: DateTime<Utc>) -> f64 {
        SunTrack::new(&station.site)
            .position(t)
            .expect("ok")
            .elevation_rad()
            .to_degrees()
    }

    fn azimuth_deg(station: &Station, t: DateTime<Utc>) -> f64 {
        SunTrack::new(&station.site)
            .position(t)
            .expect("ok")
            .azimuth_rad
            .to_degrees()
    }

    fn by_name<'a>(t: &'a Timeline, name: &str) -> &'a Occurrence {
        t.occurrences.iter().find(|o| o.name == name).expect("occurrence")
    }

    /// examples/campanile-day.ron on the example station: the solar
    /// triggers fire within 1 s of their crossings on the ephemeris, the
    /// azimuth-180° trigger within 1 s of SPA's transit from `solar_day`,
    /// and the clock trigger at exactly 20:30:00 UTC.
    #[test]
    fn the_example_days_triggers_agree_with_the_ephemeris() {
        let station = station();
        let (plan, scene) = example_plan("campanile-day.ron");
        let t = timeline(&plan, &station, scene.as_ref(), &TimelineOptions::default()).expect("timeline");
        let names: Vec<&str> = t.occurrences.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["morning", "noon", "held-out", "afternoon", "evening"]);
        let s = TimeDelta::seconds(1);
        let morning = by_name(&t, "morning").start;
        assert!(elevation_deg(&station, morning - s) < 25.0 && elevation_deg(&station, morning + s) > 25.0);
        let evening = by_name(&t, "evening").start;
        assert!(elevation_deg(&station, evening - s) > 12.0 && elevation_deg(&station, evening + s) < 12.0);
        let afternoon = by_name(&t, "afternoon").start;
        assert!(azimuth_deg(&station, afternoon - s) < 240.0 && azimuth_deg(&station, afternoon + s) > 240.0);
        let noon = by_name(&t, "noon").start;
        assert!(azimuth_deg(&station, noon - s) < 180.0 && azimuth_deg(&station, noon + s) > 180.0);
        // Pacific daylight time, the site's zone on this date.
        let zone = chrono::FixedOffset::west_opt(7 * 3600).expect("offset");
        let observer = campanile_process::sun::Observer::from_degrees(
            station.site.latitude_deg,
            station.site.longitude_deg,
            station.site.elevation_m,
            station.site.pressure_mbar,
            station.site.temperature_c,
        );
        let SolarDay::Normal {
            transit: Some(transit), ..
        } = solar_day(plan.start_date, &zone, &observer, station.site.delta_t_s).expect("ok")
        else {
            panic!("a normal day")
        };
        let gap = (noon - transit).num_milliseconds().abs();
        assert!(gap <= 1000, "noon {noon} vs transit {transit}");
        assert_eq!(by_name(&t, "held-out").start.to_rfc3339(), "2026-08-28T20:30:00+00:00");
        assert!(t.occurrences.iter().all(|o| o.key == format!("{}@2026-08-28", o.name)));
    }

    /// The frame counts of examples/campanile-day.ron, by hand from the
    /// expansion rules: sun 1 centering + 3; sky tiles × 3 plus one frame
    /// per aureole tile (rings around that occurrence's sun); environment
    /// tiles × 3; 4 views × 5 (the held-out time: 3 × 5 and a 4-exposure
    /// bracket); the morning's 12-exposure calibration bracket. Every frame
    /// is promised (no auto-brackets).
    #[test]
    fn the_example_days_frame_counts_follow_the_rules() {
        let station = station();
        let (plan, scene) = example_plan("campanile-day.ron");
        let t = timeline(&plan, &station, scene.as_ref(), &TimelineOptions::default()).expect("timeline");
        let fov = FieldOfView::of_camera(&station.camera);
        let sky: usize = sky_rows(&fov, 0.2, 0.0).expect("tiles").iter().map(Vec::len).sum();
        let env: usize = band_rows(&fov, 0.2, -30.0, 10.0)
            .expect("tiles")
            .iter()
            .map(Vec::len)
            .sum();
        let mut total = 0;
        for o in &t.occurrences {
            let bands: usize = [5.0, 10.0]
                .iter()
                .map(|&r| ring_tiles(&fov, 0.2, o.sun.0, o.sun.1, r).len())
                .sum();
            let want = if o.name == "held-out" {
                (1 + 3) + sky * 3 + 3 * 5 + 4
            } else {
                let calibration = if o.name == "morning" { 12 } else { 0 };
                (1 + 3) + sky * 3 + bands + env * 3 + 4 * 5 + calibration
            };
            assert_eq!(o.frames_promised(), want, "{}", o.key);
            assert_eq!(o.frames_at_most(), want, "{}", o.key);
            assert_eq!(o.count(ShotKind::Centering), (1, 1));
            total += want;
        }
        assert_eq!(t.frames_promised(), total);
        // Keys are unique: the journal relies on it.
        let mut keys: Vec<&str> = t
            .occurrences
            .iter()
            .flat_map(|o| o.shots.iter().map(|s| s.key.as_str()))
            .collect();
        let n = keys.len();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), n);
        assert!(t.is_covered(), "{:#?}", t.uncovered);
    }

    /// examples/room-lights.ron: 4 poses × (3 lights alone + all on) × 3
    /// frames = 48, then an auto-bracket: 1 metering shot and 1..=7 frames.
    /// Light levels follow the station's channel order.
    #[test]
    fn the_room_light_sequence_counts_and_levels() {
        let station = station();
        let (plan, scene) = example_plan("room-lights.ron");
        let t = timeline(&plan, &station, scene.as_ref(), &TimelineOptions::default()).expect("timeline");
        let o = &t.occurrences[0];
        assert_eq!(o.frames_promised(), 48 + 1 + 1);
        assert_eq!(o.frames_at_most(), 48 + 1 + 7);
        assert_eq!(o.count(ShotKind::Metering), (1, 1));
        assert_eq!(o.count(ShotKind::Data), (49, 55));
        let levels: Vec<_> = o.shots.iter().step_by(3).take(4).map(|s| s.lights.clone()).collect();
        assert_eq!(
            levels,
            [
                Some(vec![1.0, 0.0, 0.0]),
                Some(vec![0.0, 1.0, 0.0]),
                Some(vec![0.0, 0.0, 1.0]),
                Some(vec![1.0, 1.0, 1.0])
            ]
        );
        assert_eq!(o.shots[0].key, "lights@2026-08-29/s0/t0/f0");
        assert_eq!(o.shots[47].key, "lights@2026-08-29/s0/t15/f2");
    }

    /// `Every` 60 min while the sun is at or above 20°: the starts are
    /// hourly from the rising crossing, each with the sun at ≥ 20°, and the
    /// hour after the last has it below (checked on the ephemeris).
    #[test]
    fn every_repeats_stop_when_the_sun_drops_below_the_threshold() {
        let station = station();
        let plan = plan(
            r#"Plan(name: "hourly", start_date: "2026-08-28", sessions: [(
                name: "sky", trigger: SolarElevation(elevation_deg: 20.0, motion: Rising),
                repeat: Every(interval_min: 60.0, while_sun_above_deg: 20.0, days: 1),
                steps: [SunShot(filters: ["nd4", "nd5"])])])"#,
        );
        let t = timeline(&plan, &station, None, &TimelineOptions::default()).expect("timeline");
        let first = t.occurrences[0].start;
        let mut want = 0;
        while elevation_deg(&station, first + TimeDelta::hours(want)) >= 20.0 {
            want += 1;
        }
        assert!(want > 5, "a late-August day at 37.9°N has hours above 20°");
        assert_eq!(t.occurrences.len(), want as usize);
        for (k, o) in t.occurrences.iter().enumerate() {
            assert_eq!(o.start, first + TimeDelta::hours(k as i64));
            assert_eq!(o.key, format!("sky@2026-08-28#{}", k + 1));
            assert!(o.sun.1 >= 20.0);
        }
        let last = t.occurrences.last().expect("some").start;
        assert!(elevation_deg(&station, last + TimeDelta::hours(1)) < 20.0);
    }

    /// A trigger that never fires is reported with the session and the day's highest sun.
    #[test]
    fn a_trigger_that_never_fires_is_reported() {
        let station = station();
        let plan = plan(
            r#"Plan(name: "high", start_date: "2026-08-28", sessions: [(
                name: "overhead", trigger: SolarElevation(elevation_deg: 80.0, motion: Rising),
                repeat: Daily(days: 2), steps: [SunShot(filters: ["nd5"])])])"#,
        );
        let t = timeline(&plan, &station, None, &TimelineOptions::default()).expect("timeline");
        assert!(t.occurrences.is_empty());
        assert_eq!(t.uncovered.len(), 2);
        let text = t.uncovered[0].to_string();
        assert!(
            text.starts_with("session \"overhead\": the sun never reaches 80° on 2026-08-28 (highest 61."),
            "{text}"
        );
        assert!(t.uncovered[1].to_string().contains("on 2026-08-29"));
        // --days 1 looks at the first day only.
        let one = timeline(&plan, &station, None, &TimelineOptions { days: Some(1) }).expect("timeline");
        assert_eq!(one.uncovered.len(), 1);
    }

    /// Two sessions 20 s apart, the first a full sky scan (about 40 s of
    /// slews and brackets): the second would start late, and says by how much.
    #[test]
    fn overlapping_occurrences_are_reported() {
        let station = station();
        let plan = plan(
            r#"Plan(name: "tight", start_date: "2026-08-28", sessions: [
                (name: "a", trigger: Clock(time: "20:00:00"), steps: [SkyScan(min_elevation_deg: 0.0, overlap: 0.2)]),
                (name: "b", trigger: Clock(time: "20:00:20"), steps: [SunShot(filters: ["nd5"])]),
            ])"#,
        );
        let t = timeline(&plan, &station, None, &TimelineOptions::default()).expect("timeline");
        let a = &t.occurrences[0];
        let late = a.estimated_duration.as_secs_f64() - 20.0;
        assert!(late > 0.0, "the scan takes {:?}", a.estimated_duration);
        assert_eq!(
            t.uncovered,
            [Uncovered::Overlap {
                earlier: "a@2026-08-28".into(),
                later: "b@2026-08-28".into(),
                late_by_s: (late * 1000.0).round() / 1000.0,
            }]
        );
    }

    /// A head that tilts down only to −10° cannot take the environment
    /// rows centred below it: those tiles stay in the plan and are reported.
    #[test]
    fn tiles_beyond_the_heads_limits_are_reported() {
        let mut station = station();
        station.head.limits.tilt_min_deg = -10.0;
        let plan = plan(
            r#"Plan(name: "env", start_date: "2026-08-28", sessions: [
                (name: "env", trigger: Clock(time: "20:00:00"),
                 steps: [EnvironmentTiles(min_elevation_deg: -30.0, max_elevation_deg: 10.0, overlap: 0.2)])])"#,
        );
        let t = timeline(&plan, &station, None, &TimelineOptions::default()).expect("timeline");
        let fov = FieldOfView::of_camera(&station.camera);
        let rows = band_rows(&fov, 0.2, -30.0, 10.0).expect("tiles");
        let low: usize = rows.iter().filter(|r| r[0].elevation_deg < -10.0).map(Vec::len).sum();
        assert!(low > 0);
        let Some(Uncovered::Unreachable { shots, of, .. }) = t.uncovered.first() else {
            panic!("{:?}", t.uncovered)
        };
        assert_eq!((*shots, *of), (low * 3, t.occurrences[0].shots.len()));
    }

    /// Daily repeats run once per plan day, about a day apart.
    #[test]
    fn daily_repeats_run_each_day() {
        let station = station();
        let plan = plan(
            r#"Plan(name: "daily", start_date: "2026-08-28", sessions: [(
                name: "m", trigger: SolarElevation(elevation_deg: 25.0, motion: Rising),
                repeat: Daily(days: 3), steps: [SunShot(filters: ["nd5"])])])"#,
        );
        let t = timeline(&plan, &station, None, &TimelineOptions::default()).expect("timeline");
        let keys: Vec<&str> = t.occurrences.iter().map(|o| o.key.as_str()).collect();
        assert_eq!(keys, ["m@2026-08-28", "m@2026-08-29", "m@2026-08-30"]);
        for w in t.occurrences.windows(2) {
            let gap = (w[1].start - w[0].start).num_seconds() - 86_400;
            assert!(gap.abs() < 300, "{gap} s");
        }
    }
}
