//! Skies at times that were not photographed (thesis §5.5.1).
//!
//! Naive pointwise interpolation of two skies gives two aureoles (Fig. 5.7).
//! The thesis instead interpolates the three factors of eq. (5.9)
//! separately: at each grid direction, with ξ its zenith angle and γ its
//! angle from the *new* sun, the scales Lzʲ, the backgrounds Bgʲ(ξ) and the
//! aureoles Saʲ(γ) of the k known skies are averaged with weights inversely
//! proportional to the angular distance between the new sun and sky j's
//! sun; the radiance is the product of the three averages, and a new model
//! is fitted to the grid.
//!
//! Overcast skies (§5.6.3) blend a clear sky toward an overcast one by the
//! fraction of sunlight the clouds block.

use super::cie::{CieSky, CieSkyType};
use super::fit::{SkyFit, SkyFitError, SkySample, fit_sky};
use super::geometry::{angle_between, direction};
use super::seven_parameter::{SkyAngles, SkyModel};

/// A fitted sky and where its sun was.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnownSky {
    /// Unit vector toward the sun (world frame, z up).
    pub sun: [f64; 3],
    /// The sky.
    pub model: SkyModel,
}

/// Why a sky cannot be predicted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// No sky to interpolate from.
    #[error("no fitted sky to interpolate from")]
    NoSkies,
    /// The new sun is below the horizon.
    #[error("the sun is {0:.2}° below the horizon: the daylight sky model does not apply")]
    SunDown(f64),
    /// The refit failed.
    #[error("refitting the interpolated sky failed: {0}")]
    Fit(#[from] SkyFitError),
}

/// Directions on the upper hemisphere, about `step_deg` apart.
fn hemisphere(step_deg: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    let rings = (90.0 / step_deg).round().max(1.0) as usize;
    for i in 0..=rings {
        let xi = (i as f64 / rings as f64) * 89.0f64.to_radians();
        let n = ((360.0 / step_deg) * xi.sin()).ceil().max(1.0) as usize;
        for k in 0..n {
            let az = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            out.push(direction(xi, az));
        }
    }
    out
}

/// Inverse-angular-distance weights; a sky whose sun coincides with the new
/// one (within 10⁻⁹ rad) takes all the weight.
fn weights(known: &[KnownSky], sun: [f64; 3]) -> Vec<f64> {
    let dist: Vec<f64> = known.iter().map(|k| angle_between(k.sun, sun)).collect();
    if let Some(hit) = dist.iter().position(|&d| d < 1e-9) {
        return (0..known.len()).map(|j| if j == hit { 1.0 } else { 0.0 }).collect();
    }
    let w: Vec<f64> = dist.iter().map(|d| 1.0 / d).collect();
    let total: f64 = w.iter().sum();
    w.into_iter().map(|x| x / total).collect()
}

/// The sky for a sun toward `sun` (unit vector), interpolated from `known`
/// skies and refitted, eq. (5.9) on a grid of `step_deg`.
pub fn predict_sky(known: &[KnownSky], sun: [f64; 3], step_deg: f64) -> Result<SkyFit, PredictError> {
    if known.is_empty() {
        return Err(PredictError::NoSkies);
    }
    let zs = angle_between(sun, [0.0, 0.0, 1.0]);
    if zs > std::f64::consts::FRAC_PI_2 {
        return Err(PredictError::SunDown((zs - std::f64::consts::FRAC_PI_2).to_degrees()));
    }
    let w = weights(known, sun);
    let lz: f64 = known.iter().zip(&w).map(|(k, w)| w * k.model.lz).sum();
    let samples: Vec<SkySample> = hemisphere(step_deg)
        .into_iter()
        .filter_map(|v| {
            let xi = angle_between(v, [0.0, 0.0, 1.0]);
            let gamma = angle_between(v, sun);
            (gamma > 0.5f64.to_radians()).then(|| {
                let at = SkyAngles::new(xi, gamma);
                let bg: f64 = known.iter().zip(&w).map(|(k, w)| w * k.model.background_at(&at)).sum();
                let sa: f64 = known.iter().zip(&w).map(|(k, w)| w * k.model.aureole_at(&at)).sum();
                SkySample {
                    xi,
                    gamma,
                    radiance: lz * bg * sa,
                }
            })
        })
        .collect();
    let mut fit = fit_sky(&samples, zs)?;
    // The scale: the zenith radiance interpolated in the sun's zenith angle.
    let zenith_now = fit.model.radiance(0.0, zs);
    if let Some(z) = zenith_radiance(known, &w, zs)
        && zenith_now > 0.0
        && zenith_now.is_finite()
    {
        fit.model.lz *= z / zenith_now;
    }
    Ok(fit)
}

