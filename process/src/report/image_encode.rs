//! Images for the report: radiance tone-mapped to sRGB, and scalar maps
//! (relative errors, albedos) in false colour, as PNG.

use super::ReportError;

fn encode(what: &str, width: usize, height: usize, rgb: Vec<u8>) -> Result<Vec<u8>, ReportError> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::RgbImage::from_raw(width as u32, height as u32, rgb)
        .ok_or_else(|| ReportError::Encode {
            what: what.to_owned(),
            message: "buffer does not fit".into(),
        })?
        .write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| ReportError::Encode {
            what: what.to_owned(),
            message: e.to_string(),
        })?;
    Ok(out.into_inner())
}

fn check(what: &str, len: usize, width: usize, height: usize, per_pixel: usize) -> Result<(), ReportError> {
    if len != width * height * per_pixel || width == 0 || height == 0 {
        return Err(ReportError::Size {
            what: what.to_owned(),
            len,
            width,
            height,
            expected: width * height * per_pixel,
        });
    }
    Ok(())
}

/// sRGB transfer of a linear value in [0, 1].
fn srgb(v: f64) -> u8 {
    let v = if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// Interleaved RGB radiance × `scale` (e.g. the exposure that maps the
/// 99th percentile to white), clipped and sRGB-encoded. Non-finite values are black.
pub fn tonemapped_png(
    what: &str,
    width: usize,
    height: usize,
    rgb: &[f32],
    scale: f64,
) -> Result<Vec<u8>, ReportError> {
    check(what, rgb.len(), width, height, 3)?;
    let bytes = rgb.iter().map(|&v| srgb(f64::from(v) * scale)).collect();
    encode(what, width, height, bytes)
}

/// One value per pixel mapped from `range` onto a blue–white–red scale
/// (blue low, white at the middle, red high); NaN pixels are grey.
pub fn false_colour_png(
    what: &str,
    width: usize,
    height: usize,
    values: &[f64],
    range: (f64, f64),
) -> Result<Vec<u8>, ReportError> {
    check(what, values.len(), width, height, 1)?;
    let (lo, hi) = range;
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut bytes = Vec::with_capacity(values.len() * 3);
    for &v in values {
        if !v.is_finite() {
            bytes.extend_from_slice(&[128, 128, 128]);
            continue;
        }
        let t = ((v - lo) / span).clamp(0.0, 1.0) * 2.0 - 1.0;
        let (r, g, b) = if t < 0.0 {
            (1.0 + t, 1.0 + t, 1.0)
        } else {
            (1.0, 1.0 - t, 1.0 - t)
        };
        bytes.extend_from_slice(&[(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8]);
    }
    encode(what, width, height, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pngs_decode_to_the_expected_pixels() {
        let png = tonemapped_png("t", 2, 1, &[0.5, 0.5, 0.5, 2.0, f32::NAN, 0.0], 2.0).unwrap();
        let img = image::load_from_memory(&png).unwrap().into_rgb8();
        assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(1, 0).0, [255, 0, 0]);
        let png = false_colour_png("f", 3, 1, &[-1.0, 0.0, 1.0], (-1.0, 1.0)).unwrap();
        let img = image::load_from_memory(&png).unwrap().into_rgb8();
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 255]);
        assert_eq!(img.get_pixel(1, 0).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(2, 0).0, [255, 0, 0]);
        assert!(tonemapped_png("bad", 2, 2, &[0.0; 3], 1.0).is_err());
    }
}
