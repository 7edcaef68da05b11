//! `campanile sky calibrate`: a fixed sky camera calibrated from one day's
//! sun centroids (a CSV) and the station's site and nominal camera, through
//! [`campanile_process::sky_camera_calibration`], as the
//! [`CameraCalibration`] file the station takes, a report and verdicts.

use std::path::Path;

use anyhow::Context;
use campanile_config::camera::{Focal, Intrinsics};
use campanile_config::camera_calibration::CameraCalibration;
use campanile_config::head::MountCalibration;
use campanile_process::pose::{HeadPose, Mount, Pinhole};
use campanile_process::quality::{Better, Check, Gate, ProductQuality, Quality, QualityReport};
use campanile_process::sky_camera_calibration::{
    CalibrationOptions, SkyCameraCalibration, SkyCameraModel, SunSighting, calibrate_sky_camera, calibration_report,
};
use chrono::{DateTime, Utc};

use crate::error::{Error, Result};
use crate::site::observer;

/// The product's name in `quality.json`.
pub const PRODUCT: &str = "sky camera calibration";

/// What `sky calibrate` made.
#[derive(Debug, Clone)]
pub struct SkyCalibration {
    /// The calibrated camera, as the station file takes it.
    pub file: CameraCalibration,
    /// The fit, with every figure.
    pub fit: SkyCameraCalibration,
    /// The report in words.
    pub report: String,
    /// The verdict, as `quality.json`.
    pub quality: QualityReport,
}

/// Reads sun centroids from a CSV with a header row: `time` (or
/// `time_utc`; RFC 3339), `u_px` and `v_px` (the disc's centroid, pixels,
/// pixel centres at half-integers, at the camera's configured
/// resolution). Other columns are ignored.
pub fn read_sightings(path: &Path) -> Result<Vec<SunSighting>> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
    let headers = reader
        .headers()
        .map_err(|e| Error::input(format!("{}: {e}", path.display())))?
        .clone();
    let column = |names: &[&str]| {
        headers
            .iter()
            .position(|h| names.iter().any(|n| h.eq_ignore_ascii_case(n)))
    };
    let (Some(t), Some(u), Some(v)) = (column(&["time", "time_utc"]), column(&["u_px"]), column(&["v_px"])) else {
        return Err(Error::input(format!(
            "{}: header {:?}: expected the columns time (or time_utc), u_px and v_px",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        )));
    };
    let mut out = Vec::new();
    for (row, record) in reader.records().enumerate() {
        let line = row + 2;
        let record = record.map_err(|e| Error::input(format!("{}: {e}", path.display())))?;
        let cell = |i: usize| record.get(i).unwrap_or("");
        let time: DateTime<Utc> = DateTime::parse_from_rfc3339(cell(t))
            .map_err(|e| {
                Error::input(format!(
                    "{}:{line}: time {:?}: expected an RFC 3339 instant such as 2026-06-21T18:00:00Z ({e})",
                    path.display(),
                    cell(t)
                ))
            })?
            .with_timezone(&Utc);
        let number = |i: usize, name: &str| -> Result<f64> {
            cell(i).parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                Error::input(format!(
                    "{}:{line}: {name} {:?}: expected a pixel position (a finite number)",
                    path.display(),
                    cell(i)
                ))
            })
        };
        out.push(SunSighting {
            time,
            centroid_px: (number(u, "u_px")?, number(v, "v_px")?),
        });
    }
    Ok(out)
}

