//! `campanile session import`: a folder of hand-taken JPEG brackets made
//! into a session that `campanile process` takes.
//!
//! 1. Every file of the folder is read ([`camera_file`]): a JPEG with an
//!    EXIF block, else an error naming the file.
//! 2. Each photograph's true time ([`clock`]): DateTimeOriginal and
//!    SubSecTimeOriginal at OffsetTimeOriginal (or the stated
//!    `--utc-offset`), less the stated `--clock-offset-s`.
//! 3. Its exposure: ExposureTime (or the `--times` file), and the
//!    effective time `t · (S/S₀) · (N₀/N)²` relative to the first frame's
//!    ISO and f-number, as `hdr calibrate` merges brackets.
//! 4. Brackets ([`brackets`]) in time order; lone frames refused (or left
//!    out with `--skip-single`): one JPEG cannot calibrate a response and
//!    its clipped highlights would pass for radiance.
//! 5. Poses ([`poses`]) and sky brackets (`sky: true`, `--sky PATTERN`);
//!    the head angles through the station's mount.
//! 6. Occurrences: brackets closer than `occurrence_gap_s` share one
//!    light (one plan session, `import-N`); in each, a `Bracket` step per
//!    view and one `SkyScan` step whose targets are the sky brackets.
//! 7. The session written through the store ([`write_session`]): the
//!    generated plan, the station (given, or estimated from EXIF by
//!    [`station_estimate`]), the scene, every file byte for byte, and the
//!    record ([`record`]) of what was estimated.

pub mod brackets;
pub mod camera_file;
pub mod clock;
mod error;
pub mod name_pattern;
pub mod poses;
pub mod record;
pub mod station_estimate;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use campanile_config::plan::{Aim, ErrorPolicy, Plan, Session, Step, Trigger};
use campanile_config::scene::CameraPose;
use campanile_config::{Scene, Station};
use campanile_process::hdr::exposure_metadata::{ExposureMetadata, effective_times};
use chrono::{DateTime, Utc};

pub use error::ImportError;

use crate::device::{ExposureTime, Frame, FrameFile, FrameFormat, Gain};
use crate::store::{FrameMeta, PoseDeg, Provenance, SessionStore, ShotKind, Snapshot, SourcePaths, write_atomic};
use camera_file::{CameraFile, read_camera_file};
use clock::{ClockSettings, OffsetSource, TrueTime};
use poses::BracketPose;
use record::{Estimate, IMPORT_FILE, ImportRecord, ImportedBracketRecord, ImportedFrameRecord};
use station_estimate::SiteGiven;

/// What `session import` is told.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// The folder of camera files.
    pub folder: PathBuf,
    /// Largest gap between one frame's end and the next frame's start
    /// within a bracket, seconds.
    pub bracket_gap_s: f64,
    /// Largest gap between brackets that share one light (an
    /// occurrence), seconds.
    pub occurrence_gap_s: f64,
    /// The camera's clock.
    pub clock: ClockSettings,
    /// Exposure times for files without ExposureTime (CSV or `PATH TIME`
    /// lines, as `hdr calibrate --list` reads).
    pub times: Option<PathBuf>,
    /// The poses file.
    pub poses: Option<PathBuf>,
    /// The scene file.
    pub scene: Option<PathBuf>,
    /// The station file (camera and site); estimated from EXIF if absent.
    pub station: Option<PathBuf>,
    /// The site, when no station file is given.
    pub site: Option<SiteGiven>,
    /// Patterns of first file names of sky brackets.
    pub sky: Vec<String>,
    /// Leave lone frames out instead of refusing them.
    pub skip_single: bool,
}

/// One photograph, read and placed.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedFrame {
    /// The file and its EXIF.
    pub file: CameraFile,
    /// Its true time.
    pub time: TrueTime,
    /// Its exposure time, seconds.
    pub exposure_time_s: f64,
    /// Where that came from.
    pub exposure_from: String,
    /// The effective time (module doc), seconds.
    pub effective_s: f64,
}

