//! A session directory as processing input: its journal's frames, each with
//! what its plan step took it for, its head reading, filter and position.

use std::path::{Path, PathBuf};

use crate::Result;
use anyhow::{Context, anyhow};
use campanile_capture::device::FrameFormat;
use campanile_capture::store::{FrameEntry, JournalEntry, SessionReader, ShotKind};
use campanile_config::plan::Step;
use campanile_config::source::SourceFile;
use campanile_config::{Plan, Scene, Station};
use campanile_process::hdr::linear_codes;
use campanile_process::pipeline::{CapturedFrame, Purpose, clip_lossy_top};
use campanile_process::pose::{HeadPose, Mount};
use campanile_process::registration::CameraPose;
use indicatif::ProgressBar;
use nalgebra::Vector3;
use rayon::prelude::*;

/// A session's descriptions, parsed from its snapshot.
pub struct SessionInputs {
    pub reader: SessionReader,
    pub plan: Plan,
    pub station: Station,
    /// The scene and the directory its geometry path is relative to.
    pub scene: Option<(Scene, PathBuf)>,
    /// Where the head stood, when a calibration measured it
    /// ([`SessionInputs::calibrated`]): every frame is taken from here,
    /// whatever position its scene pose gives.
    pub head_position: Option<[f64; 3]>,
}

impl SessionInputs {
    /// Opens `dir`; `scene_override` replaces the session's scene snapshot
    /// (whose OBJ geometry may not have been copied into the session).
    pub fn open(dir: &Path, scene_override: Option<&Path>) -> Result<SessionInputs> {
        let reader = SessionReader::open(dir).with_context(|| format!("{}: cannot read the session", dir.display()))?;
        let snap = reader.snapshot();
        let parse = |name: &str, text: &str| SourceFile::from_text(&dir.join(name), text.to_owned());
        let plan: Plan = parse("plan.ron", &snap.plan_ron).parse().map_err(|e| anyhow!("{e}"))?;
        let station: Station = parse("station.ron", &snap.station_ron)
            .parse()
            .map_err(|e| anyhow!("{e}"))?;
        let scene = match (scene_override, &snap.scene_ron) {
            (Some(path), _) => {
                let loaded = campanile_config::load_scene(path).map_err(|e| anyhow!("{e}"))?;
                let base = loaded.source.base_dir();
                Some((loaded.value, base))
            }
            (None, Some(text)) => {
                let scene: Scene = parse("scene.ron", text).parse().map_err(|e| anyhow!("{e}"))?;
                // The geometry beside the snapshot, else beside the scene
                // file the session was captured from.
                let original = snap
                    .provenance
                    .sources
                    .as_ref()
                    .and_then(|s| s.scene.as_ref())
                    .and_then(|p| p.parent().map(Path::to_path_buf));
                let base = match original {
                    Some(o) if !dir.join(&scene.geometry).is_file() && o.join(&scene.geometry).is_file() => o,
                    _ => dir.to_path_buf(),
                };
                Some((scene, base))
            }
            (None, None) => None,
        };
        Ok(SessionInputs {
            reader,
            plan,
            station,
            scene,
            head_position: None,
        })
    }

    /// The inputs with the station's camera intrinsics and head mount
    /// replaced by the calibration file at `path` (`campanile sky
    /// calibrate`'s or `campanile station calibrate-mount`'s), and the
    /// head's place too when the calibration measured it (a tripod set up
    /// away from the scene's poses). Bad input when the file does not
    /// load or is for another resolution.
    pub fn calibrated(mut self, path: &Path) -> crate::error::Result<SessionInputs> {
        let cal = campanile_config::document::load_camera_calibration(path)
            .map_err(|e| crate::error::Error::input(e.to_string()))?
            .value;
        self.station = cal
            .apply_to(&self.station)
            .map_err(|e| crate::error::Error::input(format!("{}: {e}", path.display())))?;
        self.head_position = cal.head_position_m.map(|(x, y, z)| [x, y, z]);
        Ok(self)
    }

    /// The OBJ geometry of the scene, checked to exist.
    pub fn geometry(&self) -> Result<Option<PathBuf>> {
        let Some((scene, base)) = &self.scene else {
            return Ok(None);
        };
        let path = base.join(&scene.geometry);
        if !path.is_file() {
            bail!(
                "the scene's geometry {} is not in the session directory: pass the scene file with --scene (e.g. --scene examples/campanile-scene.ron)",
                path.display()
            );
        }
        Ok(Some(path))
    }

    /// Every data frame of the session with its purpose, read and checked
    /// (in parallel), in journal order.
    pub fn frames(&self, bar: &ProgressBar) -> Result<Vec<CapturedFrame>> {
        self.frames_where(bar, |_| true)
    }