/// Calibrates the camera of the station file `station` held at `head`
/// (degrees: pan, tilt) from the sun centroids in `shots`.
pub fn calibrate_files(
    shots: &Path,
    station: &Path,
    head_deg: (f64, f64),
    options: &CalibrationOptions,
) -> Result<SkyCalibration> {
    let station = campanile_config::load_station(station)
        .map_err(|e| Error::input(e.to_string()))?
        .value;
    let sightings = read_sightings(shots)?;
    let nominal = SkyCameraModel {
        camera: Pinhole::of_camera(&station.camera),
        mount: Mount::of_calibration(&station.head.mount),
        head: HeadPose {
            pan_rad: head_deg.0.to_radians(),
            tilt_rad: head_deg.1.to_radians(),
        },
    };
    let fit = calibrate_sky_camera(
        &sightings,
        &observer(&station.site),
        station.site.delta_t_s,
        &nominal,
        options,
    )
    .with_context(|| format!("calibrating from {}", shots.display()))?;
    let m = &fit.model;
    let file = CameraCalibration {
        resolution: station.camera.resolution,
        intrinsics: Intrinsics {
            focal: Focal::Pixels(m.camera.focal_px),
            projection: m.camera.projection,
            principal_point_px: Some(m.camera.principal_px),
            distortion: (m.camera.k1, m.camera.k2),
            falloff: station.camera.intrinsics.falloff,
        },
        mount: MountCalibration {
            pan_zero_azimuth_deg: m.mount.pan_zero_azimuth_rad.to_degrees().rem_euclid(360.0),
            tilt_zero_deg: m.mount.tilt_zero_rad.to_degrees(),
            level_roll_deg: m.mount.roll_rad.to_degrees(),
            level_pitch_deg: m.mount.pitch_rad.to_degrees(),
        },
        // The sun fixes the orientation only; the head stays where the
        // station file puts it.
        head_position_m: None,
    };
    let quality = QualityReport::new(vec![product_quality(&fit, options)], &Quality::default());
    Ok(SkyCalibration {
        report: calibration_report(&fit),
        file,
        fit,
        quality,
    })
}

/// The calibration's verdict as a product of `quality.json`: its figures
/// against the options' thresholds.
pub fn product_quality(fit: &SkyCameraCalibration, o: &CalibrationOptions) -> ProductQuality {
    if !fit.fitted {
        return ProductQuality::not_made(PRODUCT, fit.reasons.join("; "));
    }
    let gate = |poor, failed| Gate { poor, failed };
    let orientation_sigma = fit.parameters.iter().take(3).map(|p| p.sigma).fold(0.0, f64::max);
    let mut checks = vec![
        Check::new(
            "RMS residual (degrees)",
            fit.rms_residual_deg,
            gate(o.poor_residual_deg, o.failed_residual_deg),
            Better::Lower,
        ),
        Check::new(
            "the sun's track (degrees)",
            fit.track_span_deg,
            gate(o.poor_track_deg, o.failed_track_deg),
            Better::Higher,
        ),
        Check::new(
            "orientation σ (degrees)",
            orientation_sigma,
            gate(o.poor_orientation_sigma_deg, o.failed_orientation_sigma_deg),
            Better::Lower,
        ),
        Check::new(
            format!(
                "|correlation| of {} and {}",
                fit.strongest_correlation.0, fit.strongest_correlation.1
            ),
            fit.strongest_correlation.2.abs(),
            gate(o.poor_correlation, o.failed_correlation),
            Better::Lower,
        ),
        Check::new(
            "sun shots rejected (fraction)",
            fit.rejected.len() as f64 / fit.shots.max(1) as f64,
            gate(o.poor_rejected_fraction, 2.0 * o.poor_rejected_fraction),
            Better::Lower,
        ),
    ];
    if !fit.converged {
        checks.push(Check::new(
            "converged (1 yes, 0 no)",
            0.0,
            gate(0.5, -1.0),
            Better::Higher,
        ));
    }
    let mut q = ProductQuality::new(PRODUCT, checks);
    for r in &fit.rejected {
        q = q.with_note(format!(
            "rejected shot {} at {}: {}",
            r.index,
            r.time.to_rfc3339(),
            r.reason
        ));
    }
    q
}

/// The calibration file's text: RON with its struct names, so that
/// `campanile config check` and the loaders know its kind.
pub fn calibration_ron(file: &CameraCalibration) -> Result<String> {
    let config = ron::ser::PrettyConfig::default().struct_names(true);
    Ok(ron::ser::to_string_pretty(file, config).context("writing the calibration as RON")? + "\n")
}
