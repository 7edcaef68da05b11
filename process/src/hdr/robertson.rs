//! Robertson–Borman–Stevenson response recovery (1999/2003), the
//! alternative to Debevec–Malik, for comparison.
//!
//! It alternates the two maximum-likelihood updates of a Gaussian noise
//! model in the *linear* domain, with `I(z) = exp g(z)`:
//!
//! ```text
//! E_i  = Σ_j w(Z_ij) t_j I(Z_ij) / Σ_j w(Z_ij) t_j²          (radiance update)
//! I(m) = mean over {(i, j): Z_ij = m} of E_i t_j               (response update)
//! ```
//!
//! normalized by `I(z_mid) = 1`, until the largest change of `ln I` falls
//! below 1e-7 (from a γ = 2.2 start) or [`RobertsonOptions::max_iterations`]. It uses the same
//! samples ([`super::sampling`]) and hat weight as Debevec–Malik.
//!
//! **Limit.** Without a smoothness term, brackets whose exposure ratios are
//! all equal (say 4×) leave any perturbation of `ln I` that is periodic in
//! `ln 4` undetermined; the iteration then wanders (log-RMS ≈ 0.1 on the
//! 2-stop test chart). Debevec–Malik's smoothness term resolves it; prefer it
//! for such brackets. Nodes
//! without observations are interpolated in `ln I`; the result is made
//! monotone by isotonic regression. The per-node uncertainty is the standard
//! error of the mean of `ln(E_i t_j)` over the node's observations.

use super::HdrError;
use super::curve::{ChannelCurve, ResponseCurve, make_monotone, node_count, node_position};
use super::debevec::{hat_weight, to_array3};
use super::exposure_codes::ExposureCodes;
use super::sampling::{SampleOptions, select_samples};

/// Options of [`calibrate_robertson`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobertsonOptions {
    /// Sample selection.
    pub sampling: SampleOptions,
    /// Iteration cap.
    pub max_iterations: usize,
}

impl Default for RobertsonOptions {
    fn default() -> Self {
        Self {
            sampling: SampleOptions::default(),
            max_iterations: 2000,
        }
    }
}

