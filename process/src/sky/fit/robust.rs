//! Fitting a sky with the samples that are not sky left out: buildings,
//! the mount, trees and birds in front of it, glare and cloud edges.
//!
//! Outliers are decided against the best model of the sky, never against a
//! start: a smooth aureole that the start lacks is sky the model can fit,
//! and must not be masked because the start missed it.
//!
//! 1. **Start**: the CIE and Perez table skies are scored robustly (the
//!    median |ln(yᵢ / (Lz Sᵢ))| with Lz the median ratio), so that up to
//!    half the samples may be anything.
//! 2. **Graduated robust fit** of the Perez form from the best two starts:
//!    iteratively reweighted least squares with Cauchy weights
//!    `wᵢ = 1 / (1 + (uᵢ / s)²)` on the log ratio `uᵢ = ln(yᵢ / Lᵢ)`. The
//!    scale s starts at three times the start's robust spread
//!    1.4826 · median |u|, and at least 0.2, and halves each round down to the spread
//!    1.4826 · median |u| of the samples within s (the sky's own noise),
//!    and no lower than [`OUTLIER_FLOOR`] / 3: what the model can
//!    follow it follows while the weights are still wide, and what it
//!    cannot (an occluder's edge, a dark sector) loses its weight as they
//!    narrow.
//! 3. **Decision** against that model: a sample is an outlier when
//!    |uᵢ| > max(3 · 1.4826 · median |u|, [`OUTLIER_FLOOR`]), or when it
//!    or the model is not positive. At most [`SkyFitOptions::max_masked_fraction`]
//!    of the samples are masked (the worst first); the rest stay, and the
//!    fraction of outliers still feeds the verdict.
//! 4. The kept samples are fitted with the model choice of [`super::fit_sky`],
//!    starting from the robust model, and the decision is repeated against
//!    the result until it stops changing (at most 4 rounds). A capped
//!    decision is final: the kept samples still hold outliers, and the
//!    residual says how much that cost.

use super::solver::{self, Prepared, Settings};
use super::{PEREZ_FREE, SkyFit, SkyFitError, SkySample, check, fit_prepared, fit_sky, model_of, starts, theta_of};

/// The smallest log ratio |ln(y / L)| ever treated as an outlier (5%).
pub const OUTLIER_FLOOR: f64 = 0.05;

/// The smallest scale the graduated fit starts at: a sample 20% off the
/// start keeps half its weight.
const START_SCALE: f64 = 0.2;

/// The default cap on the fraction of samples masked.
pub const MAX_MASKED_FRACTION: f64 = 0.5;

/// How the fit treats samples that are not sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyFitOptions {
    /// Find and leave out samples that are not sky (default); when `false`
    /// every sample is fitted, as by [`fit_sky`].
    pub reject_outliers: bool,
    /// At most this fraction of the samples is masked (default
    /// [`MAX_MASKED_FRACTION`]).
    pub max_masked_fraction: f64,
}

impl Default for SkyFitOptions {
    fn default() -> Self {
        SkyFitOptions {
            reject_outliers: true,
            max_masked_fraction: MAX_MASKED_FRACTION,
        }
    }
}

/// A sky fitted with the samples that are not sky found and left out.
#[derive(Debug, Clone, PartialEq)]
pub struct RobustSkyFit {
    /// The fit to the samples kept.
    pub fit: SkyFit,
    /// `true` for each sample kept as sky.
    pub kept: Vec<bool>,
    /// Fraction of samples masked out.
    pub masked_fraction: f64,
    /// Fraction of samples beyond the outlier threshold, masked or, over
    /// the cap, kept.
    pub outlier_fraction: f64,
    /// Masked samples darker than the model (occluders: the mount,
    /// buildings, trees).
    pub masked_darker: usize,
    /// Masked samples brighter than the model (glare, lit cloud edges).
    pub masked_brighter: usize,
    /// The |ln(y / L)| above which a sample was an outlier (∞ with
    /// rejection off).
    pub threshold: f64,
    /// Whether more samples were outliers than the cap let be masked.
    pub capped: bool,
    /// Decide–refit rounds run.
    pub rounds: usize,
}