/// The zenith radiance for a sun at zenith angle `zs`: each known sky's
/// zenith radiance without its own aureole factor, `Lz Bg(0)`, interpolated
/// as a function of its sun's zenith angle (a monotone cubic; skies whose
/// suns are within 0.5° of each other are averaged), times the aureole
/// factor at the zenith that the thesis's construction gives the new sun,
/// `Σ wⱼ Saⱼ(Zs)` (weights `w` as in [`predict_sky`]). `None` outside the
/// range of the known suns' zenith angles, where there is nothing to
/// interpolate and the thesis's scale stands.
///
/// This departs from the thesis's scale (§5.5.1 averages Lz over the known
/// skies by angular distance between suns): on a clear day the zenith
/// radiance follows the sun's elevation, not its azimuth, and the product
/// of separately averaged factors does not keep it. Against the simulator's
/// sky at the campanile held-out time the thesis's scale is 9% off and this
/// one 0.2–0.6% RMS (sim/tests/sky_from_world.rs); when the known skies
/// share one shape both are exact.
fn zenith_radiance(known: &[KnownSky], w: &[f64], zs: f64) -> Option<f64> {
    // Interpolate Lz·Bg(0), the zenith radiance without the sky's own
    // aureole factor, then put back the aureole the thesis's construction
    // gives the new sun: exact when the known skies share one shape.
    let mut points: Vec<(f64, f64)> = known
        .iter()
        .map(|k| {
            let z = angle_between(k.sun, [0.0, 0.0, 1.0]);
            (z, k.model.lz * k.model.background(0.0))
        })
        .collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64, usize)> = Vec::new();
    for (z, l) in points {
        match merged.last_mut() {
            Some(last) if (z - last.0 / last.2 as f64) < 0.5f64.to_radians() => {
                last.0 += z;
                last.1 += l;
                last.2 += 1;
            }
            _ => merged.push((z, l, 1)),
        }
    }
    let p: Vec<(f64, f64)> = merged
        .into_iter()
        .map(|(z, l, n)| (z / n as f64, l / n as f64))
        .collect();
    let without_aureole = match p.iter().position(|&(z, _)| z >= zs) {
        None => None,
        Some(0) => (p[0].0 - zs < 1e-9).then_some(p[0].1),
        Some(i) => Some(monotone_cubic(&p, i - 1, zs)),
    }?;
    let at = SkyAngles::new(0.0, zs);
    let aureole: f64 = known.iter().zip(w).map(|(k, w)| w * k.model.aureole_at(&at)).sum();
    Some(without_aureole * aureole)
}

/// The monotone cubic (Fritsch–Carlson) through the points `p` (sorted by
/// x), evaluated at `x` in `[p[k].0, p[k + 1].0]`: exact for linear data,
/// never overshooting the neighbouring values.
fn monotone_cubic(p: &[(f64, f64)], k: usize, x: f64) -> f64 {
    let secant = |i: usize| (p[i + 1].1 - p[i].1) / (p[i + 1].0 - p[i].0);
    let slope = |i: usize| {
        if i == 0 {
            secant(0)
        } else if i == p.len() - 1 {
            secant(i - 1)
        } else {
            let (a, b) = (secant(i - 1), secant(i));
            if a * b <= 0.0 {
                0.0
            } else {
                // Weighted harmonic mean of the neighbouring secants.
                let (h0, h1) = (p[i].0 - p[i - 1].0, p[i + 1].0 - p[i].0);
                let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                (w1 + w2) / (w1 / a + w2 / b)
            }
        }
    };
    let h = p[k + 1].0 - p[k].0;
    let t = (x - p[k].0) / h;
    let (m0, m1) = (slope(k) * h, slope(k + 1) * h);
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * p[k].1
        + (t3 - 2.0 * t2 + t) * m0
        + (-2.0 * t3 + 3.0 * t2) * p[k + 1].1
        + (t3 - t2) * m1
}