/// A bracket, placed in the session.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedBracket {
    /// Its frames, in time order.
    pub frames: Vec<ImportedFrame>,
    /// Why it began where it did.
    pub began: String,
    /// Its pose.
    pub pose: BracketPose,
    /// The pose name in the plan.
    pub pose_name: String,
    /// The head's (pan, tilt), degrees, journaled for a sky bracket (fitted
    /// as a sky scan's tiles are, through the station's mount) and for a
    /// view imported without a scene. `None` for a view with a scene: a
    /// photograph taken off the head has no head reading, and processing
    /// takes its scene pose as it is (its roll too, as `campanile register`
    /// measures it).
    pub head_deg: Option<(f64, f64)>,
    /// A zoom photograph's focal length (taken at another focal length
    /// than the session's camera), pixels per pixel of the frame's width:
    /// the station camera's, scaled by the ratio of the EXIF FocalLengths.
    /// `None`: the station camera's.
    pub focal_px_per_width: Option<f64>,
    /// Its key prefix, `{occurrence}/s{step}/t{target}`.
    pub group: String,
}

/// A folder, read and grouped, ready to write.
#[derive(Debug, Clone)]
pub struct ImportPlan {
    /// The brackets in time order.
    pub brackets: Vec<ImportedBracket>,
    /// The snapshot to write.
    pub snapshot: Snapshot,
    /// The record to write (its brackets filled by [`write_session`]).
    pub record: ImportRecord,
    /// Poses entries no bracket used.
    pub unused_poses: Vec<String>,
}

