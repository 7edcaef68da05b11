//! A synthetic high-dynamic-range test chart with known radiance, for
//! response recovery and merge tests and benchmarks (until `sim` renders
//! real scenes through [`super::sensor::CameraModel`]).

use super::image::RadianceImage;

/// Radiance (W·m⁻²·sr⁻¹) of the darkest point of [`hdr_chart`].
pub const CHART_MIN_RADIANCE: f64 = 2.0e-4;
/// Radiance (W·m⁻²·sr⁻¹) of the brightest point of [`hdr_chart`].
pub const CHART_MAX_RADIANCE: f64 = 40.0;

/// Tints of the chart's bands (per channel multipliers, each in `[0.45, 1]`).
const TINTS: [[f64; 3]; 8] = [
    [1.0, 1.0, 1.0],
    [1.0, 0.75, 0.5],
    [0.5, 0.8, 1.0],
    [0.9, 1.0, 0.6],
    [1.0, 0.5, 0.8],
    [0.6, 0.6, 0.6],
    [0.7, 1.0, 0.9],
    [1.0, 0.9, 0.45],
];

/// A chart spanning `CHART_MIN_RADIANCE..CHART_MAX_RADIANCE` (about 18 stops):
/// radiance rises log-linearly from left to right, eight horizontal bands
/// carry different tints (sharp edges between them), and a gentle
/// diagonal ripple (±15 %) fills the intensity gaps. Deterministic, any size ≥ 8×8.
pub fn hdr_chart(width: usize, height: usize) -> RadianceImage {
    let (lmin, lmax) = (CHART_MIN_RADIANCE.ln(), CHART_MAX_RADIANCE.ln());
    let mut data = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        let band = (y * TINTS.len() / height.max(1)).min(TINTS.len() - 1);
        for x in 0..width {
            let u = (x as f64 + 0.5) / width as f64;
            let v = (y as f64 + 0.5) / height as f64;
            let ripple = 1.0 + 0.15 * (std::f64::consts::TAU * (3.0 * u + 5.0 * v)).sin();
            let base = (lmin + (lmax - lmin) * u).exp() / 1.15;
            for tint in TINTS[band] {
                data.push((base * ripple * tint).clamp(CHART_MIN_RADIANCE * 0.4, CHART_MAX_RADIANCE) as f32);
            }
        }
    }
    RadianceImage { width, height, data }
}

/// Seven exposure times two stops apart, 1/64 s … 64 s, which cover
/// [`hdr_chart`] with the default [`super::sensor::CameraModel::typical`] gain.
pub const SEVEN_STOP_TIMES_S: [f64; 7] = [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0, 4.0, 16.0, 64.0];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chart_spans_its_stated_range() {
        let c = hdr_chart(64, 64);
        let (lo, hi) = c
            .data
            .iter()
            .fold((f32::MAX, 0.0f32), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(f64::from(lo) >= CHART_MIN_RADIANCE * 0.4 - 1e-9);
        assert!(f64::from(hi) <= CHART_MAX_RADIANCE + 1e-6);
        assert!(f64::from(hi / lo) > 5e4, "dynamic range {}", hi / lo);
    }
}
