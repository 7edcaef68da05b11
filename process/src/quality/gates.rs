//! The gates of each product: which figures it is judged by.
//!
//! Each function takes a solver's own diagnostics and the thresholds, and
//! returns the product's [`ProductQuality`]. None of them recomputes the
//! product.

use super::{Better, Check, ProductQuality, Quality};
use crate::environment::{EnvironmentMap, RegionFit};
use crate::hdr::curve::ResponseCurve;
use crate::hdr::debevec::Calibration;
use crate::hdr::merge::{MASK_SATURATED, MASK_UNDEREXPOSED, RadianceMap};
use crate::igi::SurfaceResult;
use crate::igi::error_target::ErrorTargetReport;
use crate::igi::interreflection_check::InterreflectionCheck;
use crate::sky::ChannelSky;
use crate::sky_series::ScanProducts;

/// The worst of a figure's per-channel values (a NaN anywhere is the worst).
fn worst(values: [f64; 3], better: Better) -> f64 {
    if values.iter().any(|v| v.is_nan()) {
        return f64::NAN;
    }
    match better {
        Better::Lower => values.into_iter().fold(f64::NEG_INFINITY, f64::max),
        Better::Higher => values.into_iter().fold(f64::INFINITY, f64::min),
    }
}

/// The response curve (Debevec–Malik), from the calibration's diagnostics
/// and the bracket behind it: `used` exposures of the `planned` ones.
///
/// Figures: the condition estimate (worst channel) and the fraction of
/// nodes made monotone (worst channel), then those of [`response_curve`].
pub fn response(calibration: &Calibration, used: usize, planned: usize, q: &Quality) -> ProductQuality {
    let g = &q.response;
    let codes = calibration.curve.channels[0].support.len().max(2);
    let condition = worst(
        [0, 1, 2].map(|c| calibration.channels[c].condition_estimate),
        Better::Lower,
    );
    let monotone = worst(
        [0, 1, 2].map(|c| calibration.channels[c].monotone_adjustments as f64 / codes as f64),
        Better::Lower,
    );
    let mut checks = vec![
        Check::new("condition estimate", condition, g.condition, Better::Lower),
        Check::new("nodes made monotone", monotone, g.non_monotone, Better::Lower),
    ];
    checks.extend(response_curve(&calibration.curve, used, planned, q).checks);
    ProductQuality::new("response", checks)
}

/// The response of linear frames (RAW, FITS), which is known, not
/// recovered: there is no fit to judge, so the product is ok with no
/// figures; the merged maps are judged on their own.
pub fn known_response() -> ProductQuality {
    ProductQuality::new("response", Vec::new())
}

/// A response curve from any method, by what the curve itself shows:
/// exposures used over planned, and the span of codes observed over the
/// code range (worst channel).
pub fn response_curve(curve: &ResponseCurve, used: usize, planned: usize, q: &Quality) -> ProductQuality {
    let g = &q.response;
    let codes = curve.channels[0].support.len().max(2);
    let coverage = |c: usize| {
        let support = &curve.channels[c].support;
        let first = support.iter().position(|&n| n > 0);
        let last = support.iter().rposition(|&n| n > 0);
        match (first, last) {
            (Some(a), Some(b)) => (b - a) as f64 / (codes - 1) as f64,
            _ => 0.0,
        }
    };
    let checks = vec![
        Check::new(
            format!("exposures used ({used} of {planned} planned)"),
            used as f64 / planned.max(1) as f64,
            g.exposures_used,
            Better::Higher,
        ),
        Check::new(
            "span of codes observed",
            worst([0, 1, 2].map(coverage), Better::Higher),
            g.code_coverage,
            Better::Higher,
        ),
    ];
    ProductQuality::new("response", checks)
}

