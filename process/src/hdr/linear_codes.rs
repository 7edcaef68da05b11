//! Linear (RAW) frames as codes for the code-based pipeline (`campanile
//! process`), and the response curve those codes have.
//!
//! The session pipeline merges [`CodeImage`]s through a [`ResponseCurve`]
//! of evenly spaced nodes, interpolated linearly in `g = ln exposure`. A
//! RAW frame is linear: its [`LinearFrame`] values are the exposure itself
//! (0 = black, 1 = the white level). Stored as linear 16-bit codes, its
//! curve `g(z) = ln(z / z_max)` would be bent between the nodes (64 codes
//! apart at 16 bits: 6% off at the bottom nodes) and infinite at 0. So the
//! codes are **logarithmic**:
//!
//! ```text
//! z = z_max · (1 + ln(v) / D),   g(z) = D · (z / z_max − 1) = ln v
//! ```
//!
//! with `D = LOG_RANGE_STOPS · ln 2` (16 stops below the white level;
//! values below that, far under any sensor's read noise, become code 0,
//! which the merge weighs 0). `g` is a straight line, so the curve's nodes
//! interpolate it exactly, and one code is `D / z_max` = 0.017% of exposure,
//! far below the sensor's noise. White level: `z_max`; a sample the RAW
//! decoder flagged clipped (its photosite, or one it was interpolated from,
//! at or above the white level) is `z_max` whatever its value, so the merge
//! gives it weight 0; an unclipped one is at most `z_max − 1`.
//!
//! Why a known curve and not a Debevec recovery on these codes: the sensor
//! is linear up to its white level (the RAW decoder removed the black
//! level), so the curve is known exactly; a recovery could only add its
//! smoothing and sampling error to it, and needs a bracket the session may
//! not have. The gauge is the pipeline's full-well gauge (`g(z_max) = 0`,
//! exposure 1 at the white level).

use super::curve::{ChannelCurve, ResponseCurve, node_code, node_count};
use super::linear_frame::LinearFrame;
use crate::camera::image::{CodeImage, max_code};

/// Bit depth of the codes.
pub const LOG_CODE_BITS: u8 = 16;

/// Stops below the white level that the codes span.
pub const LOG_RANGE_STOPS: f64 = 16.0;

/// `D`: the natural-log range of the codes (module doc).
fn log_range() -> f64 {
    LOG_RANGE_STOPS * std::f64::consts::LN_2
}

/// The logarithmic code of linear value `v` (1 = white level), unclipped:
/// `0..=z_max − 1`.
pub fn log_code(v: f64) -> u16 {
    let zmax = f64::from(max_code(LOG_CODE_BITS));
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    let z = zmax * (1.0 + v.ln() / log_range());
    z.round().clamp(0.0, zmax - 1.0) as u16
}

/// `frame` as logarithmic codes (module doc), clipped samples at the
/// largest code; the label is the frame's.
pub fn log_codes(frame: &LinearFrame) -> CodeImage {
    codes_of(frame, LOG_CODE_BITS, log_code)
}

/// `frame`'s samples as `bits`-bit codes through `code` (of the linear
/// value), a clipped sample at the top code.
fn codes_of(frame: &LinearFrame, bits: u8, code: impl Fn(f64) -> u16) -> CodeImage {
    let zmax = max_code(bits);
    let data = frame
        .rgb
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            if frame.is_clipped(i / 3, i % 3) {
                zmax
            } else {
                code(f64::from(v))
            }
        })
        .collect();
    CodeImage {
        width: frame.width,
        height: frame.height,
        bits,
        data,
        label: frame.label.clone(),
    }
}

/// `frame` as 16-bit linear codes, `z = v · z_max` (a clipped sample at
/// `z_max`): what a tethered camera's RAW frame gives the capture
/// controller to meter (as a linear camera's codes), while processing reads
/// the file itself through [`log_codes`].
pub fn linear_codes16(frame: &LinearFrame) -> CodeImage {
    let zmax = f64::from(max_code(16));
    codes_of(frame, 16, |v| (v.clamp(0.0, 1.0) * zmax).round() as u16)
}

