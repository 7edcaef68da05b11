//! Plans: sessions, what starts them, how often they repeat, the steps they
//! take, and what each step does when a device fails (policy as data).

use std::path::PathBuf;

use chrono::{NaiveDate, NaiveTime};
use serde::{Deserialize, Serialize};

use crate::scene::Scene;
use crate::station::Station;
use crate::validate::{Validate, Validator, fmt_f64};

/// Rising or setting sun.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum SunMotion {
    /// Morning crossing.
    Rising,
    /// Evening crossing.
    Setting,
}

/// Sunlit or shadowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum FaceState {
    /// Direct sun reaches the face.
    Sunlit,
    /// The face is in shadow.
    Shadowed,
}

/// What starts a session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Trigger {
    /// A UTC time of day on the plan's `start_date` plus `day` days, e.g.
    /// `Clock(time: "00:30:00", day: 1)`. (Times in files are UTC; in the
    /// Americas a local afternoon falls on the next UTC day.)
    Clock {
        /// UTC time of day.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::time()"))]
        time: NaiveTime,
        /// Days after `start_date`, 0–3660.
        #[serde(default)]
        day: u32,
    },
    /// The sun crossing an elevation, e.g. `SolarElevation(elevation_deg: 10.0, motion: Rising)`.
    SolarElevation {
        /// Elevation in degrees, in [-18, 90).
        elevation_deg: f64,
        /// Which crossing.
        motion: SunMotion,
    },
    /// The sun crossing an azimuth (from north through east), in [0, 360).
    SolarAzimuth {
        /// Azimuth in degrees.
        azimuth_deg: f64,
    },
    /// A named scene surface becoming sunlit or shadowed.
    Face {
        /// A surface of the plan's scene.
        face: String,
        /// The state it changes into.
        becomes: FaceState,
    },
}

/// How often a session repeats.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Repeat {
    /// Once, on the plan's start date.
    Once,
    /// Every day at the trigger, for `days` days (1–3660).
    Daily {
        /// Number of days.
        days: u32,
    },
    /// From the trigger, every `interval_min` minutes (in (0, 1440]), for as
    /// long as the sun stays above `while_sun_above_deg` (if given), on each
    /// of `days` days.
    Every {
        /// Minutes between starts.
        interval_min: f64,
        /// Stop for the day when the sun goes below this elevation, degrees.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        while_sun_above_deg: Option<f64>,
        /// Number of days.
        days: u32,
    },
}

/// What a step does after its retries are spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Fallback {
    /// Record the failed shot as missed and go on with the step's next shot.
    Continue,
    /// Record the rest of the step as missed and go on with the next step.
    #[default]
    Skip,
    /// Stop the session.
    Abort,
}

/// Error policy of a step: retry N times, then fall back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct ErrorPolicy {
    /// Retries of a failed device call, 0–100.
    pub retries: u32,
    /// What to do after the retries.
    pub then: Fallback,
}

impl Default for ErrorPolicy {
    fn default() -> Self {
        ErrorPolicy {
            retries: 2,
            then: Fallback::Skip,
        }
    }
}

/// Where the head points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Aim {
    /// Head angles, degrees.
    PanTilt {
        /// Pan in the head's degrees.
        pan_deg: f64,
        /// Tilt in the head's degrees.
        tilt_deg: f64,
    },
    /// A camera pose named in the scene.
    Pose(String),
    /// The sun, from the ephemeris.
    Sun,
}

