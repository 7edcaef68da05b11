//! Frame files: raw sensor codes stored losslessly as 16-bit RGB PNG, or
//! the file a camera delivered (JPEG, DNG) kept byte for byte; decoded by
//! format ([`decode_frame`]).
//!
//! The codes are written unscaled (a 12-bit code of 4095 is stored as
//! 4095, not 65535); the journal records the bit depth so readers know the
//! range. PNG stores 16-bit samples big-endian and losslessly, and the
//! encoder is deterministic, so the same codes always give the same bytes
//! and the same checksum.

use super::error::StoreError;
use crate::device::{Frame, FrameFormat};
use campanile_process::camera::image::CodeImage;
use campanile_process::hdr::{HdrError, fits_file, image_file, linear_codes, raw_file};
use image::codecs::png::{CompressionType, FilterType, PngDecoder, PngEncoder};
use image::{ColorType, DynamicImage, ImageBuffer, ImageDecoder, Rgb};
use std::io::Cursor;
use std::path::Path;

use super::checksum::crc32c;
use super::journal::FrameEntry;
use super::storage::Storage;

/// Check that `frame` describes itself consistently: a nonzero size that
/// fits a PNG, 1 to 16 bits, `width · height · 3` codes, none above
/// `2^bits − 1`.
pub fn check_frame(key: &str, frame: &Frame) -> Result<(), StoreError> {
    let bad = |reason: String| {
        Err(StoreError::BadFrame {
            key: key.to_string(),
            reason,
        })
    };
    if frame.width == 0 || frame.height == 0 {
        return bad(format!("size {}×{} is empty", frame.width, frame.height));
    }
    if u32::try_from(frame.width).is_err() || u32::try_from(frame.height).is_err() {
        return bad(format!("size {}×{} is too large for PNG", frame.width, frame.height));
    }
    if !(1..=16).contains(&frame.bits) {
        return bad(format!("bit depth {} is outside 1..=16", frame.bits));
    }
    let expected = frame.width.checked_mul(frame.height).and_then(|n| n.checked_mul(3));
    if expected != Some(frame.data.len()) {
        return bad(format!(
            "{} codes for {}×{} RGB (expected {})",
            frame.data.len(),
            frame.width,
            frame.height,
            frame.width.saturating_mul(frame.height).saturating_mul(3)
        ));
    }
    let max = u16::MAX >> (16 - frame.bits);
    if let Some(i) = frame.data.iter().position(|&c| c > max) {
        return bad(format!(
            "code {} at sample {i} exceeds {max}, the largest {}-bit code",
            frame.data[i], frame.bits
        ));
    }
    Ok(())
}

/// Encode `frame`'s codes as a 16-bit RGB PNG (call [`check_frame`]
/// first).
pub fn encode_png(key: &str, frame: &Frame) -> Result<Vec<u8>, StoreError> {
    let bad = |reason: String| StoreError::BadFrame {
        key: key.to_string(),
        reason,
    };
    let (w, h) = (
        u32::try_from(frame.width).map_err(|_| bad("width too large".into()))?,
        u32::try_from(frame.height).map_err(|_| bad("height too large".into()))?,
    );
    let buf: ImageBuffer<Rgb<u16>, &[u16]> =
        ImageBuffer::from_raw(w, h, frame.data.as_slice()).ok_or_else(|| bad("codes do not fill the frame".into()))?;
    let mut out = Vec::with_capacity(frame.data.len() * 2 + 1024);
    let encoder = PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive);
    buf.write_with_encoder(encoder)
        .map_err(|e| bad(format!("PNG encoding failed: {e}")))?;
    Ok(out)
}

/// Decode a frame file written by [`encode_png`]; `path` names it in
/// errors and `bits` (from the journal) labels the codes.
pub fn decode_png(path: &Path, bytes: &[u8], bits: u8) -> Result<CodeImage, StoreError> {
    let bad = |reason: String| StoreError::BadFrameFile {
        path: path.to_path_buf(),
        reason,
    };
    let decoder = PngDecoder::new(Cursor::new(bytes)).map_err(|e| bad(format!("not a readable PNG: {e}")))?;
    if decoder.color_type() != ColorType::Rgb16 {
        return Err(bad(format!(
            "expected a 16-bit RGB PNG, found {:?}",
            decoder.color_type()
        )));
    }
    let (w, h) = decoder.dimensions();
    let image = DynamicImage::from_decoder(decoder).map_err(|e| bad(format!("PNG data unreadable: {e}")))?;
    let DynamicImage::ImageRgb16(buf) = image else {
        return Err(bad("expected a 16-bit RGB PNG".into()));
    };
    Ok(CodeImage {
        width: w as usize,
        height: h as usize,
        bits,
        data: buf.into_raw(),
        label: path.display().to_string(),
    })
}

