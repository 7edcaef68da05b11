//! Radiance RGBE (`.hdr`) output of merged radiance maps: the format of
//! RADIANCE and hdrgen, which lighting designers' tools read.
//!
//! RGBE keeps 8 bits of mantissa per channel with a shared exponent: about 1%
//! relative precision, no negative values, and no room for the variance or
//! mask (use OpenEXR for those).

use std::io::BufWriter;
use std::path::Path;

use image::Rgb;
use image::codecs::hdr::HdrEncoder;

use crate::hdr::HdrError;
use crate::hdr::merge::RadianceMap;

/// Writes the radiance of `map` as a Radiance RGBE file (run-length encoded
/// scan lines, top to bottom). Negative or non-finite values are written as 0.
pub fn write_rgbe(map: &RadianceMap, path: &Path) -> Result<(), HdrError> {
    let io = |cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let pixels: Vec<Rgb<f32>> = map
        .rgb
        .chunks_exact(3)
        .map(|p| {
            Rgb(std::array::from_fn(
                |c| if p[c].is_finite() { p[c].max(0.0) } else { 0.0 },
            ))
        })
        .collect();
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = BufWriter::new(file);
    HdrEncoder::new(&mut w)
        .encode(&pixels, map.width, map.height)
        .map_err(|cause| HdrError::Image {
            path: path.to_path_buf(),
            cause,
        })?;
    std::io::Write::flush(&mut w).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_round_trips_within_its_8_bit_mantissa() {
        let (w, h) = (9, 4);
        let rgb: Vec<f32> = (0..w * h * 3).map(|i| 1e-3 * 1.7f32.powi(i as i32 % 30)).collect();
        let map = RadianceMap {
            width: w,
            height: h,
            rgb: rgb.clone(),
            variance: vec![0.0; w * h * 3],
            mask: vec![0; w * h],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.hdr");
        write_rgbe(&map, &path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"#?RADIANCE"), "header");
        let back = image::open(&path).unwrap().into_rgb32f();
        assert_eq!((back.width() as usize, back.height() as usize), (w, h));
        // The shared exponent is the largest channel's: each channel keeps
        // 1/256 of the pixel's largest value.
        for (p, px) in back.pixels().enumerate() {
            let peak = (0..3).map(|c| rgb[p * 3 + c]).fold(0.0f32, f32::max);
            for c in 0..3 {
                let (got, want) = (px.0[c], rgb[p * 3 + c]);
                assert!(
                    (got - want).abs() <= peak / 128.0,
                    "pixel {p} channel {c}: {got} vs {want}"
                );
            }
        }
    }
}
