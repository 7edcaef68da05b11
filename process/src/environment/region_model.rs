//! The radiance model of one environment region (thesis §5.5.2): a
//! Lambertian patch lit by the sky as an ambient source and by the sun,
//!
//! `I = ρ_sky E_sky + ρ_sun E_sun max(0, n · l_sun)`      (eq. 5.13)
//!
//! per channel, fitted over several solar positions. Following eq. (5.14)
//! the sun term is carried by one vector `v = ρ_sun,g n` (its length is the
//! green sun albedo, its direction the normal) and two colour ratios
//! `ρ_sun,r / ρ_sun,g`, `ρ_sun,b / ρ_sun,g`, so the eight unknowns have no
//! constraint. The clamp at `n · l = 0` is smoothed as in eq. (5.15),
//! `(exp(α n·l) − 1) / α` below zero with α = 1000, so Levenberg–Marquardt
//! sees a derivative everywhere.
//!
//! **Conditioning.** Photometric stereo needs the sun directions to span
//! three dimensions. A day's sun path is a circle; near an equinox it is a
//! great circle and all directions lie in one plane through the observer,
//! leaving the normal's component across that plane unknown. The ratio of
//! the smallest to the largest singular value of the sun-direction matrix
//! is checked against [`SUN_TRACK_MIN_CONDITION`]; below it the sun term is
//! not fitted, and the fit says why.
//!
//! **Sky only.** A region never sunlit, or one whose sun term does not pay
//! for its five extra parameters (by BIC), keeps only `ρ_sky`.

use crate::model_choice::bic;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Matrix3xX, Owned, Vector3};

/// α of eq. (5.15).
const ALPHA: f64 = 1000.0;

/// The smallest acceptable σ_min / σ_max of the sun directions.
pub const SUN_TRACK_MIN_CONDITION: f64 = 0.05;

/// One time's measurement of a region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvironmentObservation {
    /// Mean radiance of the region, per channel.
    pub radiance: [f64; 3],
    /// Irradiance flux from the whole sky, per channel (E_sky).
    pub sky_irradiance: [f64; 3],
    /// Solar irradiance on a plane facing the sun, per channel (E_sun).
    pub sun_irradiance: [f64; 3],
    /// Unit vector toward the sun.
    pub sun: [f64; 3],
}

/// The model a region was given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RegionModelKind {
    /// Sky and sun terms, eq. (5.15).
    SkyAndSun,
    /// The sky term alone.
    SkyOnly,
}

/// A region's fitted model.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RegionFit {
    /// Which model.
    pub kind: RegionModelKind,
    /// Why, in words.
    pub reason: String,
    /// ρ_sky per channel.
    pub rho_sky: [f64; 3],
    /// ρ_sun per channel (zero for sky-only).
    pub rho_sun: [f64; 3],
    /// Unit normal (None for sky-only).
    pub normal: Option<[f64; 3]>,
    /// RMS relative residual.
    pub rms_relative: f64,
    /// σ_min / σ_max of the sun directions.
    pub sun_track_condition: f64,
    /// Condition number (σ_max / σ_min) of the weighted Jacobian at the
    /// solution: how much relative noise in the radiance is amplified in
    /// the parameters. Infinite for a rank-deficient problem; 1 for sky-only.
    pub jacobian_condition: f64,
}

impl RegionFit {
    /// Predicted radiance under new light, eq. (5.13):
    /// `ρ_sky E_sky + ρ_sun E_sun max(0, n · l)` per channel.
    pub fn radiance(&self, sky_irradiance: [f64; 3], sun_irradiance: [f64; 3], sun: [f64; 3]) -> [f64; 3] {
        let cos = self
            .normal
            .map_or(0.0, |n| (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]).max(0.0));
        [0, 1, 2].map(|c| self.rho_sky[c] * sky_irradiance[c] + self.rho_sun[c] * sun_irradiance[c] * cos)
    }
}

