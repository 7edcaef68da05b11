//! Fitting a sky to measured radiance, thesis eq. (5.10), with the choice of
//! the smallest model the data supports.
//!
//! **Weights.** The thesis minimizes Σ [(yᵢ − L(ξᵢ, γᵢ)) / σᵢ]² with
//! σᵢ = yᵢ / ln yᵢ, which depends on the radiance unit (it is undefined at
//! y = 1 and negative below). Its intent is a roughly relative error. We use
//! σᵢ = max(|yᵢ|, ε · median |y|) with ε = 10⁻³: relative error where the
//! sky is measurably bright, with a floor so that near-black or
//! noisy-negative samples cannot dominate. Scaling every yᵢ by k scales L by
//! k (through Lz) and every σᵢ by k, so the residuals, the fit and the
//! choice of model are the same in any unit.
//!
//! **Optimizer.** A bounded Levenberg–Marquardt with the analytic Jacobian
//! ([`solver`]): Lz through its logarithm, a–h inside [`PARAMETER_RANGES`],
//! which hold every sky of the Perez all-weather table and the CIE skies.
//! It reports why it stopped ([`Convergence`]); a parameter that ends at a
//! bound is named there.
//!
//! **Starts.** The fifteen CIE standard skies and the Perez table's skies at
//! the samples' sun ([`starts`]) are scored in closed form (scale only) on
//! a subset of the samples; Levenberg–Marquardt starts from the best, and
//! from the second best too when the first leaves more than
//! [`SECOND_START_RMS`] of RMS residual.
//!
//! **Model choice.** Candidates: the best CIE sky (one parameter, its scale),
//! the aureole fixed at the best start's (four: Lz, a, b, e), the Perez form
//! (eq. 5.8: eq. 5.9 with h = 1, six) and the seven-parameter sky (seven).
//! A candidate whose scaled JᵀJ is numerically singular (reciprocal
//! condition below [`RCOND_FLOOR`]) is not determined by the samples and
//! cannot win; among the others the smallest Bayesian information
//! criterion `n ln(RSS/n) + k ln n` wins. So the aureole is fixed exactly
//! when the samples do not pay for fitting it, however far from the sun
//! they lie.

mod elementary;
mod kernel;
mod robust;
mod solver;
mod starts;

use serde::{Deserialize, Serialize};

use crate::model_choice::bic;

use super::cie::CieSkyType;
use super::seven_parameter::SkyModel;
pub use robust::{MAX_MASKED_FRACTION, OUTLIER_FLOOR, RobustSkyFit, SkyFitOptions, fit_sky_robust, fit_sky_with};
use solver::{Outcome, Prepared, Settings};
pub use solver::{PARAMETER_NAMES, PARAMETER_RANGES, Termination};
use starts::Start;

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

/// The weight floor ε of the module doc.
pub const WEIGHT_FLOOR: f64 = 1e-3;

/// Below this reciprocal condition number of the column-scaled JᵀJ a
/// candidate's parameters are not determined by the samples (10⁻¹²: about
/// the square of float64's digits left after the residuals' own rounding).
pub const RCOND_FLOOR: f64 = 1e-12;

/// Which model the fit chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SkyModelKind {
    /// A CIE standard sky, scaled.
    Cie(CieSkyType),
    /// The Perez all-weather form: eq. (5.9) with h = 1, six parameters.
    Perez,
    /// The seven-parameter sky of eq. (5.9), all parameters free.
    SevenParameter,
    /// Eq. (5.9) with the aureole (c, d, h) fixed, because the samples do
    /// not pay for fitting it.
    SevenParameterFixedAureole,
}

impl SkyModelKind {
    /// The name written in sky files: `Cie(12)`, `Perez`, `SevenParameter`
    /// or `SevenParameterFixedAureole`.
    pub fn label(&self) -> String {
        match self {
            SkyModelKind::Cie(t) => format!("Cie({})", t.number()),
            SkyModelKind::Perez => "Perez".into(),
            SkyModelKind::SevenParameter => "SevenParameter".into(),
            SkyModelKind::SevenParameterFixedAureole => "SevenParameterFixedAureole".into(),
        }
    }

    fn words(&self) -> String {
        match self {
            SkyModelKind::Cie(t) => format!("CIE type {}", t.number()),
            SkyModelKind::Perez => "the Perez form".into(),
            SkyModelKind::SevenParameter => "the seven-parameter sky".into(),
            SkyModelKind::SevenParameterFixedAureole => "the fixed-aureole sky".into(),
        }
    }
}

