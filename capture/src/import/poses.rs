//! Where each bracket was taken from: a poses file (`--poses`) mapping
//! brackets, by their first file's name or a pattern of it, to a named
//! pose of the scene or to a position and direction, and marking sky
//! brackets. Poses are given: measured, or registered from targets in the
//! photographs (`campanile register`, thesis §3.3) into the scene's poses.
//!
//! ```ron
//! ImportPoses(
//!     brackets: [
//!         (files: "IMG_6955.JPG", pose: "view-se"),          // a pose of --scene
//!         (files: "IMG_70*.JPG", position_m: (12.0, -30.0, 1.6),
//!          azimuth_deg: 20.0, elevation_deg: 8.0),          // or where and which way
//!         (files: "IMG_71*.JPG", position_m: (9.0, -25.0, 1.5),
//!          azimuth_deg: 35.0, elevation_deg: 12.0, roll_deg: -4.5), // and turned
//!         (files: "SKY_*.JPG", sky: true, azimuth_deg: 0.0, elevation_deg: 90.0),
//!     ],
//! )
//! ```
//!
//! Patterns take `*` and `?` ([`super::name_pattern`]); the first entry
//! whose pattern matches a bracket's first file name is its pose.
//!
//! A view's pose is taken as it is: the bracket was taken off the head (by
//! hand, or on a plain tripod), so it journals no head reading, and
//! processing turns the camera by the pose's azimuth, elevation and roll
//! (the scene's `poses`, which `campanile register` writes from targets,
//! carry all three). A sky bracket goes through the station's head and
//! mount, as a sky scan's tiles do.

use std::path::Path;

use campanile_config::Scene;
use campanile_config::source::SourceFile;
use serde::{Deserialize, Serialize};

use super::error::ImportError;
use super::name_pattern::matches;

/// A poses file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImportPoses {
    /// One entry per bracket or pattern of brackets.
    pub brackets: Vec<PoseEntry>,
}

/// One entry of a poses file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseEntry {
    /// The bracket's first file name, or a pattern (`*`, `?`).
    pub files: String,
    /// A camera pose of the scene.
    #[serde(default)]
    pub pose: Option<String>,
    /// Where the camera stood, scene frame (x east, y north, z up), metres.
    #[serde(default)]
    pub position_m: Option<(f64, f64, f64)>,
    /// Azimuth of the optical axis, degrees from north through east.
    #[serde(default)]
    pub azimuth_deg: Option<f64>,
    /// Elevation of the optical axis, degrees.
    #[serde(default)]
    pub elevation_deg: Option<f64>,
    /// Roll about the optical axis, degrees (as `campanile register`
    /// measures it: positive when the image turns clockwise as seen by the
    /// photographer); 0 when not given.
    #[serde(default)]
    pub roll_deg: Option<f64>,
    /// The bracket is of the sky (a sky frame, fitted as a sky scan is).
    #[serde(default)]
    pub sky: bool,
}

/// A bracket's pose, resolved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BracketPose {
    /// The scene's pose name, if the entry named one.
    pub scene_pose: Option<String>,
    /// Where the camera stood, metres (`None`: not given).
    pub position_m: Option<[f64; 3]>,
    /// Azimuth of the optical axis, degrees.
    pub azimuth_deg: f64,
    /// Elevation of the optical axis, degrees.
    pub elevation_deg: f64,
    /// Roll about the optical axis, degrees.
    pub roll_deg: f64,
    /// Which entry (its `files` pattern) gave it.
    pub from_entry: String,
    /// A sky bracket.
    pub sky: bool,
}

