//! The mount-calibration photographs of a captured session: a plan takes
//! them as brackets aimed at head angles (`Bracket(aim: PanTilt(...))`,
//! e.g. `examples/mount-calibration.ron`), and `campanile station
//! calibrate-mount --session` turns each bracket into one photograph (its
//! best-exposed frame) with the head's reached reading, then registers them
//! from the targets and fits the mount ([`crate::mount_files`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_capture::store::FrameEntry;
use campanile_config::plan::{Aim, Step};
use campanile_process::pipeline::CapturedFrame;
use indicatif::ProgressBar;

use crate::error::{Error, Result};
use crate::process::SessionInputs;

/// The photographs written from a session, ready for `register` and
/// [`crate::mount_files::calibrate_mount_files`].
#[derive(Debug, Clone)]
pub struct SessionPhotos {
    /// One 8-bit PNG per bracket aimed at head angles, named for its
    /// journal key (`morning@2026-08-28/s0/t0` → `morning@2026-08-28-s0-t0.png`).
    pub photos: Vec<PathBuf>,
    /// The head's reached reading at each (CSV: photo, pan_deg, tilt_deg).
    pub readings: PathBuf,
    /// The session's station snapshot (the camera that took them).
    pub station: PathBuf,
}

/// Whether `e` belongs to a bracket the plan aims at head angles.
fn aimed_at_head_angles(inputs: &SessionInputs, e: &FrameEntry) -> bool {
    let mut parts = e.key.split('/');
    let (Some(occurrence), Some(step)) = (parts.next(), parts.next()) else {
        return false;
    };
    let name = occurrence.split('@').next().unwrap_or_default();
    let Some(step) = step.strip_prefix('s').and_then(|n| n.parse::<usize>().ok()) else {
        return false;
    };
    inputs
        .plan
        .sessions
        .iter()
        .find(|s| s.name == name)
        .and_then(|s| s.steps.get(step))
        .is_some_and(|s| {
            matches!(
                s,
                Step::Bracket {
                    aim: Aim::PanTilt { .. },
                    ..
                } | Step::AutoBracket {
                    aim: Aim::PanTilt { .. },
                    ..
                }
            )
        })
}

/// How many of a frame's pixels are well exposed: their mean code between
/// 5 % and 90 % of the largest.
fn well_exposed(f: &CapturedFrame) -> usize {
    let top = f64::from(f.codes.max_code());
    f.codes
        .data
        .chunks_exact(3)
        .filter(|p| {
            let v = p.iter().map(|&c| f64::from(c)).sum::<f64>() / (3.0 * top);
            (0.05..=0.9).contains(&v)
        })
        .count()
}

/// The frame's gray levels scaled to 8 bits (the camera's codes, not
/// radiance: the targets are found by their contrast).
fn gray8(f: &CapturedFrame) -> Vec<u8> {
    let scale = 255.0 / f64::from(f.codes.max_code());
    f.codes
        .data
        .chunks_exact(3)
        .map(|p| {
            (p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0 * scale)
                .round()
                .clamp(0.0, 255.0) as u8
        })
        .collect()
}

/// Writes the mount-calibration photographs of the session at `session`
/// into `dir` (made if missing): bad input when the session has no
/// bracket aimed at head angles, or its frames do not read.
pub fn session_photos(session: &Path, dir: &Path, bar: &ProgressBar) -> Result<SessionPhotos> {
    let inputs = SessionInputs::open(session, None)?;
    let frames = inputs.frames_where(bar, |e| aimed_at_head_angles(&inputs, e))?;
    if frames.is_empty() {
        return Err(Error::input(format!(
            "{}: no bracket aimed at head angles: a mount calibration takes brackets with \
             `aim: PanTilt(pan_deg: …, tilt_deg: …)` at three or more pans (see examples/mount-calibration.ron)",
            session.display()
        )));
    }
    // One photograph per bracket: its best-exposed frame.
    let mut brackets: BTreeMap<String, &CapturedFrame> = BTreeMap::new();
    for f in &frames {
        let bracket = f.key.rsplit_once('/').map_or(f.key.as_str(), |(b, _)| b).to_owned();
        let better = brackets.get(&bracket).is_none_or(|b| well_exposed(f) > well_exposed(b));
        if better {
            brackets.insert(bracket, f);
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let mut csv = String::from("photo,pan_deg,tilt_deg\n");
    let mut photos = Vec::with_capacity(brackets.len());
    for (bracket, f) in &brackets {
        let name = bracket.replace('/', "-");
        let path = dir.join(format!("{name}.png"));
        image::save_buffer(
            &path,
            &gray8(f),
            f.codes.width as u32,
            f.codes.height as u32,
            image::ExtendedColorType::L8,
        )
        .with_context(|| format!("{}: cannot write", path.display()))?;
        csv += &format!(
            "{name},{},{}\n",
            f.head.pan_rad.to_degrees(),
            f.head.tilt_rad.to_degrees()
        );
        photos.push(path);
    }
    let readings = dir.join("head.csv");
    std::fs::write(&readings, csv).with_context(|| format!("{}: cannot write", readings.display()))?;
    let station = dir.join("station.ron");
    std::fs::write(&station, &inputs.reader.snapshot().station_ron)
        .with_context(|| format!("{}: cannot write", station.display()))?;
    Ok(SessionPhotos {
        photos,
        readings,
        station,
    })
}