/// How the winning model's optimizer ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Convergence {
    /// Stopped by a convergence criterion (not by the budget).
    pub converged: bool,
    /// Which criterion.
    pub termination: Termination,
    /// Accepted steps.
    pub iterations: usize,
    /// Residual-and-Jacobian evaluations.
    pub evaluations: usize,
    /// Parameters that ended at a bound of [`PARAMETER_RANGES`], e.g.
    /// `"a = -3 (lower bound)"`: the sky lies outside the model's range
    /// there, a warning that feeds the sky's verdict.
    #[serde(default)]
    pub at_bound: Vec<String>,
}

impl Convergence {
    fn closed_form() -> Self {
        Convergence {
            converged: true,
            termination: Termination::ClosedForm,
            iterations: 0,
            evaluations: 0,
            at_bound: Vec::new(),
        }
    }

    fn of(out: &Outcome) -> Self {
        let t = solver::natural(&out.theta);
        Convergence {
            converged: out.termination.converged(),
            termination: out.termination,
            iterations: out.iterations,
            evaluations: out.evaluations,
            at_bound: out
                .at_bound
                .iter()
                .map(|&j| {
                    let (lo, _) = solver::bounds(j);
                    let side = if t[j] <= lo { "lower" } else { "upper" };
                    format!("{} = {} ({side} bound)", PARAMETER_NAMES[j], t[j])
                })
                .collect(),
        }
    }

    /// One line, e.g. "converged (gradient below gtol), 9 iterations".
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{} ({}), {} iterations",
            if self.converged { "converged" } else { "NOT converged" },
            self.termination.describe(),
            self.iterations
        );
        if !self.at_bound.is_empty() {
            s.push_str(&format!("; at a bound: {}", self.at_bound.join(", ")));
        }
        s
    }
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
    /// Why it could not win, if so.
    pub excluded: Option<String>,
    /// Residual-and-Jacobian evaluations its Levenberg–Marquardt used (0
    /// for a closed form or a candidate not fitted).
    pub evaluations: usize,
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
    /// Residual evaluations Levenberg–Marquardt used, over all candidates.
    pub evaluations: usize,
    /// How the winning model's optimizer ended.
    pub convergence: Convergence,
    /// The start the optimizer began from, in words.
    pub start: String,
    /// That start's sky (h = 1), e.g. to run another optimizer from it.
    pub start_model: SkyModel,
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
    /// The start given to [`fit_perez_from`] cannot be evaluated.
    #[error("the start sky {start:?} gives residuals that are not finite on these samples")]
    StartNotFinite {
        /// The start.
        start: SkyModel,
    },
}

/// Checks the samples and returns each one's σ.
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
    let mid = mags.len() / 2;
    let median = *mags.select_nth_unstable_by(mid, f64::total_cmp).1;
    if samples.iter().all(|s| s.radiance <= 0.0) || median <= 0.0 {
        return Err(SkyFitError::NoLight);
    }
    let floor = WEIGHT_FLOOR * median;
    Ok(samples.iter().map(|s| s.radiance.abs().max(floor)).collect())
}

/// θ = [ln Lz, a, b, c, d, e, h] of a model.
fn theta_of(m: &SkyModel) -> [f64; 7] {
    [m.lz.max(f64::MIN_POSITIVE).ln(), m.a, m.b, m.c, m.d, m.e, m.h]
}