/// Recovers the response of each channel; returns the curve and the iterations used per channel.
pub fn calibrate_robertson<B: ExposureCodes>(
    bracket: &B,
    opts: &RobertsonOptions,
) -> Result<(ResponseCurve, [usize; 3]), HdrError> {
    if bracket.exposures() < 2 {
        return Err(HdrError::SingleExposure(bracket.exposures()));
    }
    super::debevec::check_sampling(bracket, &opts.sampling)?;
    let bits = bracket.bits();
    let n = node_count(bits);
    let maxc = f64::from(bracket.max_code());
    let times = bracket.times_s();
    let mut chans = Vec::with_capacity(3);
    let mut iters = [0usize; 3];
    for (c, iters_c) in iters.iter_mut().enumerate() {
        let samples = select_samples(bracket, c, &opts.sampling);
        let needed = (n / (bracket.exposures() - 1)).max(16);
        if samples.len() < needed {
            return Err(HdrError::TooFewSamples {
                channel: c,
                found: samples.len(),
                needed,
            });
        }
        // Observations: (sample, node, weight, time).
        let mut obs: Vec<(usize, usize, f64, f64)> = Vec::new();
        let mut codes = Vec::new();
        for (i, &pix) in samples.iter().enumerate() {
            bracket.pixel_codes(pix, c, &mut codes);
            for (j, &z) in codes.iter().enumerate() {
                let z = f64::from(z);
                let w = hat_weight(z, maxc);
                if w > 0.0 {
                    let (k, a) = node_position(bits, z);
                    obs.push((i, if a < 0.5 { k } else { k + 1 }, w, times[j]));
                }
            }
        }
        let mid = n / 2;
        // Start from a display-gamma curve (γ = 2.2), closer to real cameras than linear.
        let mut ln_i: Vec<f64> = (0..n).map(|k| 2.2 * ((k as f64 + 0.5) / mid as f64).ln()).collect();
        let mut e = vec![0.0; samples.len()];
        let mut it = 0;
        while it < opts.max_iterations {
            it += 1;
            let mut num = vec![0.0; samples.len()];
            let mut den = vec![0.0; samples.len()];
            for &(i, k, w, t) in &obs {
                num[i] += w * t * ln_i[k].exp();
                den[i] += w * t * t;
            }
            for i in 0..samples.len() {
                e[i] = if den[i] > 0.0 { num[i] / den[i] } else { 0.0 };
            }
            let mut sum = vec![0.0; n];
            let mut cnt = vec![0usize; n];
            for &(i, k, _, t) in &obs {
                if e[i] > 0.0 {
                    sum[k] += e[i] * t;
                    cnt[k] += 1;
                }
            }
            let mut next: Vec<Option<f64>> = (0..n)
                .map(|k| (cnt[k] > 0 && sum[k] > 0.0).then(|| (sum[k] / cnt[k] as f64).ln()))
                .collect();
            fill_gaps(&mut next);
            let Some(norm) = next[mid] else {
                return Err(HdrError::TooFewSamples {
                    channel: c,
                    found: 0,
                    needed,
                });
            };
            let new: Vec<f64> = next.iter().map(|v| v.unwrap_or(0.0) - norm).collect();
            let change = new.iter().zip(&ln_i).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            ln_i = new;
            if change < 1e-7 {
                break;
            }
        }
        *iters_c = it;
        // Uncertainty: standard error of ln(E_i t_j) per node.
        let mut s1 = vec![0.0; n];
        let mut s2 = vec![0.0; n];
        let mut support = vec![0u32; n];
        for &(i, k, _, t) in &obs {
            if e[i] > 0.0 {
                let v = (e[i] * t).ln() - ln_i[k];
                s1[k] += v;
                s2[k] += v * v;
                support[k] += 1;
            }
        }
        let std: Vec<f64> = (0..n)
            .map(|k| {
                let m = f64::from(support[k]);
                if m >= 2.0 {
                    ((s2[k] - s1[k] * s1[k] / m) / (m - 1.0)).max(0.0).sqrt() / m.sqrt()
                } else {
                    f64::INFINITY
                }
            })
            .map(|s: f64| if s.is_finite() { s } else { 1.0 })
            .collect();
        let w: Vec<f64> = support.iter().map(|&s| f64::from(s) + 1.0).collect();
        make_monotone(&mut ln_i, &w);
        chans.push(ChannelCurve {
            ln_exposure: ln_i,
            ln_exposure_std: std,
            support,
        });
    }
    Ok((
        ResponseCurve {
            bits,
            channels: to_array3(chans),
        },
        iters,
    ))
}

/// Fills `None`s by linear interpolation between known neighbours and
/// constant extension at the ends.
fn fill_gaps(v: &mut [Option<f64>]) {
    let known: Vec<usize> = (0..v.len()).filter(|&k| v[k].is_some()).collect();
    let (Some(&first), Some(&last)) = (known.first(), known.last()) else {
        return;
    };
    let (head, tail) = (v[first], v[last]);
    v[..first].fill(head);
    v[last + 1..].fill(tail);
    for pair in known.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (va, vb) = (v[a].unwrap_or(0.0), v[b].unwrap_or(0.0));
        for (k, vk) in v.iter_mut().enumerate().take(b).skip(a + 1) {
            *vk = Some(va + (vb - va) * (k - a) as f64 / (b - a) as f64);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::hdr_chart;
    use crate::hdr::bracket::Bracket;

    #[test]
    fn recovers_known_curve_to_log_rms_0_03_with_irregular_times() {
        let cam = CameraModel::typical(8);
        let scene = hdr_chart(128, 96);
        // Irregular ratios: with equal ratios r, any perturbation of ln I periodic
        // in ln r fits the data equally (Robertson has no smoothness term to pick one).
        let times = [1.0 / 64.0, 1.0 / 21.0, 1.0 / 5.3, 1.0, 3.1, 13.5, 64.0];
        let imgs = times
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, 100 + j as u64))
            .collect();
        let b = Bracket::new(imgs, times.to_vec()).unwrap();
        let (curve, iters) = calibrate_robertson(&b, &RobertsonOptions::default()).unwrap();
        for (c, it) in iters.iter().enumerate() {
            let err = curve.log_rms_error(c, |z| cam.true_ln_exposure(z, c), 5, 250);
            eprintln!("robertson channel {c}: log-RMS {err:.5} after {it} iterations");
            assert!(err < 0.03, "channel {c}: {err}");
            assert!(curve.channels[c].ln_exposure.iter().all(|v| v.is_finite()));
        }
    }
}