/// A journaled frame's bytes, read from `storage` at `path` and checked
/// against the journal's size and CRC-32C.
pub(crate) fn read_checked_bytes<S: Storage + ?Sized>(
    storage: &S,
    path: &Path,
    entry: &FrameEntry,
) -> Result<Vec<u8>, StoreError> {
    let bytes = match storage.read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(StoreError::MissingFrame {
                key: entry.key.clone(),
                path: path.to_path_buf(),
            });
        }
        Err(source) => {
            return Err(StoreError::Io {
                action: "reading",
                path: path.to_path_buf(),
                source,
            });
        }
    };
    let actual = crc32c(&bytes);
    if actual != entry.crc32c || bytes.len() as u64 != entry.bytes {
        return Err(StoreError::ChecksumMismatch {
            key: entry.key.clone(),
            path: path.to_path_buf(),
            expected: entry.crc32c,
            actual,
            expected_len: entry.bytes,
            actual_len: bytes.len() as u64,
        });
    }
    Ok(bytes)
}

/// Decode a frame file of `format` through the HDR readers of
/// `campanile-process` (the ones `campanile hdr calibrate/merge` use):
/// - PNG ([`decode_png`]): the codes unscaled, `bits` (from the journal)
///   significant bits;
/// - JPEG ([`image_file::read_frame_bytes`]): 8-bit codes, turned upright
///   by the EXIF orientation;
/// - DNG and the makers' RAW files ([`raw_file::read_raw_bytes`], through
///   `rawler`): the linear frame (black level removed, white level 1,
///   clipped samples flagged) as the logarithmic 16-bit codes of
///   [`linear_codes`], whose response is known;
/// - FITS ([`fits_file::read_fits`]): the integer codes, `bits` (from the
///   journal: the camera's stated depth) significant bits.
///
/// A file that does not decode is [`StoreError::BadFrameFile`] naming it.
pub fn decode_frame(path: &Path, bytes: &[u8], format: FrameFormat, bits: u8) -> Result<CodeImage, StoreError> {
    let bad = |e: HdrError| StoreError::BadFrameFile {
        path: path.to_path_buf(),
        reason: format!("not a readable {} frame: {e}", format.name()),
    };
    if let Some(reason) = format.signature_problem(bytes).or_else(|| format.end_problem(bytes)) {
        return Err(StoreError::BadFrameFile {
            path: path.to_path_buf(),
            reason,
        });
    }
    match format {
        FrameFormat::Png => decode_png(path, bytes, bits),
        FrameFormat::Jpeg => image_file::read_frame_bytes(path, bytes)
            .map(|(image, _)| image)
            .map_err(bad),
        FrameFormat::Dng
        | FrameFormat::Cr2
        | FrameFormat::Cr3
        | FrameFormat::Nef
        | FrameFormat::Arw
        | FrameFormat::Raf
        | FrameFormat::Rw2
        | FrameFormat::Orf
        | FrameFormat::Pef
        | FrameFormat::Srw => raw_file::read_raw_bytes(path, bytes.to_vec())
            .map(|frame| linear_codes::log_codes(&frame))
            .map_err(bad),
        FrameFormat::Fits => fits_file::read_fits(bytes, &path.display().to_string())
            .map(|f| {
                let mut image = f.image;
                image.bits = bits;
                image
            })
            .map_err(|e| StoreError::BadFrameFile {
                path: path.to_path_buf(),
                reason: format!("not a readable FITS frame: {}", e.reason),
            }),
    }
}

/// The codes of a journaled frame, decoded by its format ([`decode_frame`]:
/// a PNG's codes exactly as recorded, unscaled with `entry.bits`
/// significant bits; a JPEG's 8-bit codes; a DNG's logarithmic codes),
/// after checking its checksum and size, and that its (upright) size is
/// the journaled one.
pub(crate) fn read_checked_frame<S: Storage + ?Sized>(
    storage: &S,
    path: &Path,
    entry: &FrameEntry,
) -> Result<CodeImage, StoreError> {
    let bytes = read_checked_bytes(storage, path, entry)?;
    let mut image = decode_frame(path, &bytes, entry.format, entry.bits)?;
    if (image.width, image.height) != (entry.width as usize, entry.height as usize) {
        return Err(StoreError::BadFrameFile {
            path: path.to_path_buf(),
            reason: format!(
                "image is {}×{}, the journal says {}×{}",
                image.width, image.height, entry.width, entry.height
            ),
        });
    }
    image.label = entry.key.clone();
    Ok(image)
}
