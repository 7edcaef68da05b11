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
use rayon::prelude::*;

use super::bracket::Bracket;

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

/// Selects up to `opts.samples` pixel indices (`y · width + x`) for channel `c`.
///
/// Pixels are drawn at random (seeded) and tested lazily, so the cost grows
/// with the number of samples, not with the image: each stratum accepts up to
/// twice its fair share, drawing stops when every stratum is full or after
/// `min(16 × samples, 4 × pixels)` draws, and the strata are then drained round-robin.
pub fn select_samples(bracket: &Bracket, c: usize, opts: &SampleOptions) -> Vec<usize> {
    let (w, h) = (bracket.width(), bracket.height());
    if w < 3 || h < 3 || opts.samples == 0 {
        return Vec::new();
    }
    let images = bracket.images();
    let maxc = images[0].max_code();
    let scale = f64::from(maxc) / 255.0;
    let drop_tol = (3.0 * scale).round() as i32;
    let well_exposed = maxc / 10..=maxc - maxc / 10;
    let sum = |p: usize| -> u32 { images.iter().map(|im| u32::from(im.data[p * 3 + c])).sum() };
    let interior = |p: usize| {
        let (x, y) = (p % w, p / w);
        x > 0 && y > 0 && x + 1 < w && y + 1 < h
    };
    // The largest relative code difference |Z(p) − Z(q)| / mean(Z(p), Z(q)) to a
    // 4-neighbour, in any exposure where p is well exposed; ∞ if never (or border).
    // For gamma-like curves it is about (1/γ) × the relative radiance difference.
    let edge = |p: usize| -> f32 {
        if !interior(p) {
            return f32::INFINITY;
        }
        let mut m = f32::INFINITY;
        for im in images {
            let zp = im.data[p * 3 + c];
            if !well_exposed.contains(&zp) {
                continue;
            }
            let mut mj = 0.0f32;
            for q in [p - 1, p + 1, p - w, p + w] {
                let zq = im.data[q * 3 + c];
                let mean = 0.5 * (f32::from(zp) + f32::from(zq));
                mj = mj.max(f32::from(zp.abs_diff(zq)) / mean.max(1.0));
            }
            m = if m.is_finite() { m.max(mj) } else { mj };
        }
        m
    };
    // Static (codes never fall as exposure rises) and informative (≥ 2 unclipped).
    let usable = |p: usize| {
        let mut prev = 0i32;
        let mut unclipped = 0;
        for im in images {
            let z = im.data[p * 3 + c];
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
    let n = w * h;
    // Edge threshold from a seeded subset.
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    rng.set_stream(100 + c as u64);
    let mut measures: Vec<f32> = (0..EDGE_MEDIAN_PIXELS.min(n))
        .map(|_| edge(rng.random_range(0..n)))
        .filter(|e| e.is_finite())
        .collect();
    if measures.is_empty() {
        return Vec::new();
    }
    let mid = measures.len() / 2;
    let median = *measures.select_nth_unstable_by(mid, f32::total_cmp).1;
    let threshold = opts.edge_factor as f32 * median.max(0.01);
    // Strata of S = Σ_j Z_j over the whole image (one streaming, parallel pass).
    let sums: Vec<u32> = (0..n).into_par_iter().map(sum).collect();
    let (smin, smax) = sums
        .par_iter()
        .fold(|| (u32::MAX, 0), |a, &s| (a.0.min(s), a.1.max(s)))
        .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
    let strata = opts.strata.max(1);
    let span = f64::from(smax - smin) + 1.0;
    let quota = (2 * opts.samples).div_ceil(strata);
    let mut bins: Vec<Vec<usize>> = vec![Vec::new(); strata];
    let mut full = 0;
    let mut seen = vec![false; n];
    rng.set_stream(c as u64);
    for _ in 0..(DRAWS_PER_SAMPLE * opts.samples).min(4 * n) {
        if full == strata {
            break;
        }
        let p = rng.random_range(0..n);
        if std::mem::replace(&mut seen[p], true) {
            continue;
        }
        let b = (((f64::from(sums[p] - smin) / span) * strata as f64) as usize).min(strata - 1);
        if bins[b].len() >= quota {
            continue;
        }
        let e = edge(p);
        if !e.is_finite() || e > threshold || !usable(p) {
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