/// One step of a session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Step {
    /// A fixed exposure bracket.
    Bracket {
        /// Where to aim.
        aim: Aim,
        /// Exposure times in seconds, each within the camera's limits.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        exposures_s: Vec<f64>,
        /// ND filter slot, if any.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        filter: Option<String>,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Meter, then take the fewest exposures that cover the dynamic range.
    AutoBracket {
        /// Where to aim.
        aim: Aim,
        /// At most this many frames (1–15).
        max_frames: u32,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Filtered shots of the sun (thesis §5.3.1).
    SunShot {
        /// Candidate ND slots, the densest last; the controller picks the
        /// one that leaves the disc unsaturated.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        filters: Vec<String>,
        /// Take three frames and check their agreement.
        #[serde(default)]
        triplet: bool,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Tiles over the sky hemisphere (thesis §5.3.2).
    SkyScan {
        /// Lowest elevation covered, degrees, in [-10, 90).
        min_elevation_deg: f64,
        /// Fractional overlap between tiles, in [0, 0.9].
        overlap: f64,
        /// Radii of aureole bands around the sun taken at faster shutters, degrees, each in (0, 45].
        #[serde(default)]
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        aureole_bands_deg: Vec<f64>,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Environment tiles below and around the horizon (thesis §5.3.3).
    EnvironmentTiles {
        /// Lowest elevation, degrees, in [-90, 90).
        min_elevation_deg: f64,
        /// Highest elevation, degrees, above `min_elevation_deg`.
        max_elevation_deg: f64,
        /// Fractional overlap between tiles, in [0, 0.9].
        overlap: f64,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Brackets of the target from named poses.
    Views {
        /// Camera poses of the scene.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        poses: Vec<String>,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
    /// Each light alone, then all on (thesis §4.7.2), from named poses.
    LightSequence {
        /// Lights of the station, in order.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        lights: Vec<String>,
        /// Finish with every listed light on.
        #[serde(default)]
        all_on: bool,
        /// Camera poses of the scene.
        #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
        poses: Vec<String>,
        /// Error policy.
        #[serde(default)]
        on_error: ErrorPolicy,
    },
}

impl Step {
    /// The step's error policy.
    pub fn on_error(&self) -> ErrorPolicy {
        match self {
            Step::Bracket { on_error, .. }
            | Step::AutoBracket { on_error, .. }
            | Step::SunShot { on_error, .. }
            | Step::SkyScan { on_error, .. }
            | Step::EnvironmentTiles { on_error, .. }
            | Step::Views { on_error, .. }
            | Step::LightSequence { on_error, .. } => *on_error,
        }
    }

    /// A short name of the kind of step.
    pub fn kind(&self) -> &'static str {
        match self {
            Step::Bracket { .. } => "bracket",
            Step::AutoBracket { .. } => "auto-bracket",
            Step::SunShot { .. } => "sun shot",
            Step::SkyScan { .. } => "sky scan",
            Step::EnvironmentTiles { .. } => "environment tiles",
            Step::Views { .. } => "views",
            Step::LightSequence { .. } => "light sequence",
        }
    }
}

/// A session: a trigger, a repeat rule and steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Session {
    /// Name, unique in the plan.
    pub name: String,
    /// What starts it.
    pub trigger: Trigger,
    /// How often.
    #[serde(default = "default_repeat")]
    pub repeat: Repeat,
    /// Held out from fitting, kept to compare re-renders against (thesis §5.6).
    #[serde(default)]
    pub held_out: bool,
    /// The steps, in order.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub steps: Vec<Step>,
}

fn default_repeat() -> Repeat {
    Repeat::Once
}

/// A plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Name for logs and reports.
    pub name: String,
    /// First day (UTC date) of the plan.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::date()"))]
    pub start_date: NaiveDate,
    /// The scene the plan photographs, relative to this file; needed for
    /// named poses and face triggers.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::opt_path()"))]
    pub scene: Option<PathBuf>,
    /// The sessions.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub sessions: Vec<Session>,
    /// Quality gates for this plan's products, where they differ from the
    /// defaults (`crate::quality`); a command's `--thresholds` file wins.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(value = "None"))]
    pub quality: Option<crate::quality::Quality>,
}

impl Validate for Plan {
    fn validate(&self, v: &mut Validator) {
        v.non_empty("name", &self.name);
        if self.sessions.is_empty() {
            v.invalid("sessions", "an empty list".into(), "at least one session");
        }
        v.unique_names("sessions", self.sessions.iter().map(|s| s.name.as_str()));
        if let Some(q) = &self.quality {
            v.at("quality", |v| q.validate(v));
        }
        v.at("sessions", |v| {
            for (i, s) in self.sessions.iter().enumerate() {
                v.at(i, |v| validate_session(s, v));
            }
        });
    }
}

fn validate_session(s: &Session, v: &mut Validator) {
    v.non_empty("name", &s.name);
    v.at("trigger", |v| match &s.trigger {
        Trigger::Clock { day, .. } => v.range_u("day", (*day).into(), 0, 3660, "a day offset"),
        Trigger::SolarElevation { elevation_deg, .. } => v.range_open_high(
            "elevation_deg",
            *elevation_deg,
            -18.0,
            90.0,
            "a solar elevation in degrees",
        ),
        Trigger::SolarAzimuth { azimuth_deg } => {
            v.range_open_high("azimuth_deg", *azimuth_deg, 0.0, 360.0, "a solar azimuth in degrees")
        }
        Trigger::Face { face, .. } => v.non_empty("face", face),
    });
    v.at("repeat", |v| match &s.repeat {
        Repeat::Once => {}
        Repeat::Daily { days } => v.range_u("days", (*days).into(), 1, 3660, "a number of days"),
        Repeat::Every {
            interval_min,
            while_sun_above_deg,
            days,
        } => {
            v.range_open_low("interval_min", *interval_min, 0.0, 1440.0, "an interval in minutes");
            if let Some(e) = while_sun_above_deg {
                v.range("while_sun_above_deg", *e, -18.0, 90.0, "a solar elevation in degrees");
            }
            v.range_u("days", (*days).into(), 1, 3660, "a number of days");
        }
    });
    if s.steps.is_empty() {
        v.invalid("steps", "an empty list".into(), "at least one step");
    }
    v.at("steps", |v| {
        for (i, step) in s.steps.iter().enumerate() {
            v.at(i, |v| validate_step(step, v));
        }
    });
}

fn validate_step(step: &Step, v: &mut Validator) {
    v.at("on_error", |v| {
        v.range_u("retries", step.on_error().retries.into(), 0, 100, "a number of retries")
    });
    match step {
        Step::Bracket { exposures_s, .. } => {
            if exposures_s.is_empty() {
                v.invalid("exposures_s", "an empty list".into(), "at least one exposure time");
            }
            v.at("exposures_s", |v| {
                for (k, &t) in exposures_s.iter().enumerate() {
                    v.range_open_low(k, t, 0.0, 3600.0, "an exposure time in seconds");
                    if exposures_s[..k].contains(&t) {
                        v.invalid(k, fmt_f64(t), "an exposure time not already in the bracket");
                    }
                }
            });
        }
        Step::AutoBracket { max_frames, .. } => {
            v.range_u("max_frames", (*max_frames).into(), 1, 15, "a number of frames")
        }
        Step::SunShot { filters, .. } => {
            if filters.is_empty() {
                v.invalid("filters", "an empty list".into(), "at least one ND filter slot name");
            }
        }
        Step::SkyScan {
            min_elevation_deg,
            overlap,
            aureole_bands_deg,
            ..
        } => {
            v.range_open_high(
                "min_elevation_deg",
                *min_elevation_deg,
                -10.0,
                90.0,
                "an elevation in degrees",
            );
            v.range("overlap", *overlap, 0.0, 0.9, "a fractional tile overlap");
            v.at("aureole_bands_deg", |v| {
                for (k, &r) in aureole_bands_deg.iter().enumerate() {
                    v.range_open_low(k, r, 0.0, 45.0, "an aureole band radius in degrees");
                }
            });
        }
        Step::EnvironmentTiles {
            min_elevation_deg,
            max_elevation_deg,
            overlap,
            ..
        } => {
            v.range_open_high(
                "min_elevation_deg",
                *min_elevation_deg,
                -90.0,
                90.0,
                "an elevation in degrees",
            );
            v.range_open_low(
                "max_elevation_deg",
                *max_elevation_deg,
                *min_elevation_deg,
                90.0,
                "an elevation in degrees (above min_elevation_deg)",
            );
            v.range("overlap", *overlap, 0.0, 0.9, "a fractional tile overlap");
        }
        Step::Views { poses, .. } => {
            if poses.is_empty() {
                v.invalid("poses", "an empty list".into(), "at least one camera pose name");
            }
        }
        Step::LightSequence { lights, poses, .. } => {
            if lights.is_empty() {
                v.invalid("lights", "an empty list".into(), "at least one light name");
            }
            if poses.is_empty() {
                v.invalid("poses", "an empty list".into(), "at least one camera pose name");
            }
        }
    }
}

/// Checks the plan's references to its scene: named poses and faces.
pub fn check_against_scene(plan: &Plan, scene: Option<&Scene>, v: &mut Validator) {
    let pose_ok = |name: &str| scene.is_some_and(|s| s.pose(name).is_some());
    let expected_pose = || match scene {
        Some(s) => format!(
            "a camera pose of scene {:?} (it has: {})",
            s.name,
            s.poses.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
        ),
        None => "a camera pose, which needs the plan's `scene` to be set".to_owned(),
    };
    v.at("sessions", |v| {
        for (i, s) in plan.sessions.iter().enumerate() {
            v.at(i, |v| {
                if let Trigger::Face { face, .. } = &s.trigger
                    && scene.is_none_or(|sc| sc.surface(face).is_none())
                {
                    let expected = match scene {
                        Some(sc) => format!(
                            "a surface of scene {:?} (it has: {})",
                            sc.name,
                            sc.surfaces
                                .iter()
                                .map(|p| p.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                        None => "a surface, which needs the plan's `scene` to be set".to_owned(),
                    };
                    v.at("trigger", |v| v.invalid("face", format!("{face:?}"), &expected));
                }
                v.at("steps", |v| {
                    for (k, step) in s.steps.iter().enumerate() {
                        v.at(k, |v| match step {
                            Step::Bracket { aim: Aim::Pose(p), .. } | Step::AutoBracket { aim: Aim::Pose(p), .. }
                                if !pose_ok(p) =>
                            {
                                v.invalid("aim", format!("Pose({p:?})"), &expected_pose());
                            }
                            Step::Views { poses, .. } | Step::LightSequence { poses, .. } => v.at("poses", |v| {
                                for (j, p) in poses.iter().enumerate() {
                                    if !pose_ok(p) {
                                        v.invalid(j, format!("{p:?}"), &expected_pose());
                                    }
                                }
                            }),
                            _ => {}
                        });
                    }
                });
            });
        }
    });
}

/// Checks that the plan can run on `station`: filters and lights exist,
/// exposures are within the camera's limits, and every head pose is
/// reachable.
pub fn check_against_station(plan: &Plan, scene: Option<&Scene>, station: &Station, v: &mut Validator) {
    let slot_names = || match &station.filter_wheel {
        Some(w) => format!(
            "a filter slot of station {:?} (it has: {})",
            station.name,
            w.slots.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
        ),
        None => format!("a filter slot, but station {:?} has no filter wheel", station.name),
    };
    let has_slot = |name: &str| {
        station
            .filter_wheel
            .as_ref()
            .is_some_and(|w| w.position_of(name).is_some())
    };
    let limits = station.head.limits;
    let limits_text = format!(
        "a pose within the head's limits of station {:?}: pan [{}, {}]°, tilt [{}, {}]°",
        station.name,
        fmt_f64(limits.pan_min_deg),
        fmt_f64(limits.pan_max_deg),
        fmt_f64(limits.tilt_min_deg),
        fmt_f64(limits.tilt_max_deg)
    );
    let check_pose = |v: &mut Validator, field: Option<usize>, name: &str| {
        if let Some(p) = scene.and_then(|s| s.pose(name))
            && station.head.reach(p.azimuth_deg, p.elevation_deg).is_none()
        {
            let value = format!(
                "{name:?} (azimuth {}°, elevation {}°: pan {}°, tilt {}° on this head)",
                fmt_f64(p.azimuth_deg),
                fmt_f64(p.elevation_deg),
                fmt_f64(p.azimuth_deg - station.head.mount.pan_zero_azimuth_deg),
                fmt_f64(p.elevation_deg + station.head.mount.tilt_zero_deg)
            );
            match field {
                Some(j) => v.invalid(j, value, &limits_text),
                None => v.invalid_here(value, &limits_text),
            }
        }
    };
    let cam = station.camera.exposure;
    v.at("sessions", |v| {
        for (i, s) in plan.sessions.iter().enumerate() {
            v.at(i, |v| {
                v.at("steps", |v| {
                    for (k, step) in s.steps.iter().enumerate() {
                        v.at(k, |v| {
                            match step {
                                Step::Bracket { aim, .. } | Step::AutoBracket { aim, .. } => {
                                    v.at("aim", |v| match aim {
                                        Aim::PanTilt { pan_deg, tilt_deg } => {
                                            if !limits.contains(*pan_deg, *tilt_deg) {
                                                let field =
                                                    if (limits.pan_min_deg..=limits.pan_max_deg).contains(pan_deg) {
                                                        ("tilt_deg", *tilt_deg)
                                                    } else {
                                                        ("pan_deg", *pan_deg)
                                                    };
                                                v.invalid(field.0, fmt_f64(field.1), &limits_text);
                                            }
                                        }
                                        Aim::Pose(p) => check_pose(v, None, p),
                                        Aim::Sun => {}
                                    })
                                }
                                Step::Views { poses, .. } => v.at("poses", |v| {
                                    for (j, p) in poses.iter().enumerate() {
                                        check_pose(v, Some(j), p);
                                    }
                                }),
                                Step::LightSequence { lights, poses, .. } => {
                                    v.at("lights", |v| {
                                        for (j, l) in lights.iter().enumerate() {
                                            let ok = station.lights.as_ref().is_some_and(|ls| ls.channel(l).is_some());
                                            if !ok {
                                                let expected = match &station.lights {
                                                    Some(ls) => format!(
                                                        "a light of station {:?} (it has: {})",
                                                        station.name,
                                                        ls.channels
                                                            .iter()
                                                            .map(|c| c.name.as_str())
                                                            .collect::<Vec<_>>()
                                                            .join(", ")
                                                    ),
                                                    None => {
                                                        format!("a light, but station {:?} has no lights", station.name)
                                                    }
                                                };
                                                v.invalid(j, format!("{l:?}"), &expected);
                                            }
                                        }
                                    });
                                    v.at("poses", |v| {
                                        for (j, p) in poses.iter().enumerate() {
                                            check_pose(v, Some(j), p);
                                        }
                                    });
                                }
                                _ => {}
                            }
                            match step {
                                Step::Bracket {
                                    exposures_s, filter, ..
                                } => {
                                    v.at("exposures_s", |v| {
                                        for (j, &t) in exposures_s.iter().enumerate() {
                                            if t > 0.0 && !(cam.min_s..=cam.max_s).contains(&t) {
                                                v.invalid(
                                                    j,
                                                    fmt_f64(t),
                                                    &format!(
                                                        "an exposure within the camera's limits [{}, {}] s",
                                                        fmt_f64(cam.min_s),
                                                        fmt_f64(cam.max_s)
                                                    ),
                                                );
                                            }
                                        }
                                    });
                                    if let Some(f) = filter
                                        && !has_slot(f)
                                    {
                                        v.invalid("filter", format!("{f:?}"), &slot_names());
                                    }
                                }
                                Step::SunShot { filters, .. } => v.at("filters", |v| {
                                    for (j, f) in filters.iter().enumerate() {
                                        if !has_slot(f) {
                                            v.invalid(j, format!("{f:?}"), &slot_names());
                                        }
                                    }
                                }),
                                _ => {}
                            }
                        });
                    }
                });
            });
        }
    });
}
