//! The zenith-to-horizon profile of a sky scan in the sun's vertical plane
//! (the almucantar's companion, the "principal plane"): measured radiance
//! binned along it, and the fitted eq. (5.9) sky at the bin centres. One
//! profile per scan is one column of the day's keogram.

use serde::{Deserialize, Serialize};

use super::sky_pixels::for_each_sky_pixel;
use crate::pipeline::{MergedGroup, SUN_MARGIN_RAD, StationOptics};
use crate::sky::{SkyAngles, SkyModel, angle_between, direction};
use crate::sun::SunPosition;

/// Width of a profile bin, degrees.
pub const PROFILE_BIN_DEG: f64 = 5.0;
/// Bins from the horizon under the sun, through the zenith, to the horizon opposite.
pub const PROFILE_BINS: usize = 36;
/// Largest angle off the sun's vertical plane of a pixel counted in a bin, degrees.
pub const PROFILE_HALF_WIDTH_DEG: f64 = 5.0;

/// One scan's profile in the sun's vertical plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeridianProfile {
    /// Centre of each bin: signed zenith angle, degrees, positive toward the
    /// sun's azimuth (so +87.5 is just above the horizon under the sun and
    /// −87.5 just above the opposite horizon).
    pub signed_zenith_deg: Vec<f64>,
    /// Mean measured radiance per channel in each bin, W·m⁻²·sr⁻¹ (`None`:
    /// no valid pixel fell in it, e.g. within 3° of the sun).
    pub measured: Vec<Option<[f64; 3]>>,
    /// Valid pixels averaged per bin.
    pub pixels: Vec<usize>,
    /// The fitted sky per channel at each bin centre, W·m⁻²·sr⁻¹ (`None`: no fit).
    pub fitted: Option<Vec<[f64; 3]>>,
}

/// The direction of a signed zenith angle in the vertical plane of azimuth `azimuth_rad`.
pub fn plane_direction(signed_zenith_rad: f64, azimuth_rad: f64) -> [f64; 3] {
    if signed_zenith_rad >= 0.0 {
        direction(signed_zenith_rad, azimuth_rad)
    } else {
        direction(-signed_zenith_rad, azimuth_rad + std::f64::consts::PI)
    }
}

/// The profile of the sky groups of `occurrence` in `merged` (every
/// `stride`-th pixel in each direction), with the fitted `models` if any.
pub fn meridian_profile(
    merged: &[MergedGroup],
    optics: &StationOptics,
    occurrence: &str,
    sun: &SunPosition,
    models: Option<&[SkyModel; 3]>,
    stride: usize,
) -> MeridianProfile {
    let az = sun.azimuth_rad;
    let (u, n) = ([az.sin(), az.cos(), 0.0], [az.cos(), -az.sin(), 0.0]);
    let sun_dir = sun.direction();
    let max_off = PROFILE_HALF_WIDTH_DEG.to_radians().sin();
    let mut sum = vec![[0.0f64; 3]; PROFILE_BINS];
    let mut count = vec![0usize; PROFILE_BINS];
    for_each_sky_pixel(merged, optics, occurrence, stride, |d, rgb| {
        let off = d[0] * n[0] + d[1] * n[1];
        if d[2] <= 0.0 || off.abs() > max_off || angle_between(d, sun_dir) < SUN_MARGIN_RAD {
            return;
        }
        let along = d[0] * u[0] + d[1] * u[1];
        let s = along.atan2(d[2]).to_degrees();
        let bin = ((s + 90.0) / PROFILE_BIN_DEG).floor();
        if !(0.0..PROFILE_BINS as f64).contains(&bin) {
            return;
        }
        if rgb.iter().all(|v| v.is_finite()) {
            let b = bin as usize;
            (0..3).for_each(|c| sum[b][c] += rgb[c]);
            count[b] += 1;
        }
    });
    let centres: Vec<f64> = (0..PROFILE_BINS)
        .map(|i| -90.0 + PROFILE_BIN_DEG * (i as f64 + 0.5))
        .collect();
    let fitted = models.map(|m| {
        centres
            .iter()
            .map(|&s| {
                let d = plane_direction(s.to_radians(), az);
                let (xi, gamma) = (d[2].clamp(-1.0, 1.0).acos(), angle_between(d, sun_dir));
                let at = SkyAngles::new(xi, gamma);
                [0, 1, 2].map(|c| m[c].radiance_at(&at))
            })
            .collect()
    });
    MeridianProfile {
        signed_zenith_deg: centres,
        measured: sum
            .iter()
            .zip(&count)
            .map(|(s, &k)| (k > 0).then(|| s.map(|v| v / k as f64)))
            .collect(),
        pixels: count,
        fitted,
    }
}

impl MeridianProfile {
    /// RMS of fitted/measured − 1 over the bins with both, per channel (`None`: no such bin).
    pub fn rms_relative(&self) -> Option<[f64; 3]> {
        let fitted = self.fitted.as_ref()?;
        let pairs: Vec<([f64; 3], [f64; 3])> = self
            .measured
            .iter()
            .zip(fitted)
            .filter_map(|(m, f)| m.map(|m| (m, *f)))
            .filter(|(m, _)| m.iter().all(|v| *v > 0.0))
            .collect();
        if pairs.is_empty() {
            return None;
        }
        Some(
            [0, 1, 2].map(|c| {
                (pairs.iter().map(|(m, f)| (f[c] / m[c] - 1.0).powi(2)).sum::<f64>() / pairs.len() as f64).sqrt()
            }),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_directions_cross_the_zenith_toward_and_away_from_the_sun() {
        let az = 90f64.to_radians(); // sun in the east (+x)
        let toward = plane_direction(30f64.to_radians(), az);
        let away = plane_direction(-30f64.to_radians(), az);
        assert!((toward[0] - 0.5).abs() < 1e-12 && toward[1].abs() < 1e-12);
        assert!((away[0] + 0.5).abs() < 1e-12 && away[1].abs() < 1e-12);
        assert!((toward[2] - 30f64.to_radians().cos()).abs() < 1e-12);
    }

    #[test]
    fn the_rms_compares_fitted_with_measured_where_both_exist() {
        let p = MeridianProfile {
            signed_zenith_deg: vec![-2.5, 2.5, 7.5],
            measured: vec![Some([1.0, 2.0, 4.0]), None, Some([1.0, 2.0, 4.0])],
            pixels: vec![3, 0, 3],
            fitted: Some(vec![[1.1, 2.0, 4.0], [9.0, 9.0, 9.0], [0.9, 2.0, 3.0]]),
        };
        let rms = p.rms_relative().unwrap();
        assert!((rms[0] - 0.1).abs() < 1e-12 && rms[1] == 0.0);
        assert!((rms[2] - (0.0625f64 / 2.0).sqrt()).abs() < 1e-12);
    }
}