/// A merged radiance map. `expect_dark`: a sun shot through an ND filter,
/// where everything but the disc is meant to be below the noise floor, so
/// the dark fraction is not held against it.
pub fn radiance(name: &str, map: &RadianceMap, expect_dark: bool, q: &Quality) -> ProductQuality {
    let g = &q.merge;
    let n = map.mask.len().max(1) as f64;
    let count = |bits: u8| map.mask.iter().filter(|&&m| m & bits != 0).count() as f64 / n;
    let saturated = MASK_SATURATED | (MASK_SATURATED << 1) | (MASK_SATURATED << 2);
    let dark = MASK_UNDEREXPOSED | (MASK_UNDEREXPOSED << 1) | (MASK_UNDEREXPOSED << 2);
    let valid = map.mask.iter().filter(|&&m| m == 0).count() as f64 / n;
    let mut checks = vec![Check::new(
        "fraction of pixels clipped in every exposure",
        count(saturated),
        g.clipped,
        Better::Lower,
    )];
    if !expect_dark {
        checks.push(Check::new("fraction of pixels valid", valid, g.valid, Better::Higher));
        checks.push(Check::new(
            "fraction of pixels dark in every exposure",
            count(dark),
            g.dark,
            Better::Lower,
        ));
    }
    ProductQuality::new(format!("radiance {name}"), checks)
}

/// A sun measurement: the triplet's spread and the frames refused.
pub fn sun(name: &str, spread: [f64; 3], measured: usize, refused: &[String], q: &Quality) -> ProductQuality {
    let g = &q.sun;
    let worst = worst(spread, Better::Lower);
    let taken = measured + refused.len();
    let mut p = ProductQuality::new(
        format!("sun {name}"),
        vec![
            Check::new(
                format!("triplet spread, worst channel ({measured} frames)"),
                worst,
                g.triplet_spread,
                Better::Lower,
            ),
            Check::new(
                format!("frames refused ({} of {taken})", refused.len()),
                refused.len() as f64 / taken.max(1) as f64,
                g.refused,
                Better::Lower,
            ),
        ],
    );
    p.notes.extend(refused.iter().cloned());
    p
}

/// A sky fit, per channel: the residual and the samples masked, with
/// the model chosen and why, what was masked and the optimizer's ending as
/// notes. Convergence comes from each channel's record (absent in files
/// written before it was kept): a fit that did not converge fails; one with
/// a parameter at a bound of its range is at best `poor`.
pub fn sky(name: &str, channels: &[ChannelSky], q: &Quality) -> ProductQuality {
    let g = &q.sky;
    let mut checks = Vec::new();
    let mut notes = Vec::new();
    for ch in channels {
        checks.push(Check::new(
            format!("{}: RMS relative residual ({} samples)", ch.channel, ch.samples),
            ch.rms_relative,
            g.residual,
            Better::Lower,
        ));
        checks.push(Check::new(
            format!("{}: fraction of samples masked", ch.channel),
            ch.masked_fraction,
            g.masked,
            Better::Lower,
        ));
        notes.push(format!("{}: {}, {}", ch.channel, ch.chosen, ch.reason));
        if let Some(m) = &ch.masked {
            notes.push(format!("{}: {m}", ch.channel));
        }
        // The optimizer's own criteria: not converged fails the sky; a
        // parameter that ended at a bound of its range makes it poor (the
        // sky lies outside what the model was given).
        let (done, at_bound) = match &ch.convergence {
            Some(cv) => {
                notes.push(format!("{}: {}", ch.channel, cv.summary()));
                (cv.converged, cv.at_bound.len())
            }
            None => (true, 0),
        };
        if !done {
            checks.push(Check::new(
                format!("{}: converged (1 yes, 0 no)", ch.channel),
                0.0,
                super::Gate::new(1.0, 0.5),
                Better::Higher,
            ));
        }
        if at_bound > 0 {
            checks.push(Check::new(
                format!("{}: parameters ended at a bound of their range", ch.channel),
                at_bound as f64,
                super::Gate::new(0.0, 7.0),
                Better::Lower,
            ));
        }
    }
    let mut p = ProductQuality::new(format!("sky {name}"), checks);
    p.notes = notes;
    p
}

