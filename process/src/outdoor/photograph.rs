//! Renders as a camera would have shot them: radiance through a recovered
//! response curve at a chosen shutter (the thesis's 1/1500 s figures,
//! §5.6). The curve's `g(z) = ln X` is the log relative exposure of code
//! `z`; a merged radiance map reads `L = k · exp(g(z)) / t`, so a radiance
//! `L` shot at shutter `t` gives the largest code with `g(z) ≤ ln(L t / k)`
//! (0 below the curve, the top code above it).

use crate::camera::image::{CodeImage, RadianceImage, max_code};
use crate::hdr::curve::ResponseCurve;

/// The codes `curve` gives `image` at shutter `shutter_s`, with `scale` the
/// radiance of one unit of relative exposure per second (`k` above; 1 when
/// the merge used no radiometric scale). Non-finite or negative radiance
/// gives code 0.
pub fn photograph(image: &RadianceImage, curve: &ResponseCurve, shutter_s: f64, scale: f64) -> CodeImage {
    let top = max_code(curve.bits);
    let luts: Vec<Vec<f64>> = (0..3)
        .map(|c| (0..=top).map(|z| curve.ln_exposure(c, f64::from(z))).collect())
        .collect();
    let data = image
        .data
        .iter()
        .enumerate()
        .map(|(i, &l)| {
            let l = f64::from(l);
            if !(l.is_finite() && l > 0.0 && shutter_s > 0.0 && scale > 0.0) {
                return 0;
            }
            let x = (l * shutter_s / scale).ln();
            let lut = &luts[i % 3];
            // Largest z with g(z) ≤ x (g is non-decreasing after calibration).
            lut.partition_point(|g| *g <= x).saturating_sub(1).min(usize::from(top)) as u16
        })
        .collect();
    CodeImage {
        width: image.width,
        height: image.height,
        bits: curve.bits,
        data,
        label: format!("render at {shutter_s} s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::curve::ChannelCurve;

    /// A linear 8-bit camera (g(z) = ln((z + 0.5)/256)): radiance 0.25 at
    /// 1/2 s with scale 1 is relative exposure 1/8, code 31 (g(31) = ln(31.5/256)
    /// ≤ ln(1/8) < g(32)); a radiance 100 × too bright saturates at 255.
    #[test]
    fn a_linear_camera_gives_the_expected_codes() {
        let g: Vec<f64> = (0..256).map(|z| ((f64::from(z) + 0.5) / 256.0).ln()).collect();
        let ch = ChannelCurve {
            ln_exposure: g,
            ln_exposure_std: vec![0.0; 256],
            support: vec![1; 256],
        };
        let curve = ResponseCurve {
            bits: 8,
            channels: [ch.clone(), ch.clone(), ch],
        };
        let img = RadianceImage {
            width: 2,
            height: 1,
            data: vec![0.25, 0.25, 0.25, 25.0, -1.0, f32::NAN],
        };
        let codes = photograph(&img, &curve, 0.5, 1.0);
        assert_eq!(codes.data, vec![31, 31, 31, 255, 0, 0]);
    }
}
