//! Reading camera RAW files (DNG, CR2, CR3, NEF, ARW, RAF, RW2, ORF, PEF,
//! SRW) into [`LinearFrame`]s through the `rawler` decoder.
//!
//! Steps: refuse a DNG whose only image is a thumbnail or preview (checked
//! on the TIFF structure before decoding, and the decoded size against the
//! declared DefaultCropSize); decode the raw samples with rawler; crop to
//! the active area; subtract the black level of each 2×2 position and
//! divide by `white − black`, so black = 0 and the white level = 1; flag
//! every photosite at or above the white level; demosaic bilinearly (each
//! missing colour is the mean of the same-colour photosites in the 3×3
//! neighbourhood, any of RGGB, BGGR, GRBG, GBRG) and flag a pixel's channel
//! as clipped when ANY photosite it was computed from was clipped, so
//! saturation never turns into a valid-looking interpolated value.
//! Bilinear rather than rawler's own demosaic because the clipped flag has
//! to follow exactly which photosites contributed.

use std::io::Read;
use std::path::Path;
use std::sync::Arc;

use rayon::prelude::*;

use super::HdrError;
use super::linear_frame::{FrameMetadata, LinearFrame};
use super::raw_error::RawError;
use super::tiff_structure::{
    self, PHOTOMETRIC_CFA, PHOTOMETRIC_LINEAR_RAW, TAG_BITS_PER_SAMPLE, TAG_DEFAULT_CROP_SIZE, TAG_NEW_SUBFILE_TYPE,
    TAG_PHOTOMETRIC, TiffStructure,
};
use crate::camera::bayer::CfaPattern;

/// Extensions of the RAW formats read (lower case).
pub const RAW_EXTENSIONS: [&str; 10] = ["dng", "cr2", "cr3", "nef", "arw", "raf", "rw2", "orf", "pef", "srw"];

/// Whether `path` has a RAW extension (case-insensitive).
pub fn is_raw(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| RAW_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// Whether `bytes` are a TIFF whose IFD0 carries the DNGVersion tag (50706).
pub fn sniff_dng(bytes: &[u8]) -> bool {
    tiff_structure::parse(bytes).is_some_and(|s| s.is_dng())
}

/// [`sniff_dng`] on a file: reads its first MiB (where IFD0 lives in every
/// DNG seen), and the whole file only if IFD0 lies further. `false` when
/// the file cannot be read.
pub fn sniff_dng_file(path: &Path) -> bool {
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut head = Vec::new();
    if file.take(1 << 20).read_to_end(&mut head).is_err() {
        return false;
    }
    if sniff_dng(&head) {
        return true;
    }
    if head.len() == 1 << 20
        && tiff_structure::parse(&head).is_none()
        && head.starts_with(b"II") | head.starts_with(b"MM")
    {
        return std::fs::read(path).is_ok_and(|b| sniff_dng(&b));
    }
    false
}

/// Whether `path` is read as RAW: a RAW extension, or a DNG under another name.
pub fn is_raw_input(path: &Path) -> bool {
    is_raw(path) || sniff_dng_file(path)
}

/// Refuses a DNG with no full-resolution raw image, naming what it holds.
fn check_dng_structure(path: &Path, s: &TiffStructure) -> Result<(), RawError> {
    let is_raw_ifd = |i: &&tiff_structure::Ifd| {
        !i.is_reduced() && matches!(i.first(TAG_PHOTOMETRIC), Some(PHOTOMETRIC_CFA | PHOTOMETRIC_LINEAR_RAW))
    };
    let declared = s.all().find_map(|i| {
        i.get(TAG_DEFAULT_CROP_SIZE)
            .filter(|v| v.len() == 2)
            .map(|v| (v[0], v[1]))
    });
    match s.all().find(is_raw_ifd) {
        None => {
            let largest = s.all().max_by_key(|i| i.size().0 * i.size().1).unwrap_or(&s.ifd0);
            let (w, h) = largest.size();
            let what = match largest.first(TAG_PHOTOMETRIC) {
                Some(2) => "RGB preview",
                Some(6) => "YCbCr (JPEG) preview",
                Some(1) => "greyscale preview",
                Some(PHOTOMETRIC_CFA | PHOTOMETRIC_LINEAR_RAW) => "reduced-resolution raw preview",
                _ => "image",
            };
            Err(RawError::ThumbnailOnly {
                path: path.to_path_buf(),
                width: w as u32,
                height: h as u32,
                bits: largest.first(TAG_BITS_PER_SAMPLE).unwrap_or(0) as u16,
                what: what.into(),
                subfile_type: largest.first(TAG_NEW_SUBFILE_TYPE).unwrap_or(0) as u32,
                declared: declared.map_or_else(String::new, |(w, h)| format!(", declared {w}×{h}")),
            })
        }
        Some(raw) => {
            let (w, h) = raw.size();
            match declared {
                Some((dw, dh)) if w < dw || h < dh => Err(RawError::SmallerThanDeclared {
                    path: path.to_path_buf(),
                    width: w as usize,
                    height: h as usize,
                    declared_width: dw as usize,
                    declared_height: dh as usize,
                }),
                _ => Ok(()),
            }
        }
    }
}

fn rational(r: &rawler::formats::tiff::Rational) -> Option<f64> {
    (r.d != 0).then(|| f64::from(r.n) / f64::from(r.d))
}

/// The raw photosites of a RAW file's active area, before demosaicing.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMosaic {
    /// The file, for messages.
    pub label: String,
    /// Width in photosites.
    pub width: usize,
    /// Height in photosites.
    pub height: usize,
    /// Raw codes, row-major.
    pub data: Vec<u16>,
    /// The colour filter pattern relative to the top-left photosite.
    pub pattern: CfaPattern,
    /// Metadata (levels, exposure, colour).
    pub meta: FrameMetadata,
}