/// An environment map: the share of azimuth sectors something was seen in.
pub fn environment(name: &str, map: &EnvironmentMap, q: &Quality) -> ProductQuality {
    let cols = map.cols.max(1);
    let seen = (0..map.cols)
        .filter(|&x| (0..map.rows).any(|y| map.regions[y * map.cols + x].count > 0))
        .count();
    ProductQuality::new(
        format!("environment {name}"),
        vec![Check::new(
            format!("azimuth sectors seen ({seen} of {cols})"),
            seen as f64 / cols as f64,
            q.environment.azimuth_coverage,
            Better::Higher,
        )],
    )
}

/// An environment region's radiance model (eq. 5.15): its residual, with
/// the model chosen and why as a note.
pub fn environment_region(label: &str, fit: &RegionFit, q: &Quality) -> ProductQuality {
    ProductQuality::new(
        format!("environment region {label}"),
        vec![Check::new(
            "RMS relative residual",
            fit.rms_relative,
            q.environment.region_residual,
            Better::Lower,
        )],
    )
    .with_note(format!("{:?}: {}", fit.kind, fit.reason))
}

/// One scan of a sky time series (what the station writes per scan): its
/// sun and its sky. A sun shot or sky scan taken that gave nothing is
/// `failed`, with the scan's notes as the reason.
pub fn scan(scan: &ScanProducts, q: &Quality) -> Vec<ProductQuality> {
    let occ = &scan.occurrence;
    let not_made = |what: &str, absent: &str| {
        (!scan.notes.iter().any(|n| n == absent)).then(|| {
            ProductQuality::not_made(
                format!("{what} {occ}"),
                format!("not measured: {}", scan.notes.join("; ")),
            )
        })
    };
    let sun = match &scan.sun {
        Some(s) => Some(sun(occ, s.spread, s.frames, &s.refused, q)),
        None => not_made("sun", "no sun shot"),
    };
    let sky = match &scan.sky {
        Some(channels) => Some(sky(occ, channels, q)),
        None => not_made("sky", "no sky scan"),
    };
    [sun, sky].into_iter().flatten().collect()
}

/// A surface's recovered BRDF (inverse global illumination): the fit's
/// residual and the energy bound (the largest directional albedo, at
/// normal and at 60° incidence), with the model chosen and why as a note
/// (diffuse-only where no highlight was seen, and the like).
pub fn brdf(surface: &SurfaceResult, q: &Quality) -> ProductQuality {
    let albedo = worst(
        [surface.directional_albedo[0], surface.directional_albedo[1], 0.0],
        Better::Lower,
    );
    ProductQuality::new(
        format!("brdf {}", surface.name),
        vec![
            Check::new(
                format!("RMS relative residual ({} samples)", surface.samples),
                surface.rms_relative,
                q.igi.residual,
                Better::Lower,
            ),
            Check::new("largest directional albedo", albedo, q.igi.energy, Better::Lower),
        ],
    )
    .with_note(format!("{:?}: {}", surface.model, surface.reason))
}

/// The images against the interreflection the solver assumed
/// ([`crate::igi::interreflection_check`]): how much worse the assumption
/// fits the diffuse pixels than the other (the pooled weighted residual's
/// ratio less one; ≤ 0 when the assumption fits at least as well). Images
/// that cannot tell (too little indirect light, or a tie) give 0 and a note.
pub fn interreflection(check: &InterreflectionCheck, q: &Quality) -> ProductQuality {
    let excess = match check.consistent {
        None => 0.0,
        Some(_) => check.excess_residual.max(0.0),
    };
    ProductQuality::new(
        "igi interreflection",
        vec![Check::new(
            if check.assumed {
                "residual excess of interreflection (as modelled) over direct light only"
            } else {
                "residual excess of direct light only (--direct-only) over interreflection"
            },
            excess,
            q.igi.interreflection,
            Better::Lower,
        )],
    )
    .with_note(check.message.clone())
}

