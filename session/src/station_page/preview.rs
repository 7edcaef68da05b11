//! The latest sky frame as a small 8-bit PNG for the page, made on the
//! fly from the raw frame the station stored (any format the store
//! writes: 16-bit PNG, the camera's JPEG, DNG or FITS).
//!
//! The frame's codes are already the camera's response curve (close to a
//! display curve), so the preview stretches them linearly: the 99th
//! percentile of all channels' codes becomes white (245 of 255), zero
//! stays black. It is a picture of the sky, not a measurement.

use std::path::Path;

use campanile_capture::store::{FrameEntry, decode_frame};
use campanile_process::camera::image::CodeImage;
use image::ImageEncoder;

/// The 8-bit level the 99th-percentile code is mapped to.
pub const WHITE_LEVEL: f64 = 245.0;

/// The preview PNG of `frame`, a frame of the session in `day_dir`.
pub fn frame_preview_png(day_dir: &Path, frame: &FrameEntry) -> Result<Vec<u8>, String> {
    if !frame.file.starts_with("frames/") || frame.file.contains("..") {
        return Err(format!("the journal names {:?}, not a file under frames/", frame.file));
    }
    let path = day_dir.join(&frame.file);
    let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let codes = decode_frame(&path, &bytes, frame.format, frame.bits).map_err(|e| e.to_string())?;
    preview_png(&codes)
}

/// The codes stretched to 8 bits (see the module's text) as an RGB PNG.
pub fn preview_png(codes: &CodeImage) -> Result<Vec<u8>, String> {
    let n = codes.width * codes.height * 3;
    if codes.width == 0 || codes.height == 0 || codes.data.len() != n {
        return Err(format!(
            "{}: {} codes for {} × {} pixels",
            codes.label,
            codes.data.len(),
            codes.width,
            codes.height
        ));
    }
    let mut sorted = codes.data.clone();
    sorted.sort_unstable();
    let p99 = f64::from(sorted[((n - 1) as f64 * 0.99) as usize]).max(1.0);
    let rgb: Vec<u8> = codes
        .data
        .iter()
        .map(|&c| (f64::from(c) / p99 * WHITE_LEVEL).round().clamp(0.0, 255.0) as u8)
        .collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &rgb,
            codes.width as u32,
            codes.height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| format!("{}: PNG encoding failed: {e}", codes.label))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_99th_percentile_becomes_white_and_zero_stays_black() {
        // 100 pixels: codes 0, 100, 200, … 9900 in every channel.
        let data: Vec<u16> = (0..100u16).flat_map(|i| [i * 100; 3]).collect();
        let codes = CodeImage {
            width: 10,
            height: 10,
            bits: 16,
            data,
            label: "test".into(),
        };
        let png = preview_png(&codes).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (10, 10));
        // Index 0.99 · 299 = 296 of the 300 sorted codes is pixel 98's: 9800.
        let level = |i: u32| img.get_pixel(i % 10, i / 10)[0];
        assert_eq!(level(0), 0);
        assert_eq!(level(98), 245);
        assert_eq!(level(49), (4900.0f64 / 9800.0 * 245.0).round() as u8);
        assert_eq!(level(99), (9900.0f64 / 9800.0 * 245.0).round() as u8);
        let bad = CodeImage {
            width: 2,
            height: 2,
            bits: 16,
            data: vec![0; 5],
            label: "short".into(),
        };
        assert!(preview_png(&bad).unwrap_err().contains("short: 5 codes for 2 × 2"));
    }
}