/// Reads a poses file (errors name the line and field).
pub fn read_poses(path: &Path) -> Result<ImportPoses, ImportError> {
    let source = SourceFile::read(path).map_err(|e| ImportError::Description(e.to_string()))?;
    let poses: ImportPoses = source.parse().map_err(|e| ImportError::Description(e.to_string()))?;
    for (i, e) in poses.brackets.iter().enumerate() {
        let bad = |what: &str| {
            ImportError::Description(format!(
                "{}: brackets[{i}] (files {:?}): {what}",
                path.display(),
                e.files
            ))
        };
        match (&e.pose, e.azimuth_deg, e.elevation_deg) {
            (Some(_), None, None) if e.position_m.is_none() && e.roll_deg.is_none() => {}
            (Some(_), _, _) => {
                return Err(bad(
                    "give either pose or position_m/azimuth_deg/elevation_deg/roll_deg, not both",
                ));
            }
            (None, Some(az), Some(el)) => {
                if !(az.is_finite() && (-360.0..=360.0).contains(&az)) {
                    return Err(bad(&format!("azimuth_deg is {az}: expected degrees in [-360, 360]")));
                }
                if !(el.is_finite() && (-90.0..=90.0).contains(&el)) {
                    return Err(bad(&format!("elevation_deg is {el}: expected degrees in [-90, 90]")));
                }
            }
            (None, _, _) => {
                return Err(bad(
                    "no pose: expected pose: \"NAME\" (a pose of the scene) or azimuth_deg and elevation_deg",
                ));
            }
        }
        if let Some(r) = e.roll_deg
            && !(r.is_finite() && (-180.0..=180.0).contains(&r))
        {
            return Err(bad(&format!("roll_deg is {r}: expected degrees in [-180, 180]")));
        }
        if e.sky && e.roll_deg.is_some_and(|r| r != 0.0) {
            return Err(bad(
                "a sky bracket takes no roll_deg: it is fitted through the station's head and mount",
            ));
        }
        if let Some(p) = e.position_m
            && ![p.0, p.1, p.2].iter().all(|v| v.is_finite())
        {
            return Err(bad(&format!("position_m is {p:?}: expected finite metres")));
        }
    }
    Ok(poses)
}

impl ImportPoses {
    /// The pose of the bracket whose first file is `first`, if an entry
    /// matches it; a named pose the scene lacks is an error.
    pub fn pose_of(&self, first: &str, scene: Option<&Scene>) -> Result<Option<BracketPose>, ImportError> {
        let Some(e) = self.brackets.iter().find(|e| matches(&e.files, first)) else {
            return Ok(None);
        };
        let resolved = match &e.pose {
            Some(name) => {
                let pose = scene.and_then(|s| s.pose(name)).ok_or_else(|| {
                    ImportError::Description(format!(
                        "poses entry {:?} (for {first}) names pose {name:?}, which {}",
                        e.files,
                        match scene {
                            Some(s) => format!(
                                "the scene does not have (its poses: {})",
                                s.poses.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                            ),
                            None => "needs a scene: give --scene".to_owned(),
                        }
                    ))
                })?;
                BracketPose {
                    scene_pose: Some(name.clone()),
                    position_m: Some([pose.position_m.0, pose.position_m.1, pose.position_m.2]),
                    azimuth_deg: pose.azimuth_deg,
                    elevation_deg: pose.elevation_deg,
                    roll_deg: pose.roll_deg,
                    from_entry: e.files.clone(),
                    sky: e.sky,
                }
            }
            None => BracketPose {
                scene_pose: None,
                position_m: e.position_m.map(|p| [p.0, p.1, p.2]),
                azimuth_deg: e.azimuth_deg.unwrap_or_default(),
                elevation_deg: e.elevation_deg.unwrap_or_default(),
                roll_deg: e.roll_deg.unwrap_or_default(),
                from_entry: e.files.clone(),
                sky: e.sky,
            },
        };
        Ok(Some(resolved))
    }

    /// Entries that no bracket's first file matches (likely typos).
    pub fn unused<'a>(&'a self, firsts: &'a [&str]) -> impl Iterator<Item = &'a str> + 'a {
        self.brackets
            .iter()
            .filter(|e| !firsts.iter().any(|f| matches(&e.files, f)))
            .map(|e| e.files.as_str())
    }
}