/// Reads a RAW file and demosaics it into a [`LinearFrame`].
pub fn read_raw(path: &Path) -> Result<LinearFrame, HdrError> {
    Ok(demosaic(&read_raw_mosaic(path)?))
}

/// Reads the raw photosites of a RAW file (cropped to the active area) and
/// its metadata, refusing thumbnails.
pub fn read_raw_mosaic(path: &Path) -> Result<RawMosaic, HdrError> {
    let bytes = std::fs::read(path).map_err(|cause| RawError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    read_raw_mosaic_bytes(path, bytes)
}

/// [`read_raw`] on a file's bytes already in memory (a frame a camera
/// delivered, as a session stores it); `path` names it in errors.
pub fn read_raw_bytes(path: &Path, bytes: Vec<u8>) -> Result<LinearFrame, HdrError> {
    Ok(demosaic(&read_raw_mosaic_bytes(path, bytes)?))
}

/// [`read_raw_mosaic`] on a file's bytes already in memory.
pub fn read_raw_mosaic_bytes(path: &Path, bytes: Vec<u8>) -> Result<RawMosaic, HdrError> {
    if let Some(s) = tiff_structure::parse(&bytes)
        && s.is_dng()
    {
        check_dng_structure(path, &s)?;
    }
    let src = rawler::rawsource::RawSource::new_from_shared_vec(Arc::new(bytes)).with_path(path);
    let params = rawler::decoders::RawDecodeParams::default();
    let decode_err = |cause: String| RawError::Decode {
        path: path.to_path_buf(),
        cause,
    };
    // rawler reports most problems as errors but a few as panics (unknown
    // photometric interpretations): both become a decode error here.
    let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let decoder = rawler::get_decoder(&src)?;
        let image = decoder.raw_image(&src, &params, false)?;
        let meta = decoder.raw_metadata(&src, &params)?;
        Ok::<_, rawler::RawlerError>((image, meta))
    }));
    let (image, meta) = match decoded {
        Ok(Ok(v)) => v,
        Ok(Err(e)) => return Err(decode_err(e.to_string()).into()),
        Err(_) => return Err(decode_err("the decoder stopped on an unexpected layout".into()).into()),
    };
    Ok(mosaic_from_raw(path, &image, &meta.exif)?)
}

/// Normalizes, flags and demosaics a mosaic (see the module's notes).
pub fn demosaic(m: &RawMosaic) -> LinearFrame {
    let (rgb, clipped) = demosaic_bilinear(
        &m.data,
        m.width,
        (0, 0, m.width, m.height),
        m.pattern,
        &m.meta.black_levels,
        m.meta.white_level,
    );
    LinearFrame {
        label: m.label.clone(),
        width: m.width,
        height: m.height,
        rgb,
        clipped,
        meta: m.meta.clone(),
    }
}