/// Reddens a sky predicted for a lower sun (§5.5.1): light crossing
/// `delta_air_mass` more air is dimmed by `exp(−β Δm)`. "We use the same
/// coefficients to get the color of solar aureole. For the sky background,
/// we use an average β for all three color channels to decrease the
/// brightness but keep the color unchanged." So each channel's scale Lz is
/// multiplied by `exp(−β̄ Δm)` and its aureole strength c (the circumsolar
/// part) further by `exp(−(β_c − β̄) Δm)`, giving the aureole the sun's own
/// attenuation `exp(−β_c Δm)`.
pub fn redden(models: [SkyModel; 3], beta: [f64; 3], delta_air_mass: f64) -> [SkyModel; 3] {
    let mean = (beta[0] + beta[1] + beta[2]) / 3.0;
    let mut out = models;
    for (m, b) in out.iter_mut().zip(beta) {
        m.lz *= (-mean * delta_air_mass).exp();
        m.c *= (-(b - mean) * delta_air_mass).exp();
    }
    out
}

/// A clear sky under a uniform cloud layer that blocks a fraction `blocked`
/// (0–1) of the sunlight (§5.6.3): `(1 − p) clear + p overcast`, with the
/// overcast sky the CIE standard overcast (type 1) of zenith radiance
/// `overcast_zenith` (its colour is the cloud colour).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OvercastSky {
    /// The clear sky.
    pub clear: SkyModel,
    /// The overcast sky.
    pub overcast: SkyModel,
    /// Fraction of sunlight blocked, in [0, 1].
    pub blocked: f64,
}

impl OvercastSky {
    /// The blend; `blocked` is clamped to [0, 1].
    pub fn new(clear: SkyModel, overcast_zenith: f64, sun_zenith: f64, blocked: f64) -> OvercastSky {
        let kind = CieSkyType::new(1).unwrap_or_else(|| unreachable!("type 1 exists"));
        let overcast = CieSky::new(kind, overcast_zenith, sun_zenith).as_seven_parameter();
        OvercastSky {
            clear,
            overcast,
            blocked: blocked.clamp(0.0, 1.0),
        }
    }

