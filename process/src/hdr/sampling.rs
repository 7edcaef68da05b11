//! Selection of the pixels whose codes feed response recovery.
//!
//! Debevec and Malik ask for samples that (1) cover the range of intensities,
//! (2) lie in smooth regions, so that small misregistration does not matter,
//! and (3) see a static scene. Here:
//!
//! - **Intensity strata.** The sum of a pixel's codes over the bracket,
//!   `S = Σ_j Z_j`, rises monotonically with scene radiance, so strata of `S`
//!   are strata of log radiance across the whole bracket. Candidates are binned
//!   into [`SampleOptions::strata`] equal-width bins of `S`, and the bins are
//!   drained round-robin, so every intensity level gets the same share.
//!   The edge threshold's median comes from 20 000 random pixels.
//! - **Edge-free.** A pixel is dropped when the largest *relative* code
//!   difference `|Z(p) − Z(q)| / mean(Z(p), Z(q))` to one of its four
//!   neighbours, in any exposure where the pixel is well exposed (10 %–90 % of
//!   full scale, where noise is small), exceeds `edge_factor ×` the image's
//!   median of that measure. Pixels never well exposed, and border pixels, are
//!   dropped (dark codes are still observed in the short exposures of brighter
//!   pixels).
//! - **Motion-free.** In a static scene codes never fall as exposure rises; a
//!   pixel whose code drops by more than 3 codes (8-bit units) between two
//!   consecutive exposures is dropped.
//! - **Informative.** At least two exposures must be unclipped (`0 < Z < max`).
//! - **Seeded.** Pixels are drawn by a ChaCha8 stream of `seed` and the
//!   channel, so the same seed selects the same pixels.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::exposure_codes::ExposureCodes;

/// Options of [`select_samples`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleOptions {
    /// Number of pixels to select per channel.
    pub samples: usize,
    /// Number of intensity strata.
    pub strata: usize,
    /// Edge threshold, as a multiple of the median neighbour difference.
    pub edge_factor: f64,
    /// Seed of the selection.
    pub seed: u64,
}

impl Default for SampleOptions {
    fn default() -> Self {
        Self {
            samples: 4000,
            strata: 64,
            edge_factor: 2.0,
            seed: 0,
        }
    }
}

/// Pixels whose edge measure sets the threshold (a seeded random subset).
const EDGE_MEDIAN_PIXELS: usize = 20_000;

/// Random pixel draws per requested sample before giving up on rare strata.
const DRAWS_PER_SAMPLE: usize = 16;

/// The pixels sample selection looks at for one channel, in the order it
/// looks at them: drawn by the seeded stream alone, so they are known before
/// any code is read (which lets a bracket read from files keep only these
/// pixels and their 4-neighbours: [`super::sampled_bracket`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawPlan {
    /// The random pixels whose edge measure sets the threshold.
    pub edge_pixels: Vec<usize>,
    /// The candidate pixels, in drawing order (selection stops early when
    /// every stratum is full).
    pub draws: Vec<usize>,
}

/// The [`DrawPlan`] of channel `c` for an image of `width × height` pixels.
pub fn draw_plan(width: usize, height: usize, c: usize, opts: &SampleOptions) -> DrawPlan {
    let n = width * height;
    if width < 3 || height < 3 || opts.samples == 0 {
        return DrawPlan {
            edge_pixels: Vec::new(),
            draws: Vec::new(),
        };
    }
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    rng.set_stream(100 + c as u64);
    let edge_pixels = (0..EDGE_MEDIAN_PIXELS.min(n)).map(|_| rng.random_range(0..n)).collect();
    rng.set_stream(c as u64);
    let draws = (0..(DRAWS_PER_SAMPLE * opts.samples).min(4 * n))
        .map(|_| rng.random_range(0..n))
        .collect();
    DrawPlan { edge_pixels, draws }
}

