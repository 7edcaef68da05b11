//! The camera response from the session's own brackets.

use super::{FrameGroup, PipelineError, Purpose};
use crate::hdr::bracket::Bracket;
use crate::hdr::debevec::{Calibration, ChannelDiagnostics, DebevecOptions, calibrate_debevec};
use crate::hdr::linear_codes;
use crate::hdr::noise_bias::NoiseBiasReport;

/// Most brackets stacked into one calibration.
pub const MAX_STACKED: usize = 12;

/// Which bracket calibrated the response, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseChoice {
    /// The group's key.
    pub group: String,
    /// Number of exposures.
    pub exposures: usize,
    /// Longest over shortest exposure.
    pub exposure_ratio: f64,
    /// In words.
    pub reason: String,
}

/// Recovers the response from the bracket with the most exposures (then
/// the widest span of times) among the unfiltered views and tiles, and
/// fixes its gauge so that the top code is full well (`g(z_max) = 0`, see
/// the module's units).
///
/// A session of RAW frames ([`CapturedFrame::linear`](super::CapturedFrame)
/// on every frame) is not recovered: its codes are the logarithmic codes of
/// a linear sensor, whose curve is known exactly
/// ([`linear_codes::log_code_curve`], already in the full-well gauge: the
/// white level is exposure 1). A recovery could only add its smoothing and
/// sampling error to that line, and would need a bracket. A session mixing
/// RAW and processed frames is refused ([`PipelineError::MixedFrames`]):
/// one curve cannot serve both.
pub fn calibrate_response(
    groups: &[FrameGroup],
    opts: &DebevecOptions,
) -> Result<(Calibration, ResponseChoice), PipelineError> {
    let frames = || groups.iter().flat_map(|g| &g.frames);
    let linear = frames().filter(|f| f.linear).count();
    if linear > 0 {
        let total = frames().count();
        if linear < total {
            let example = |want: bool| {
                frames()
                    .find(|f| f.linear == want)
                    .map(|f| f.key.clone())
                    .unwrap_or_default()
            };
            return Err(PipelineError::MixedFrames {
                linear,
                total,
                raw_example: example(true),
                other_example: example(false),
            });
        }
        return Ok(linear_response(linear));
    }
    let unfiltered = |g: &FrameGroup| {
        g.frames
            .iter()
            .all(|f| f.filter_transmittance.iter().all(|&t| t == 1.0))
    };
    let span = |g: &FrameGroup| {
        let (lo, hi) = g.frames.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), f| {
            (lo.min(f.exposure_s), hi.max(f.exposure_s))
        });
        hi / lo
    };
    let best = groups
        .iter()
        .filter(|g| {
            g.frames.len() >= 2
                && unfiltered(g)
                && matches!(g.purpose(), Purpose::View { .. } | Purpose::Sky | Purpose::Environment)
        })
        .max_by(|a, b| {
            a.frames
                .len()
                .cmp(&b.frames.len())
                .then(span(a).total_cmp(&span(b)))
                .then(b.key.cmp(&a.key))
        })
        .ok_or(PipelineError::NoBracket)?;
    // Every bracket with the same exposure ratios as the best one (metered
    // brackets differ only by a common factor, which each pixel's unknown
    // radiance absorbs in eq. 2 of Debevec–Malik) is stacked under it: more
    // scenes give more radiances per code, and a better curve.
    let ratios = |g: &FrameGroup| {
        let mut t: Vec<f64> = g.frames.iter().map(|f| f.exposure_s).collect();
        t.sort_by(f64::total_cmp);
        t.iter().map(|x| x / t[0]).collect::<Vec<f64>>()
    };
    let reference = ratios(best);
    let same_size = |g: &FrameGroup| {
        (g.frames[0].codes.width, g.frames[0].codes.bits) == (best.frames[0].codes.width, best.frames[0].codes.bits)
    };
    let stack: Vec<&FrameGroup> = std::iter::once(best)
        .chain(groups.iter().filter(|g| {
            !std::ptr::eq(*g, best)
                && unfiltered(g)
                && g.frames.len() == best.frames.len()
                && same_size(g)
                && ratios(g)
                    .iter()
                    .zip(&reference)
                    .all(|(a, b)| (a / b - 1.0).abs() < 0.02)
        }))
        .take(MAX_STACKED)
        .collect();
    fn sorted(g: &FrameGroup) -> Vec<&super::CapturedFrame> {
        let mut f: Vec<&super::CapturedFrame> = g.frames.iter().collect();
        f.sort_by(|a, b| a.exposure_s.total_cmp(&b.exposure_s));
        f
    }
    let first = sorted(best);
    let images = (0..best.frames.len())
        .map(|j| {
            let mut image = first[j].codes.clone();
            for g in &stack[1..] {
                let other = &sorted(g)[j].codes;
                image.data.extend_from_slice(&other.data);
                image.height += other.height;
            }
            image
        })
        .collect();
    let bracket = Bracket::new(images, first.iter().map(|f| f.exposure_s).collect()).map_err(|source| {
        PipelineError::Response {
            group: best.key.clone(),
            source,
        }
    })?;
    let mut calibration = calibrate_debevec(&bracket, opts).map_err(|source| PipelineError::Response {
        group: best.key.clone(),
        source,
    })?;
    for ch in &mut calibration.curve.channels {
        let top = *ch.ln_exposure.last().unwrap_or(&0.0);
        ch.ln_exposure.iter_mut().for_each(|g| *g -= top);
    }
    let choice = ResponseChoice {
        group: best.key.clone(),
        exposures: best.frames.len(),
        exposure_ratio: span(best),
        reason: format!(
            "the unfiltered brackets with the most exposures ({}), then the widest span ({:.0}×): {} of them with the same exposure ratios, stacked",
            best.frames.len(),
            span(best),
            stack.len()
        ),
    };
    Ok((calibration, choice))
}

/// The known response of `frames` linear (RAW or FITS) frames (see [`calibrate_response`]).
fn linear_response(frames: usize) -> (Calibration, ResponseChoice) {
    let calibration = Calibration {
        curve: linear_codes::log_code_curve(),
        // Nothing was solved: no samples, no residual, no adjustment.
        channels: std::array::from_fn(|_| ChannelDiagnostics {
            samples: 0,
            observations: 0,
            residual_rms: 0.0,
            monotone_adjustments: 0,
            noise_bias: NoiseBiasReport::default(),
            condition_estimate: 1.0,
        }),
        times_s: Vec::new(),
        method: format!(
            "linear (RAW or FITS: black level removed, white level = exposure 1, {}-stop logarithmic codes)",
            linear_codes::LOG_RANGE_STOPS
        ),
    };
    let choice = ResponseChoice {
        group: "linear frames".into(),
        exposures: 0,
        exposure_ratio: 1.0,
        reason: format!(
            "all {frames} frames are linear (RAW or FITS): the sensor is linear up to its white level, so the response is known, not recovered"
        ),
    };
    (calibration, choice)
}
