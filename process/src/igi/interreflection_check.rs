//! Do the images hold interreflected light? The solver either models it
//! (§4.3–4.5: indirect irradiance gathered from the photographs' own
//! radiance, the indirect specular term ΔS) or, with
//! [`super::IgiOptions::interreflection`] off, takes the images to be of
//! direct light only. A wrong assumption is silent in the fit itself: ρd
//! absorbs the scale (19–45 % low when single-bounce images are solved as
//! interreflected). This check asks the images.
//!
//! For every diffuse-dominated observation (specular share of the
//! estimate below [`MAX_SPECULAR_SHARE`]) the measured diffuse radiance is
//! regressed, per surface and in the channel mean, on the two irradiances
//! the solver knows apart:
//!
//! `L = a · E_direct / π + b · E_indirect / π`,
//!
//! with `E_indirect` gathered from the photographs' own diffuse radiance
//! (so it exists, and has its true size, whatever the assumption). Where
//! the images hold interreflection, `b / a ≈ 1`; where they do not,
//! `b / a ≈ 0`. Each surface's `k = b / a` comes with its standard error
//! from the weighted least-squares covariance (weights `1 / L²`, residual
//! variance from the fit), and the surfaces are pooled by inverse variance.
//! `k` is a figure, not the decision: the gather's Monte Carlo noise is
//! error in a regressor, which pulls `k` toward 0 (0.60 on the simulated
//! room at `--quick`'s 32 gather rays, where the images do hold
//! interreflection).
//!
//! The decision compares the two hypotheses each with one ρ per surface:
//! `L = ρ E_direct / π` against `L = ρ (E_direct + E_indirect) / π`. The
//! pooled weighted residual of the assumption taken over the other's,
//! less one, is the figure the quality gate holds
//! ([`InterreflectionCheck::excess_residual`]); within
//! [`TIE_MARGIN`] the images cannot tell.

use super::observation::Observation;
use super::ward_fit::TwoTermSums;

/// Observations whose estimated specular share exceeds this are left out.
pub const MAX_SPECULAR_SHARE: f64 = 0.1;

/// Below this pooled share of indirect in the total irradiance, the two
/// assumptions differ by less than the solver's own noise: no verdict.
pub const MIN_INDIRECT_SHARE: f64 = 0.02;

/// Residuals of the two hypotheses within this fraction of each other: a tie.
pub const TIE_MARGIN: f64 = 0.02;

/// What the images say.
#[derive(Debug, Clone, PartialEq)]
pub struct InterreflectionCheck {
    /// Whether the solver assumed interreflected light.
    pub assumed: bool,
    /// The pooled scale `k` of the indirect irradiance (0: none in the
    /// images, 1: as gathered).
    pub indirect_scale: f64,
    /// Its standard error.
    pub indirect_scale_sigma: f64,
    /// Mean share of the gathered indirect in the total irradiance over
    /// the observations used.
    pub indirect_share: f64,
    /// Observations used.
    pub samples: usize,
    /// The pooled weighted residual of the assumption taken over that of
    /// the other, less one (≤ 0: the assumption fits at least as well).
    pub excess_residual: f64,
    /// `Some(true)` when the images agree with the assumption,
    /// `Some(false)` when they contradict it, `None` when they cannot
    /// tell (too little indirect light, or too noisy).
    pub consistent: Option<bool>,
    /// The finding in words, with its figures.
    pub message: String,
}

/// One surface's diffuse-dominated observations: `(E_direct/π, E_indirect/π, L)`
/// in the channel mean.
pub(crate) type SurfaceSamples = Vec<(f64, f64, f64)>;