/// The files of `folder` to import: every regular file that is not
/// hidden, by name.
fn list_folder(folder: &Path) -> Result<Vec<PathBuf>, ImportError> {
    let err = |source| ImportError::Folder {
        path: folder.to_path_buf(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(err)? {
        let entry = entry.map_err(err)?;
        let hidden = entry.file_name().to_string_lossy().starts_with('.');
        if !hidden && entry.file_type().map_err(err)?.is_file() {
            files.push(entry.path());
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(ImportError::NoImages {
            path: folder.to_path_buf(),
        });
    }
    Ok(files)
}

/// Exposure times by file name from a times file.
fn read_times(path: &Path) -> Result<BTreeMap<String, f64>, ImportError> {
    let (paths, times) = campanile_process::hdr::bracket_list::read_bracket_list(path)
        .map_err(|e| ImportError::Description(format!("--times: {e}")))?;
    Ok(paths
        .iter()
        .zip(times)
        .filter_map(|(p, t)| p.file_name().map(|n| (n.to_string_lossy().into_owned(), t)))
        .collect())
}

/// Reads and groups the folder (`progress` is called after each file is
/// read); nothing is written.
pub fn plan_import(opts: &ImportOptions, progress: &dyn Fn(usize, usize)) -> Result<ImportPlan, ImportError> {
    if !(opts.bracket_gap_s.is_finite() && opts.bracket_gap_s >= 0.0) {
        return Err(ImportError::Option(format!(
            "--bracket-gap-s {}: expected seconds ≥ 0",
            opts.bracket_gap_s
        )));
    }
    let clock_offset = opts.clock.clock_offset()?;
    let paths = list_folder(&opts.folder)?;
    let mut files = Vec::with_capacity(paths.len());
    for (i, p) in paths.iter().enumerate() {
        files.push(read_camera_file(p)?);
        progress(i + 1, paths.len());
    }

    // One camera per session: one geometry, one response.
    let mut cameras: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for f in &files {
        cameras.entry(&f.camera).or_default().push(&f.name);
    }
    if cameras.len() > 1 {
        let list: Vec<String> = cameras
            .iter()
            .map(|(c, names)| format!("{c:?}: {} files, e.g. {}", names.len(), names[0]))
            .collect();
        return Err(ImportError::Grouping(format!(
            "{}: photographs from {} cameras (EXIF Make/Model/BodySerialNumber) — {}; a session has one camera \
             (one geometry, one response): import each camera's files into its own session",
            opts.folder.display(),
            cameras.len(),
            list.join("; ")
        )));
    }
    let reference_focal_mm = reference_focal_length(opts, &files)?;

    // Times and exposures.
    let times = match &opts.times {
        Some(p) => read_times(p)?,
        None => BTreeMap::new(),
    };
    let mut placed = Vec::with_capacity(files.len());
    for f in files {
        let time = opts.clock.true_time(&f)?;
        let (t, from) = match (times.get(&f.name), f.exposure_time_s) {
            (Some(&t), _) => (
                t,
                format!("--times {}", opts.times.as_deref().unwrap_or(Path::new("")).display()),
            ),
            (None, Some(t)) => (t, "EXIF ExposureTime".to_owned()),
            (None, None) => {
                return Err(ImportError::Tag {
                    path: f.path.clone(),
                    tag: "ExposureTime",
                    value: "absent".into(),
                    expected: "the exposure time, seconds: give it with --times FILE (CSV `file,time` or \
                               `NAME TIME` lines, as `hdr calibrate --list` reads)"
                        .into(),
                });
            }
        };
        placed.push((f, time, t, from));
    }
    placed.sort_by(|a, b| a.1.utc.cmp(&b.1.utc).then_with(|| a.0.name.cmp(&b.0.name)));
    let metas: Vec<(PathBuf, ExposureMetadata)> = placed
        .iter()
        .map(|(f, _, t, _)| {
            (
                f.path.clone(),
                ExposureMetadata {
                    exposure_time_s: Some(*t),
                    f_number: f.f_number,
                    iso: f.iso,
                    ..Default::default()
                },
            )
        })
        .collect();
    let effective = effective_times(&metas).map_err(|e| ImportError::Grouping(e.to_string()))?;
    let (reference_iso, reference_f_number) = (placed[0].0.iso, placed[0].0.f_number);
    let frames: Vec<ImportedFrame> = placed
        .into_iter()
        .zip(effective)
        .map(
            |((file, time, exposure_time_s, exposure_from), effective_s)| ImportedFrame {
                file,
                time,
                exposure_time_s,
                exposure_from,
                effective_s,
            },
        )
        .collect();

    // Brackets.
    let inputs: Vec<brackets::GroupingInput> = frames
        .iter()
        .map(|f| brackets::GroupingInput {
            start: f.time.utc,
            exposure_s: f.exposure_time_s,
            iso: f.file.iso,
            f_number: f.file.f_number,
            focal_length_mm: f.file.focal_length_mm,
        })
        .collect();
    let groups = brackets::group(&inputs, opts.bracket_gap_s);
    let mut skipped = Vec::new();
    let mut kept = Vec::new();
    for g in groups {
        if g.frames.len() == 1 {
            let f = &frames[g.frames[0]];
            let why = format!(
                "{}: a bracket of one frame (taken {}, {}; {}): a bracket needs two or more exposures — one JPEG \
                 cannot calibrate the response, and its clipped highlights and shadows would pass for radiance",
                f.file.path.display(),
                f.time.utc.to_rfc3339(),
                exposure_text(f.exposure_time_s),
                if g.began.is_empty() {
                    "the first frame".to_owned()
                } else {
                    format!("began {}", g.began)
                },
            );
            if opts.skip_single {
                skipped.push(why);
                continue;
            }
            return Err(ImportError::Grouping(format!(
                "{why}; remove it from the folder, raise --bracket-gap-s if it belongs to a bracket, or pass \
                 --skip-single to leave lone frames out"
            )));
        }
        kept.push(g);
    }
    if kept.is_empty() {
        return Err(ImportError::Grouping(format!(
            "{}: no bracket of two or more frames ({} lone frames left out)",
            opts.folder.display(),
            skipped.len()
        )));
    }

    // Scene, station, poses.
    let scene = match &opts.scene {
        Some(p) => {
            let loaded = campanile_config::load_scene(p).map_err(|e| ImportError::Description(e.to_string()))?;
            Some((loaded.value, loaded.source.text.clone()))
        }
        None => None,
    };
    let poses = match &opts.poses {
        Some(p) => Some(poses::read_poses(p)?),
        None => None,
    };
    let first_frame = &frames[kept[0].frames[0]];
    // The camera (estimated from EXIF, or the station file's) is the lens at
    // the session's focal length; brackets at another are zoom photographs.
    let reference_frame = kept
        .iter()
        .map(|g| &frames[g.frames[0]])
        .find(|f| f.file.focal_length_mm == reference_focal_mm)
        .unwrap_or(first_frame);
    let exposures: Vec<f64> = frames.iter().map(|f| f.effective_s).collect();
    let lo = exposures.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = exposures.iter().copied().fold(0.0, f64::max);
    let (station_ron, station_from, camera_estimates) = match (&opts.station, &opts.site) {
        (Some(p), _) => {
            let text = std::fs::read_to_string(p).map_err(|source| ImportError::Read {
                path: p.clone(),
                source,
            })?;
            campanile_config::load_station(p).map_err(|e| ImportError::Description(e.to_string()))?;
            (text, format!("station file {}", p.display()), Vec::new())
        }
        (None, Some(site)) => {
            let (image, _) =
                campanile_process::hdr::image_file::read_frame(&reference_frame.file.path).map_err(|e| {
                    ImportError::NotJpeg {
                        path: reference_frame.file.path.clone(),
                        reason: format!("it does not decode: {e}"),
                    }
                })?;
            let (text, notes) =
                station_estimate::estimate_station(&reference_frame.file, image.width, image.height, site, (lo, hi))?;
            (text, "estimated from EXIF".to_owned(), notes)
        }
        (None, None) => {
            return Err(ImportError::Option(
                "no station and no site: give --station STATION.ron (a calibrated camera and the site), or --site \
                 LAT,LON[,ELEVATION_M] to estimate the camera from EXIF (the sun's position needs the site)"
                    .into(),
            ));
        }
    };
    let station: Station = station_estimate::check_station_text(
        opts.station.as_deref().unwrap_or(Path::new("station.ron")),
        &station_ron,
    )?;

    let mut placed_brackets: Vec<ImportedBracket> = Vec::new();
    let mut made_poses: Vec<CameraPose> = Vec::new();
    let mut firsts: Vec<&str> = Vec::new();
    for g in &kept {
        let members: Vec<ImportedFrame> = g.frames.iter().map(|&i| frames[i].clone()).collect();
        let first = members[0].file.name.clone();
        let last = members[members.len() - 1].file.name.clone();
        let by_pattern = opts.sky.iter().find(|p| name_pattern::matches(p, &first));
        let pose = match &poses {
            Some(p) => p.pose_of(&first, scene.as_ref().map(|(s, _)| s))?,
            None => None,
        };
        let mut pose = pose.ok_or_else(|| {
            ImportError::Description(format!(
                "the bracket of {} frames {first} … {last} has no pose: {}",
                members.len(),
                match &opts.poses {
                    Some(p) => format!(
                        "add an entry (files: {first:?}, pose: \"NAME\") or (files: {first:?}, azimuth_deg: …, \
                         elevation_deg: …) to {}",
                        p.display()
                    ),
                    None => "give --poses POSES.ron (see `campanile session import --help`)".to_owned(),
                }
            ))
        })?;
        if let Some(p) = by_pattern {
            pose.sky = true;
            pose.from_entry = format!("{} (sky by --sky {p:?})", pose.from_entry);
        }
        let pose_name = match &pose.scene_pose {
            Some(n) => n.clone(),
            None => {
                let stem = Path::new(&first)
                    .file_stem()
                    .map_or(first.clone(), |s| s.to_string_lossy().into_owned());
                let name = format!("import-{stem}");
                made_poses.push(CameraPose {
                    name: name.clone(),
                    position_m: pose.position_m.map_or((0.0, 0.0, 0.0), |p| (p[0], p[1], p[2])),
                    azimuth_deg: pose.azimuth_deg.rem_euclid(360.0),
                    elevation_deg: pose.elevation_deg,
                    roll_deg: pose.roll_deg,
                });
                name
            }
        };
        // A view's pose is kept in the scene (the given scene's pose, or one
        // made for it), and processing takes it from there; without a scene
        // the view is journaled as a head reading, which cannot roll.
        if scene.is_none() && pose.roll_deg != 0.0 {
            return Err(ImportError::Description(format!(
                "the bracket {first} … {last} is given roll_deg {}: a rolled view needs --scene (its pose is \
                 kept among the scene's poses)",
                pose.roll_deg
            )));
        }
        let head_deg = if pose.sky || scene.is_none() {
            Some(
                crate::controller::aim::head_angles(&station, pose.azimuth_deg, pose.elevation_deg).ok_or_else(
                    || {
                        ImportError::Description(format!(
                            "the bracket {first} … {last}: azimuth {}° elevation {}° is outside the station's head \
                             limits",
                            pose.azimuth_deg, pose.elevation_deg
                        ))
                    },
                )?,
            )
        } else {
            None
        };
        let focal_px_per_width = zoom_focal(&station, &members[0], reference_focal_mm, pose.sky, &last)?;
        firsts.push(&frames[g.frames[0]].file.name);
        placed_brackets.push(ImportedBracket {
            frames: members,
            began: g.began.clone(),
            pose,
            pose_name,
            head_deg,
            focal_px_per_width,
            group: String::new(),
        });
    }
    let unused_poses: Vec<String> = poses
        .as_ref()
        .map(|p| p.unused(&firsts).map(str::to_owned).collect())
        .unwrap_or_default();

    // Occurrences and the plan.
    let start_date = placed_brackets[0].frames[0].time.utc.date_naive();
    let mut sessions: Vec<Session> = Vec::new();
    let mut occurrence_end: Option<DateTime<Utc>> = None;
    let mut sky_step: Option<usize> = None;
    let mut sky_targets = 0usize;
    for b in &mut placed_brackets {
        let start = b.frames[0].time.utc;
        let new =
            occurrence_end.is_none_or(|end| (start - end).num_milliseconds() as f64 / 1000.0 > opts.occurrence_gap_s);
        if new {
            let day = (start.date_naive() - start_date).num_days().max(0) as u32;
            sessions.push(Session {
                name: format!("import-{}", sessions.len() + 1),
                trigger: Trigger::Clock {
                    time: start.time(),
                    day,
                },
                repeat: campanile_config::plan::Repeat::Once,
                held_out: false,
                steps: Vec::new(),
            });
            sky_step = None;
            sky_targets = 0;
        }
        let last = &b.frames[b.frames.len() - 1];
        occurrence_end = Some(last.time.utc + chrono::Duration::nanoseconds((last.exposure_time_s * 1e9) as i64));
        let Some(session) = sessions.last_mut() else { continue };
        let occurrence = format!("{}@{}", session.name, start.date_naive());
        let exposures_s: Vec<f64> = b.frames.iter().map(|f| f.effective_s).collect();
        b.group = if b.pose.sky {
            let step = *sky_step.get_or_insert_with(|| {
                session.steps.push(Step::SkyScan {
                    min_elevation_deg: 0.0,
                    overlap: 0.0,
                    aureole_bands_deg: Vec::new(),
                    on_error: ErrorPolicy::default(),
                });
                session.steps.len() - 1
            });
            let target = sky_targets;
            sky_targets += 1;
            format!("{occurrence}/s{step}/t{target}")
        } else {
            session.steps.push(Step::Bracket {
                aim: Aim::Pose(b.pose_name.clone()),
                exposures_s,
                filter: None,
                on_error: ErrorPolicy::default(),
            });
            format!("{occurrence}/s{}/t0", session.steps.len() - 1)
        };
    }
    let plan = Plan {
        name: format!("imported from {}", opts.folder.display()),
        start_date,
        scene: opts.scene.as_ref().map(|_| PathBuf::from("scene.ron")),
        sessions,
        quality: None,
    };
    let plan_ron = format!(
        "// Made by `campanile session import` from {}: one session per time\n// the light was photographed at, one step per bracket (sky brackets as a sky scan).\n{}\n",
        opts.folder.display(),
        ron::ser::to_string_pretty(&plan, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| ImportError::Description(format!("the generated plan: {e}")))?
    );
    let scene_ron = match &scene {
        Some((_, text)) if made_poses.is_empty() => Some(text.clone()),
        Some((s, _)) => {
            let mut s: Scene = s.clone();
            s.poses.extend(made_poses.iter().cloned());
            Some(format!(
                "// The scene of {}, with the poses given in the poses file added (import-…).\n{}\n",
                opts.scene.as_deref().unwrap_or(Path::new("")).display(),
                ron::ser::to_string_pretty(&s, ron::ser::PrettyConfig::default().struct_names(true))
                    .map_err(|e| ImportError::Description(format!("the scene with the given poses: {e}")))?
            ))
        }
        None => None,
    };
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let sources = opts.scene.as_ref().map(|scene| SourcePaths {
        plan: absolute(&opts.folder),
        station: opts.station.as_deref().map_or_else(|| absolute(&opts.folder), absolute),
        scene: Some(absolute(scene)),
    });
    let snapshot = Snapshot {
        plan_ron,
        station_ron,
        scene_ron,
        provenance: Provenance {
            campanile_version: env!("CARGO_PKG_VERSION").to_owned(),
            created_utc: Utc::now(),
            calibration: Vec::new(),
            sources,
        },
    };

    // What was estimated.
    let mut estimated = Vec::new();
    let all = |v: &[&str]| v.iter().map(|s| (*s).to_owned()).collect::<Vec<String>>();
    if !camera_estimates.is_empty() {
        estimated.push(Estimate {
            what: "camera".into(),
            how: format!(
                "camera estimated from EXIF, not calibrated: {}",
                camera_estimates.join("; ")
            ),
            affects: all(&["radiance", "sun", "sky", "environment", "pseudo-albedos"]),
        });
    }
    let offsets: BTreeMap<String, usize> =
        placed_brackets
            .iter()
            .flat_map(|b| &b.frames)
            .fold(BTreeMap::new(), |mut m, f| {
                let from = match f.time.offset_from {
                    OffsetSource::Exif => "EXIF OffsetTimeOriginal",
                    OffsetSource::Stated => "--utc-offset",
                };
                *m.entry(format!("{} ({from})", f.time.utc_offset)).or_default() += 1;
                m
            });
    estimated.push(Estimate {
        what: "time".into(),
        how: format!(
            "time from EXIF DateTimeOriginal with a stated clock offset of {clock_offset} s (--clock-offset-s) and \
             UTC offset {}",
            offsets
                .iter()
                .map(|(o, n)| format!("{o} for {n} frames"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        affects: all(&["sun", "sky", "pseudo-albedos"]),
    });
    estimated.push(Estimate {
        what: "exposure".into(),
        how: "exposure from EXIF (ExposureTime, FNumber, ISO as labelled by the camera), not measured".into(),
        affects: all(&["response", "radiance"]),
    });
    let zooms: Vec<String> = placed_brackets
        .iter()
        .filter(|b| b.focal_px_per_width.is_some())
        .map(|b| {
            format!(
                "{} (FocalLength {} mm)",
                b.frames[0].file.name,
                b.frames[0].file.focal_length_mm.unwrap_or(f64::NAN)
            )
        })
        .collect();
    if !zooms.is_empty() {
        estimated.push(Estimate {
            what: "zoom".into(),
            how: format!(
                "zoom photographs' focal lengths from EXIF: the camera's at {} mm scaled by FocalLength / {} mm, an \
                 undistorted lens centred on the frame with no falloff: {}",
                reference_focal_mm.unwrap_or(f64::NAN),
                reference_focal_mm.unwrap_or(f64::NAN),
                zooms.join(", ")
            ),
            affects: all(&["zoom"]),
        });
    }
    let views = placed_brackets.iter().filter(|b| !b.pose.sky).count();
    let skies = placed_brackets.len() - views;
    if skies == 0 {
        estimated.push(Estimate {
            what: "sky".into(),
            how: "no sky frames were imported: the sky is not measured (process estimates it from the CIE clear-sky model, scaled by the views' sky pixels, and the photographs' sunlit/shadowed ratio)".into(),
            affects: all(&["sky", "pseudo-albedos"]),
        });
    }
    estimated.push(Estimate {
        what: "sun".into(),
        how: "no filtered sun shots in hand-taken brackets: the sun's irradiance is not measured".into(),
        affects: all(&["sun", "pseudo-albedos"]),
    });
    let record = ImportRecord {
        folder: opts.folder.display().to_string(),
        camera: first_frame.file.camera.clone(),
        clock_offset_s: clock_offset,
        clock_offset_from: "--clock-offset-s".into(),
        bracket_gap_s: opts.bracket_gap_s,
        exposure_rule: "exposure_requested_s is ExposureTime (EXIF or --times); exposure_actual_s is the effective \
                        time t · (ISO/ISO₀) · (N₀/N)² at the reference ISO and f-number"
            .into(),
        reference_iso,
        reference_f_number,
        station_from,
        brackets: Vec::new(),
        skipped,
        estimated,
    };
    Ok(ImportPlan {
        brackets: placed_brackets,
        snapshot,
        record,
        unused_poses,
    })
}

/// The session's focal length, mm: the one most of the files were taken
/// at (the first file's among equals). Files at another are zoom
/// photographs, which need every file's FocalLength, and a scene (a zoom
/// photograph is processed at its scene pose, off the head).
fn reference_focal_length(opts: &ImportOptions, files: &[CameraFile]) -> Result<Option<f64>, ImportError> {
    let Some(first) = files.first() else {
        return Ok(None);
    };
    if files.iter().all(|f| f.focal_length_mm == first.focal_length_mm) {
        return Ok(first.focal_length_mm);
    }
    if let Some(f) = files.iter().find(|f| f.focal_length_mm.is_none()) {
        return Err(ImportError::Tag {
            path: f.path.clone(),
            tag: "FocalLength",
            value: "absent".into(),
            expected: format!(
                "the focal length, mm, as the other files have (e.g. {:?} mm in {}): photographs at several focal \
                 lengths are told apart by it",
                files.iter().find_map(|f| f.focal_length_mm),
                files
                    .iter()
                    .find(|f| f.focal_length_mm.is_some())
                    .map_or("", |f| f.name.as_str())
            ),
        });
    }
    let mut counts: Vec<(f64, usize)> = Vec::new();
    for f in files.iter().filter_map(|f| f.focal_length_mm) {
        match counts.iter_mut().find(|(v, _)| *v == f) {
            Some((_, n)) => *n += 1,
            None => counts.push((f, 1)),
        }
    }
    let most = counts.iter().map(|(_, n)| *n).max().unwrap_or(0);
    let reference = counts.iter().find(|(_, n)| *n == most).map(|(v, _)| *v);
    if opts.scene.is_none() {
        let other = files
            .iter()
            .find(|f| f.focal_length_mm != reference)
            .map_or_else(String::new, |f| format!("{} at {:?} mm", f.name, f.focal_length_mm));
        return Err(ImportError::Option(format!(
            "{}: photographs at {} focal lengths (most at {:?} mm; {other}): a zoom photograph is processed at its \
             scene pose, off the head: give --scene SCENE.ron with the poses, or import each focal length as its own \
             session",
            opts.folder.display(),
            counts.len(),
            reference
        )));
    }
    Ok(reference)
}

/// The focal length, pixels per pixel of the frame's width, of a bracket
/// whose first frame is `frame`, when it was taken at another focal length
/// than the session's `reference_mm`: the station camera's scaled by the
/// ratio of the two. A sky bracket must be at the session's (it is fitted
/// through the station's lens), and a zoom needs a rectilinear lens.
fn zoom_focal(
    station: &Station,
    frame: &ImportedFrame,
    reference_mm: Option<f64>,
    sky: bool,
    last: &str,
) -> Result<Option<f64>, ImportError> {
    let (Some(f), Some(reference)) = (frame.file.focal_length_mm, reference_mm) else {
        return Ok(None);
    };
    if f == reference {
        return Ok(None);
    }
    let first = &frame.file.name;
    let bad = |why: String| {
        Err(ImportError::Tag {
            path: frame.file.path.clone(),
            tag: "FocalLength",
            value: format!("{f} mm"),
            expected: why,
        })
    };
    if !(f.is_finite() && f > 0.0) {
        return bad("a focal length > 0 mm".into());
    }
    if sky {
        return bad(format!(
            "{reference} mm, the session's focal length, for the sky bracket {first} … {last}: sky frames are fitted \
             through the station's lens"
        ));
    }
    let i = &station.camera.intrinsics;
    if !i.projection.is_pinhole() {
        return bad(format!(
            "{reference} mm, the session's focal length: the station's lens is a {:?} fisheye, and a zoom \
             photograph is taken as a rectilinear lens",
            i.projection
        ));
    }
    let width = station.camera.resolution.width;
    Ok(Some(
        i.focal.pixels_for(i.projection, width) / f64::from(width) * f / reference,
    ))
}

fn exposure_text(t: f64) -> String {
    if t < 1.0 {
        format!("ExposureTime 1/{:.0} s", 1.0 / t)
    } else {
        format!("ExposureTime {t} s")
    }
}

/// Writes `plan` as a new session in `out` (absent or empty) through the
/// store: the snapshot, every frame byte for byte with its journal line
/// (`progress` after each), then the import record. Returns the record.
pub fn write_session(
    plan: &ImportPlan,
    out: &Path,
    progress: &dyn Fn(usize, usize),
) -> Result<ImportRecord, ImportError> {
    let mut store = SessionStore::create(out, plan.snapshot.clone())?;
    let total: usize = plan.brackets.iter().map(|b| b.frames.len()).sum();
    let mut record = plan.record.clone();
    let mut sequence = 0u64;
    for b in &plan.brackets {
        let mut frames = Vec::with_capacity(b.frames.len());
        let mut focal_px = None;
        for (k, f) in b.frames.iter().enumerate() {
            let path = &f.file.path;
            let bytes = std::fs::read(path).map_err(|source| ImportError::Read {
                path: path.clone(),
                source,
            })?;
            if let Some(reason) = FrameFormat::Jpeg.end_problem(&bytes) {
                return Err(ImportError::NotJpeg {
                    path: path.clone(),
                    reason,
                });
            }
            let (image, _) = campanile_process::hdr::image_file::read_frame_bytes(path, &bytes).map_err(|e| {
                ImportError::NotJpeg {
                    path: path.clone(),
                    reason: format!("it does not decode: {e}"),
                }
            })?;
            let key = format!("{}/f{k}", b.group);
            let exposure = |s: f64| {
                ExposureTime::from_seconds(s).ok_or_else(|| ImportError::Tag {
                    path: path.clone(),
                    tag: "ExposureTime",
                    value: s.to_string(),
                    expected: "seconds > 0".into(),
                })
            };
            let frame = Frame {
                width: image.width,
                height: image.height,
                bits: image.bits,
                data: image.data,
                exposure_requested: exposure(f.exposure_time_s)?,
                exposure_actual: exposure(f.effective_s)?,
                gain: Gain::UNITY,
                sequence,
                timestamp: f.time.utc,
                temperature_c: None,
                file: Some(FrameFile {
                    format: FrameFormat::Jpeg,
                    bytes,
                }),
            };
            let head = b.head_deg.map(|(pan_deg, tilt_deg)| PoseDeg { pan_deg, tilt_deg });
            let mut meta = FrameMeta::from_frame(&frame, ShotKind::Data);
            meta.pose_requested = head;
            meta.pose_reached = head;
            meta.focal_px = b.focal_px_per_width.map(|f| f * frame.width as f64);
            focal_px = focal_px.or(meta.focal_px);
            meta.notes.push(format!(
                "imported from {}: DateTimeOriginal {}, {}{}{}",
                f.file.name,
                f.file.date_time_original,
                exposure_text(f.exposure_time_s),
                f.file.f_number.map_or(String::new(), |n| format!(", FNumber {n}")),
                f.file.iso.map_or(String::new(), |s| format!(", ISO {s}")),
            ));
            store.record_frame(&key, &meta, &frame)?;
            sequence += 1;
            progress(sequence as usize, total);
            frames.push(ImportedFrameRecord {
                file: f.file.name.clone(),
                key,
                date_time_original: f.file.date_time_original.clone(),
                utc: f.time.utc.to_rfc3339(),
                utc_offset: f.time.utc_offset.to_string(),
                utc_offset_from: match f.time.offset_from {
                    OffsetSource::Exif => "EXIF OffsetTimeOriginal".into(),
                    OffsetSource::Stated => "--utc-offset".into(),
                },
                exposure_time_s: f.exposure_time_s,
                exposure_time_from: f.exposure_from.clone(),
                iso: f.file.iso,
                f_number: f.file.f_number,
                effective_exposure_s: f.effective_s,
            });
        }
        record.brackets.push(ImportedBracketRecord {
            group: b.group.clone(),
            purpose: if b.pose.sky { "sky" } else { "view" }.into(),
            pose: b.pose_name.clone(),
            azimuth_deg: b.pose.azimuth_deg,
            elevation_deg: b.pose.elevation_deg,
            position_m: b.pose.position_m,
            head_deg: b.head_deg.map(|(pan, tilt)| [pan, tilt]),
            focal_px,
            from: b.pose.from_entry.clone(),
            began: b.began.clone(),
            frames,
        });
    }
    let mut json =
        serde_json::to_vec_pretty(&record).map_err(|e| ImportError::Description(format!("the import record: {e}")))?;
    json.push(b'\n');
    write_atomic(&crate::store::FsStorage, out, IMPORT_FILE, &json).map_err(|e| {
        ImportError::Store(crate::store::StoreError::Io {
            action: e.action,
            path: e.path,
            source: e.source,
        })
    })?;
    Ok(record)
}
