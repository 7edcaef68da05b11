//! Fitting a sky to measured radiance, thesis eq. (5.10), with the choice of
//! the smallest model the data supports.
//!
//! **Weights.** The thesis minimizes Σ [(yᵢ − L(ξᵢ, γᵢ)) / σᵢ]² with
//! σᵢ = yᵢ / ln yᵢ, which depends on the radiance unit (it is undefined at
//! y = 1 and negative below). Its intent is a roughly relative error. We use
//! σᵢ = max(yᵢ, ε · median y) with ε = 10⁻³: relative error where the sky is
//! measurably bright, with a floor so that near-black or noisy-negative
//! samples cannot dominate. Scaling every yᵢ by k scales L by k (through Lz)
//! and every σᵢ by k, so the residuals, the fit and the choice of model are
//! the same in any unit.
//!
//! **Parameters.** Lz = exp(p₀); every other parameter maps an unbounded pᵢ
//! through a logistic onto its physical range (a ∈ (−1.05, 10),
//! b ∈ (−5, 0.2), c ∈ (0, 60), d ∈ (−12, 0), e ∈ (−0.5, 3), h ∈ (0.25, 4)),
//! so the optimizer never sees a bound and never leaves the range.
//!
//! **Starts.** The fifteen CIE standard skies are exactly seven-parameter
//! skies with h = 1 ([`CieSky::as_seven_parameter`]); each is first fitted
//! in closed form (its scale only), and Levenberg–Marquardt starts from the
//! three best.
//!
//! **Model choice.** Candidates are the best CIE sky (one parameter) and the
//! seven-parameter sky (seven, or four with the aureole fixed when no
//! sample lies within [`AUREOLE_SEEN_RAD`] of the sun). The smallest
//! Bayesian information criterion `n ln(RSS/n) + k ln n` wins.

use crate::model_choice::bic;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::cie::{CieSky, CieSkyType};
use super::seven_parameter::{COS_XI_FLOOR, SkyModel};

/// One measured sky element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkySample {
    /// Zenith angle ξ, radians.
    pub xi: f64,
    /// Angle from the sun γ, radians.
    pub gamma: f64,
    /// Measured radiance, any unit.
    pub radiance: f64,
}

/// The aureole counts as observed when a sample lies within this angle of
/// the sun (10°).
pub const AUREOLE_SEEN_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// The weight floor ε of the module doc.
pub const WEIGHT_FLOOR: f64 = 1e-3;

const A: (f64, f64) = (-1.05, 10.0);
const B: (f64, f64) = (-5.0, 0.2);
const C: (f64, f64) = (0.0, 60.0);
const D: (f64, f64) = (-12.0, 0.0);
const E: (f64, f64) = (-0.5, 3.0);
const H: (f64, f64) = (0.25, 4.0);
const RANGES: [(f64, f64); 6] = [A, B, C, D, E, H];

/// Which model the fit chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SkyModelKind {
    /// A CIE standard sky, scaled.
    Cie(CieSkyType),
    /// The seven-parameter sky of eq. (5.9), all parameters free.
    SevenParameter,
    /// Eq. (5.9) with the aureole (c, d, h) fixed, because it was not seen.
    SevenParameterFixedAureole,
}

/// One candidate's score.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The model.
    pub kind: SkyModelKind,
    /// Free parameters.
    pub parameters: usize,
    /// Weighted residual sum of squares.
    pub rss: f64,
    /// Bayesian information criterion.
    pub bic: f64,
}

/// A fitted sky and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyFit {
    /// The fitted sky, always as eq. (5.9) parameters.
    pub model: SkyModel,
    /// The chosen model.
    pub kind: SkyModelKind,
    /// Why it was chosen, in words.
    pub reason: String,
    /// Root-mean-square relative residual over the samples.
    pub rms_relative: f64,
    /// Every candidate considered.
    pub candidates: Vec<Candidate>,
    /// Residual evaluations Levenberg–Marquardt used, over all starts.
    pub evaluations: usize,
    /// Whether the winning Levenberg–Marquardt run reported success.
    pub converged: bool,
}