/// Regresses each surface's samples (module doc) and pools the surfaces.
pub(crate) fn check(surfaces: &[SurfaceSamples], assumed: bool) -> InterreflectionCheck {
    let mut sum_w = 0.0;
    let mut sum_wk = 0.0;
    let mut share_sum = 0.0;
    let mut used = 0usize;
    // Pooled residuals of the direct-only and the interreflected hypothesis.
    let (mut r_direct, mut r_inter) = (0.0, 0.0);
    for samples in surfaces {
        if samples.len() < 8 {
            continue;
        }
        let mut sums = TwoTermSums::default();
        for &(d, i, l) in samples {
            sums.add(1.0 / (l * l).max(1e-300), d, i, l);
        }
        let TwoTermSums {
            xx: dd,
            xy: di,
            yy: ii,
            xl: dl,
            yl: il,
            ll,
        } = sums;
        // One ρ per hypothesis: x = d, or x = d + i.
        let one = |xx: f64, xl: f64| if xx > 0.0 { ll - xl * xl / xx } else { ll };
        r_direct += one(dd, dl).max(0.0);
        r_inter += one(dd + 2.0 * di + ii, dl + il).max(0.0);
        let det = dd * ii - di * di;
        if !(det > 1e-12 * dd * ii && det.is_finite()) {
            continue;
        }
        let a = (dl * ii - il * di) / det;
        let b = (il * dd - dl * di) / det;
        if a.is_nan() || a <= 0.0 {
            continue;
        }
        let n = samples.len() as f64;
        let residual = (ll - 2.0 * a * dl - 2.0 * b * il + a * a * dd + 2.0 * a * b * di + b * b * ii).max(0.0);
        let s2 = residual / (n - 2.0);
        // Covariance of (a, b): s² (XᵀWX)⁻¹; k = b / a by the delta method.
        let (var_a, var_b, cov_ab) = (s2 * ii / det, s2 * dd / det, -s2 * di / det);
        let k = b / a;
        let var_k = (var_b - 2.0 * k * cov_ab + k * k * var_a) / (a * a);
        let var_k = var_k.max(1e-12);
        sum_w += 1.0 / var_k;
        sum_wk += k / var_k;
        share_sum += samples.iter().map(|&(d, i, _)| i / (d + i).max(1e-300)).sum::<f64>();
        used += samples.len();
    }
    if used == 0 || sum_w == 0.0 {
        return InterreflectionCheck {
            assumed,
            indirect_scale: 0.0,
            indirect_scale_sigma: f64::INFINITY,
            indirect_share: 0.0,
            samples: 0,
            excess_residual: 0.0,
            consistent: None,
            message: "interreflection not checked: no surface has enough diffuse-dominated pixels".into(),
        };
    }
    let k = sum_wk / sum_w;
    let sigma = sum_w.recip().sqrt();
    let share = share_sum / used as f64;
    let (r_assumed, r_other) = if assumed {
        (r_inter, r_direct)
    } else {
        (r_direct, r_inter)
    };
    let excess = if r_other > 0.0 { r_assumed / r_other - 1.0 } else { 0.0 };
    let tie = (r_inter / r_direct.max(1e-300) - 1.0).abs() < TIE_MARGIN;
    let says = if share < MIN_INDIRECT_SHARE || tie || !excess.is_finite() {
        None
    } else {
        Some(r_inter < r_direct)
    };
    let consistent = says.map(|interreflected| interreflected == assumed);
    let figures = format!(
        "weighted residual direct-only {r_direct:.4}, interreflected {r_inter:.4}; indirect scale k = {k:.2} ± {sigma:.2} (0: none, 1: as gathered; pulled toward 0 by the gather's noise); indirect share {:.1} %; {used} pixels",
        100.0 * share
    );
    let message = match (says, assumed) {
        (None, _) if share < MIN_INDIRECT_SHARE => {
            format!("interreflection: too little indirect light to tell ({figures})")
        }
        (None, _) => format!("interreflection: the images cannot tell ({figures})"),
        (Some(true), true) => format!("interreflection: the images hold interreflected light, as assumed ({figures})"),
        (Some(false), false) => format!("interreflection: the images hold direct light only, as assumed ({figures})"),
        (Some(false), true) => format!(
            "interreflection: the images hold direct light only, but the solver subtracted interreflection: ρd is too low and ρs too high; run again with --direct-only ({figures})"
        ),
        (Some(true), false) => format!(
            "interreflection: the images hold interreflected light, but the solver was told --direct-only: ρd is too high; run again without it ({figures})"
        ),
    };
    InterreflectionCheck {
        assumed,
        indirect_scale: k,
        indirect_scale_sigma: sigma,
        indirect_share: share,
        samples: used,
        excess_residual: excess,
        consistent,
        message,
    }
}