    /// The data frames whose journal entry `keep` accepts, read and checked
    /// (in parallel), in journal order.
    pub fn frames_where(&self, bar: &ProgressBar, keep: impl Fn(&FrameEntry) -> bool) -> Result<Vec<CapturedFrame>> {
        let entries: Vec<&FrameEntry> = self
            .reader
            .frames()
            .filter(|f| f.meta.kind != ShotKind::Metering && keep(f))
            .collect();
        bar.set_length(entries.len() as u64);
        // Where the head stood: the last pose a view aimed from, starting at
        // the scene's first pose (where a station is set up).
        let mut position = self
            .scene
            .as_ref()
            .and_then(|(s, _)| s.poses.first())
            .map_or([0.0; 3], |p| [p.position_m.0, p.position_m.1, p.position_m.2]);
        let mut described = Vec::with_capacity(entries.len());
        for e in &entries {
            let (purpose, pos) = self.purpose(e)?;
            let (head, held_by, position_m) = match e.meta.pose_reached.or(e.meta.pose_requested) {
                Some(pose) => {
                    if let Some(p) = pos {
                        position = p;
                    }
                    let head = HeadPose {
                        pan_rad: pose.pan_deg.to_radians(),
                        tilt_rad: pose.tilt_deg.to_radians(),
                    };
                    (head, None, self.head_position.unwrap_or(position))
                }
                // A photograph taken off the head stood where its pose
                // says, wherever a calibration put the head; the head did
                // not move for it.
                None => {
                    let (mount, head, at) = self.held(e, &purpose)?;
                    (head, Some(mount), at)
                }
            };
            described.push((purpose, head, held_by, position_m));
        }
        let frames: Result<Vec<CapturedFrame>> = entries
            .par_iter()
            .zip(described)
            .map(|(e, (purpose, head, held_by, position_m))| {
                // A frame file that is missing, damaged or undecodable is
                // bad input (exit 2), named by the store's error.
                let mut codes = self
                    .reader
                    .read_frame(e)
                    .map_err(|err| crate::error::bad_input(err.to_string()))?;
                if e.format == FrameFormat::Jpeg {
                    clip_lossy_top(&mut codes);
                }
                // A FITS frame (an INDI camera's) holds a linear sensor's
                // codes: its response is known, as a RAW frame's is. Black
                // is code 0: the FITS header states no black level (a
                // camera with a bias offset needs dark frames, not done here).
                if e.format == FrameFormat::Fits {
                    codes = linear_codes::log_codes_of_linear(&codes, 0.0);
                }
                bar.inc(1);
                let filter_transmittance = match &e.meta.filter {
                    None => [1.0; 3],
                    Some(name) => self
                        .station
                        .filter_wheel
                        .as_ref()
                        .and_then(|w| w.slots.iter().find(|s| &s.name == name))
                        .map(|s| s.transmittance())
                        .ok_or_else(|| {
                            anyhow!(
                                "frame {:?} was taken through filter {name:?}, which the station's wheel does not have",
                                e.key
                            )
                        })?,
                };
                let occurrence = e.key.split('/').next().unwrap_or_default().to_owned();
                let held_out = self.session_of(&occurrence).is_some_and(|s| s.held_out);
                Ok(CapturedFrame {
                    key: e.key.clone(),
                    occurrence,
                    held_out,
                    time: e.meta.time,
                    purpose,
                    head,
                    held_by,
                    position_m,
                    exposure_s: e.meta.exposure_actual_s,
                    filter_transmittance,
                    codes,
                    linear: e.format.is_raw() || e.format == FrameFormat::Fits,
                    focal_px: e.meta.focal_px,
                })
            })
            .collect();
        frames
    }