/// Why a sky could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SkyFitError {
    /// Fewer samples than the smallest model needs beyond its parameters.
    #[error("{found} sky samples; at least {needed} are needed")]
    TooFewSamples {
        /// Samples given.
        found: usize,
        /// Samples needed.
        needed: usize,
    },
    /// A sample is NaN or infinite, or its angles are out of range.
    #[error("sky sample {index} is invalid: {what}")]
    InvalidSample {
        /// Its index.
        index: usize,
        /// What is wrong.
        what: String,
    },
    /// No sample is brighter than zero.
    #[error("no sky sample has positive radiance: nothing to fit")]
    NoLight,
}

fn sigmoid(p: f64) -> f64 {
    1.0 / (1.0 + (-p).exp())
}

fn logit(x: f64) -> f64 {
    let x = x.clamp(1e-9, 1.0 - 1e-9);
    (x / (1.0 - x)).ln()
}

/// Natural parameters [Lz, a, b, c, d, e, h] from unbounded ones.
fn natural(p: &[f64; 7]) -> [f64; 7] {
    let mut t = [p[0].exp(), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    for k in 0..6 {
        let (lo, hi) = RANGES[k];
        t[k + 1] = lo + (hi - lo) * sigmoid(p[k + 1]);
    }
    t
}

fn unbounded(m: &SkyModel) -> [f64; 7] {
    let t = [m.a, m.b, m.c, m.d, m.e, m.h];
    let mut p = [m.lz.max(f64::MIN_POSITIVE).ln(), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    for k in 0..6 {
        let (lo, hi) = RANGES[k];
        p[k + 1] = logit((t[k] - lo) / (hi - lo));
    }
    p
}

fn model_of(t: &[f64; 7]) -> SkyModel {
    SkyModel {
        lz: t[0],
        a: t[1],
        b: t[2],
        c: t[3],
        d: t[4],
        e: t[5],
        h: t[6],
    }
}

/// The least-squares problem over the free subset of the seven unbounded
/// parameters.
struct Problem<'a> {
    samples: &'a [SkySample],
    sigma: &'a [f64],
    p: [f64; 7],
    free: Vec<usize>,
}

impl Problem<'_> {
    fn model(&self) -> SkyModel {
        model_of(&natural(&self.p))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        for (k, &i) in self.free.iter().enumerate() {
            self.p[i] = x[k];
        }
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_iterator(self.free.len(), self.free.iter().map(|&i| self.p[i]))
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let m = self.model();
        let r = DVector::from_iterator(
            self.samples.len(),
            self.samples
                .iter()
                .zip(self.sigma)
                .map(|(s, sg)| (m.radiance(s.xi, s.gamma) - s.radiance) / sg),
        );
        r.iter().all(|x| x.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let t = natural(&self.p);
        let m = model_of(&t);
        // dθ/dp for the logistic parameters: (hi − lo) σ (1 − σ).
        let mut dtheta = [t[0]; 7];
        for k in 0..6 {
            let (lo, hi) = RANGES[k];
            let s = sigmoid(self.p[k + 1]);
            dtheta[k + 1] = (hi - lo) * s * (1.0 - s);
        }
        let mut j = DMatrix::zeros(self.samples.len(), self.free.len());
        for (row, (s, sg)) in self.samples.iter().zip(self.sigma).enumerate() {
            let cx = s.xi.cos().max(COS_XI_FLOOR);
            let e1 = (m.b / cx).exp();
            let g = s.gamma.abs();
            let gh = g.powf(m.h);
            let e2 = (m.d * gh).exp();
            let bg = 1.0 + m.a * e1;
            let sa = 1.0 + m.c * e2 + m.e * g.cos().powi(2);
            let dh = if g > 0.0 { m.c * e2 * m.d * gh * g.ln() } else { 0.0 };
            let grad = [
                bg * sa,                     // ∂L/∂Lz
                m.lz * sa * e1,              // ∂L/∂a
                m.lz * sa * m.a * e1 / cx,   // ∂L/∂b
                m.lz * bg * e2,              // ∂L/∂c
                m.lz * bg * m.c * e2 * gh,   // ∂L/∂d
                m.lz * bg * g.cos().powi(2), // ∂L/∂e
                m.lz * bg * dh,              // ∂L/∂h
            ];
            for (col, &i) in self.free.iter().enumerate() {
                j[(row, col)] = grad[i] * dtheta[i] / sg;
            }
        }
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

fn check(samples: &[SkySample]) -> Result<Vec<f64>, SkyFitError> {
    for (index, s) in samples.iter().enumerate() {
        if !(s.xi.is_finite() && s.gamma.is_finite() && s.radiance.is_finite()) {
            return Err(SkyFitError::InvalidSample {
                index,
                what: format!("{s:?} is not finite"),
            });
        }
        if !(0.0..=std::f64::consts::FRAC_PI_2 + 1e-9).contains(&s.xi)
            || !(0.0..=std::f64::consts::PI + 1e-9).contains(&s.gamma)
        {
            return Err(SkyFitError::InvalidSample {
                index,
                what: format!("ξ = {} rad must be in [0, π/2] and γ = {} rad in [0, π]", s.xi, s.gamma),
            });
        }
    }
    if samples.len() < 10 {
        return Err(SkyFitError::TooFewSamples {
            found: samples.len(),
            needed: 10,
        });
    }
    let mut mags: Vec<f64> = samples.iter().map(|s| s.radiance.abs()).collect();
    mags.sort_by(f64::total_cmp);
    let median = mags[mags.len() / 2];
    if samples.iter().all(|s| s.radiance <= 0.0) || median <= 0.0 {
        return Err(SkyFitError::NoLight);
    }
    let floor = WEIGHT_FLOOR * median;
    Ok(samples.iter().map(|s| s.radiance.abs().max(floor)).collect())
}

fn rss_of(m: &SkyModel, samples: &[SkySample], sigma: &[f64]) -> f64 {
    samples
        .iter()
        .zip(sigma)
        .map(|(s, sg)| ((m.radiance(s.xi, s.gamma) - s.radiance) / sg).powi(2))
        .sum()
}

/// Fits a sky to samples of one channel, with the sun at zenith angle
/// `sun_zenith` (radians), choosing the smallest adequate model.
pub fn fit_sky(samples: &[SkySample], sun_zenith: f64) -> Result<SkyFit, SkyFitError> {
    let sigma = check(samples)?;
    let n = samples.len();
    // 1. Every CIE sky, its scale in closed form: Lz = Σ w y S / Σ w S².
    let mut cie: Vec<(CieSkyType, SkyModel, f64)> = CieSkyType::all()
        .map(|kind| {
            let shape = CieSky::new(kind, 1.0, sun_zenith.clamp(0.0, std::f64::consts::FRAC_PI_2)).as_seven_parameter();
            let (mut num, mut den) = (0.0, 0.0);
            for (s, sg) in samples.iter().zip(&sigma) {
                let v = shape.radiance(s.xi, s.gamma) / sg;
                num += v * s.radiance / sg;
                den += v * v;
            }
            let scale = if den > 0.0 {
                (num / den).max(f64::MIN_POSITIVE)
            } else {
                1.0
            };
            let model = SkyModel {
                lz: shape.lz * scale,
                ..shape
            };
            (kind, model, rss_of(&model, samples, &sigma))
        })
        .collect();
    cie.sort_by(|x, y| x.2.total_cmp(&y.2));
    let (best_cie_kind, best_cie, best_cie_rss) = cie[0];
    let mut candidates = vec![Candidate {
        kind: SkyModelKind::Cie(best_cie_kind),
        parameters: 1,
        rss: best_cie_rss,
        bic: bic(best_cie_rss, n, 1),
    }];

    // 2. Eq. (5.9) by Levenberg–Marquardt from the three best CIE skies.
    let aureole_seen = samples.iter().any(|s| s.gamma < AUREOLE_SEEN_RAD);
    let free: Vec<usize> = if aureole_seen {
        (0..7).collect()
    } else {
        vec![0, 1, 2, 5]
    };
    let kind = if aureole_seen {
        SkyModelKind::SevenParameter
    } else {
        SkyModelKind::SevenParameterFixedAureole
    };
    let mut evaluations = 0;
    let mut best: Option<(SkyModel, f64, bool)> = None;
    if n > free.len() + 2 {
        for (_, start, _) in cie.iter().take(3) {
            let problem = Problem {
                samples,
                sigma: &sigma,
                p: unbounded(start),
                free: free.clone(),
            };
            let (solved, report) = LevenbergMarquardt::new().with_patience(200).minimize(problem);
            evaluations += report.number_of_evaluations;
            let model = solved.model();
            let rss = rss_of(&model, samples, &sigma);
            if rss.is_finite() && best.as_ref().is_none_or(|b| rss < b.1) {
                best = Some((model, rss, report.termination.was_successful()));
            }
        }
    }
    if let Some((_, rss, _)) = &best {
        candidates.push(Candidate {
            kind,
            parameters: free.len(),
            rss: *rss,
            bic: bic(*rss, n, free.len()),
        });
    }
    let winner = candidates
        .iter()
        .min_by(|x, y| x.bic.total_cmp(&y.bic))
        .cloned()
        .unwrap_or_else(|| candidates[0].clone());
    let (model, converged) = match (winner.kind, &best) {
        (SkyModelKind::Cie(_), _) | (_, None) => (best_cie, true),
        (_, Some((m, _, ok))) => (*m, *ok),
    };
    let reason = match winner.kind {
        SkyModelKind::Cie(t) => format!(
            "CIE standard sky type {} ({}) fits as well as the {}-parameter model once its fewer parameters are counted (BIC {:.1} vs {:.1})",
            t.number(),
            t.description(),
            free.len(),
            winner.bic,
            candidates.get(1).map_or(f64::NAN, |c| c.bic)
        ),
        SkyModelKind::SevenParameter => format!(
            "the seven-parameter sky fits better than the best CIE sky (type {}) by more than its extra parameters cost (BIC {:.1} vs {:.1})",
            best_cie_kind.number(),
            winner.bic,
            candidates[0].bic
        ),
        SkyModelKind::SevenParameterFixedAureole => format!(
            "no sample within {:.0}° of the sun, so the aureole (c, d, h) is fixed at CIE type {}'s; the four-parameter sky beats the best CIE sky (BIC {:.1} vs {:.1})",
            AUREOLE_SEEN_RAD.to_degrees(),
            best_cie_kind.number(),
            winner.bic,
            candidates[0].bic
        ),
    };
    Ok(SkyFit {
        model,
        kind: winner.kind,
        reason,
        rms_relative: (winner.rss / n as f64).sqrt(),
        candidates,
        evaluations,
        converged,
    })
}

/// A sky fitted with outliers (buildings, trees, clouds in front of the
/// sky) found and left out automatically.
#[derive(Debug, Clone, PartialEq)]
pub struct RobustSkyFit {
    /// The fit to the samples kept.
    pub fit: SkyFit,
    /// `true` for each sample kept as sky.
    pub kept: Vec<bool>,
    /// Fraction of samples masked out.
    pub masked_fraction: f64,
    /// Fit–reject rounds run.
    pub rounds: usize,
}

/// The smallest relative residual ever treated as an outlier (5%).
pub const OUTLIER_FLOOR: f64 = 0.05;

/// Fits a sky with non-sky samples left out automatically.
///
/// 1. A robust start (least median of squares over the CIE shapes): for each
///    of the fifteen CIE skies, the scale is the median of yᵢ / Sᵢ and the
///    score the median |ln(yᵢ / (scale Sᵢ))|; the best one starts.
/// 2. Samples whose relative residual from the current model exceeds
///    max(3 × 1.4826 × MAD, [`OUTLIER_FLOOR`]) are left out, the model is
///    refitted with [`fit_sky`], and this repeats until the kept set stops
///    changing (at most 8 rounds).
///
/// A least-squares start would not do: relative weights give dark
/// occluders (buildings, trees) more pull than the bright sky, and trimming
/// from there would keep the building. The thesis picked sky regions by
/// hand; this needs no hand, up to about half of the samples occluded.
pub fn fit_sky_robust(samples: &[SkySample], sun_zenith: f64) -> Result<RobustSkyFit, SkyFitError> {
    check(samples)?;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let start = CieSkyType::all()
        .filter_map(|kind| {
            let shape = CieSky::new(kind, 1.0, sun_zenith.clamp(0.0, std::f64::consts::FRAC_PI_2)).as_seven_parameter();
            let q: Vec<f64> = samples
                .iter()
                .filter(|s| s.radiance > 0.0)
                .map(|s| s.radiance / shape.radiance(s.xi, s.gamma))
                .filter(|q| q.is_finite() && *q > 0.0)
                .collect();
            if q.len() < 10 {
                return None;
            }
            let scale = median(q.clone());
            let score = median(q.iter().map(|x| (x / scale).ln().abs()).collect());
            Some((
                score,
                SkyModel {
                    lz: shape.lz * scale,
                    ..shape
                },
            ))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, m)| m)
        .ok_or(SkyFitError::NoLight)?;
    let relative = |m: &SkyModel| -> Vec<f64> {
        samples
            .iter()
            .map(|s| {
                let v = m.radiance(s.xi, s.gamma);
                ((s.radiance - v) / v.abs().max(f64::MIN_POSITIVE)).abs()
            })
            .collect()
    };
    let select = |rel: &[f64], current: Option<&[bool]>| -> Vec<bool> {
        let pool: Vec<f64> = match current {
            Some(k) => rel.iter().zip(k).filter(|(_, k)| **k).map(|(r, _)| *r).collect(),
            None => rel.to_vec(),
        };
        let threshold = (3.0 * 1.4826 * median(pool)).max(OUTLIER_FLOOR);
        rel.iter().map(|&r| r <= threshold).collect()
    };
    let mut kept = select(&relative(&start), None);
    let mut rounds = 0;
    loop {
        rounds += 1;
        let subset: Vec<SkySample> = samples
            .iter()
            .zip(&kept)
            .filter(|(_, k)| **k)
            .map(|(s, _)| *s)
            .collect();
        let fit = fit_sky(&subset, sun_zenith)?;
        let next = select(&relative(&fit.model), Some(&kept));
        if next == kept || rounds >= 8 || next.iter().filter(|k| **k).count() < 10 {
            let masked = kept.iter().filter(|k| !**k).count();
            return Ok(RobustSkyFit {
                fit,
                masked_fraction: masked as f64 / samples.len() as f64,
                kept,
                rounds,
            });
        }
        kept = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Sky directions on a grid, as (ξ, γ) for a sun at (zs, azimuth 0),
    /// keeping those with ξ ≤ `max_xi` and outside the 0.5° disc.
    fn directions(zs: f64, max_xi: f64, step_deg: f64) -> Vec<(f64, f64)> {
        let sun = [zs.sin(), 0.0, zs.cos()];
        let mut out = Vec::new();
        let mut xi = 0.0;
        while xi <= max_xi + 1e-12 {
            let n = ((360.0 / step_deg) * xi.sin()).ceil().max(1.0) as usize;
            for k in 0..n {
                let az = 2.0 * PI * k as f64 / n as f64;
                let v = [xi.sin() * az.cos(), xi.sin() * az.sin(), xi.cos()];
                let g = super::super::angle_between(v, sun);
                if g > 0.5f64.to_radians() {
                    out.push((xi, g));
                }
            }
            xi += step_deg.to_radians();
        }
        out
    }

    fn samples_of(m: &SkyModel, dirs: &[(f64, f64)], noise: f64, rng: &mut ChaCha8Rng) -> Vec<SkySample> {
        dirs.iter()
            .map(|&(xi, gamma)| SkySample {
                xi,
                gamma,
                radiance: m.radiance(xi, gamma) * (1.0 + noise * (rng.random::<f64>() * 2.0 - 1.0) * 3f64.sqrt()),
            })
            .collect()
    }

    fn rel_rms(a: &SkyModel, b: &SkyModel, dirs: &[(f64, f64)]) -> f64 {
        let s: f64 = dirs
            .iter()
            .map(|&(x, g)| (a.radiance(x, g) / b.radiance(x, g) - 1.0).powi(2))
            .sum();
        (s / dirs.len() as f64).sqrt()
    }

    fn clear_sky() -> SkyModel {
        SkyModel {
            lz: 0.08,
            a: -1.0,
            b: -0.45,
            c: 14.0,
            d: -3.6,
            e: 0.6,
            h: 0.85,
        }
    }

    #[test]
    fn recovers_a_clear_sky_within_1_percent_from_noisy_partial_views() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let truth = clear_sky();
        let zs = 0.7;
        // Visible: ξ up to 75°, and only the half of the sky facing the sun's side
        // (an occluding building on the other side).
        let all = directions(zs, 85f64.to_radians(), 3.0);
        let visible: Vec<_> = all
            .iter()
            .copied()
            .filter(|&(xi, g)| xi < 75f64.to_radians() && g < 1.9)
            .collect();
        let fit = fit_sky(&samples_of(&truth, &visible, 0.02, &mut rng), zs).expect("fits");
        assert_eq!(fit.kind, SkyModelKind::SevenParameter, "{}", fit.reason);
        let vis = rel_rms(&fit.model, &truth, &visible);
        let whole = rel_rms(&fit.model, &truth, &all);
        assert!(vis < 0.01, "visible-sky error {vis}");
        assert!(whole < 0.03, "extrapolated-sky error {whole}");
    }

    #[test]
    fn all_15_cie_skies_median_2_percent_p95_5_percent() {
        let mut errors = Vec::new();
        for kind in CieSkyType::all() {
            for zs in [0.2, 0.8, 1.3] {
                let truth = CieSky::new(kind, 5.0, zs).as_seven_parameter();
                let dirs = directions(zs, 88f64.to_radians(), 4.0);
                let mut rng = ChaCha8Rng::seed_from_u64(u64::from(kind.number()));
                let fit = fit_sky(&samples_of(&truth, &dirs, 0.02, &mut rng), zs).expect("fits");
                errors.push(rel_rms(&fit.model, &truth, &dirs));
            }
        }
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        let p95 = errors[(errors.len() * 95).div_ceil(100) - 1];
        assert!(median <= 0.02 && p95 <= 0.05, "median {median} p95 {p95}");
    }

    #[test]
    fn buildings_in_front_of_the_sky_are_masked_automatically() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let truth = clear_sky();
        let zs = 0.7;
        let dirs = directions(zs, 85f64.to_radians(), 3.0);
        let mut samples = samples_of(&truth, &dirs, 0.02, &mut rng);
        // A building and trees: every sample below 25° elevation on one side,
        // textured and a fifth to half as bright as the sky there.
        let mut truly_sky = vec![true; samples.len()];
        for (k, s) in samples.iter_mut().enumerate() {
            if s.xi > 65f64.to_radians() && s.gamma > 1.2 {
                s.radiance *= 0.2 + 0.3 * rng.random::<f64>();
                truly_sky[k] = false;
            }
        }
        let occluded = truly_sky.iter().filter(|k| !**k).count() as f64 / samples.len() as f64;
        assert!(occluded > 0.15, "{occluded}");
        let plain = fit_sky(&samples, zs).expect("fits");
        let robust = fit_sky_robust(&samples, zs).expect("fits");
        let vis: Vec<_> = dirs
            .iter()
            .zip(&truly_sky)
            .filter(|(_, k)| **k)
            .map(|(d, _)| *d)
            .collect();
        let e_plain = rel_rms(&plain.model, &truth, &vis);
        let e_robust = rel_rms(&robust.fit.model, &truth, &vis);
        assert!(e_robust < 0.01, "robust {e_robust} (plain {e_plain})");
        assert!(
            e_plain > 3.0 * e_robust,
            "the mask matters: plain {e_plain}, robust {e_robust}"
        );
        // Every occluded sample is masked; few true sky samples are.
        let missed = truly_sky
            .iter()
            .zip(&robust.kept)
            .filter(|(sky, kept)| !**sky && **kept)
            .count();
        let lost = truly_sky
            .iter()
            .zip(&robust.kept)
            .filter(|(sky, kept)| **sky && !**kept)
            .count();
        assert_eq!(missed, 0);
        assert!((lost as f64) < 0.02 * samples.len() as f64, "{lost} sky samples masked");
    }

    #[test]
    fn the_same_answer_at_every_scale_of_units() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let dirs = directions(0.6, 1.4, 4.0);
        let base = samples_of(&clear_sky(), &dirs, 0.02, &mut rng);
        let fits: Vec<SkyFit> = [1e-3, 1.0, 1e3]
            .iter()
            .map(|k| {
                let s: Vec<_> = base
                    .iter()
                    .map(|x| SkySample {
                        radiance: x.radiance * k,
                        ..*x
                    })
                    .collect();
                fit_sky(&s, 0.6).expect("fits")
            })
            .collect();
        for f in &fits[1..] {
            assert_eq!(f.kind, fits[0].kind);
            assert!((f.rms_relative - fits[0].rms_relative).abs() < 1e-9);
            for (x, y) in [
                (f.model.a, fits[0].model.a),
                (f.model.c, fits[0].model.c),
                (f.model.h, fits[0].model.h),
            ] {
                assert!((x - y).abs() < 1e-5 * (1.0 + y.abs()), "{x} vs {y}");
            }
        }
        assert!((fits[2].model.lz / fits[0].model.lz / 1e6 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn converges_on_at_least_99_percent_of_random_valid_skies() {
        let mut rng = ChaCha8Rng::seed_from_u64(1000);
        let mut ok = 0;
        let trials = 200;
        for _ in 0..trials {
            let zs = rng.random_range(0.05..1.5);
            let truth = SkyModel {
                lz: rng.random_range(0.01..10.0),
                a: rng.random_range(-1.0..2.0),
                b: rng.random_range(-1.0..-0.1),
                c: rng.random_range(0.0..25.0),
                d: rng.random_range(-4.0..-1.0),
                e: rng.random_range(0.0..0.6),
                h: rng.random_range(0.7..1.3),
            };
            let dirs = directions(zs, 85f64.to_radians(), 6.0);
            let fit = fit_sky(&samples_of(&truth, &dirs, 0.0, &mut rng), zs).expect("fits");
            if rel_rms(&fit.model, &truth, &dirs) < 0.01 {
                ok += 1;
            }
        }
        assert!(ok * 100 >= trials * 99, "{ok} of {trials}");
    }

    #[test]
    fn hard_cases_give_answers_or_errors_never_nan() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        // Samples down to ξ = 89.9°, sun at the zenith, sun at the horizon.
        for zs in [0.0, FRAC_PI_2] {
            let mut dirs = directions(zs, 89.9f64.to_radians(), 5.0);
            dirs.push((89.9f64.to_radians(), 1.0));
            let truth = CieSky::new(CieSkyType::new(12).expect("t"), 1.0, zs).as_seven_parameter();
            let fit = fit_sky(&samples_of(&truth, &dirs, 0.02, &mut rng), zs).expect("fits");
            assert!(
                fit.model.radiance(1.0, 1.0).is_finite() && rel_rms(&fit.model, &truth, &dirs) < 0.03,
                "zs {zs}: {fit:?}"
            );
        }
        // The sun not in view: the aureole is fixed, and says so.
        let zs = 0.5;
        let dirs: Vec<_> = directions(zs, 1.4, 4.0).into_iter().filter(|&(_, g)| g > 0.6).collect();
        let fit = fit_sky(&samples_of(&clear_sky(), &dirs, 0.01, &mut rng), zs).expect("fits");
        assert!(!matches!(fit.kind, SkyModelKind::SevenParameter), "{:?}", fit.kind);
        assert!(
            fit.reason.contains("CIE") || fit.reason.contains("fixed"),
            "{}",
            fit.reason
        );
        // Bad inputs are errors.
        let nan = vec![
            SkySample {
                xi: f64::NAN,
                gamma: 0.1,
                radiance: 1.0
            };
            20
        ];
        assert!(matches!(
            fit_sky(&nan, 0.5),
            Err(SkyFitError::InvalidSample { index: 0, .. })
        ));
        let dark = vec![
            SkySample {
                xi: 0.3,
                gamma: 0.4,
                radiance: 0.0
            };
            20
        ];
        assert_eq!(fit_sky(&dark, 0.5), Err(SkyFitError::NoLight));
        assert!(matches!(
            fit_sky(&dark[..3], 0.5),
            Err(SkyFitError::TooFewSamples { found: 3, .. })
        ));
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let dirs = directions(0.6, 1.4, 15.0);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let samples = samples_of(&clear_sky(), &dirs, 0.0, &mut rng);
        let sigma = check(&samples).expect("valid");
        let mut p = Problem {
            samples: &samples,
            sigma: &sigma,
            p: unbounded(&clear_sky()),
            free: (0..7).collect(),
        };
        p.p[1] += 0.3; // away from any special point
        let j = p.jacobian().expect("finite");
        let x0 = p.params();
        for col in 0..7 {
            let h = 1e-6;
            let mut xp = x0.clone();
            xp[col] += h;
            p.set_params(&xp);
            let rp = p.residuals().expect("finite");
            let mut xm = x0.clone();
            xm[col] -= h;
            p.set_params(&xm);
            let rm = p.residuals().expect("finite");
            p.set_params(&x0);
            for row in 0..samples.len() {
                let fd = (rp[row] - rm[row]) / (2.0 * h);
                assert!(
                    (fd - j[(row, col)]).abs() < 1e-5 * (1.0 + fd.abs()),
                    "({row}, {col}): {fd} vs {}",
                    j[(row, col)]
                );
            }
        }
    }
}