/// The sample of observation `o` for the check: `None` when its specular
/// share (`specular`, the estimate's specular radiance) is too large.
pub(crate) fn sample(o: &Observation, e_indirect: [f64; 3], specular: [f64; 3]) -> Option<(f64, f64, f64)> {
    let l = o.radiance.iter().sum::<f64>() / 3.0;
    let s = specular.iter().sum::<f64>() / 3.0;
    if l.is_nan() || l <= 0.0 || s > MAX_SPECULAR_SHARE * l {
        return None;
    }
    let pi = std::f64::consts::PI;
    let d = o.e_direct.iter().sum::<f64>() / (3.0 * pi);
    let i = e_indirect.iter().sum::<f64>() / (3.0 * pi);
    Some((d, i, l - s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples with direct and indirect parts that vary independently.
    fn samples(rho: f64, k_true: f64, noise: f64, n: usize) -> SurfaceSamples {
        (0..n)
            .map(|j| {
                let x = j as f64 / n as f64;
                let d = 1.0 + 0.8 * (7.0 * x).sin();
                let i = 0.3 + 0.2 * (3.0 * x + 1.0).cos();
                // A deterministic ±noise pattern (uncorrelated with d and i).
                let e = noise * if (j * 7919) % 13 < 6 { 1.0 } else { -1.0 };
                (d, i, rho * (d + k_true * i) * (1.0 + e))
            })
            .collect()
    }

    #[test]
    fn interreflected_images_solved_as_interreflected_agree() {
        let c = check(&[samples(0.5, 1.0, 0.01, 400), samples(0.2, 1.0, 0.01, 300)], true);
        assert!((c.indirect_scale - 1.0).abs() < 0.05, "{c:?}");
        assert_eq!(c.consistent, Some(true), "{}", c.message);
    }

    #[test]
    fn direct_only_images_solved_as_interreflected_are_flagged() {
        let c = check(&[samples(0.5, 0.0, 0.01, 400), samples(0.2, 0.0, 0.01, 300)], true);
        assert!(c.indirect_scale.abs() < 0.05, "{c:?}");
        assert_eq!(c.consistent, Some(false), "{}", c.message);
        assert!(c.message.contains("--direct-only"), "{}", c.message);
        let c = check(&[samples(0.5, 0.0, 0.01, 400)], false);
        assert_eq!(c.consistent, Some(true), "{}", c.message);
        let c = check(&[samples(0.5, 1.0, 0.01, 400)], false);
        assert_eq!(c.consistent, Some(false), "{}", c.message);
    }

    #[test]
    fn a_noisy_gather_pulls_k_down_but_not_the_decision() {
        // Interreflected images; the solver's indirect irradiance carries
        // noise of half the variance of its own spread (a regressor with
        // error, as the simulated room at --quick: k 0.60).
        let s: SurfaceSamples = (0..600)
            .map(|j| {
                let x = j as f64 / 600.0;
                let d = 1.0 + 0.8 * (7.0 * x).sin();
                let i = 0.3 + 0.2 * (3.0 * x + 1.0).cos();
                let noise = 0.05 * if (j * 7919) % 13 < 6 { 1.0 } else { -1.0 };
                (d, i + noise, 0.5 * (d + i))
            })
            .collect();
        let c = check(std::slice::from_ref(&s), true);
        assert!(c.indirect_scale < 0.7, "attenuated: {c:?}");
        assert_eq!(c.consistent, Some(true), "{}", c.message);
        assert!(c.excess_residual < 0.0, "{c:?}");
        let c = check(&[s], false);
        assert_eq!(c.consistent, Some(false), "{}", c.message);
        assert!(c.excess_residual > 0.1, "{c:?}");
    }

    #[test]
    fn indirect_light_proportional_to_direct_cannot_tell() {
        // E_indirect a fixed fraction of E_direct: k and ρ are not separable.
        let s: SurfaceSamples = (0..200)
            .map(|j| {
                let d = 1.0 + j as f64 / 200.0;
                (d, 0.3 * d, 0.5 * 1.3 * d)
            })
            .collect();
        let c = check(&[s], true);
        assert_eq!(c.consistent, None, "{c:?}");
        assert!(c.indirect_scale.is_finite(), "{c:?}");
        // And no samples at all: no verdict, no NaN.
        let c = check(&[], false);
        assert_eq!(c.consistent, None);
        assert!(!c.indirect_scale.is_nan());
    }
}
