//! Sun shots (thesis §5.3.1): find the disc in a frame, choose the ND
//! filter and exposure, and check a triplet's agreement.
//!
//! - **Disc.** The brightest pixel (sum of channels) and, within
//!   [`DISC_WINDOW_PX`] of it, the pixels above half-way between the
//!   frame's median and that peak; their code-weighted centroid above the
//!   median is the disc's centre.
//! - **Filter.** The predicted solar radiance per channel (a clear
//!   atmosphere: `process::sky::Daylight::clear` with
//!   `Atmosphere::clear()`), times each filter's transmittance
//!   `10^-OD`, scaled by the camera's sensitivity measured on the
//!   centering frame (its disc peak, linearized with the assumed gamma of
//!   [`super::metering::ASSUMED_GAMMA`]), predicts each filter's disc peak.
//!   The least dense listed filter whose peak stays below
//!   [`MAX_PEAK_FRACTION`] of full scale at the camera's shortest exposure
//!   is chosen, and the exposure that puts the peak at
//!   [`TARGET_PEAK_FRACTION`] through it (at most the centering exposure).
//!   A frame whose disc still saturates is retaken through the next denser
//!   filter.
//! - **Agreement.** A triplet agrees when the disc sums (codes above the
//!   median) lie within [`TRIPLET_TOLERANCE`] of their mean, as AERONET
//!   checks its triplets; otherwise a note is journaled.

use super::metering::{ASSUMED_GAMMA, Codes, max_code};

/// Half-size of the window searched around the brightest pixel, pixels.
pub const DISC_WINDOW_PX: usize = 12;
/// The disc must stay below this fraction of full scale.
pub const MAX_PEAK_FRACTION: f64 = 0.8;
/// The exposure aims the disc's peak at this fraction of full scale.
pub const TARGET_PEAK_FRACTION: f64 = 0.5;
/// A disc code at or above this fraction of full scale is saturated.
pub const SATURATED_FRACTION: f64 = 0.98;
/// Largest relative spread of a triplet's disc sums.
pub const TRIPLET_TOLERANCE: f64 = 0.03;

/// The disc in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    /// Centroid, pixels (pixel centres at half-integers).
    pub centroid_px: (f64, f64),
    /// Brightest channel code in the disc, as a fraction of full scale.
    pub peak_fraction: f64,
    /// Sum of codes above the background over the disc pixels.
    pub sum: f64,
    /// Pixels in the disc.
    pub pixels: usize,
}

impl Disc {
    /// Whether any disc pixel is saturated.
    pub fn saturated(&self) -> bool {
        self.peak_fraction >= SATURATED_FRACTION
    }
}

/// The brightest blob of `frame`, or `None` when nothing stands 5% of full
/// scale above the median.
pub fn find_disc(frame: Codes<'_>) -> Option<Disc> {
    let (w, h) = (frame.width, frame.height);
    let full = max_code(frame);
    let sum = |i: usize| -> f64 { frame.data[3 * i..3 * i + 3].iter().map(|&c| f64::from(c)).sum() };
    let n = w * h;
    if n == 0 || frame.data.len() < 3 * n {
        return None;
    }
    let (peak_i, peak) = (0..n).map(|i| (i, sum(i))).max_by(|a, b| a.1.total_cmp(&b.1))?;
    let mut all: Vec<f64> = (0..n).map(sum).collect();
    let (_, median, _) = all.select_nth_unstable_by(n / 2, f64::total_cmp);
    let background = *median;
    if peak - background < 0.05 * 3.0 * full {
        return None;
    }
    let threshold = background + 0.5 * (peak - background);
    let (px, py) = (peak_i % w, peak_i / w);
    let (mut sx, mut sy, mut sw, mut pixels, mut peak_code) = (0.0, 0.0, 0.0, 0, 0u16);
    for y in py.saturating_sub(DISC_WINDOW_PX)..(py + DISC_WINDOW_PX + 1).min(h) {
        for x in px.saturating_sub(DISC_WINDOW_PX)..(px + DISC_WINDOW_PX + 1).min(w) {
            let i = y * w + x;
            let s = sum(i);
            if s < threshold {
                continue;
            }
            let weight = s - background;
            sx += weight * (x as f64 + 0.5);
            sy += weight * (y as f64 + 0.5);
            sw += weight;
            pixels += 1;
            peak_code = peak_code.max(*frame.data[3 * i..3 * i + 3].iter().max().unwrap_or(&0));
        }
    }
    (sw > 0.0).then(|| Disc {
        centroid_px: (sx / sw, sy / sw),
        peak_fraction: f64::from(peak_code) / full,
        sum: sw,
        pixels,
    })
}

/// A candidate filter: its name, wheel slot and transmittance per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterCandidate {
    /// Slot name.
    pub name: String,
    /// Wheel slot, 0-based.
    pub slot: u8,
    /// Transmittance per channel, `10^-OD`.
    pub transmittance: [f64; 3],
}