fn model_of(theta: &[f64; 7]) -> SkyModel {
    let t = solver::natural(theta);
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

/// The weighted RSS of a model with its scale refitted in closed form.
fn rescaled(prep: &Prepared, m: &SkyModel) -> (SkyModel, f64) {
    let (sy, ss, yy) = prep.scale_sums(&[1.0, m.a, m.b, m.c, m.d, m.e, m.h]);
    let lz = if ss > 0.0 {
        (sy / ss).max(f64::MIN_POSITIVE)
    } else {
        m.lz
    };
    (SkyModel { lz, ..*m }, (yy - 2.0 * lz * sy + lz * lz * ss).max(0.0))
}

/// The relative RMS residual below which the best start's fit is kept
/// without trying the second (0.3%: on RADIANCE's
/// `gdl-bin4-el75-d50-az160` the best start's fit stopped at 0.9% RMS in a
/// wrong minimum, 1.8% p95, where the second start reaches 0.1%).
const SECOND_START_RMS: f64 = 0.003;

/// The relative standard error under which the Perez fit's c and d count
/// as pinned by the samples (1%), so that the fixed-aureole candidate is not
/// fitted.
const AUREOLE_PINNED: f64 = 0.01;

/// The free θ entries of the Perez form (h held at 1).
const PEREZ_FREE: [usize; 6] = [0, 1, 2, 3, 4, 5];
/// All seven.
const SEVEN_FREE: [usize; 7] = [0, 1, 2, 3, 4, 5, 6];
/// Aureole (c, d, h) held.
const FIXED_AUREOLE_FREE: [usize; 4] = [0, 1, 2, 5];

/// Fits a sky to samples of one channel, with the sun at zenith angle
/// `sun_zenith` (radians), choosing the smallest adequate model. Every
/// sample counts; [`fit_sky_robust`] leaves out those that are not sky.
pub fn fit_sky(samples: &[SkySample], sun_zenith: f64) -> Result<SkyFit, SkyFitError> {
    let sigma = check(samples)?;
    let prep = Prepared::new(samples, &sigma);
    let starts = starts::scored_least_squares(&prep, sun_zenith);
    if starts.is_empty() {
        return Err(SkyFitError::NoLight);
    }
    Ok(fit_prepared(&prep, &starts, None))
}

/// Levenberg–Marquardt of the Perez form alone (eq. 5.9 with h = 1) from
/// `start` (its h ignored), every sample counted, and nothing else: no
/// scored starts, no other candidate, no model choice. This is the fit
/// `scipy.optimize.least_squares(method="lm")` makes from the same start,
/// for like-for-like comparisons (`bench/sky/run.sh`); [`fit_sky`] is the
/// fit to use. Returns the fitted sky and how the optimizer ended.
pub fn fit_perez_from(samples: &[SkySample], start: &SkyModel) -> Result<(SkyModel, Convergence), SkyFitError> {
    let sigma = check(samples)?;
    let prep = Prepared::new(samples, &sigma);
    let start = SkyModel { h: 1.0, ..*start };
    let out = solver::minimize(&prep, theta_of(&start), &PEREZ_FREE, None, &Settings::default())
        .ok_or(SkyFitError::StartNotFinite { start })?;
    Ok((model_of(&out.theta), Convergence::of(&out)))
}

/// The model choice of the module doc, from the scored starts and, if
/// given, a model to start the Perez form from first.
fn fit_prepared(prep: &Prepared, starts: &[Start], first: Option<SkyModel>) -> SkyFit {
    let n = prep.len();
    let settings = Settings::default();
    let mut evaluations = 0;
    // The best CIE sky by the subset, its scale and RSS over every sample.
    let (cie_kind, cie_model, cie_rss) = starts
        .iter()
        .filter_map(|s| match s.origin {
            starts::Origin::Cie(t) => Some((t, s.model)),
            starts::Origin::Perez { .. } => None,
        })
        .take(1)
        .map(|(t, m)| {
            let (m, rss) = rescaled(prep, &m);
            (t, m, rss)
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .unwrap_or_else(|| {
            let t = CieSkyType::new(12).unwrap_or_else(|| unreachable!("type 12 exists"));
            let (m, rss) = rescaled(prep, &starts[0].model);
            (t, m, rss)
        });
    let mut fits: Vec<(SkyModelKind, usize, Option<Outcome>, SkyModel, f64)> =
        vec![(SkyModelKind::Cie(cie_kind), 1, None, cie_model, cie_rss)];
    let run = |start: &SkyModel, free: &[usize], evaluations: &mut usize| {
        // The seven-parameter sky starts at the Perez fit, a minimum in all
        // but h: nearly undamped steps from there (λ = 10⁻⁶ instead of
        // 10⁻³; median 5 → 3 evaluations on the references, the same
        // choices).
        let settings = if free == SEVEN_FREE {
            Settings {
                initial_lambda: 1e-6,
                ..settings
            }
        } else {
            settings
        };
        let out = solver::minimize(prep, theta_of(start), free, None, &settings)?;
        *evaluations += out.evaluations;
        Some(out)
    };
    // The Perez form from the given model, then the two best starts.
    let mut perez: Option<Outcome> = None;
    let mut origins = Vec::new();
    let mut start_models = Vec::new();
    // Given a model (the robust fit's), only it; else the best two starts,
    // the second only when the first leaves more than SECOND_START_RMS.
    let tries: Vec<(SkyModel, String)> = match first {
        Some(m) => vec![(m, "the robust fit".to_owned())],
        None => starts.iter().take(2).map(|s| (s.model, s.origin.describe())).collect(),
    };
    for (m, origin) in tries {
        if perez
            .as_ref()
            .is_some_and(|p| 2.0 * p.cost < SECOND_START_RMS.powi(2) * n as f64)
        {
            break;
        }
        if let Some(out) = run(&SkyModel { h: 1.0, ..m }, &PEREZ_FREE, &mut evaluations)
            && perez.as_ref().is_none_or(|p| out.cost < p.cost)
        {
            perez = Some(out);
            origins.push(origin);
            start_models.push(SkyModel { h: 1.0, ..m });
        }
    }
    let start = origins.last().cloned().unwrap_or_else(|| starts[0].origin.describe());
    let start_model = start_models.last().copied().unwrap_or(starts[0].model);
    if let Some(p) = &perez {
        let m = model_of(&p.theta);
        fits.push((SkyModelKind::Perez, 6, Some(p.clone()), m, 2.0 * p.cost));
        if let Some(out) = run(&m, &SEVEN_FREE, &mut evaluations) {
            let m7 = model_of(&out.theta);
            fits.push((SkyModelKind::SevenParameter, 7, Some(out.clone()), m7, 2.0 * out.cost));
        }
    }
    // The aureole fixed, unless the Perez fit already pins it: c and d
    // each known to within AUREOLE_PINNED of themselves (their standard
    // errors from its JᵀJ), when holding them at a start's values can only
    // fit worse for fewer parameters than BIC would forgive.
    let pinned = perez.as_ref().and_then(|p| {
        let (c, d) = (p.theta[3], p.theta[4]);
        let (sc, sd) = (p.standard_errors[3], p.standard_errors[4]);
        (sc <= AUREOLE_PINNED * c.abs() && sd <= AUREOLE_PINNED * d.abs())
            .then(|| format!("the samples pin the aureole (c = {c:.3} ± {sc:.1e}, d = {d:.3} ± {sd:.1e})"))
    });
    let mut skipped: Vec<(SkyModelKind, usize, String)> = Vec::new();
    match pinned {
        Some(why) => skipped.push((SkyModelKind::SevenParameterFixedAureole, 4, why)),
        None => {
            if let Some(out) = run(&starts[0].model, &FIXED_AUREOLE_FREE, &mut evaluations) {
                let m = model_of(&out.theta);
                fits.push((
                    SkyModelKind::SevenParameterFixedAureole,
                    4,
                    Some(out.clone()),
                    m,
                    2.0 * out.cost,
                ));
            }
        }
    }
    let mut candidates: Vec<Candidate> = fits
        .iter()
        .map(|(kind, k, out, _, rss)| {
            let excluded = if !rss.is_finite() {
                Some("its residuals are not finite".to_owned())
            } else if n <= k + 2 {
                Some(format!("{n} samples cannot support {k} parameters"))
            } else {
                out.as_ref().and_then(|o| {
                    (o.rcond < RCOND_FLOOR).then(|| {
                        format!(
                            "its parameters are not determined by the samples (reciprocal condition {:.1e})",
                            o.rcond
                        )
                    })
                })
            };
            Candidate {
                kind: *kind,
                parameters: *k,
                rss: *rss,
                bic: bic(*rss, n, *k),
                excluded,
                evaluations: out.as_ref().map_or(0, |o| o.evaluations),
            }
        })
        .collect();
    candidates.extend(skipped.into_iter().map(|(kind, parameters, why)| Candidate {
        kind,
        parameters,
        rss: f64::INFINITY,
        bic: f64::INFINITY,
        excluded: Some(format!("not fitted: {why}")),
        evaluations: 0,
    }));
    // Smallest BIC among the eligible; on a tie, fewer parameters.
    let winner = (0..candidates.len())
        .filter(|&i| candidates[i].excluded.is_none())
        .min_by(|&i, &j| {
            let (a, b) = (&candidates[i], &candidates[j]);
            a.bic.total_cmp(&b.bic).then(a.parameters.cmp(&b.parameters))
        })
        .unwrap_or(0);
    let (kind, _, out, model, rss) = &fits[winner];
    let convergence = out.as_ref().map_or_else(Convergence::closed_form, Convergence::of);
    let others: Vec<String> = candidates
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != winner)
        .map(|(_, c)| match &c.excluded {
            Some(why) => format!("{} excluded: {why}", c.kind.words()),
            None => format!("{} {:.1}", c.kind.words(), c.bic),
        })
        .collect();
    let lead = match kind {
        SkyModelKind::Cie(t) => format!("CIE standard sky type {} ({})", t.number(), t.description()),
        SkyModelKind::Perez => "the Perez all-weather form (eq. 5.9 with h = 1, 6 parameters)".to_owned(),
        SkyModelKind::SevenParameter => "the seven-parameter sky (eq. 5.9, h free)".to_owned(),
        SkyModelKind::SevenParameterFixedAureole => format!(
            "eq. 5.9 with the aureole (c, d, h) fixed at {start}'s (4 parameters): the samples do not pay for fitting it"
        ),
    };
    let reason = format!(
        "{lead}: smallest BIC {:.1} (others: {})",
        candidates[winner].bic,
        others.join("; ")
    );
    SkyFit {
        model: *model,
        kind: *kind,
        reason,
        rms_relative: (rss / n as f64).sqrt(),
        candidates,
        evaluations,
        convergence,
        start,
        start_model,
    }
}

#[cfg(test)]
mod tests;
