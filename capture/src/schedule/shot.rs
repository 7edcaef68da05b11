//! A planned shot: one frame the controller will take, with everything
//! decided in advance, and the runtime choices (metered exposure, which ND
//! slot) named but left open.

use campanile_config::head::PanTiltHead;
use serde::{Deserialize, Serialize};

/// What a frame is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum ShotKind {
    /// A frame the processing uses.
    Data,
    /// A frame taken to choose the exposures of an auto-bracket.
    Metering,
    /// A short exposure of the sun to centre the head on the disc's centroid.
    Centering,
}

/// Where a shot points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum PlannedAim {
    /// Head angles, degrees, as the plan gives them.
    Head {
        /// Pan in the head's degrees.
        pan_deg: f64,
        /// Tilt in the head's degrees.
        tilt_deg: f64,
    },
    /// A world direction; the controller turns it into head angles through
    /// [`PanTiltHead::reach`] and its exact mount kinematics.
    Sky {
        /// Azimuth from north through east, degrees.
        azimuth_deg: f64,
        /// Elevation above the horizon, degrees.
        elevation_deg: f64,
    },
    /// A named camera pose of the scene.
    Pose {
        /// The pose's name.
        name: String,
        /// Where the head stands, scene frame, metres.
        position_m: (f64, f64, f64),
        /// Azimuth of the optical axis, degrees.
        azimuth_deg: f64,
        /// Elevation of the optical axis, degrees.
        elevation_deg: f64,
    },
    /// The sun, from the ephemeris at the moment of the shot.
    Sun,
}

impl PlannedAim {
    /// The head angles `(pan, tilt)` in degrees, with the sun at `sun`
    /// (azimuth, elevation in degrees) for [`PlannedAim::Sun`]; `None` when
    /// the head cannot reach the aim.
    pub fn head_angles(&self, head: &PanTiltHead, sun: (f64, f64)) -> Option<(f64, f64)> {
        match self {
            PlannedAim::Head { pan_deg, tilt_deg } => head
                .limits
                .contains(*pan_deg, *tilt_deg)
                .then_some((*pan_deg, *tilt_deg)),
            PlannedAim::Sky {
                azimuth_deg,
                elevation_deg,
            }
            | PlannedAim::Pose {
                azimuth_deg,
                elevation_deg,
                ..
            } => head.reach(*azimuth_deg, *elevation_deg),
            PlannedAim::Sun => head.reach(sun.0, sun.1),
        }
    }

    /// A short description for reports, e.g. "azimuth 45.0°, elevation -26.3°".
    pub fn describe(&self) -> String {
        match self {
            PlannedAim::Head { pan_deg, tilt_deg } => format!("pan {pan_deg:.1}°, tilt {tilt_deg:.1}°"),
            PlannedAim::Sky {
                azimuth_deg,
                elevation_deg,
            } => format!("azimuth {azimuth_deg:.1}°, elevation {elevation_deg:.1}°"),
            PlannedAim::Pose {
                name,
                azimuth_deg,
                elevation_deg,
                ..
            } => format!("pose {name:?} (azimuth {azimuth_deg:.1}°, elevation {elevation_deg:.1}°)"),
            PlannedAim::Sun => "the sun".to_owned(),
        }
    }
}

/// How long a shot exposes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PlannedExposure {
    /// This many seconds.
    Fixed {
        /// Exposure time, seconds.
        seconds: f64,
    },
    /// `2^stops` times the exposure the controller meters for the shot's
    /// target (tile, pose), e.g. −2, 0, +2 for a three-frame bracket.
    Metered {
        /// Stops relative to the metered exposure.
        stops: f64,
    },
    /// Chosen by the controller at run time (auto-bracket frames from the
    /// metering shot; sun frames from the predicted solar radiance).
    Auto,
}

/// Which ND filter a shot is taken through.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum FilterChoice {
    /// Whatever is in the light path when no filter is asked for (the
    /// wheel's clear slot, if it has one).
    None,
    /// This slot.
    Slot(String),
    /// The least dense of these slots (listed lightest first) that leaves
    /// the sun's disc unsaturated, chosen by the controller (thesis §5.3.1):
    /// the most light that still measures the disc.
    LightestUnsaturated(Vec<String>),
}

/// One frame the plan will take.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedShot {
    /// Stable unique id `"{occurrence}/s{step}/t{target}/f{frame}"`, which
    /// the session journal records so a resumed session skips what is done.
    pub key: String,
    /// Index of the step in the session.
    pub step: usize,
    /// What the frame is for.
    pub kind: ShotKind,
    /// Where it points.
    pub aim: PlannedAim,
    /// How long it exposes.
    pub exposure: PlannedExposure,
    /// Through which filter.
    pub filter: FilterChoice,
    /// Light levels in [0, 1] per light channel of the station, in the
    /// station's order; `None` leaves the lights as they are.
    pub lights: Option<Vec<f64>>,
    /// Whether the plan promises this frame. Only auto-bracket frames after
    /// the first are not promised: the controller takes them only when the
    /// metered dynamic range needs them.
    pub promised: bool,
}