/// Why a region could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionFitError {
    /// No observations.
    #[error("no observations of the region")]
    Empty,
    /// An observation is not finite or has no sky light.
    #[error("observation {index} is unusable: {what}")]
    Invalid {
        /// Which.
        index: usize,
        /// What is wrong.
        what: String,
    },
}

fn smooth_cos(x: f64) -> (f64, f64) {
    if x >= 0.0 {
        (x, 1.0)
    } else {
        (((ALPHA * x).exp() - 1.0) / ALPHA, (ALPHA * x).exp())
    }
}

/// Unknowns: [v (3), ln(ρ_r/ρ_g), ln(ρ_b/ρ_g), ln ρ_sky (3)].
struct Problem<'a> {
    obs: &'a [EnvironmentObservation],
    sigma: Vec<[f64; 3]>,
    x: [f64; 8],
}

impl Problem<'_> {
    fn unpack(&self) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let v = [self.x[0], self.x[1], self.x[2]];
        let ratio = [self.x[3].exp(), 1.0, self.x[4].exp()];
        let sky = [self.x[5].exp(), self.x[6].exp(), self.x[7].exp()];
        (v, ratio, sky)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        for k in 0..8 {
            self.x[k] = x[k];
        }
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_row_slice(&self.x)
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let (v, ratio, sky) = self.unpack();
        let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-300);
        let mut r = DVector::zeros(self.obs.len() * 3);
        for (t, o) in self.obs.iter().enumerate() {
            let (s, _) = smooth_cos((v[0] * o.sun[0] + v[1] * o.sun[1] + v[2] * o.sun[2]) / norm);
            for c in 0..3 {
                let model = sky[c] * o.sky_irradiance[c] + ratio[c] * norm * o.sun_irradiance[c] * s;
                r[3 * t + c] = (model - o.radiance[c]) / self.sigma[t][c];
            }
        }
        r.iter().all(|x| x.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let (v, ratio, sky) = self.unpack();
        let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt().max(1e-300);
        let n = [v[0] / norm, v[1] / norm, v[2] / norm];
        let mut j = DMatrix::zeros(self.obs.len() * 3, 8);
        for (t, o) in self.obs.iter().enumerate() {
            let cos = n[0] * o.sun[0] + n[1] * o.sun[1] + n[2] * o.sun[2];
            let (s, ds) = smooth_cos(cos);
            for c in 0..3 {
                let row = 3 * t + c;
                let sg = self.sigma[t][c];
                let k = ratio[c] * o.sun_irradiance[c];
                // term = k |v| s(v·l/|v|); ∂/∂v = k [n s + ds (l − n cos)].
                for a in 0..3 {
                    j[(row, a)] = k * (n[a] * s + ds * (o.sun[a] - n[a] * cos)) / sg;
                }
                let sun_term = k * norm * s;
                if c == 0 {
                    j[(row, 3)] = sun_term / sg;
                }
                if c == 2 {
                    j[(row, 4)] = sun_term / sg;
                }
                j[(row, 5 + c)] = sky[c] * o.sky_irradiance[c] / sg;
            }
        }
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

/// σ_min / σ_max of the sun directions (0 with fewer than three).
fn track_condition(obs: &[EnvironmentObservation]) -> f64 {
    if obs.len() < 3 {
        return 0.0;
    }
    let m = Matrix3xX::from_iterator(obs.len(), obs.iter().flat_map(|o| o.sun));
    let sv = m.singular_values();
    let (lo, hi) = (sv.min(), sv.max());
    if hi > 0.0 { lo / hi } else { 0.0 }
}

/// Fits one region's model to its observations at several solar positions.
pub fn fit_region(obs: &[EnvironmentObservation]) -> Result<RegionFit, RegionFitError> {
    if obs.is_empty() {
        return Err(RegionFitError::Empty);
    }
    for (index, o) in obs.iter().enumerate() {
        let finite = o
            .radiance
            .iter()
            .chain(&o.sky_irradiance)
            .chain(&o.sun_irradiance)
            .chain(&o.sun)
            .all(|x| x.is_finite());
        if !finite || o.sky_irradiance.iter().any(|&e| e <= 0.0) || o.sun_irradiance.iter().any(|&e| e < 0.0) {
            return Err(RegionFitError::Invalid {
                index,
                what: format!("{o:?}: need finite values, E_sky > 0 and E_sun ≥ 0"),
            });
        }
    }
    let mean_i: Vec<f64> = (0..3)
        .map(|c| obs.iter().map(|o| o.radiance[c].abs()).sum::<f64>() / obs.len() as f64)
        .collect();
    let sigma: Vec<[f64; 3]> = obs
        .iter()
        .map(|o| [0, 1, 2].map(|c| o.radiance[c].abs().max(1e-3 * mean_i[c]).max(f64::MIN_POSITIVE)))
        .collect();
    let nres = obs.len() * 3;
    // Sky only: each channel's ρ_sky in closed form (weighted least squares).
    let rho_sky_only = [0, 1, 2].map(|c| {
        let (num, den) = obs.iter().zip(&sigma).fold((0.0, 0.0), |(a, b), (o, s)| {
            let e = o.sky_irradiance[c] / s[c];
            (a + e * o.radiance[c] / s[c], b + e * e)
        });
        (num / den).max(0.0)
    });
    let rss_sky: f64 = obs
        .iter()
        .zip(&sigma)
        .map(|(o, s)| {
            (0..3)
                .map(|c| ((rho_sky_only[c] * o.sky_irradiance[c] - o.radiance[c]) / s[c]).powi(2))
                .sum::<f64>()
        })
        .sum();
    let condition = track_condition(obs);
    let sky_only = |reason: String| RegionFit {
        kind: RegionModelKind::SkyOnly,
        reason,
        rho_sky: rho_sky_only,
        rho_sun: [0.0; 3],
        normal: None,
        rms_relative: (rss_sky / nres as f64).sqrt(),
        sun_track_condition: condition,
        jacobian_condition: 1.0,
    };
    if obs.len() < 3 {
        return Ok(sky_only(format!(
            "{} solar positions: the sun term needs at least 3",
            obs.len()
        )));
    }
    if condition < SUN_TRACK_MIN_CONDITION {
        return Ok(sky_only(format!(
            "ill-conditioned: the sun directions are nearly coplanar (σmin/σmax = {condition:.4} < {SUN_TRACK_MIN_CONDITION}), so the normal cannot be recovered; sky term only"
        )));
    }
    // Sky and sun: LM from several normals.
    let mean_sun: f64 = obs.iter().map(|o| o.sun_irradiance[1]).sum::<f64>() / obs.len() as f64;
    let mean_sky: Vec<f64> = (0..3)
        .map(|c| obs.iter().map(|o| o.sky_irradiance[c]).sum::<f64>() / obs.len() as f64)
        .collect();
    let rho_sun0 = (mean_i[1] / mean_sun.max(f64::MIN_POSITIVE)).max(1e-3);
    let mut best: Option<(f64, [f64; 8])> = None;
    for n0 in [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ] {
        let x0 = [
            rho_sun0 * n0[0],
            rho_sun0 * n0[1],
            rho_sun0 * n0[2],
            0.0,
            0.0,
            (0.5 * mean_i[0] / mean_sky[0]).max(1e-6).ln(),
            (0.5 * mean_i[1] / mean_sky[1]).max(1e-6).ln(),
            (0.5 * mean_i[2] / mean_sky[2]).max(1e-6).ln(),
        ];
        let problem = Problem {
            obs,
            sigma: sigma.clone(),
            x: x0,
        };
        let (solved, _report) = LevenbergMarquardt::new().with_patience(300).minimize(problem);
        if let Some(r) = solved.residuals() {
            let rss = r.norm_squared();
            if best.as_ref().is_none_or(|b| rss < b.0) {
                best = Some((rss, solved.x));
            }
        }
    }
    let Some((rss, x)) = best else {
        return Ok(sky_only("the sky-and-sun fit did not converge; sky term only".into()));
    };
    let (b_sun, b_sky) = (bic(rss, nres, 8), bic(rss_sky, nres, 3));
    if b_sky <= b_sun {
        return Ok(sky_only(format!(
            "the sun term does not pay for its five parameters (BIC {b_sun:.1} vs {b_sky:.1} sky-only): the region is never sunlit or faces away from the sun"
        )));
    }
    let jacobian_condition = Problem {
        obs,
        sigma: sigma.clone(),
        x,
    }
    .jacobian()
    .map_or(f64::INFINITY, |j| {
        let sv = j.singular_values();
        let (lo, hi) = (sv.min(), sv.max());
        if lo > 0.0 { hi / lo } else { f64::INFINITY }
    });
    if !jacobian_condition.is_finite() {
        return Ok(sky_only(
            "the sun term is not determined by these observations (singular Jacobian: the region is never sunlit or the lighting does not vary enough); sky term only".into(),
        ));
    }
    let v = Vector3::new(x[0], x[1], x[2]);
    let g = v.norm();
    let normal = v / g;
    Ok(RegionFit {
        kind: RegionModelKind::SkyAndSun,
        reason: format!(
            "sky and sun terms (BIC {b_sun:.1} vs {b_sky:.1} sky-only; sun track σmin/σmax = {condition:.3}; Jacobian condition {jacobian_condition:.0})"
        ),
        rho_sky: [x[5].exp(), x[6].exp(), x[7].exp()],
        rho_sun: [g * x[3].exp(), g, g * x[4].exp()],
        normal: Some([normal.x, normal.y, normal.z]),
        rms_relative: (rss / nres as f64).sqrt(),
        sun_track_condition: condition,
        jacobian_condition,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sun::{Ephemeris, Observer};
    use chrono::{TimeZone, Utc};

    fn berkeley_suns(day: (i32, u32, u32), hours_utc: &[u32]) -> Vec<[f64; 3]> {
        let obs = Observer::from_degrees(37.8721, -122.2578, 90.0, 1010.0, 18.0);
        hours_utc
            .iter()
            .map(|&h| {
                let t = Utc.with_ymd_and_hms(day.0, day.1, day.2, h, 0, 0).single().expect("t");
                Ephemeris::at(t, Some(69.0))
                    .and_then(|e| e.position(&obs))
                    .expect("ok")
                    .direction()
            })
            .collect()
    }

    fn observe(
        suns: &[[f64; 3]],
        rho_sky: [f64; 3],
        rho_sun: [f64; 3],
        n: [f64; 3],
        noise: f64,
    ) -> Vec<EnvironmentObservation> {
        let mut k = 99u64;
        suns.iter()
            .map(|&sun| {
                let e_sky = [80.0 + 40.0 * sun[2], 95.0 + 45.0 * sun[2], 130.0 + 60.0 * sun[2]];
                let e_sun = [
                    900.0 * sun[2].max(0.05).powf(0.1),
                    850.0 * sun[2].max(0.05).powf(0.12),
                    780.0 * sun[2].max(0.05).powf(0.15),
                ];
                let cos = (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]).max(0.0);
                let radiance = [0, 1, 2].map(|c| {
                    k = k.wrapping_mul(6364136223846793005).wrapping_add(1);
                    let u = ((k >> 33) as f64 / f64::from(1u32 << 31)) * 2.0 - 1.0;
                    (rho_sky[c] * e_sky[c] + rho_sun[c] * e_sun[c] * cos) * (1.0 + noise * u)
                });
                EnvironmentObservation {
                    radiance,
                    sky_irradiance: e_sky,
                    sun_irradiance: e_sun,
                    sun,
                }
            })
            .collect()
    }

    fn unit(v: [f64; 3]) -> [f64; 3] {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / n, v[1] / n, v[2] / n]
    }

    #[test]
    fn recovers_normal_and_pseudo_albedos_from_four_times_of_day() {
        // Late August at Berkeley: 9:00, 12:30, 15:00, 17:30 PDT.
        let suns = berkeley_suns((2026, 8, 28), &[16, 19, 22, 0]);
        let n = unit([0.3, -0.6, 0.75]); // a slope facing south-east-ish
        let (rho_sky, rho_sun) = ([0.05, 0.07, 0.06], [0.12, 0.15, 0.10]);
        let mut suns = suns;
        suns[3] = berkeley_suns((2026, 8, 29), &[0])[0];
        let fit = fit_region(&observe(&suns, rho_sky, rho_sun, n, 0.0)).expect("fits");
        assert_eq!(fit.kind, RegionModelKind::SkyAndSun, "{}", fit.reason);
        let got = fit.normal.expect("normal");
        let angle = (got[0] * n[0] + got[1] * n[1] + got[2] * n[2])
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        assert!(angle < 0.5, "normal off by {angle}°");
        for c in 0..3 {
            assert!((fit.rho_sky[c] / rho_sky[c] - 1.0).abs() < 0.01, "{fit:?}");
            assert!((fit.rho_sun[c] / rho_sun[c] - 1.0).abs() < 0.01, "{fit:?}");
        }
        // Region means average hundreds of pixels: with 0.1% noise the normal
        // is within 5° and the albedos within 2%. The error grows with the
        // reported Jacobian condition (sky light that rises with the sun
        // trades off against the normal's vertical component), which the
        // fit states rather than hides.
        let fit = fit_region(&observe(&suns, rho_sky, rho_sun, n, 0.001)).expect("fits");
        let got = fit.normal.expect("normal");
        let angle = (got[0] * n[0] + got[1] * n[1] + got[2] * n[2])
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        assert!(angle < 5.0, "noisy normal off by {angle}° ({})", fit.reason);
        assert!(
            (0..3).all(|c| (fit.rho_sun[c] / rho_sun[c] - 1.0).abs() < 0.02),
            "{fit:?}"
        );
        assert!(
            fit.jacobian_condition.is_finite() && fit.reason.contains("Jacobian condition"),
            "{}",
            fit.reason
        );
    }

    #[test]
    fn an_equinox_like_planar_sun_track_is_flagged_ill_conditioned() {
        // Sun directions on one great circle through the observer.
        let axis = unit([0.0, 0.8, 0.6]);
        let e1 = [1.0, 0.0, 0.0];
        let e2 = [0.0, -axis[2], axis[1]];
        let suns: Vec<[f64; 3]> = [0.3, 0.9, 1.5, 2.2, 2.8]
            .iter()
            .map(|&t: &f64| [0, 1, 2].map(|i| t.cos() * e1[i] + t.sin() * e2[i]))
            .collect();
        let fit = fit_region(&observe(&suns, [0.05; 3], [0.1; 3], [0.0, 0.0, 1.0], 0.0)).expect("fits");
        assert_eq!(fit.kind, RegionModelKind::SkyOnly);
        assert!(fit.reason.starts_with("ill-conditioned"), "{}", fit.reason);
        assert!(fit.sun_track_condition < 1e-9);
    }

    #[test]
    fn a_region_never_sunlit_keeps_the_sky_term_only() {
        let suns = berkeley_suns((2026, 8, 28), &[16, 19, 22]);
        // Facing down and north: never lit by a southern summer sun.
        let n = unit([0.0, 0.3, -0.95]);
        let fit = fit_region(&observe(&suns, [0.05, 0.06, 0.07], [0.1; 3], n, 0.0)).expect("fits");
        assert_eq!(fit.kind, RegionModelKind::SkyOnly, "{}", fit.reason);
        assert!((fit.rho_sky[1] / 0.06 - 1.0).abs() < 1e-6);
        assert!(matches!(fit_region(&[]), Err(RegionFitError::Empty)));
    }
}