    /// Radiance at (ξ, γ).
    pub fn radiance(&self, xi: f64, gamma: f64) -> f64 {
        let at = SkyAngles::new(xi, gamma);
        (1.0 - self.blocked) * self.clear.radiance_at(&at) + self.blocked * self.overcast.radiance_at(&at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun_at(zenith_deg: f64, azimuth_deg: f64) -> [f64; 3] {
        direction(zenith_deg.to_radians(), azimuth_deg.to_radians())
    }

    fn rms(a: impl Fn(f64, f64) -> f64, b: impl Fn(f64, f64) -> f64, sun: [f64; 3]) -> f64 {
        let dirs: Vec<_> = hemisphere(3.0)
            .into_iter()
            .map(|v| (angle_between(v, [0.0, 0.0, 1.0]), angle_between(v, sun)))
            .filter(|&(_, g)| g > 0.01)
            .collect();
        (dirs
            .iter()
            .map(|&(x, g)| (a(x, g) / b(x, g) - 1.0).powi(2))
            .sum::<f64>()
            / dirs.len() as f64)
            .sqrt()
    }

    #[test]
    fn a_constant_shaped_sky_is_predicted_exactly_between_four_times() {
        // The thesis's premise: Lz, Bg and Sa keep their shapes; only the sun moves.
        let m = SkyModel {
            lz: 0.07,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.5,
            h: 0.9,
        };
        let known: Vec<KnownSky> = [(60.0, 100.0), (35.0, 150.0), (30.0, 210.0), (55.0, 250.0)]
            .iter()
            .map(|&(z, a)| KnownSky {
                sun: sun_at(z, a),
                model: m,
            })
            .collect();
        let sun = sun_at(32.0, 185.0);
        let fit = predict_sky(&known, sun, 4.0).expect("predicts");
        let e = rms(|x, g| fit.model.radiance(x, g), |x, g| m.radiance(x, g), sun);
        assert!(e < 1e-3, "{e}");
    }

    #[test]
    fn a_cie_clear_sky_at_a_held_out_time_within_5_percent() {
        // CIE type 12 with a constant zenith radiance: its 7-parameter scale
        // changes with the sun, which the interpolation only approximates.
        let kind = CieSkyType::new(12).expect("type");
        let sky = |z: f64, a: f64| KnownSky {
            sun: sun_at(z, a),
            model: CieSky::new(kind, 0.05, z.to_radians()).as_seven_parameter(),
        };
        let known = [sky(62.0, 95.0), sky(38.0, 140.0), sky(31.0, 215.0), sky(58.0, 258.0)];
        let truth = CieSky::new(kind, 0.05, 36f64.to_radians());
        let sun = sun_at(36.0, 160.0);
        let fit = predict_sky(&known, sun, 4.0).expect("predicts");
        // The shape (the best-scaled error) is right to 5%, and the zenith
        // radiance, interpolated in the sun's zenith angle, to 0.1%
        // (measured 0.066%; the thesis's Lz average is 16.6% off here).
        let scale = truth.radiance(0.0, 36f64.to_radians()) / fit.model.radiance(0.0, 36f64.to_radians());
        assert!((scale - 1.0).abs() < 1e-3, "zenith radiance off by {}", scale - 1.0);
        let shape = rms(
            |x, g| scale * fit.model.radiance(x, g),
            |x, g| truth.radiance(x, g),
            sun,
        );
        eprintln!("shape error {shape}, scale error {}", scale - 1.0);
        assert!(shape < 0.05, "{shape}");
    }

    #[test]
    fn a_known_time_returns_its_own_sky_and_errors_are_clear() {
        let m = SkyModel {
            lz: 0.07,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.5,
            h: 0.9,
        };
        let other = SkyModel { lz: 0.2, ..m };
        let s1 = sun_at(30.0, 180.0);
        let fit = predict_sky(
            &[
                KnownSky { sun: s1, model: m },
                KnownSky {
                    sun: sun_at(60.0, 90.0),
                    model: other,
                },
            ],
            s1,
            4.0,
        )
        .expect("ok");
        assert!(rms(|x, g| fit.model.radiance(x, g), |x, g| m.radiance(x, g), s1) < 1e-3);
        assert_eq!(predict_sky(&[], s1, 4.0), Err(PredictError::NoSkies));
        assert!(matches!(
            predict_sky(&[KnownSky { sun: s1, model: m }], sun_at(95.0, 0.0), 4.0),
            Err(PredictError::SunDown(_))
        ));
    }

    #[test]
    fn reddening_colours_the_aureole_and_only_dims_the_background() {
        let m = SkyModel {
            lz: 0.07,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.0,
            h: 1.0,
        };
        let beta = [0.10, 0.15, 0.30];
        let dm = 10.0;
        let red = redden([m, m, m], beta, dm);
        // Near the sun the aureole dominates: its colour follows the sun's, exp(−β_c Δm).
        let gamma = 0.01;
        let aureole = |k: usize| red[k].lz * red[k].background(0.5) * red[k].c * (red[k].d * gamma).exp();
        let before = m.lz * m.background(0.5) * m.c * (m.d * gamma).exp();
        for (k, b) in beta.iter().enumerate() {
            assert!((aureole(k) / before - (-b * dm).exp()).abs() < 1e-12);
        }
        // Far from the sun (γ = 143°, where c e^{dγ} ≈ 0.004 of the background)
        // the colour stays as it was (all channels were equal) within 1%,
        // and only the brightness drops, by exp(−β̄ Δm).
        let far = |k: usize| red[k].radiance(0.5, 2.5);
        assert!((far(0) / far(2) - 1.0).abs() < 0.01, "{}", far(0) / far(2));
        assert!((far(1) / m.radiance(0.5, 2.5) / (-(0.55 / 3.0) * dm).exp() - 1.0).abs() < 0.01);
    }

    #[test]
    fn overcast_blend_runs_from_clear_to_cie_overcast() {
        let clear = SkyModel {
            lz: 0.07,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.5,
            h: 0.9,
        };
        let zs = 0.6;
        let none = OvercastSky::new(clear, 0.03, zs, 0.0);
        let full = OvercastSky::new(clear, 0.03, zs, 1.0);
        assert_eq!(none.radiance(0.4, 0.3), clear.radiance(0.4, 0.3));
        // Fully overcast: a third as bright at the horizon as at the zenith, whatever the sun.
        assert!((full.radiance(std::f64::consts::FRAC_PI_2, 2.0) / full.radiance(0.0, zs) - 0.3349).abs() < 1e-3);
        let half = OvercastSky::new(clear, 0.03, zs, 0.5);
        assert!((half.radiance(0.4, 0.3) - 0.5 * (none.radiance(0.4, 0.3) + full.radiance(0.4, 0.3))).abs() < 1e-15);
    }
}
