//! A keogram-style strip of the day: one column per scan (in time order),
//! one row per bin of the zenith-to-horizon profile in the sun's vertical
//! plane (the sun-side horizon at the top, the zenith in the middle). The
//! measured strip sits above the fitted one; a third strip shows
//! fitted/measured − 1 on a blue–white–red scale.

use super::profile::PROFILE_BINS;
use super::scan::ScanProducts;
use crate::report::{ReportError, false_colour_png, tonemapped_png};

/// Pixels per scan column and per profile row.
pub const CELL_PX: usize = 4;
/// Range of the residual strip, ± this.
pub const RESIDUAL_RANGE: f64 = 0.2;

/// The measured (top) and fitted (bottom) strips as one tone-mapped RGB PNG,
/// scaled so the 99th percentile of the measured radiance is white.
pub fn keogram_png(scans: &[ScanProducts]) -> Result<Vec<u8>, ReportError> {
    let cols = scans.len().max(1);
    let (w, band) = (cols * CELL_PX, PROFILE_BINS * CELL_PX);
    let h = 2 * band + CELL_PX;
    let mut rgb = vec![f32::NAN; w * h * 3];
    let mut all: Vec<f64> = scans
        .iter()
        .flat_map(|s| s.profile.measured.iter().flatten().flat_map(|m| m.iter().copied()))
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    all.sort_by(f64::total_cmp);
    let p99 = all.get((all.len() as f64 * 0.99) as usize).copied().unwrap_or(1.0);
    let mut put = |col: usize, row: usize, top: usize, v: [f64; 3]| {
        for dy in 0..CELL_PX {
            for dx in 0..CELL_PX {
                let (x, y) = (col * CELL_PX + dx, top + row * CELL_PX + dy);
                for c in 0..3 {
                    rgb[3 * (y * w + x) + c] = v[c] as f32;
                }
            }
        }
    };
    for (col, s) in scans.iter().enumerate() {
        for bin in 0..PROFILE_BINS.min(s.profile.measured.len()) {
            // Row 0 is the sun-side horizon: the last bin.
            let row = PROFILE_BINS - 1 - bin;
            if let Some(m) = s.profile.measured[bin] {
                put(col, row, 0, m);
            }
            if let Some(f) = s.profile.fitted.as_ref().and_then(|f| f.get(bin)) {
                put(col, row, band + CELL_PX, *f);
            }
        }
    }
    tonemapped_png("keogram", w, h, &rgb, 1.0 / p99.max(1e-12))
}

/// fitted/measured − 1 in the green channel, one cell per scan and bin,
/// on ±[`RESIDUAL_RANGE`].
pub fn keogram_residual_png(scans: &[ScanProducts]) -> Result<Vec<u8>, ReportError> {
    let cols = scans.len().max(1);
    let (w, h) = (cols * CELL_PX, PROFILE_BINS * CELL_PX);
    let mut values = vec![f64::NAN; w * h];
    for (col, s) in scans.iter().enumerate() {
        let Some(fitted) = s.profile.fitted.as_ref() else {
            continue;
        };
        for (bin, (m, f)) in s.profile.measured.iter().zip(fitted).enumerate().take(PROFILE_BINS) {
            let Some(m) = m else { continue };
            if m[1] <= 0.0 {
                continue;
            }
            let v = f[1] / m[1] - 1.0;
            let row = PROFILE_BINS - 1 - bin;
            for dy in 0..CELL_PX {
                for dx in 0..CELL_PX {
                    values[(row * CELL_PX + dy) * w + col * CELL_PX + dx] = v;
                }
            }
        }
    }
    false_colour_png("keogram residual", w, h, &values, (-RESIDUAL_RANGE, RESIDUAL_RANGE))
}