/// The camera's sensitivity measured on a centering frame: normalized
/// exposure per (radiance · second), per channel, from the disc's peak.
/// `None` when the disc is saturated or absent (then only a lower bound is known).
pub fn sensitivity(disc: &Disc, predicted_radiance: [f64; 3], transmittance: [f64; 3], exposure_s: f64) -> Option<f64> {
    if disc.saturated() || disc.peak_fraction <= 0.0 {
        return None;
    }
    let x = disc.peak_fraction.powf(ASSUMED_GAMMA);
    let l = (0..3)
        .map(|c| predicted_radiance[c] * transmittance[c])
        .fold(0.0, f64::max);
    (l > 0.0).then(|| x / (l * exposure_s))
}

/// The predicted peak fraction of the disc through `filter` at `exposure_s`.
pub fn predicted_peak(k: f64, predicted_radiance: [f64; 3], filter: &FilterCandidate, exposure_s: f64) -> f64 {
    let l = (0..3)
        .map(|c| predicted_radiance[c] * filter.transmittance[c])
        .fold(0.0, f64::max);
    (k * l * exposure_s).min(1.0).powf(1.0 / ASSUMED_GAMMA)
}

/// The filter (index into `filters`, lightest first) and exposure for the
/// sun's data frames; with no sensitivity, the densest filter at the
/// centering exposure.
pub fn choose(
    k: Option<f64>,
    predicted_radiance: [f64; 3],
    filters: &[FilterCandidate],
    exposure_range: (f64, f64),
    centering_s: f64,
) -> (usize, f64) {
    let densest = filters.len().saturating_sub(1);
    let Some(k) = k else {
        return (densest, centering_s);
    };
    let index = filters
        .iter()
        .position(|f| predicted_peak(k, predicted_radiance, f, exposure_range.0) < MAX_PEAK_FRACTION)
        .unwrap_or(densest);
    let Some(f) = filters.get(index) else {
        return (densest, centering_s);
    };
    let at_min = predicted_peak(k, predicted_radiance, f, exposure_range.0).max(1e-9);
    let t = exposure_range.0 * (TARGET_PEAK_FRACTION / at_min).powf(ASSUMED_GAMMA);
    (index, t.clamp(exposure_range.0, centering_s.max(exposure_range.0)))
}

/// The relative spread `(max − min) / mean` of a triplet's disc sums.
pub fn spread(sums: &[f64]) -> f64 {
    let mean = sums.iter().sum::<f64>() / sums.len().max(1) as f64;
    let (lo, hi) = sums
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &s| (l.min(s), h.max(s)));
    if mean > 0.0 { (hi - lo) / mean } else { f64::INFINITY }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{ExposureTime, Frame, Gain};

    fn frame_with_disc(cx: f64, cy: f64, peak: u16) -> Frame {
        let (w, h) = (64, 48);
        let mut data = vec![100u16; w * h * 3];
        for y in 0..h {
            for x in 0..w {
                let r = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
                if r < 2.5 {
                    data[(y * w + x) * 3..(y * w + x) * 3 + 3].fill(peak);
                }
            }
        }
        Frame {
            width: w,
            height: h,
            bits: 12,
            data,
            exposure_requested: ExposureTime::from_seconds(1e-3).unwrap(),
            exposure_actual: ExposureTime::from_seconds(1e-3).unwrap(),
            gain: Gain::UNITY,
            sequence: 0,
            timestamp: chrono::DateTime::default(),
            temperature_c: None,
            file: None,
        }
    }

    /// A uniform disc of radius 2.5 px is found at its centre to 0.05 px.
    #[test]
    fn finds_the_disc_centroid() {
        let d = find_disc(Codes::from(&frame_with_disc(40.3, 12.7, 2000))).unwrap();
        assert!(
            (d.centroid_px.0 - 40.3).abs() < 0.3 && (d.centroid_px.1 - 12.7).abs() < 0.3,
            "{d:?}"
        );
        assert!(!d.saturated());
        assert!(
            find_disc(Codes::from(&frame_with_disc(40.3, 12.7, 4095)))
                .unwrap()
                .saturated()
        );
    }

    /// With a measured sensitivity, the lightest filter that keeps the disc
    /// below 80% at the shortest exposure is chosen.
    #[test]
    fn chooses_the_lightest_unsaturated_filter() {
        let f = |name: &str, od: f64, slot| FilterCandidate {
            name: name.into(),
            slot,
            transmittance: [10f64.powf(-od); 3],
        };
        let filters = [f("nd3", 3.0, 3), f("nd4", 4.0, 4), f("nd5", 5.0, 5)];
        let l = [2.0e6; 3];
        // nd5 at 1 ms: x = 0.02; k = 1.
        let (i, t) = choose(Some(1.0), l, &filters, (1e-5, 30.0), 1e-3);
        // nd3 at 10 µs: x = 0.02 → peak 0.17 < 0.8: nd3.
        assert_eq!(i, 0);
        assert!(t > 1e-5 && t <= 1e-3);
        let (i, _) = choose(Some(1000.0), l, &filters, (1e-5, 30.0), 1e-3);
        assert_eq!(i, 2);
        assert!((spread(&[100.0, 101.0, 99.0]) - 0.02).abs() < 1e-12);
    }
}