impl RobustSkyFit {
    /// What was masked and why, in one line.
    pub fn masked_summary(&self) -> String {
        if self.threshold.is_infinite() {
            return "outlier rejection off: every sample fitted".to_owned();
        }
        let masked = self.masked_darker + self.masked_brighter;
        let mut s = format!(
            "{masked} samples masked ({:.1}%): {} darker than the sky model (occluders), {} brighter (glare, clouds), beyond |ln(measured/model)| > {:.3}",
            100.0 * self.masked_fraction,
            self.masked_darker,
            self.masked_brighter,
            self.threshold
        );
        if self.capped {
            s.push_str(&format!(
                "; {:.1}% were outliers, more than the cap: the rest were kept",
                100.0 * self.outlier_fraction
            ));
        }
        s
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// uᵢ = ln(yᵢ / Lᵢ), +∞ when either is not positive.
fn log_ratios(prep: &Prepared, theta: &[f64; 7]) -> Vec<f64> {
    let t = solver::natural(theta);
    (0..prep.len())
        .map(|i| {
            let l = prep.model_at(&t, i);
            let y = prep.y(i);
            if l > 0.0 && y > 0.0 {
                (y / l).ln()
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

/// The robust spread 1.4826 · median |u|.
fn spread(u: &[f64]) -> f64 {
    1.4826 * median(u.iter().map(|x| x.abs()).collect())
}

/// Fits a sky with non-sky samples left out automatically (the module
/// doc), with the default options.
pub fn fit_sky_robust(samples: &[SkySample], sun_zenith: f64) -> Result<RobustSkyFit, SkyFitError> {
    fit_sky_with(samples, sun_zenith, &SkyFitOptions::default())
}

/// The graduated robust fit of step 2 from one start; returns θ and its
/// median |u|.
fn graduated(prep: &Prepared, start: &[f64; 7]) -> Option<([f64; 7], f64)> {
    let settings = Settings {
        ftol: 1e-6,
        xtol: 1e-8,
        gtol: 1e-8,
        max_evaluations: 30,
        ..Settings::default()
    };
    let mut theta = *start;
    let mut u = log_ratios(prep, &theta);
    if u.iter().filter(|x| x.is_finite()).count() < 10 {
        return None;
    }
    let mut s = (3.0 * spread(&u)).max(START_SCALE);
    for _ in 0..12 {
        // Cauchy weights on u, carried over to the solver's residual
        // r = (L − y)/σ by (u / r)², so that the weighted squares follow
        // the log ratio: r alone would let a sample at a fifth of the sky
        // (r = 4) outweigh one at 1.6 times it (r = −0.4).
        let t = solver::natural(&theta);
        let w: Vec<f64> = u
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                if !x.is_finite() {
                    return 0.0;
                }
                let r = (prep.model_at(&t, i) - prep.y(i)) * prep.inv_sigma(i);
                let carry = if r != 0.0 && x != 0.0 { (x / r).powi(2) } else { 1.0 };
                carry / (1.0 + (x / s).powi(2))
            })
            .collect();
        let out = solver::minimize(prep, theta, &PEREZ_FREE, Some(&w), &settings)?;
        theta = out.theta;
        u = log_ratios(prep, &theta);
        // The spread of the samples the model currently follows.
        let inliers: Vec<f64> = u.iter().copied().filter(|x| x.abs() <= s).collect();
        let floor = spread(&inliers).max(OUTLIER_FLOOR / 3.0);
        // Done at the sky's own spread, or when nothing is left for a
        // narrower scale to down-weight.
        if s <= floor || u.iter().all(|x| x.abs() <= floor) {
            break;
        }
        s = (s / 2.0).max(floor);
    }
    let score = median(u.iter().map(|x| x.abs()).collect());
    Some((theta, score))
}

/// Fits a sky with the options given (the module doc).
pub fn fit_sky_with(
    samples: &[SkySample],
    sun_zenith: f64,
    options: &SkyFitOptions,
) -> Result<RobustSkyFit, SkyFitError> {
    if !options.reject_outliers {
        let fit = fit_sky(samples, sun_zenith)?;
        return Ok(RobustSkyFit {
            fit,
            kept: vec![true; samples.len()],
            masked_fraction: 0.0,
            outlier_fraction: 0.0,
            masked_darker: 0,
            masked_brighter: 0,
            threshold: f64::INFINITY,
            capped: false,
            rounds: 1,
        });
    }
    let sigma = check(samples)?;
    let prep = Prepared::new(samples, &sigma);
    let robust_starts = starts::scored_robust(&prep, sun_zenith);
    // From the best start, and from the second when the first leaves a
    // median misfit over the outlier floor.
    let mut best: Option<([f64; 7], f64)> = None;
    for start in robust_starts.iter().take(2) {
        if best.is_some_and(|b| b.1 <= OUTLIER_FLOOR) {
            break;
        }
        if let Some(g) = graduated(&prep, &theta_of(&start.model))
            && best.is_none_or(|b| g.1 < b.1)
        {
            best = Some(g);
        }
    }
    let (mut theta, _) = best.ok_or(SkyFitError::NoLight)?;
    let n = samples.len();
    let cap = ((options.max_masked_fraction.clamp(0.0, 1.0) * n as f64).floor() as usize).min(n.saturating_sub(10));
    let decide = |theta: &[f64; 7]| -> Decision {
        let u = log_ratios(&prep, theta);
        let threshold = (3.0 * spread(&u)).max(OUTLIER_FLOOR);
        let mut outliers: Vec<usize> = (0..n)
            .filter(|&i| u[i].abs().is_nan() || u[i].abs() > threshold)
            .collect();
        let outlier_fraction = outliers.len() as f64 / n as f64;
        let capped = outliers.len() > cap;
        if capped {
            outliers.sort_by(|&i, &j| u[j].abs().total_cmp(&u[i].abs()));
            outliers.truncate(cap);
        }
        let mut kept = vec![true; n];
        for &i in &outliers {
            kept[i] = false;
        }
        let darker = outliers.iter().filter(|&&i| u[i] < 0.0).count();
        Decision {
            kept,
            masked: outliers.len(),
            darker,
            threshold,
            outlier_fraction,
            capped,
        }
    };
    let mut decision = decide(&theta);
    let mut rounds = 0;
    loop {
        rounds += 1;
        let subset: Vec<SkySample> = samples
            .iter()
            .zip(&decision.kept)
            .filter(|(_, k)| **k)
            .map(|(s, _)| *s)
            .collect();
        let sub_sigma = check(&subset)?;
        let sub = Prepared::new(&subset, &sub_sigma);
        let sub_starts = starts::scored_least_squares(&sub, sun_zenith);
        if sub_starts.is_empty() {
            return Err(SkyFitError::NoLight);
        }
        let fit = fit_prepared(&sub, &sub_starts, Some(model_of(&theta)));
        theta = theta_of(&fit.model);
        let next = decide(&theta);
        // A capped decision is not revised: the fit to its kept samples
        // still holds outliers, and deciding against it would unmask them.
        if next.kept == decision.kept || decision.capped || rounds >= 4 {
            return Ok(RobustSkyFit {
                masked_fraction: decision.masked as f64 / n as f64,
                outlier_fraction: decision.outlier_fraction,
                masked_darker: decision.darker,
                masked_brighter: decision.masked - decision.darker,
                threshold: decision.threshold,
                capped: decision.capped,
                rounds,
                kept: decision.kept,
                fit,
            });
        }
        decision = next;
    }
}

/// Which samples a model leaves out, and the figures of that decision.
struct Decision {
    kept: Vec<bool>,
    masked: usize,
    darker: usize,
    threshold: f64,
    outlier_fraction: f64,
    capped: bool,
}