/// Selects up to `opts.samples` pixel indices (`y · width + x`) for channel `c`.
///
/// Pixels are drawn at random (seeded, [`draw_plan`]) and tested lazily, so
/// the cost grows with the number of samples, not with the image: each
/// stratum accepts up to twice its fair share, drawing stops when every
/// stratum is full or after `min(16 × samples, 4 × pixels)` draws, and the
/// strata are then drained round-robin.
pub fn select_samples<B: ExposureCodes + ?Sized>(bracket: &B, c: usize, opts: &SampleOptions) -> Vec<usize> {
    let (w, h) = (bracket.width(), bracket.height());
    let plan = draw_plan(w, h, c, opts);
    if plan.draws.is_empty() {
        return Vec::new();
    }
    let maxc = bracket.max_code();
    let scale = f64::from(maxc) / 255.0;
    let drop_tol = (3.0 * scale).round() as i32;
    let well_exposed = maxc / 10..=maxc - maxc / 10;
    let interior = |p: usize| {
        let (x, y) = (p % w, p / w);
        x > 0 && y > 0 && x + 1 < w && y + 1 < h
    };
    let mut zp = Vec::new();
    let mut zq: [Vec<u16>; 4] = Default::default();
    // The largest relative code difference |Z(p) − Z(q)| / mean(Z(p), Z(q)) to a
    // 4-neighbour, in any exposure where p is well exposed; ∞ if never (or border).
    // For gamma-like curves it is about (1/γ) × the relative radiance difference.
    let mut edge = |p: usize| -> f32 {
        if !interior(p) {
            return f32::INFINITY;
        }
        bracket.pixel_codes(p, c, &mut zp);
        for (q, out) in [p - 1, p + 1, p - w, p + w].into_iter().zip(zq.iter_mut()) {
            bracket.pixel_codes(q, c, out);
        }
        let mut m = f32::INFINITY;
        for (j, &zp) in zp.iter().enumerate() {
            if !well_exposed.contains(&zp) {
                continue;
            }
            let mut mj = 0.0f32;
            for zq in &zq {
                let zq = zq[j];
                let mean = 0.5 * (f32::from(zp) + f32::from(zq));
                mj = mj.max(f32::from(zp.abs_diff(zq)) / mean.max(1.0));
            }
            m = if m.is_finite() { m.max(mj) } else { mj };
        }
        m
    };
    // Static (codes never fall as exposure rises) and informative (≥ 2 unclipped).
    let usable = |codes: &[u16]| {
        let mut prev = 0i32;
        let mut unclipped = 0;
        for &z in codes {
            let zi = i32::from(z);
            if zi < prev - drop_tol {
                return false;
            }
            prev = prev.max(zi);
            if z > 0 && z < maxc {
                unclipped += 1;
            }
        }
        unclipped >= 2
    };
    // Edge threshold from a seeded subset.
    let mut measures: Vec<f32> = plan
        .edge_pixels
        .iter()
        .map(|&p| edge(p))
        .filter(|e| e.is_finite())
        .collect();
    if measures.is_empty() {
        return Vec::new();
    }
    let mid = measures.len() / 2;
    let median = *measures.select_nth_unstable_by(mid, f32::total_cmp).1;
    let threshold = opts.edge_factor as f32 * median.max(0.01);
    // Strata of S = Σ_j Z_j over the whole image.
    let (smin, smax) = bracket.code_sum_range(c);
    let strata = opts.strata.max(1);
    let span = f64::from(smax.saturating_sub(smin)) + 1.0;
    let quota = (2 * opts.samples).div_ceil(strata);
    let mut bins: Vec<Vec<usize>> = vec![Vec::new(); strata];
    let mut full = 0;
    let mut seen = vec![false; w * h];
    let mut codes = Vec::new();
    for &p in &plan.draws {
        if full == strata {
            break;
        }
        if std::mem::replace(&mut seen[p], true) {
            continue;
        }
        bracket.pixel_codes(p, c, &mut codes);
        let sum: u32 = codes.iter().map(|&z| u32::from(z)).sum();
        let b = (((f64::from(sum.saturating_sub(smin)) / span) * strata as f64) as usize).min(strata - 1);
        if bins[b].len() >= quota {
            continue;
        }
        if !usable(&codes) {
            continue;
        }
        let e = edge(p);
        if !e.is_finite() || e > threshold {
            continue;
        }
        bins[b].push(p);
        if bins[b].len() == quota {
            full += 1;
        }
    }
    let mut out = Vec::with_capacity(opts.samples);
    let mut round = 0;
    while out.len() < opts.samples {
        let mut took = false;
        for b in &bins {
            if let Some(&p) = b.get(round) {
                out.push(p);
                took = true;
                if out.len() == opts.samples {
                    break;
                }
            }
        }
        if !took {
            break;
        }
        round += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
    use crate::hdr::bracket::Bracket;

    fn bracket() -> Bracket {
        let cam = CameraModel::typical(8);
        let scene = hdr_chart(96, 64);
        let imgs = SEVEN_STOP_TIMES_S
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, j as u64))
            .collect();
        Bracket::new(imgs, SEVEN_STOP_TIMES_S.to_vec()).unwrap()
    }

    #[test]
    fn deterministic_avoids_band_edges_and_covers_range() {
        let b = bracket();
        let opts = SampleOptions {
            samples: 500,
            ..Default::default()
        };
        let s1 = select_samples(&b, 1, &opts);
        let s2 = select_samples(&b, 1, &opts);
        assert_eq!(s1, s2);
        assert_eq!(s1.len(), 500);
        let s3 = select_samples(&b, 1, &SampleOptions { seed: 9, ..opts });
        assert_ne!(s1, s3);
        // No selected pixel sits on an edge of the chart's bands: its radiance
        // differs from each 4-neighbour's by less than 60 % (the ramp and ripple
        // change by ≈ 14 % per pixel; most band edges by 1.6× to 2×).
        let chart = hdr_chart(96, 64);
        for &p in &s1 {
            let l = chart.data[p * 3 + 1];
            for q in [p - 1, p + 1, p - 96, p + 96] {
                let r = chart.data[q * 3 + 1] / l;
                assert!((1.0 / 1.6..1.6).contains(&r), "pixel {p} next to an edge (ratio {r})");
            }
        }
        // Columns (log radiance) spread across the chart: every eighth of the width is used.
        let mut seen = [false; 8];
        for &p in &s1 {
            seen[(p % 96) * 8 / 96] = true;
        }
        assert!(seen.iter().all(|&s| s), "{seen:?}");
    }

    #[test]
    fn moving_pixels_are_dropped() {
        let mut imgs = bracket().images().to_vec();
        // "Motion": a 10×10 block goes dark in the longest exposure.
        for y in 20..30 {
            for x in 40..50 {
                for c in 0..3 {
                    imgs[6].data[(y * 96 + x) * 3 + c] = 5;
                }
            }
        }
        let b = Bracket::new(imgs, SEVEN_STOP_TIMES_S.to_vec()).unwrap();
        let s = select_samples(
            &b,
            0,
            &SampleOptions {
                samples: 5000,
                ..Default::default()
            },
        );
        assert!(
            s.iter()
                .all(|&p| !((20..30).contains(&(p / 96)) && (40..50).contains(&(p % 96))))
        );
    }
}