/// The active area, levels and metadata of a decoded raw image.
fn mosaic_from_raw(path: &Path, image: &rawler::RawImage, exif: &rawler::exif::Exif) -> Result<RawMosaic, RawError> {
    let layout = |what: String| RawError::UnsupportedLayout {
        path: path.to_path_buf(),
        what,
    };
    if image.cpp != 1 {
        return Err(layout(format!(
            "{} samples per pixel: expected 1 (a colour filter array); linear (demosaiced) RAW is not read",
            image.cpp
        )));
    }
    let rawler::RawImageData::Integer(samples) = &image.data else {
        return Err(layout("floating-point samples: expected integer raw codes".into()));
    };
    let cfa = match &image.photometric {
        rawler::rawimage::RawPhotometricInterpretation::Cfa(conf) => &conf.cfa,
        other => return Err(layout(format!("photometric interpretation {other:?}: expected a CFA"))),
    };
    let (full_w, full_h) = (image.width, image.height);
    if samples.len() != full_w * full_h {
        return Err(layout(format!(
            "{} samples for {full_w}×{full_h}: expected {}",
            samples.len(),
            full_w * full_h
        )));
    }
    let (ax, ay, aw, ah) = match &image.active_area {
        Some(r) if r.p.x + r.d.w <= full_w && r.p.y + r.d.h <= full_h => (r.p.x, r.p.y, r.d.w, r.d.h),
        _ => (0, 0, full_w, full_h),
    };
    // The pattern relative to the active area's top-left photosite.
    let colors: Vec<u8> = (0..4).map(|i| cfa.color_at(ay + i / 2, ax + i % 2) as u8).collect();
    let unsupported = || RawError::UnsupportedCfa {
        path: path.to_path_buf(),
        pattern: cfa.name.clone(),
        pattern_width: cfa.width,
        pattern_height: cfa.height,
    };
    if cfa.width != 2 || cfa.height != 2 {
        return Err(unsupported());
    }
    let pattern = CfaPattern::from_colors([colors[0], colors[1], colors[2], colors[3]]).ok_or_else(unsupported)?;
    if aw < 2 || ah < 2 {
        return Err(layout(format!("active area {aw}×{ah}: expected at least 2×2")));
    }
    // Black per 2×2 position of the active area.
    let bl = &image.blacklevel;
    let blacks: [f64; 4] = std::array::from_fn(|i| {
        let (y, x) = (i / 2, i % 2);
        let k = (y % bl.height.max(1)) * bl.width.max(1) + x % bl.width.max(1);
        bl.levels
            .get(k)
            .or(bl.levels.first())
            .map_or(0.0, |r| f64::from(r.as_f32()))
    });
    let white = image.whitelevel.0.first().copied().map_or(0.0, f64::from);
    let max_black = blacks.iter().copied().fold(f64::MIN, f64::max);
    if !(white > max_black && blacks.iter().all(|b| b.is_finite() && *b >= 0.0)) {
        return Err(RawError::BadLevels {
            path: path.to_path_buf(),
            white,
            black: max_black,
        });
    }
    let data: Vec<u16> = (ay..ay + ah)
        .flat_map(|y| samples[y * full_w + ax..y * full_w + ax + aw].iter().copied())
        .collect();

    let wb = image.wb_coeffs;
    let wb_multipliers = (wb[..3].iter().all(|v| v.is_finite() && *v > 0.0)).then(|| {
        let g = f64::from(wb[1]);
        [f64::from(wb[0]) / g, 1.0, f64::from(wb[2]) / g]
    });
    let mut mats: Vec<_> = image.color_matrix.iter().filter(|(_, m)| m.len() == 9).collect();
    mats.sort_by_key(|(ill, _)| (**ill != rawler::imgop::xyz::Illuminant::D65, **ill as u16));
    let xyz_to_camera = mats.first().map(|(ill, m)| {
        (
            std::array::from_fn(|r| std::array::from_fn(|c| f64::from(m[r * 3 + c]))),
            **ill as u16,
        )
    });
    let iso = exif
        .iso_speed_ratings
        .map(f64::from)
        .filter(|v| *v > 0.0)
        .or(exif.iso_speed.map(f64::from).filter(|v| *v > 0.0))
        .or(exif.recommended_exposure_index.map(f64::from).filter(|v| *v > 0.0));
    Ok(RawMosaic {
        label: path.display().to_string(),
        width: aw,
        height: ah,
        data,
        pattern,
        meta: FrameMetadata {
            make: image.make.clone(),
            model: image.model.clone(),
            exposure_time_s: exif.exposure_time.as_ref().and_then(rational),
            f_number: exif.fnumber.as_ref().and_then(rational),
            iso,
            cfa: pattern.name().into(),
            black_levels: blacks,
            white_level: white,
            white_level_electrons: None,
            wb_multipliers,
            xyz_to_camera,
        },
    })
}

