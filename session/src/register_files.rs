//! `campanile register` on files: photographs and a survey of targets in,
//! camera poses out (thesis §3.3). The targets file's kind says how:
//! coded targets are found ([`TagDetector`]), paired with the surveyed
//! corners by id, and registered ([`register`]); the thesis's circle
//! targets are found ([`detect_circles`]), paired with the survey by
//! search and registered ([`register_circles`]). The poses are written in
//! the form a scene file's `poses` take, with each photograph's verdict and
//! figures beside.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_config::targets::Targets;
use campanile_process::pose::Pinhole;
use campanile_process::registration::apriltag::{TagDetector, correspondences};
use campanile_process::registration::circle_detect::{CircleDetectorSettings, detect_circles};
use campanile_process::registration::circle_search::{CircleSearchSettings, SurveyedCircle, register_circles};
use campanile_process::registration::{Quality, RegistrationSettings, Verdict, register};
use serde::{Deserialize, Serialize};

use crate::error::bad_input;

/// One photograph's registration, as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhotoRegistration {
    /// The pose's name: the photograph's file stem.
    pub name: String,
    /// The photograph.
    pub file: PathBuf,
    /// Roll about the optical axis, degrees (the scene's poses have none:
    /// a head's views are level). `None` when failed.
    pub roll_deg: Option<f64>,
    /// Tags decoded that the survey does not list.
    pub unknown_tags: Vec<u32>,
    /// Circle targets: what the detection and the correspondence search found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circles: Option<CircleSearchFigures>,
    /// Verdict and figures.
    pub quality: Quality,
}

/// The circle search's figures for one photograph.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSearchFigures {
    /// Circles (ellipses) found in the photograph.
    pub found: usize,
    /// Those paired with a surveyed target: (detection index, target id).
    pub matched: Vec<(usize, u32)>,
    /// Detections paired with none (false or unsurveyed targets).
    pub unmatched: Vec<usize>,
    /// Pose hypotheses tried by the search.
    pub hypotheses: usize,
}

/// The file `register` writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "RegisteredPoses")]
pub struct RegisteredPoses {
    /// The poses of the photographs not `failed`, in the scene file's form
    /// (copy them into a scene's `poses`).
    pub poses: Vec<campanile_config::scene::CameraPose>,
    /// Every photograph's registration, in the order given.
    pub photos: Vec<PhotoRegistration>,
}

/// What `register` was asked.
#[derive(Debug, Clone)]
pub struct RegisterRequest {
    /// The photographs.
    pub photos: Vec<PathBuf>,
    /// The surveyed targets file.
    pub targets: PathBuf,
    /// The station file whose camera took them (its intrinsics).
    pub station: PathBuf,
    /// Where to write the poses.
    pub out: PathBuf,
    /// Registration settings.
    pub settings: RegistrationSettings,
}

/// The 8-bit gray pixels of a photograph.
fn gray_photo(path: &Path) -> Result<(usize, usize, Vec<u8>)> {
    if !path.is_file() {
        return Err(bad_input(format!("{}: no such photograph", path.display())));
    }
    let image = image::open(path).map_err(|e| {
        bad_input(format!(
            "{}: not a readable image ({e}); expected PNG, JPEG or TIFF",
            path.display()
        ))
    })?;
    let gray = image.to_luma8();
    Ok((gray.width() as usize, gray.height() as usize, gray.into_raw()))
}

