//! Starting skies, scored in closed form: the fifteen CIE standard skies
//! and skies of the Perez all-weather table (eight clearness bins, several
//! brightnesses) at the samples' sun, each with its best scale.
//!
//! Scoring costs one evaluation of each shape on at most
//! [`SCORE_SAMPLES`] samples, so the optimizer can start from the best one
//! or two for the price of about one of its own iterations.

use super::super::cie::{CieSky, CieSkyType};
use super::super::perez::{CLEARNESS_BIN_EDGES, PerezSky};
use super::super::seven_parameter::SkyModel;
use super::solver::Prepared;

/// Samples a shape is scored on (evenly strided over the table).
pub const SCORE_SAMPLES: usize = 256;

/// Where a start comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Origin {
    /// A CIE standard sky.
    Cie(CieSkyType),
    /// A Perez table sky: its bin and brightness Δ.
    Perez {
        /// Clearness bin, 1–8.
        bin: usize,
        /// Δ.
        brightness: f64,
    },
}

impl Origin {
    /// In words.
    pub fn describe(&self) -> String {
        match self {
            Origin::Cie(t) => format!("CIE type {}", t.number()),
            Origin::Perez { bin, brightness } => format!("Perez bin {bin}, Δ {brightness:.2}"),
        }
    }
}

/// A start: a shape (h = 1), scaled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// The sky, its Lz the best scale.
    pub model: SkyModel,
    /// Its origin.
    pub origin: Origin,
    /// Its score (lower is better).
    pub score: f64,
}

/// The brightnesses each table bin is tried at.
const BRIGHTNESSES: [f64; 6] = [0.05, 0.1, 0.2, 0.3, 0.45, 0.6];

/// Every starting shape for a sun at zenith angle `sun_zenith`, with Lz = 1.
pub fn shapes(sun_zenith: f64) -> Vec<(SkyModel, Origin)> {
    let zs = sun_zenith.clamp(0.0, std::f64::consts::FRAC_PI_2);
    let mut out: Vec<(SkyModel, Origin)> = CieSkyType::all()
        .map(|kind| {
            let m = CieSky::new(kind, 1.0, zs).as_seven_parameter();
            (SkyModel { lz: 1.0, ..m }, Origin::Cie(kind))
        })
        .collect();
    for bin in 1..=8 {
        // A clearness inside the bin.
        let clearness = match bin {
            1 => 1.03,
            8 => 8.0,
            _ => 0.5 * (CLEARNESS_BIN_EDGES[bin - 2] + CLEARNESS_BIN_EDGES[bin - 1]),
        };
        let mut seen: Vec<f64> = Vec::new();
        for brightness in BRIGHTNESSES {
            let sky = PerezSky {
                clearness,
                brightness,
                sun_zenith: zs,
            };
            let eff = sky.effective_brightness();
            if seen.contains(&eff) {
                continue;
            }
            seen.push(eff);
            out.push((sky.as_seven_parameter(1.0), Origin::Perez { bin, brightness: eff }));
        }
    }
    out
}

/// The stride that picks about [`SCORE_SAMPLES`] of `n`.
fn stride(n: usize) -> usize {
    n.div_ceil(SCORE_SAMPLES).max(1)
}

fn params(m: &SkyModel) -> [f64; 7] {
    [m.lz, m.a, m.b, m.c, m.d, m.e, m.h]
}

/// Least-squares scores: the scale in closed form,
/// `Lz = Σ S y / σ² / Σ S² / σ²`, and the weighted residual sum of squares.
/// Sorted best first.
pub fn scored_least_squares(prep: &Prepared, sun_zenith: f64) -> Vec<Start> {
    let subset = prep.strided(stride(prep.len()));
    let mut out: Vec<Start> = shapes(sun_zenith)
        .into_iter()
        .filter_map(|(shape, origin)| {
            let (sy, ss, yy) = subset.scale_sums(&params(&shape));
            if !(ss > 0.0 && sy > 0.0 && ss.is_finite() && sy.is_finite()) {
                return None;
            }
            let lz = sy / ss;
            let rss = (yy - sy * sy / ss).max(0.0);
            Some(Start {
                model: SkyModel { lz, ..shape },
                origin,
                score: rss,
            })
        })
        .collect();
    out.sort_by(|a, b| a.score.total_cmp(&b.score));
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::INFINITY;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Robust scores (least median of log ratios): the scale is the median of
/// yᵢ / Sᵢ, the score the median |ln(yᵢ / (Lz Sᵢ))|, so that up to half of
/// the samples may be anything. Samples with y ≤ 0 or S ≤ 0 count as
/// misfits. Sorted best first.
pub fn scored_robust(prep: &Prepared, sun_zenith: f64) -> Vec<Start> {
    let step = stride(prep.len());
    let mut out: Vec<Start> = shapes(sun_zenith)
        .into_iter()
        .filter_map(|(shape, origin)| {
            let t = params(&shape);
            let mut ratios = Vec::with_capacity(SCORE_SAMPLES + 1);
            let mut bad = 0usize;
            for i in (0..prep.len()).step_by(step) {
                let s = prep.model_at(&t, i);
                let y = prep.y(i);
                if s > 0.0 && y > 0.0 {
                    ratios.push(y / s);
                } else {
                    bad += 1;
                }
            }
            if ratios.len() < 10 {
                return None;
            }
            let scale = median(ratios.clone());
            let mut logs: Vec<f64> = ratios.iter().map(|r| (r / scale).ln().abs()).collect();
            logs.extend(std::iter::repeat_n(f64::INFINITY, bad));
            Some(Start {
                model: SkyModel { lz: scale, ..shape },
                origin,
                score: median(logs),
            })
        })
        .collect();
    out.sort_by(|a, b| a.score.total_cmp(&b.score));
    out
}

#[cfg(test)]
mod tests {
    use super::super::SkySample;
    use super::*;

    #[test]
    fn a_table_sky_is_found_among_the_starts_exactly() {
        let zs = 0.6;
        let truth = PerezSky {
            clearness: 8.0,
            brightness: 0.1,
            sun_zenith: zs,
        }
        .as_seven_parameter(3.0);
        let samples: Vec<SkySample> = (0..40)
            .flat_map(|i| {
                (0..30).map(move |j| {
                    let (xi, gamma) = (0.02 * f64::from(i) + 0.01, 0.1 * f64::from(j) + 0.02);
                    SkySample {
                        xi,
                        gamma,
                        radiance: truth.radiance(xi, gamma),
                    }
                })
            })
            .collect();
        let sigma: Vec<f64> = samples.iter().map(|s| s.radiance).collect();
        let prep = Prepared::new(&samples, &sigma);
        for starts in [scored_least_squares(&prep, zs), scored_robust(&prep, zs)] {
            let best = &starts[0];
            assert_eq!(
                best.origin,
                Origin::Perez {
                    bin: 8,
                    brightness: 0.1
                }
            );
            assert!(best.score < 1e-9, "{}", best.score);
            assert!((best.model.lz / 3.0 - 1.0).abs() < 1e-9, "{}", best.model.lz);
        }
        // 15 CIE skies; bins 2–5 have four distinct brightnesses (Δ ≥ 0.2), the others six.
        assert_eq!(shapes(zs).len(), 15 + 4 * 6 + 4 * 4);
    }
}