/// Bilinear demosaic of the active area `(ax, ay, aw, ah)` of a mosaic of
/// row length `stride`: returns interleaved normalized RGB and the clipped bits.
fn demosaic_bilinear(
    samples: &[u16],
    stride: usize,
    (ax, ay, aw, ah): (usize, usize, usize, usize),
    pattern: CfaPattern,
    blacks: &[f64; 4],
    white: f64,
) -> (Vec<f32>, Vec<u8>) {
    let scale: [f32; 4] = std::array::from_fn(|i| (1.0 / (white - blacks[i])) as f32);
    let black: [f32; 4] = std::array::from_fn(|i| blacks[i] as f32);
    let white_code = white;
    // Normalized photosites and their clipped flags, over the active area.
    let site = |x: usize, y: usize| -> (f32, bool) {
        let z = samples[(ay + y) * stride + ax + x];
        let k = (y % 2) * 2 + x % 2;
        ((f32::from(z) - black[k]) * scale[k], f64::from(z) >= white_code)
    };
    let mut rgb = vec![0.0f32; aw * ah * 3];
    let mut clipped = vec![0u8; aw * ah];
    rgb.par_chunks_mut(aw * 3)
        .zip(clipped.par_chunks_mut(aw))
        .enumerate()
        .for_each(|(y, (row, crow))| {
            for x in 0..aw {
                let own = pattern.color_at(x, y);
                let mut sum = [0.0f32; 3];
                let mut n = [0u8; 3];
                let mut clip = 0u8;
                for yy in y.saturating_sub(1)..(y + 2).min(ah) {
                    for xx in x.saturating_sub(1)..(x + 2).min(aw) {
                        let c = pattern.color_at(xx, yy);
                        // The own colour comes from the photosite itself only.
                        if c == own && (xx != x || yy != y) {
                            continue;
                        }
                        let (v, s) = site(xx, yy);
                        sum[c] += v;
                        n[c] += 1;
                        if s {
                            clip |= 1 << c;
                        }
                    }
                }
                for c in 0..3 {
                    row[x * 3 + c] = sum[c] / f32::from(n[c].max(1));
                }
                crow[x] = clip;
            }
        });
    (rgb, clipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_extensions_are_case_insensitive_and_others_are_not_raw() {
        for p in [
            "a.DNG", "b.cr2", "c.Nef", "d.ARW", "e.raf", "f.rw2", "g.orf", "h.pef", "i.srw", "j.CR3",
        ] {
            assert!(is_raw(Path::new(p)), "{p}");
        }
        for p in ["a.tif", "b.png", "c.jpg", "noext", "d.dng.txt"] {
            assert!(!is_raw(Path::new(p)), "{p}");
        }
    }

    #[test]
    fn bilinear_demosaic_fills_flat_patches_and_propagates_clipping() {
        // A 4×4 RGGB mosaic: R = 1000, G = 2000, B = 3000 (black 0, white 4000),
        // except one green photosite at (1, 0) saturated.
        let pattern = CfaPattern::Rggb;
        let mut s: Vec<u16> = (0..16)
            .map(|i| [1000, 2000, 3000][pattern.color_at(i % 4, i / 4)])
            .collect();
        s[1] = 4000;
        let (rgb, clipped) = demosaic_bilinear(&s, 4, (0, 0, 4, 4), pattern, &[0.0; 4], 4000.0);
        // Pixel (2, 2) is red; its green comes from (2,1), (1,2), (3,2), (2,3): flat.
        let p = 2 * 4 + 2;
        for (c, want) in [0.25f32, 0.5, 0.75].into_iter().enumerate() {
            assert!((rgb[p * 3 + c] - want).abs() < 1e-6, "channel {c}: {}", rgb[p * 3 + c]);
        }
        assert_eq!(clipped[p], 0);
        // Pixel (0, 0) is red; its green uses (1, 0), the saturated one.
        assert_eq!(clipped[0], 0b010);
        // Pixel (1, 0) itself: its own green is clipped, R and B are not.
        assert_eq!(clipped[1], 0b010);
        assert_eq!(rgb[3 + 1], 1.0);
        // Pixel (3, 3) is blue, far from (1, 0): nothing clipped.
        assert_eq!(clipped[15], 0);
    }
}
