//! The fit's tests: the simulator's skies, the CIE skies, hard cases.

use super::*;
use crate::sky::CieSky;
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
fn rejection_can_be_turned_off_and_the_mask_is_capped() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let zs = 0.6;
    let dirs = directions(zs, 80f64.to_radians(), 4.0);
    let samples = samples_of(&clear_sky(), &dirs, 0.01, &mut rng);
    // Off: exactly the plain fit, nothing masked.
    let off = fit_sky_with(
        &samples,
        zs,
        &SkyFitOptions {
            reject_outliers: false,
            ..SkyFitOptions::default()
        },
    )
    .expect("fits");
    assert_eq!(off.fit, fit_sky(&samples, zs).expect("fits"));
    assert_eq!(off.masked_fraction, 0.0);
    assert!(off.kept.iter().all(|k| *k));
    assert!(off.masked_summary().contains("off"), "{}", off.masked_summary());
    // A quarter of the samples behind a dark occluder, with the cap set to
    // a tenth: a tenth is masked (the darkest first), and the summary says
    // that more were outliers.
    let mut bad = samples.clone();
    for (i, s) in bad.iter_mut().enumerate() {
        if i % 4 == 0 {
            s.radiance *= 0.1 + 0.2 * rng.random::<f64>();
        }
    }
    let options = SkyFitOptions {
        max_masked_fraction: 0.1,
        ..SkyFitOptions::default()
    };
    let capped = fit_sky_with(&bad, zs, &options).expect("fits");
    assert!(capped.masked_fraction <= 0.1 + 1e-12, "{}", capped.masked_fraction);
    assert!(
        capped.capped && (capped.outlier_fraction - 0.25).abs() < 0.02,
        "{}",
        capped.masked_summary()
    );
    assert!(
        capped.masked_summary().contains("more than the cap"),
        "{}",
        capped.masked_summary()
    );
    assert!(capped.fit.model.radiance(0.5, 0.5).is_finite());
    // With the default cap the same occluder is masked whole.
    let whole = fit_sky_robust(&bad, zs).expect("fits");
    assert!(
        !whole.capped && (whole.masked_fraction - 0.25).abs() < 0.02,
        "{}",
        whole.masked_summary()
    );
}

#[test]
fn the_perez_form_alone_from_a_start_reaches_a_perez_sky_and_refuses_a_start_it_cannot_evaluate() {
    // Noise-free samples of a Perez-form sky (h = 1), started from CIE
    // type 12 scaled by 3: the fit ends at the sky to 10⁻⁸ and says it
    // converged.
    let zs = 0.7;
    let truth = SkyModel { h: 1.0, ..clear_sky() };
    let dirs = directions(zs, 85f64.to_radians(), 3.0);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let samples = samples_of(&truth, &dirs, 0.0, &mut rng);
    let cie12 = CieSky::new(CieSkyType::new(12).expect("type 12"), 3.0 * truth.lz, zs).as_seven_parameter();
    let (fit, convergence) = fit_perez_from(&samples, &cie12).expect("fits");
    assert!(convergence.converged, "{}", convergence.summary());
    assert_eq!(fit.h, 1.0);
    let err = rel_rms(&fit, &truth, &dirs);
    assert!(err < 1e-8, "relative RMS {err:e}");
    // Lz = ∞ gives residuals that are not finite.
    let bad = SkyModel {
        lz: f64::INFINITY,
        ..cie12
    };
    assert!(
        matches!(fit_perez_from(&samples, &bad), Err(SkyFitError::StartNotFinite { .. })),
        "{:?}",
        fit_perez_from(&samples, &bad)
    );
}
