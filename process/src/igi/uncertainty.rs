//! How well each recovered parameter is known: the spread of the final fit
//! over bootstrap resamplings of the photographs.
//!
//! A surface's observations are grouped by the view that took them; each
//! replicate draws as many views as the surface has, with replacement, and
//! refits the surface's chosen model (roughness search and linear step,
//! App. A) on the observations of the views drawn, counting a view drawn
//! twice twice. The standard deviation of each parameter over the
//! replicates is its uncertainty. Views, not pixels, are resampled because
//! a photograph's errors are shared by its pixels (its exposure, its
//! Monte Carlo or sensor noise pattern, its share of the highlights), so
//! pixel resampling would understate them many times over. A surface seen
//! from fewer than [`MIN_VIEWS`] views falls back to resampling pixels, and
//! says so ([`MaterialSigma::by_views`]).
//!
//! What it does not cover: error shared by every view (the light's
//! intensity, the geometry, the indirect estimate's bias).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::recover::canonical_lobe;
use crate::brdf::WardMaterial;

/// Bootstrap replicates.
pub const REPLICATES: usize = 24;

/// Fewer views than this: pixels are resampled instead.
pub const MIN_VIEWS: usize = 3;

/// One standard deviation of each parameter of a recovered material.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MaterialSigma {
    /// ρd per channel.
    pub rho_d: [f64; 3],
    /// ρs per channel (0 without a lobe).
    pub rho_s: [f64; 3],
    /// αx (0 without a lobe).
    pub alpha_x: f64,
    /// αy.
    pub alpha_y: f64,
    /// γ, degrees (0 for an isotropic lobe).
    pub gamma_deg: f64,
    /// Replicates that gave a material.
    pub replicates: usize,
    /// Whether views were resampled (`false`: pixels, too few views).
    pub by_views: bool,
}

/// The bootstrap of module doc for one surface: `indices` are its
/// observations, `view_of` gives each one's view, `refit` fits the
/// surface's model to a replicate's observations (duplicates counted) and
/// `reference` is the fit to all of them.
pub(crate) fn bootstrap(
    indices: &[usize],
    view_of: &dyn Fn(usize) -> usize,
    refit: &(dyn Fn(&[usize]) -> Option<WardMaterial> + Sync),
    reference: &WardMaterial,
    seed: u64,
) -> Option<MaterialSigma> {
    let mut views: Vec<usize> = indices.iter().map(|&i| view_of(i)).collect();
    views.sort_unstable();
    views.dedup();
    let by_views = views.len() >= MIN_VIEWS;
    let groups: Vec<Vec<usize>> = if by_views {
        views
            .iter()
            .map(|&v| indices.iter().copied().filter(|&i| view_of(i) == v).collect())
            .collect()
    } else {
        indices.iter().map(|&i| vec![i]).collect()
    };
    if groups.len() < 2 {
        return None;
    }
    let reference = canonical(reference);
    let draws: Vec<Vec<usize>> = {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..REPLICATES)
            .map(|_| {
                let mut chosen = Vec::with_capacity(indices.len());
                for _ in 0..groups.len() {
                    chosen.extend_from_slice(&groups[rng.random_range(0..groups.len())]);
                }
                chosen
            })
            .collect()
    };
    use rayon::prelude::*;
    let fits: Vec<WardMaterial> = draws
        .par_iter()
        .filter_map(|d| refit(d))
        .map(|m| canonical(&m))
        .collect();
    if fits.len() < 2 {
        return None;
    }
    let n = fits.len() as f64;
    let sd = |f: &dyn Fn(&WardMaterial) -> f64| {
        let mean = fits.iter().map(f).sum::<f64>() / n;
        (fits.iter().map(|m| (f(m) - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    };
    let lobe = |m: &WardMaterial| m.lobe;
    let mut s = MaterialSigma {
        replicates: fits.len(),
        by_views,
        ..MaterialSigma::default()
    };
    for c in 0..3 {
        s.rho_d[c] = sd(&|m| m.rho_d[c]);
        if reference.lobe.is_some() {
            s.rho_s[c] = sd(&|m| lobe(m).map_or(0.0, |l| l.rho_s[c]));
        }
    }
    if let Some(r) = reference.lobe {
        s.alpha_x = sd(&|m| lobe(m).map_or(r.alpha_x, |l| l.alpha_x));
        s.alpha_y = sd(&|m| lobe(m).map_or(r.alpha_y, |l| l.alpha_y));
        if r.alpha_x != r.alpha_y {
            // γ differences from the reference, wrapped to (−90°, 90°].
            let d = |m: &WardMaterial| {
                let g = lobe(m).map_or(r.gamma_rad, |l| l.gamma_rad) - r.gamma_rad;
                let g = g.to_degrees().rem_euclid(180.0);
                if g > 90.0 { g - 180.0 } else { g }
            };
            s.gamma_deg = (fits.iter().map(|m| d(m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        }
    }
    Some(s)
}

fn canonical(m: &WardMaterial) -> WardMaterial {
    WardMaterial {
        rho_d: m.rho_d,
        lobe: m.lobe.map(canonical_lobe),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{WardLobe, WardVariant};

    #[test]
    fn the_spread_of_per_view_estimates_is_the_standard_error_of_their_mean() {
        // Ten views, each of which alone would give ρd = 0.5 + e_v; the
        // replicate's estimate is the mean over the views drawn, so the
        // bootstrap's standard deviation is sd(e) / √10 (± its own noise).
        let e: Vec<f64> = (0..10).map(|v| 0.02 * ((v as f64) * 2.1).sin()).collect();
        let indices: Vec<usize> = (0..100).collect();
        let view_of = |i: usize| i / 10;
        let refit = |d: &[usize]| {
            let mean = d.iter().map(|&i| 0.5 + e[i / 10]).sum::<f64>() / d.len() as f64;
            Some(WardMaterial {
                rho_d: [mean; 3],
                lobe: None,
            })
        };
        let reference = WardMaterial {
            rho_d: [0.5; 3],
            lobe: None,
        };
        let s = bootstrap(&indices, &view_of, &refit, &reference, 7).unwrap();
        let m = e.iter().sum::<f64>() / 10.0;
        let sd_e = (e.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 10.0).sqrt();
        let want = sd_e / 10f64.sqrt();
        assert!(s.by_views && s.replicates == REPLICATES);
        assert!(
            (s.rho_d[0] - want).abs() < 0.35 * want,
            "sigma {} vs {want}",
            s.rho_d[0]
        );
        assert_eq!(s.rho_s, [0.0; 3]);
    }

    #[test]
    fn gamma_spread_is_measured_across_the_wrap() {
        // Replicates alternate between γ = 89° and γ = −89° (the same axis
        // to within 2°): the spread is about 1°, not 89°.
        let indices: Vec<usize> = (0..40).collect();
        let lobe = |g: f64| WardLobe::new([0.05; 3], 0.2, 0.05, g.to_radians(), WardVariant::Ward1992).unwrap();
        let refit = |d: &[usize]| {
            let g = if d.iter().sum::<usize>() % 2 == 0 { 89.0 } else { -89.0 };
            Some(WardMaterial {
                rho_d: [0.3; 3],
                lobe: Some(lobe(g)),
            })
        };
        let reference = WardMaterial {
            rho_d: [0.3; 3],
            lobe: Some(lobe(90.0)),
        };
        let s = bootstrap(&indices, &|i| i / 4, &refit, &reference, 3).unwrap();
        assert!(s.gamma_deg > 0.5 && s.gamma_deg < 1.5, "{s:?}");
    }
}
