//! `campanile station calibrate-mount`: the head's mount calibration (its
//! pan and tilt zero, the base's level) and the tripod's place, from
//! photographs taken from the head and registered from targets
//! (`campanile register`'s poses file) and the head's reading at each
//! (a CSV). Written as the [`CameraCalibration`] file that `campanile
//! process --camera-calibration` and the station take, with a verdict.

use std::path::Path;

use campanile_config::camera_calibration::CameraCalibration;
use campanile_config::head::MountCalibration;
use campanile_process::pose::HeadPose;
use campanile_process::quality::{Better, Check, Gate, ProductQuality, Quality, QualityReport};
use campanile_process::registration::mount::{HeadView, MountFit, MountLimits, fit_mount};
use campanile_process::registration::{CameraPose, Verdict};
use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::register_files::RegisteredPoses;

/// The product's name in `quality.json`.
pub const PRODUCT: &str = "mount calibration";

/// A head reading, as the readings CSV gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The photograph's pose name in the poses file (its file stem).
    pub photo: String,
    /// The head's reading.
    pub head: HeadPose,
}

/// What `calibrate-mount` made.
#[derive(Debug, Clone)]
pub struct MountCalibrationRun {
    /// The calibration file.
    pub file: CameraCalibration,
    /// The fit, with every figure.
    pub fit: MountFit,
    /// The photographs used, in fit order.
    pub used: Vec<String>,
    /// Photographs read but not used, each with why.
    pub skipped: Vec<String>,
    /// The report in words.
    pub report: String,
    /// The verdict, as `quality.json`.
    pub quality: QualityReport,
}

/// Reads head readings from a CSV with a header row: `photo` (a pose name
/// in the poses file, i.e. the photograph's file stem; a path is reduced
/// to its stem), `pan_deg` and `tilt_deg`. Other columns are ignored.
pub fn read_readings(path: &Path) -> Result<Vec<Reading>> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
    let headers = reader
        .headers()
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let (Some(photo), Some(pan), Some(tilt)) = (column("photo"), column("pan_deg"), column("tilt_deg")) else {
        return Err(Error::input(format!(
            "{}: header {:?}: expected the columns photo, pan_deg and tilt_deg",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        )));
    };
    let mut out: Vec<Reading> = Vec::new();
    for (row, record) in reader.records().enumerate() {
        let line = row + 2;
        let record = record.map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
        let cell = |i: usize| record.get(i).unwrap_or("");
        let angle = |i: usize, name: &str| -> Result<f64> {
            cell(i)
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && x.abs() <= 720.0)
                .ok_or_else(|| {
                    Error::input(format!(
                        "{}:{line}: {name} {:?}: expected the head's reading in degrees (a number within ±720)",
                        path.display(),
                        cell(i)
                    ))
                })
        };
        let name = Path::new(cell(photo))
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if name.is_empty() {
            return Err(Error::input(format!(
                "{}:{line}: photo {:?}: expected the photograph's name (its file stem in the poses file)",
                path.display(),
                cell(photo)
            )));
        }
        if out.iter().any(|r| r.photo == name) {
            return Err(Error::input(format!(
                "{}:{line}: photo {name:?} is listed twice: expected one reading per photograph",
                path.display()
            )));
        }
        out.push(Reading {
            photo: name,
            head: HeadPose {
                pan_rad: angle(pan, "pan_deg")?.to_radians(),
                tilt_rad: angle(tilt, "tilt_deg")?.to_radians(),
            },
        });
    }
    if out.is_empty() {
        return Err(Error::input(format!(
            "{}: no readings: expected a row per registered photograph taken from the head",
            path.display()
        )));
    }
    Ok(out)
}

/// The registered view of each reading found in `poses` with a pose and
/// stated uncertainties; the others are skipped, each with why.
fn views(readings: &[Reading], poses: &RegisteredPoses) -> (Vec<HeadView>, Vec<String>, Vec<String>) {
    let (mut views, mut used, mut skipped) = (Vec::new(), Vec::new(), Vec::new());
    for r in readings {
        let Some(photo) = poses.photos.iter().find(|p| p.name == r.photo) else {
            skipped.push(format!("{}: not in the poses file", r.photo));
            continue;
        };
        let pose = poses.poses.iter().find(|p| p.name == r.photo);
        let (Some(pose), Some(roll), Some(sa), Some(sp)) = (
            pose,
            photo.roll_deg,
            photo.quality.sigma_angle_deg,
            photo.quality.sigma_position_m,
        ) else {
            skipped.push(format!(
                "{}: registration {} ({})",
                r.photo,
                photo.quality.verdict,
                photo.quality.reasons.join("; ")
            ));
            continue;
        };
        if photo.quality.verdict == Verdict::Failed {
            skipped.push(format!("{}: registration failed", r.photo));
            continue;
        }
        let (x, y, z) = pose.position_m;
        views.push(HeadView {
            head: r.head,
            pose: CameraPose::from_angles(pose.azimuth_deg, pose.elevation_deg, roll, Vector3::new(x, y, z)),
            sigma_angle_rad: sa.iter().copied().fold(0.0, f64::max).to_radians(),
            sigma_position_m: sp.iter().copied().fold(0.0, f64::max),
        });
        used.push(r.photo.clone());
    }
    (views, used, skipped)
}