/// A linear sensor's codes (an astro or machine-vision camera's FITS
/// frame: code ∝ exposure above `black`, its largest code the white level)
/// as logarithmic codes: `v = (z − black) / (z_max − black)`, a code at
/// `z_max` clipped. Its label is kept.
pub fn log_codes_of_linear(image: &CodeImage, black: f64) -> CodeImage {
    let top = image.max_code();
    let span = (f64::from(top) - black).max(1.0);
    let data = image
        .data
        .iter()
        .map(|&z| {
            if z >= top {
                max_code(LOG_CODE_BITS)
            } else {
                log_code((f64::from(z) - black) / span)
            }
        })
        .collect();
    CodeImage {
        width: image.width,
        height: image.height,
        bits: LOG_CODE_BITS,
        data,
        label: image.label.clone(),
    }
}

/// The response curve of [`log_codes`]: `g(z) = D · (z / z_max − 1)` in
/// every channel, exact at every node (zero uncertainty, no support).
pub fn log_code_curve() -> ResponseCurve {
    let nodes = node_count(LOG_CODE_BITS);
    let zmax = f64::from(max_code(LOG_CODE_BITS));
    let channel = || ChannelCurve {
        ln_exposure: (0..nodes)
            .map(|k| log_range() * (node_code(LOG_CODE_BITS, k) / zmax - 1.0))
            .collect(),
        ln_exposure_std: vec![0.0; nodes],
        support: vec![0; nodes],
    };
    ResponseCurve {
        bits: LOG_CODE_BITS,
        channels: [channel(), channel(), channel()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::linear_frame::FrameMetadata;

    #[test]
    fn the_curve_inverts_the_codes_within_a_code_and_clipping_is_the_top_code() {
        let values = [1e-4, 0.003, 0.18, 0.5, 0.999];
        let frame = LinearFrame {
            label: "f.dng".into(),
            width: 2,
            height: 3,
            rgb: values.iter().chain(&[0.9]).flat_map(|&v| [v as f32; 3]).collect(),
            clipped: vec![0, 0, 0, 0, 0, 0b010],
            meta: FrameMetadata::default(),
        };
        let codes = log_codes(&frame);
        let curve = log_code_curve();
        // One code is D / 65535 = 1.69e-4 in ln v: half of it after rounding.
        for (p, &v) in values.iter().enumerate() {
            let z = f64::from(codes.data[p * 3]);
            let back = curve.ln_exposure(0, z).exp();
            assert!((back / v - 1.0).abs() < 1e-4, "v {v}: code {z} gives {back}");
        }
        // Pixel 5: green flagged clipped → 65535; red at 0.9 is not; a
        // negative value (read noise below black) is code 0.
        assert_eq!(codes.data[5 * 3 + 1], 65_535);
        assert_eq!(log_code(-0.01), 0);
        assert!(codes.data[5 * 3] < 65_535);
        // Unclipped white stays below the top code; the top code is exposure 1.
        assert_eq!(log_code(1.0), 65_534);
        assert!(curve.ln_exposure(1, 65_535.0).abs() < 1e-12);
    }

    /// Linear codes: v · 65535, a flagged sample at the top code, noise
    /// below black at 0.
    #[test]
    fn linear_codes_scale_the_white_level_to_the_top_code() {
        let frame = LinearFrame {
            label: "f.cr2".into(),
            width: 1,
            height: 2,
            rgb: vec![0.5, -0.01, 0.25, 0.9, 0.1, 1.0],
            clipped: vec![0, 0b001],
            meta: FrameMetadata::default(),
        };
        let codes = linear_codes16(&frame);
        assert_eq!(codes.bits, 16);
        assert_eq!(codes.data, vec![32768, 0, 16384, 65535, 6554, 65535]);
    }

    /// A 16-bit linear frame: half the white level is one stop below it,
    /// the white level is clipped, 0 is below the codes' range.
    #[test]
    fn linear_sensor_codes_become_log_codes() {
        let image = CodeImage {
            width: 2,
            height: 1,
            bits: 16,
            data: vec![65535, 32767, 0, 4095, 16383, 100],
            label: "fits".into(),
        };
        let log = log_codes_of_linear(&image, 0.0);
        let curve = log_code_curve();
        let g = |z: u16| curve.ln_exposure(0, f64::from(z));
        assert_eq!(log.data[0], max_code(LOG_CODE_BITS));
        assert!(
            (g(log.data[1]) - (32767.0f64 / 65535.0).ln()).abs() < 2e-4,
            "{}",
            g(log.data[1])
        );
        assert_eq!(log.data[2], 0);
        assert!((g(log.data[3]) - (4095.0f64 / 65535.0).ln()).abs() < 2e-4);
        assert!((g(log.data[4]) - (16383.0f64 / 65535.0).ln()).abs() < 2e-4);
        assert_eq!(log.bits, LOG_CODE_BITS);
    }
}
