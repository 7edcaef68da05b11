//! Reading exposure brackets from image files (PNG, TIFF, JPEG; 8 or 16
//! bits), turned upright by their EXIF orientation.

use std::path::Path;

use image::{ColorType, DynamicImage, ImageDecoder};
use rayon::prelude::*;

use super::HdrError;
use super::exposure_metadata::{ExposureMetadata, Orientation, read_exposure_metadata_bytes};
use crate::camera::image::CodeImage;

/// Reads an image file as upright RGB codes with its EXIF exposure metadata
/// (see [`read_code_image`] and [`read_exposure_metadata`](super::exposure_metadata::read_exposure_metadata)).
pub fn read_frame(path: &Path) -> Result<(CodeImage, ExposureMetadata), HdrError> {
    let bytes = std::fs::read(path).map_err(|cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    read_frame_bytes(path, &bytes)
}

/// [`read_frame`] on a file's bytes already in memory (a frame a camera
/// delivered, as a session stores it); `path` names it in errors and labels
/// the image. The format is found from the bytes, not the name.
pub fn read_frame_bytes(path: &Path, bytes: &[u8]) -> Result<(CodeImage, ExposureMetadata), HdrError> {
    let meta = read_exposure_metadata_bytes(path, bytes)?;
    let img = read_stored_codes(path, bytes)?;
    Ok((turn_upright(img, meta.orientation), meta))
}

/// [`read_frame`] into buffers reused from frame to frame (`bytes` for the
/// decoder's output, `out` for the codes): a bracket read one frame at a
/// time allocates its buffers once. 8- and 16-bit RGB (the cameras' JPEG,
/// PNG and TIFF) decode straight into them; other layouts go through
/// [`read_frame_bytes`] on the bytes already read.
pub fn read_frame_into(path: &Path, bytes: &mut Vec<u8>, out: &mut CodeImage) -> Result<ExposureMetadata, HdrError> {
    let file = std::fs::read(path).map_err(|cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let meta = read_exposure_metadata_bytes(path, &file)?;
    check_not_cut_short(path, &file)?;
    let image_error = |cause| HdrError::Image {
        path: path.to_path_buf(),
        cause,
    };
    let format = file_format(path, &file).map_err(image_error)?;
    let decoder = image::ImageReader::with_format(std::io::Cursor::new(&file), format)
        .into_decoder()
        .map_err(image_error)?;
    let (w, h) = decoder.dimensions();
    let bits = match decoder.color_type() {
        ColorType::Rgb8 => 8,
        ColorType::Rgb16 => 16,
        _ => {
            drop(decoder);
            *out = read_frame_bytes(path, &file)?.0;
            return Ok(meta);
        }
    };
    let len = usize::try_from(decoder.total_bytes()).unwrap_or(usize::MAX);
    bytes.resize(len, 0);
    decoder.read_image(bytes).map_err(image_error)?;
    const CHUNK: usize = 1 << 16;
    if bits == 8 {
        out.data.resize(bytes.len(), 0);
        out.data
            .par_chunks_mut(CHUNK)
            .zip(bytes.par_chunks(CHUNK))
            .for_each(|(d, b)| {
                for (d, &b) in d.iter_mut().zip(b) {
                    *d = u16::from(b);
                }
            });
    } else {
        out.data.resize(bytes.len() / 2, 0);
        out.data
            .par_chunks_mut(CHUNK)
            .zip(bytes.par_chunks(2 * CHUNK))
            .for_each(|(d, b)| {
                for (d, b) in d.iter_mut().zip(b.chunks_exact(2)) {
                    *d = u16::from_ne_bytes([b[0], b[1]]);
                }
            });
    }
    out.width = w as usize;
    out.height = h as usize;
    out.bits = bits;
    out.label = path.display().to_string();
    if meta.orientation != Orientation::Upright {
        let img = std::mem::replace(
            out,
            CodeImage {
                width: 0,
                height: 0,
                bits,
                data: Vec::new(),
                label: String::new(),
            },
        );
        *out = turn_upright(img, meta.orientation);
    }
    Ok(meta)
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

/// A file's image format: by the name's extension first (as `image::open`
/// does), else by its bytes.
fn file_format(path: &Path, bytes: &[u8]) -> image::ImageResult<image::ImageFormat> {
    image::ImageFormat::from_path(path).or_else(|_| image::guess_format(bytes))
}

/// Refuses a JPEG whose image data stops before its end-of-image marker: a
/// file cut short (a copy interrupted, a card pulled), which the decoder
/// would fill with grey and merge as data. The marker segments are walked
/// to the first start of scan; from there the entropy-coded data stuffs
/// every `FF` as `FF 00`, so the first `FF D9` is the end of the image (data
/// a phone appends after it is allowed). Not a JPEG, or headers the decoder
/// will refuse anyway: nothing to say here.
fn check_not_cut_short(path: &Path, bytes: &[u8]) -> Result<(), HdrError> {
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return Ok(());
    }
    let cut = |what: String| HdrError::BadImage {
        image: path.display().to_string(),
        what,
    };
    let mut i = 2;
    loop {
        if i + 4 > bytes.len() {
            return Err(cut(format!(
                "JPEG of {} bytes ends inside its headers, before the image data: the file is cut short",
                bytes.len()
            )));
        }
        match (bytes[i], bytes[i + 1]) {
            (0xFF, 0xFF) => i += 1,
            (0xFF, 0xDA) => break,
            (0xFF, 0xD9) | (0xFF, 0xD0..=0xD7) => return Ok(()),
            (0xFF, _) => i += 2 + usize::from(u16::from_be_bytes([bytes[i + 2], bytes[i + 3]])),
            _ => return Ok(()),
        }
    }
    if bytes[i..].windows(2).any(|w| w == [0xFF, 0xD9]) {
        Ok(())
    } else {
        Err(cut(format!(
            "JPEG of {} bytes has no end-of-image marker (FF D9) after its image data: the file is cut short",
            bytes.len()
        )))
    }
}

/// The codes as stored in the file, before any EXIF orientation.
fn read_stored_codes(path: &Path, bytes: &[u8]) -> Result<CodeImage, HdrError> {
    let image_err = |cause| HdrError::Image {
        path: path.to_path_buf(),
        cause,
    };
    check_not_cut_short(path, bytes)?;
    let format = file_format(path, bytes).map_err(image_err)?;
    let img = image::load_from_memory_with_format(bytes, format).map_err(image_err)?;
    let label = path.display().to_string();
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (bits, data) = match img {
        // The common cases without a copy of the decoded buffer.
        DynamicImage::ImageRgb8(buf) => (8, buf.into_raw().into_iter().map(u16::from).collect()),
        DynamicImage::ImageRgb16(buf) => (16, buf.into_raw()),
        DynamicImage::ImageLuma8(_) | DynamicImage::ImageLumaA8(_) | DynamicImage::ImageRgba8(_) => {
            (8, img.to_rgb8().into_raw().into_iter().map(u16::from).collect())
        }
        DynamicImage::ImageLuma16(_) | DynamicImage::ImageLumaA16(_) | DynamicImage::ImageRgba16(_) => {
            (16, img.to_rgb16().into_raw())
        }
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

/// The bytes of a baseline JPEG of `img`'s codes scaled to 8 bits
/// (`round(z · 255 / z_max)`) at `quality` (1–100), with an EXIF block
/// holding ExposureTime when `exposure_time_s` is given (as a camera writes
/// it; [`read_frame_bytes`] reads it back).
pub fn jpeg_bytes(img: &CodeImage, quality: u8, exposure_time_s: Option<f64>) -> Result<Vec<u8>, HdrError> {
    use image::ImageEncoder;
    let expected = img.width * img.height * 3;
    let (Ok(w), Ok(h)) = (u32::try_from(img.width), u32::try_from(img.height)) else {
        return Err(HdrError::BadImage {
            image: img.label.clone(),
            what: format!("size {}×{}: too large for a JPEG", img.width, img.height),
        });
    };
    if img.data.len() != expected {
        return Err(HdrError::BufferLength {
            image: img.label.clone(),
            len: img.data.len(),
            width: img.width,
            height: img.height,
            expected,
        });
    }
    let scale = 255.0 / f64::from(crate::camera::image::max_code(img.bits));
    let buf: Vec<u8> = img
        .data
        .iter()
        .map(|&z| (f64::from(z) * scale).round().min(255.0) as u8)
        .collect();
    let encode_err = |cause: image::ImageError| HdrError::BadImage {
        image: img.label.clone(),
        what: format!("JPEG encoding failed: {cause}"),
    };
    let mut out = Vec::new();
    let mut encoder = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality.clamp(1, 100));
    if let Some(t) = exposure_time_s.filter(|t| t.is_finite() && *t > 0.0) {
        // A rational as cameras write it: 1/N below a second, else N/1000.
        let r = if t < 1.0 {
            exif::Rational {
                num: 1,
                denom: (1.0 / t).round().clamp(1.0, f64::from(u32::MAX)) as u32,
            }
        } else {
            exif::Rational {
                num: (t * 1000.0).round().min(f64::from(u32::MAX)) as u32,
                denom: 1000,
            }
        };
        let field = exif::Field {
            tag: exif::Tag::ExposureTime,
            ifd_num: exif::In::PRIMARY,
            value: exif::Value::Rational(vec![r]),
        };
        let mut writer = exif::experimental::Writer::new();
        writer.push_field(&field);
        let mut block = std::io::Cursor::new(Vec::new());
        writer.write(&mut block, false).map_err(|e| HdrError::BadImage {
            image: img.label.clone(),
            what: format!("EXIF block not written: {e}"),
        })?;
        // The JPEG encoder accepts EXIF; the error type says "unsupported" only for formats without it.
        let _ = encoder.set_exif_metadata(block.into_inner());
    }
    encoder
        .write_image(&buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(encode_err)?;
    Ok(out)
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
    fn a_cut_short_jpeg_is_refused_and_a_trailer_after_its_end_is_not() {
        let (w, h) = (64usize, 48usize);
        let img = CodeImage {
            width: w,
            height: h,
            bits: 8,
            data: (0..w * h * 3).map(|i| ((i * 7) % 251) as u16).collect(),
            label: "noise".into(),
        };
        let full = jpeg_bytes(&img, 95, Some(0.01)).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.jpg");
        let (mut bytes, mut out) = (Vec::new(), img.clone());
        // Whole, and with data appended after the end (as phones do): read.
        let mut trailer = full.clone();
        trailer.extend_from_slice(b"motion photo trailer");
        for ok in [&full, &trailer] {
            std::fs::write(&path, ok).unwrap();
            read_frame_into(&path, &mut bytes, &mut out).unwrap();
            assert_eq!((out.width, out.height), (w, h));
            read_frame(&path).unwrap();
        }
        // Cut at 90 %: the decoder would fill the rest; refused by both readers.
        std::fs::write(&path, &full[..full.len() * 9 / 10]).unwrap();
        for e in [
            read_frame_into(&path, &mut bytes, &mut out).unwrap_err(),
            read_frame(&path).unwrap_err(),
        ] {
            let e = e.to_string();
            assert!(
                e.contains("f.jpg") && e.contains("no end-of-image marker (FF D9)"),
                "{e}"
            );
        }
    }

    #[test]
    fn jpeg_bytes_read_back_as_8_bit_codes_with_the_exposure_time() {
        // A 12-bit ramp, smooth enough for JPEG at quality 95.
        let (w, h) = (32usize, 16usize);
        let data: Vec<u16> = (0..w * h)
            .flat_map(|i| [((i % w) * 4095 / (w - 1)) as u16; 3])
            .collect();
        let img = CodeImage {
            width: w,
            height: h,
            bits: 12,
            data,
            label: "ramp".into(),
        };
        let bytes = jpeg_bytes(&img, 95, Some(1.0 / 250.0)).unwrap();
        let (back, meta) = read_frame_bytes(Path::new("frames/ramp.jpg"), &bytes).unwrap();
        assert_eq!((back.width, back.height, back.bits), (w, h, 8));
        assert_eq!(meta.exposure_time_s, Some(0.004));
        let worst = back
            .data
            .iter()
            .zip(&img.data)
            .map(|(&a, &z)| (f64::from(a) - f64::from(z) * 255.0 / 4095.0).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 3.0, "worst code error {worst}");
        // A damaged JPEG names the file.
        let e = read_frame_bytes(Path::new("frames/ramp.jpg"), &bytes[..bytes.len() / 3]).unwrap_err();
        assert!(e.to_string().contains("frames/ramp.jpg"), "{e}");
    }

    #[test]
    fn missing_file_names_the_path() {
        let e = read_code_image(Path::new("/nonexistent/x.png")).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/x.png"), "{e}");
    }
}
