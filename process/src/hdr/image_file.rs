//! Reading exposure brackets from image files (PNG, TIFF, JPEG; 8 or 16
//! bits), turned upright by their EXIF orientation.

use std::path::Path;

use image::DynamicImage;

use super::HdrError;
use super::exposure_metadata::{ExposureMetadata, Orientation, read_exposure_metadata};
use crate::camera::image::CodeImage;

/// Reads an image file as upright RGB codes with its EXIF exposure metadata
/// (see [`read_code_image`] and [`read_exposure_metadata`]).
pub fn read_frame(path: &Path) -> Result<(CodeImage, ExposureMetadata), HdrError> {
    let meta = read_exposure_metadata(path)?;
    let img = read_stored_codes(path)?;
    Ok((turn_upright(img, meta.orientation), meta))
}

/// Reads an image file as RGB codes, turned upright by its EXIF
/// orientation. 8-bit files give 8-bit codes, 16-bit files 16-bit codes;
/// grey images are expanded to RGB. Float images are refused.
pub fn read_code_image(path: &Path) -> Result<CodeImage, HdrError> {
    read_frame(path).map(|(img, _)| img)
}

/// Turns `img` upright: the pixel stored at `o.source_of(x, y)` goes to `(x, y)`.
pub fn turn_upright(img: CodeImage, o: Orientation) -> CodeImage {
    if o == Orientation::Upright {
        return img;
    }
    let (w, h) = (img.width, img.height);
    let (wo, ho) = if o.swaps_axes() { (h, w) } else { (w, h) };
    let mut data = Vec::with_capacity(img.data.len());
    for yo in 0..ho {
        for xo in 0..wo {
            let (x, y) = o.source_of(xo, yo, w, h);
            let i = (y * w + x) * 3;
            data.extend_from_slice(&img.data[i..i + 3]);
        }
    }
    CodeImage {
        width: wo,
        height: ho,
        data,
        ..img
    }
}

/// The codes as stored in the file, before any EXIF orientation.
fn read_stored_codes(path: &Path) -> Result<CodeImage, HdrError> {
    let img = image::open(path).map_err(|cause| HdrError::Image {
        path: path.to_path_buf(),
        cause,
    })?;
    let label = path.display().to_string();
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (bits, data) = match img {
        // The common cases without a copy of the decoded buffer.
        DynamicImage::ImageRgb8(buf) => (8, buf.into_raw().into_iter().map(u16::from).collect()),
        DynamicImage::ImageRgb16(buf) => (16, buf.into_raw()),
        DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgba8(_) => (8, img.to_rgb8().into_raw().into_iter().map(u16::from).collect()),
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgba16(_) => (16, img.to_rgb16().into_raw()),
        other => {
            return Err(HdrError::BadImage {
                image: label,
                what: format!(
                    "pixel format {:?}: expected 8- or 16-bit integer samples",
                    other.color()
                ),
            });
        }
    };
    Ok(CodeImage {
        width,
        height,
        bits,
        data,
        label,
    })
}

/// Writes 8-bit (`bits == 8`) or 16-bit codes as a PNG.
pub fn write_png(img: &CodeImage, path: &Path) -> Result<(), HdrError> {
    let (w, h) = (img.width as u32, img.height as u32);
    let res = if img.bits <= 8 {
        let buf: Vec<u8> = img.data.iter().map(|&z| z.min(255) as u8).collect();
        image::RgbImage::from_raw(w, h, buf).map(|b| b.save(path))
    } else {
        let shift = 16 - img.bits;
        let buf: Vec<u16> = img.data.iter().map(|&z| z << shift).collect();
        image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, buf).map(|b| b.save(path))
    };
    match res {
        Some(r) => r.map_err(|cause| HdrError::Image {
            path: path.to_path_buf(),
            cause,
        }),
        None => Err(HdrError::BufferLength {
            image: img.label.clone(),
            len: img.data.len(),
            width: img.width,
            height: img.height,
            expected: img.width * img.height * 3,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_8_and_16_bit() {
        let dir = tempfile::tempdir().unwrap();
        for bits in [8u8, 16] {
            let max = crate::camera::image::max_code(bits);
            let data: Vec<u16> = (0..4 * 3 * 3).map(|i| (i as u16 * 997) % (max / 2 + 1) * 2).collect();
            let img = CodeImage {
                width: 4,
                height: 3,
                bits,
                data,
                label: "t".into(),
            };
            let p = dir.path().join(format!("t{bits}.png"));
            write_png(&img, &p).unwrap();
            let back = read_code_image(&p).unwrap();
            assert_eq!(back.bits, bits);
            assert_eq!(back.data, img.data);
        }
    }

    #[test]
    fn missing_file_names_the_path() {
        let e = read_code_image(Path::new("/nonexistent/x.png")).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/x.png"), "{e}");
    }
}