/// Calibrates the head of the station file `station` from the poses file
/// `poses` (`campanile register`'s) and the head readings in `readings`.
pub fn calibrate_mount_files(
    poses: &Path,
    readings: &Path,
    station: &Path,
    limits: &MountLimits,
) -> Result<MountCalibrationRun> {
    let station = campanile_config::load_station(station)
        .map_err(|e| Error::input(e.to_string()))?
        .value;
    let text = std::fs::read_to_string(poses).map_err(|e| Error::input(format!("{}: {e}", poses.display())))?;
    let registered: RegisteredPoses = ron::from_str(&text).map_err(|e| {
        Error::input(format!(
            "{}: {e}: expected the RegisteredPoses(...) file `campanile register --out` writes",
            poses.display()
        ))
    })?;
    let readings = read_readings(readings)?;
    let (views, used, skipped) = views(&readings, &registered);
    if views.is_empty() {
        return Err(Error::input(format!(
            "{}: none of the {} photographs in the readings has a registered pose ({})",
            poses.display(),
            readings.len(),
            skipped.join("; ")
        )));
    }
    let fit = fit_mount(&views, limits).map_err(|e| Error::input(e.to_string()))?;
    let m = &fit.mount;
    let file = CameraCalibration {
        resolution: station.camera.resolution,
        intrinsics: station.camera.intrinsics.clone(),
        mount: MountCalibration {
            pan_zero_azimuth_deg: m.pan_zero_azimuth_rad.to_degrees().rem_euclid(360.0),
            tilt_zero_deg: m.tilt_zero_rad.to_degrees(),
            level_roll_deg: m.roll_rad.to_degrees(),
            level_pitch_deg: m.pitch_rad.to_degrees(),
        },
        head_position_m: Some((fit.position.x, fit.position.y, fit.position.z)),
    };
    let quality = QualityReport::new(vec![product_quality(&fit, limits, &skipped)], &Quality::default());
    Ok(MountCalibrationRun {
        report: report(&file, &fit, &used, &skipped),
        file,
        fit,
        used,
        skipped,
        quality,
    })
}

/// The calibration's verdict as a product of `quality.json`: `poor` at the
/// limits, `failed` at four times them, `not made` when the views do not
/// fix the four angles.
pub fn product_quality(fit: &MountFit, limits: &MountLimits, skipped: &[String]) -> ProductQuality {
    let Some(sigma) = fit.sigma_deg else {
        return ProductQuality::not_made(PRODUCT, fit.reasons.join("; "));
    };
    let gate = |poor: f64| Gate {
        poor,
        failed: 4.0 * poor,
    };
    let worst = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let mut q = ProductQuality::new(
        PRODUCT,
        vec![
            Check::new(
                "mount angle σ (degrees)",
                worst(&sigma),
                gate(limits.max_sigma_angle_deg),
                Better::Lower,
            ),
            Check::new(
                "worst view residual (degrees)",
                worst(&fit.residuals_deg),
                gate(limits.max_residual_deg),
                Better::Lower,
            ),
            Check::new(
                "centre spread (metres)",
                worst(&fit.centre_offsets_m),
                gate(limits.max_centre_spread_m),
                Better::Lower,
            ),
        ],
    );
    for r in fit.reasons.iter().chain(skipped) {
        q = q.with_note(r.clone());
    }
    q
}

fn report(file: &CameraCalibration, fit: &MountFit, used: &[String], skipped: &[String]) -> String {
    let m = &file.mount;
    let mut s = format!(
        "mount from {} registered view(s): pan zero at azimuth {:.4}°, tilt zero {:.4}°, base roll {:.4}°, pitch {:.4}°\n",
        used.len(),
        m.pan_zero_azimuth_deg,
        m.tilt_zero_deg,
        m.level_roll_deg,
        m.level_pitch_deg
    );
    match fit.sigma_deg {
        Some(sd) => {
            s += &format!(
                "  one sigma: {:.4}°, {:.4}°, {:.4}°, {:.4}°\n",
                sd[0], sd[1], sd[2], sd[3]
            )
        }
        None => s += "  the views do not fix all four angles\n",
    }
    s += &format!(
        "  head at ({:.4}, {:.4}, {:.4}) m\n",
        fit.position.x, fit.position.y, fit.position.z
    );
    for (i, name) in used.iter().enumerate() {
        s += &format!(
            "  {name}: {:.4}° from the mount's prediction, centre {:.1} mm from the head\n",
            fit.residuals_deg[i],
            1e3 * fit.centre_offsets_m[i]
        );
    }
    for k in skipped {
        s += &format!("  skipped {k}\n");
    }
    s += &format!("verdict: {}", fit.verdict);
    if !fit.reasons.is_empty() {
        s += &format!(" ({})", fit.reasons.join("; "));
    }
    s + "\n"
}