/// A view relit to an error target (`igi --relight … --error`, `render
/// --igi … --error`): the share of its blocks that stopped at the most
/// paths above the target, with the run's figures as a note.
pub fn relit_view(view: &str, report: &ErrorTargetReport, q: &Quality) -> ProductQuality {
    ProductQuality::new(
        format!("igi relit {view}"),
        vec![Check::new(
            format!(
                "share of 4 × 4 blocks above the {:.2} % error target",
                100.0 * report.target
            ),
            report.not_converged as f64 / report.blocks.max(1) as f64,
            q.igi.relit_blocks,
            Better::Lower,
        )],
    )
    .with_note(report.to_string())
}

/// The outdoor pseudo-albedos (thesis §5.4) from their fit's diagnostics:
/// the median over solved cells of each cell's RMS relative residual, with
/// counts of how the cells were obtained and the photos left out as notes.
/// The light they were divided by is judged on its own (its sky's
/// verdicts); the caller inherits those.
pub fn pseudo_albedos(refl: &crate::outdoor::Reflectance, q: &Quality) -> ProductQuality {
    use crate::outdoor::CellStatus;
    let mut residuals: Vec<f64> = refl
        .cells
        .iter()
        .filter(|c| c.status == CellStatus::Solved)
        .map(|c| c.rms_relative)
        .collect();
    residuals.sort_by(f64::total_cmp);
    let median = if residuals.is_empty() {
        f64::NAN
    } else {
        residuals[residuals.len() / 2]
    };
    let mut p = ProductQuality::new(
        "pseudo-albedos",
        vec![Check::new(
            format!(
                "median RMS relative residual of eqs. 5.11-5.12 ({} solved cells)",
                residuals.len()
            ),
            median,
            q.outdoor.residual,
            Better::Lower,
        )],
    );
    let count = |s: CellStatus| refl.count(s);
    p = p.with_note(format!(
        "{} cells: {} solved, {} never sunlit (rho_sun from the face's ratio), {} never shadowed, {} ill-conditioned, {} unseen (filled from neighbours)",
        refl.cells.len(),
        count(CellStatus::Solved),
        count(CellStatus::NeverSunlit),
        count(CellStatus::NeverShadowed),
        count(CellStatus::IllConditioned),
        count(CellStatus::Unseen)
    ));
    for photo in refl.photos.iter().filter(|c| c.outlier) {
        p = p.with_note(format!(
            "photo {} left out as an outlier (trimmed mean log ratio {:.3})",
            photo.label, photo.median_log_ratio
        ));
    }
    p
}

