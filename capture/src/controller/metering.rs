//! Metering: choosing an exposure from unstored test captures, so that the
//! median pixel lands near the middle of the code range.
//!
//! The controller does not know the camera's response curve (it is
//! recovered later, from the brackets), so each step assumes a gamma of
//! [`ASSUMED_GAMMA`] between normalized exposure and code: the next
//! exposure is `t · (target / median)^γ`, at most ×/÷ 64 per step, ×/÷ 16
//! when the frame is black or white. A few captures converge.

use crate::device::Frame;
use campanile_process::camera::image::CodeImage;

/// Raw RGB codes of a frame, live or read back from the store.
#[derive(Debug, Clone, Copy)]
pub struct Codes<'a> {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Significant bits per sample.
    pub bits: u8,
    /// Interleaved RGB codes.
    pub data: &'a [u16],
}

impl<'a> From<&'a Frame> for Codes<'a> {
    fn from(f: &'a Frame) -> Self {
        Codes {
            width: f.width,
            height: f.height,
            bits: f.bits,
            data: &f.data,
        }
    }
}

impl<'a> From<&'a CodeImage> for Codes<'a> {
    fn from(f: &'a CodeImage) -> Self {
        Codes {
            width: f.width,
            height: f.height,
            bits: f.bits,
            data: &f.data,
        }
    }
}

/// The median code fraction aimed at.
pub const TARGET_FRACTION: f64 = 0.45;
/// Accepted when the median lies in this range.
pub const ACCEPT: (f64, f64) = (0.3, 0.6);
/// Test captures at most.
pub const MAX_CAPTURES: usize = 8;
/// The response gamma assumed between exposure and code.
pub const ASSUMED_GAMMA: f64 = 2.2;

/// A linear camera's codes ([`crate::device::CameraInfo::linear`]) as a
/// camera with the [`ASSUMED_GAMMA`] response would give them, `z' = z_max
/// · (z / z_max)^(1/γ)`: the controller meters, brackets and finds the sun
/// on these, so a linear sensor is exposed as a gamma camera is (its median
/// at 0.45^2.2 = 17 % of full scale, not at 45 %, which clips skies).
pub fn gamma_equivalent(frame: Codes<'_>) -> CodeImage {
    let top = max_code(frame);
    CodeImage {
        width: frame.width,
        height: frame.height,
        bits: frame.bits,
        data: frame
            .data
            .iter()
            .map(|&z| (top * (f64::from(z) / top).powf(1.0 / ASSUMED_GAMMA)).round() as u16)
            .collect(),
        label: String::new(),
    }
}

/// The largest code of a frame.
pub fn max_code(frame: Codes<'_>) -> f64 {
    f64::from((1u32 << frame.bits.min(16)) - 1)
}

/// Each pixel's brightest channel as a fraction of full scale.
pub fn pixel_peaks(frame: Codes<'_>) -> Vec<f64> {
    let full = max_code(frame);
    frame
        .data
        .chunks_exact(3)
        .map(|p| f64::from(p[0].max(p[1]).max(p[2])) / full)
        .collect()
}

/// The median of the pixels' mean channel code, as a fraction of full scale.
pub fn median_fraction(frame: Codes<'_>) -> f64 {
    let full = max_code(frame);
    let mut v: Vec<f64> = frame
        .data
        .chunks_exact(3)
        .map(|p| (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / (3.0 * full))
        .collect();
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// What to do after a test capture at `exposure_s` whose median is
/// `median`: `None` to accept it, or the next exposure to try (not yet
/// clamped to the camera's range).
pub fn next_exposure(exposure_s: f64, median: f64) -> Option<f64> {
    if (ACCEPT.0..=ACCEPT.1).contains(&median) {
        return None;
    }
    Some(if median >= 0.97 {
        exposure_s / 16.0
    } else if median <= 0.01 {
        exposure_s * 16.0
    } else {
        exposure_s * (TARGET_FRACTION / median).powf(ASSUMED_GAMMA).clamp(1.0 / 64.0, 64.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear camera's code at 0.45^2.2 of full scale reads as the
    /// metering target 0.45; the ends stay where they are.
    #[test]
    fn linear_codes_read_through_the_assumed_gamma() {
        let data = [0u16, 4095, (4095.0 * 0.45f64.powf(ASSUMED_GAMMA)).round() as u16];
        let frame = Codes {
            width: 1,
            height: 1,
            bits: 12,
            data: &data,
        };
        let g = gamma_equivalent(frame);
        assert_eq!(g.data[0], 0);
        assert_eq!(g.data[1], 4095);
        assert!(
            (f64::from(g.data[2]) / 4095.0 - TARGET_FRACTION).abs() < 1e-3,
            "{}",
            g.data[2]
        );
    }

    /// A camera with an exact gamma-2.2 response converges in a few steps
    /// from 10 ms for radiances over six decades.
    #[test]
    fn converges_on_a_gamma_camera_within_the_capture_limit() {
        for radiance in [1e-2, 1.0, 30.0, 1e4] {
            let code = |t: f64| (radiance * t).min(1.0).powf(1.0 / 2.2);
            let mut t = 0.01;
            let mut n = 0;
            while let Some(next) = next_exposure(t, code(t)) {
                t = next;
                n += 1;
                assert!(n < MAX_CAPTURES, "radiance {radiance}: {n} captures");
            }
            assert!((ACCEPT.0..=ACCEPT.1).contains(&code(t)));
        }
    }
}