/// Registers every photograph of `request` and writes the poses file.
/// Returns what was written; failed photographs are in it with their
/// reasons (the caller turns them into the exit status).
pub fn register_photos(request: &RegisterRequest) -> Result<RegisteredPoses> {
    if request.photos.is_empty() {
        return Err(bad_input("no photographs given: expected one or more image files"));
    }
    let targets: Targets = campanile_config::load_targets(&request.targets)?.value;
    let circles = SurveyedCircle::from_targets(&targets);
    let station = campanile_config::load_station(&request.station)?.value;
    let configured = Pinhole::of_camera(&station.camera);
    let configured_size = (
        station.camera.resolution.width as usize,
        station.camera.resolution.height as usize,
    );
    let mut detector: Option<TagDetector> = None;
    let mut out = RegisteredPoses {
        poses: Vec::new(),
        photos: Vec::new(),
    };
    for path in &request.photos {
        let (w, h, gray) = gray_photo(path)?;
        // The camera's intrinsics at this photograph's size (a reduced
        // JPEG keeps the same field of view).
        if (w as f64 / h as f64 - configured_size.0 as f64 / configured_size.1 as f64).abs() > 0.01 {
            return Err(bad_input(format!(
                "{}: {w} × {h} pixels, but the station's camera is {} × {}: expected the same aspect ratio",
                path.display(),
                configured_size.0,
                configured_size.1
            )));
        }
        let pinhole = configured.rescaled(configured_size, w, h);
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        if let Some(surveyed) = &circles {
            let found = detect_circles(&gray, w, h, &CircleDetectorSettings::default());
            let r = register_circles(
                &pinhole,
                &found,
                surveyed,
                &request.settings,
                &CircleSearchSettings::default(),
            );
            let reg = r.registration;
            tracing::info!(photo = %path.display(), verdict = %reg.quality.verdict, circles = found.len(),
                hypotheses = r.hypotheses, "registered");
            push_photo(
                &mut out,
                name,
                path,
                reg.pose,
                reg.quality,
                Vec::new(),
                Some(CircleSearchFigures {
                    found: found.len(),
                    matched: r.matches,
                    unmatched: r.unmatched,
                    hypotheses: r.hypotheses,
                }),
            );
            continue;
        }
        if detector.as_ref().is_none_or(|d| d.size() != (w, h)) {
            detector = Some(TagDetector::new(w, h).context("starting the tag detector")?);
        }
        let found = detector
            .as_mut()
            .map(|d| d.detect(&gray))
            .transpose()
            .with_context(|| format!("{}: looking for tags", path.display()))?
            .unwrap_or_default();
        let (points, unknown_tags) = correspondences(&found, &targets.targets);
        let reg = register(&pinhole, &points, &request.settings);
        tracing::info!(photo = %path.display(), verdict = %reg.quality.verdict, tags = found.len(), "registered");
        push_photo(&mut out, name, path, reg.pose, reg.quality, unknown_tags, None);
    }
    let text = ron::ser::to_string_pretty(&out, ron::ser::PrettyConfig::default()).context("serializing the poses")?;
    std::fs::write(&request.out, text + "\n").with_context(|| format!("writing {}", request.out.display()))?;
    Ok(out)
}

/// Adds one photograph's registration (and its pose, unless failed) to `out`.
fn push_photo(
    out: &mut RegisteredPoses,
    name: String,
    path: &Path,
    pose: Option<campanile_process::registration::CameraPose>,
    quality: Quality,
    unknown_tags: Vec<u32>,
    circles: Option<CircleSearchFigures>,
) {
    if let Some(pose) = pose {
        out.poses.push(campanile_config::scene::CameraPose {
            name: name.clone(),
            position_m: (pose.centre.x, pose.centre.y, pose.centre.z),
            azimuth_deg: pose.azimuth_deg(),
            elevation_deg: pose.elevation_deg(),
            roll_deg: pose.roll_deg(),
        });
    }
    out.photos.push(PhotoRegistration {
        name,
        file: path.to_path_buf(),
        roll_deg: pose.map(|p| p.roll_deg()),
        unknown_tags,
        circles,
        quality,
    });
}

/// The photographs whose verdict is `failed`, each with its reasons.
pub fn failed_photos(poses: &RegisteredPoses) -> Vec<String> {
    poses
        .photos
        .iter()
        .filter(|p| p.quality.verdict == Verdict::Failed)
        .map(|p| format!("{}: {}", p.file.display(), p.quality.reasons.join("; ")))
        .collect()
}