    /// Exposures the plan asked for in the bracket that calibrated the
    /// response (`group`, of which `used` frames were read): the frames
    /// journaled missed in that group added back, and at least the
    /// densest unfiltered fixed bracket of the plan (the calibration
    /// bracket, which a response from a lesser bracket stands in for).
    pub fn planned_exposures(&self, group: &str, used: usize) -> usize {
        let prefix = format!("{group}/");
        let missed = self
            .reader
            .entries()
            .iter()
            .filter(|e| matches!(e, JournalEntry::Missed(m) if m.key.starts_with(&prefix)))
            .count();
        let densest = self
            .plan
            .sessions
            .iter()
            .flat_map(|s| &s.steps)
            .filter_map(|step| match step {
                Step::Bracket {
                    exposures_s,
                    filter: None,
                    ..
                } => Some(exposures_s.len()),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        (used + missed).max(densest)
    }

    /// The plan session of an occurrence id (`{session}@…`).
    pub fn session_of(&self, occurrence: &str) -> Option<&campanile_config::plan::Session> {
        let name = occurrence.split('@').next()?;
        self.plan.sessions.iter().find(|s| s.name == name)
    }

    /// A view taken off the head (by hand, or on a plain tripod; an
    /// imported one), whose journal line has no head reading: the scene
    /// pose its step names, as it is (azimuth, elevation, roll and
    /// position, as `campanile register` measures them), through
    /// [`CameraPose::holding`]. A frame with no head reading and no scene
    /// pose is bad input.
    fn held(&self, e: &FrameEntry, purpose: &Purpose) -> Result<(Mount, HeadPose, [f64; 3])> {
        let no_pose = |why: &str| {
            crate::error::bad_input(format!(
                "{}: journal line of {:?} has no head reading, and {why}: a frame taken off the head needs \
                 the scene pose it was taken from",
                self.reader.dir().display(),
                e.key
            ))
        };
        let name = match purpose {
            Purpose::View { pose } | Purpose::Lights { pose, .. } => pose,
            _ => return Err(no_pose("it is not a view of a scene pose").into()),
        };
        let pose = self
            .scene
            .as_ref()
            .and_then(|(s, _)| s.pose(name))
            .ok_or_else(|| no_pose(&format!("the scene has no pose {name:?}")))?;
        let (x, y, z) = pose.position_m;
        let (mount, head) =
            CameraPose::from_angles(pose.azimuth_deg, pose.elevation_deg, pose.roll_deg, Vector3::zeros()).holding();
        Ok((mount, head, [x, y, z]))
    }

    /// What a frame was for, from its key `"{session}@{date}/s{step}/t{target}/f{frame}"`,
    /// and for a view the position it was taken from.
    fn purpose(&self, e: &FrameEntry) -> Result<(Purpose, Option<[f64; 3]>)> {
        let bad = |why: &str| crate::Error::from(anyhow!("frame key {:?}: {why}", e.key));
        let parts: Vec<&str> = e.key.split('/').collect();
        let [occurrence, step, target, _frame] = parts[..] else {
            return Err(bad("expected SESSION@DATE/sSTEP/tTARGET/fFRAME"));
        };
        let number = |s: &str, prefix: char| -> Result<usize> {
            s.strip_prefix(prefix)
                .and_then(|n| n.parse().ok())
                .ok_or_else(|| bad(&format!("expected {prefix}N, found {s:?}")))
        };
        let (step, target) = (number(step, 's')?, number(target, 't')?);
        let session = self
            .session_of(occurrence)
            .ok_or_else(|| bad("no session of that name in the plan"))?;
        let step = session
            .steps
            .get(step)
            .ok_or_else(|| bad(&format!("the session has {} steps", session.steps.len())))?;
        if e.meta.kind == ShotKind::Centering {
            return Ok((Purpose::SunCentering, None));
        }
        let pose = |name: &str| -> Result<(Purpose, Option<[f64; 3]>)> {
            let position = self
                .scene
                .as_ref()
                .and_then(|(s, _)| s.pose(name))
                .map(|p| [p.position_m.0, p.position_m.1, p.position_m.2]);
            Ok((Purpose::View { pose: name.to_owned() }, position))
        };
        let levels = || e.meta.lights.iter().flatten().map(|l| l.level).collect::<Vec<f64>>();
        match step {
            Step::SunShot { .. } => Ok((Purpose::Sun, None)),
            Step::SkyScan { .. } => Ok((Purpose::Sky, None)),
            Step::EnvironmentTiles { .. } => Ok((Purpose::Environment, None)),
            Step::Views { poses, .. } => pose(poses.get(target).ok_or_else(|| bad("no such pose in the step"))?),
            Step::Bracket { aim, .. } | Step::AutoBracket { aim, .. } => match aim {
                campanile_config::plan::Aim::Pose(name) => pose(name),
                campanile_config::plan::Aim::Sun => Ok((Purpose::Sun, None)),
                campanile_config::plan::Aim::PanTilt { pan_deg, tilt_deg } => Ok((
                    Purpose::View {
                        pose: format!("pan {pan_deg}° tilt {tilt_deg}°"),
                    },
                    None,
                )),
            },
            Step::LightSequence {
                lights, all_on, poses, ..
            } => {
                // Per pose, each light alone, then all on (capture::schedule).
                let states = lights.len() + usize::from(*all_on);
                let name = poses
                    .get(target / states.max(1))
                    .ok_or_else(|| bad("no such pose in the light sequence"))?;
                let (_, position) = pose(name)?;
                Ok((
                    Purpose::Lights {
                        pose: name.clone(),
                        levels: levels(),
                    },
                    position,
                ))
            }
        }
    }
}