/// A re-render against the photograph of the same view: the relative RMSE
/// of 4 × 4-pixel block means over the target pixels.
pub fn outdoor_render(view: &str, block_rmse: f64, blocks: usize, q: &Quality) -> ProductQuality {
    ProductQuality::new(
        format!("render {view}"),
        vec![Check::new(
            format!("relative RMSE of 4x4 block means against the photograph ({blocks} blocks)"),
            block_rmse,
            q.outdoor.render,
            Better::Lower,
        )],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::Verdict;

    fn map(mask: Vec<u8>) -> RadianceMap {
        let n = mask.len();
        RadianceMap {
            width: n,
            height: 1,
            rgb: vec![1.0; 3 * n],
            variance: vec![0.0; 3 * n],
            mask,
        }
    }

    #[test]
    fn an_all_black_or_all_white_map_fails_and_a_clean_one_passes() {
        let q = Quality::default();
        let black = radiance("black", &map(vec![MASK_UNDEREXPOSED << 1; 100]), false, &q);
        assert_eq!(black.verdict, Verdict::Failed, "{black:?}");
        assert!(
            black
                .reasons()
                .contains("fraction of pixels dark in every exposure 1 > 0.5")
        );
        let white = radiance("white", &map(vec![MASK_SATURATED; 100]), false, &q);
        assert_eq!(white.verdict, Verdict::Failed);
        assert!(white.reasons().contains("clipped in every exposure 1 > 0.5"));
        let mut mask = vec![0u8; 100];
        mask[0] = MASK_SATURATED;
        assert_eq!(radiance("clean", &map(mask), false, &q).verdict, Verdict::Ok);
        // A sun shot is dark around the disc by design.
        let sun_shot = radiance("sun", &map(vec![MASK_UNDEREXPOSED; 100]), true, &q);
        assert_eq!(sun_shot.verdict, Verdict::Ok);
    }

    #[test]
    fn a_sun_triplet_that_disagrees_or_lost_frames_is_judged() {
        let q = Quality::default();
        assert_eq!(sun("s", [0.01, 0.02, 0.01], 3, &[], &q).verdict, Verdict::Ok);
        assert_eq!(sun("s", [0.01, 0.05, 0.01], 3, &[], &q).verdict, Verdict::Poor);
        assert_eq!(sun("s", [0.01, 0.25, 0.01], 3, &[], &q).verdict, Verdict::Failed);
        let refused = ["f2 channel 0: saturated".to_owned()];
        let one_refused = sun("s", [0.01, 0.01, 0.01], 2, &refused, &q);
        assert_eq!(one_refused.verdict, Verdict::Poor);
        assert!(one_refused.notes[0].contains("saturated"));
        assert_eq!(sun("s", [f64::NAN, 0.0, 0.0], 3, &[], &q).verdict, Verdict::Failed);
    }

    #[test]
    fn an_environment_with_gaps_in_azimuth_is_judged() {
        let q = Quality::default();
        let mut m = EnvironmentMap::new(2, 10);
        for x in 0..10 {
            m.regions[x].count = 1;
        }
        assert_eq!(environment("e", &m, &q).verdict, Verdict::Ok);
        for x in 5..10 {
            m.regions[x].count = 0;
        }
        let half = environment("e", &m, &q);
        assert_eq!(half.verdict, Verdict::Poor);
        assert!(
            half.reasons().contains("azimuth sectors seen (5 of 10) 0.5 < 0.9"),
            "{}",
            half.reasons()
        );
    }

    #[test]
    fn a_sky_parameter_at_a_bound_is_poor_and_no_convergence_fails() {
        use crate::sky::{ChannelSky, Convergence, SkyModel, Termination};
        let q = Quality::default();
        let channel = |converged: bool, at_bound: Vec<String>| ChannelSky {
            channel: "g".into(),
            model: SkyModel {
                lz: 1.0,
                a: -1.0,
                b: -0.3,
                c: 10.0,
                d: -3.0,
                e: 0.45,
                h: 1.0,
            },
            chosen: "Perez".into(),
            reason: "test".into(),
            rms_relative: 0.001,
            samples: 500,
            masked_fraction: 0.0,
            masked: None,
            convergence: Some(Convergence {
                converged,
                termination: if converged {
                    Termination::Gradient
                } else {
                    Termination::Evaluations
                },
                iterations: 9,
                evaluations: 12,
                at_bound,
            }),
        };
        assert_eq!(sky("s", &[channel(true, vec![])], &q).verdict, Verdict::Ok);
        let bound = sky("s", &[channel(true, vec!["a = -3 (lower bound)".into()])], &q);
        assert_eq!(bound.verdict, Verdict::Poor, "{bound:?}");
        assert!(
            bound.notes.iter().any(|n| n.contains("a = -3 (lower bound)")),
            "{:?}",
            bound.notes
        );
        assert_eq!(sky("s", &[channel(false, vec![])], &q).verdict, Verdict::Failed);
    }
}
