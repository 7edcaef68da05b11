//! Writing DNG 1.4 files (uncompressed, 16-bit CFA samples) from a
//! [`BayerMosaic`], so the RAW path can be tested end to end here and its
//! files checked by a public DNG reader (`validation/raw/`).
//!
//! Little-endian TIFF written byte by byte. Two layouts:
//! - [`DngLayout::SingleIfd`]: the raw CFA image in IFD0.
//! - [`DngLayout::ThumbnailAndSubIfd`]: an 8-bit RGB thumbnail (1/8 size) in
//!   IFD0 (NewSubFileType 1), the raw image in its SubIFD — the layout of
//!   most DNG converters.
//!
//! Tags: DNGVersion 1.4, DNGBackwardVersion 1.1, Make, Model,
//! UniqueCameraModel, CFARepeatPatternDim, CFAPattern, CFAPlaneColor,
//! CFALayout, BlackLevelRepeatDim, BlackLevel (per 2×2 position), WhiteLevel,
//! ColorMatrix1, CalibrationIlluminant1, AsShotNeutral, and an EXIF IFD with
//! ExposureTime, FNumber and ISOSpeedRatings.

use std::path::Path;

use super::raw_error::RawError;
use crate::camera::bayer::{BayerMosaic, Exposure};

/// Where the raw image goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DngLayout {
    /// The raw image in IFD0.
    SingleIfd,
    /// A small 8-bit RGB thumbnail in IFD0, the raw image in a SubIFD.
    ThumbnailAndSubIfd,
}

/// What a DNG says about its frame besides the pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct DngMetadata {
    /// Make.
    pub make: String,
    /// Model (also the UniqueCameraModel).
    pub model: String,
    /// Exposure time, f-number and ISO (EXIF).
    pub exposure: Exposure,
    /// ColorMatrix1: XYZ → camera, row-major (DNG convention).
    pub xyz_to_camera: [[f64; 3]; 3],
    /// AsShotNeutral: the camera's response to white, per channel.
    pub as_shot_neutral: [f64; 3],
    /// CalibrationIlluminant1 (EXIF light source; 21 = D65).
    pub calibration_illuminant: u16,
}

#[derive(Debug, Clone)]
enum Val {
    Byte(Vec<u8>),
    Ascii(String),
    Short(Vec<u16>),
    Long(Vec<u32>),
    Rational(Vec<(u32, u32)>),
    SRational(Vec<(i32, i32)>),
}

impl Val {
    fn type_and_count(&self) -> (u16, usize) {
        match self {
            Val::Byte(v) => (1, v.len()),
            Val::Ascii(s) => (2, s.len() + 1),
            Val::Short(v) => (3, v.len()),
            Val::Long(v) => (4, v.len()),
            Val::Rational(v) => (5, v.len()),
            Val::SRational(v) => (10, v.len()),
        }
    }
    fn bytes(&self) -> Vec<u8> {
        match self {
            Val::Byte(v) => v.clone(),
            Val::Ascii(s) => s.bytes().chain([0]).collect(),
            Val::Short(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Val::Long(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Val::Rational(v) => v
                .iter()
                .flat_map(|(a, b)| [a.to_le_bytes(), b.to_le_bytes()])
                .flatten()
                .collect(),
            Val::SRational(v) => v
                .iter()
                .flat_map(|(a, b)| [a.to_le_bytes(), b.to_le_bytes()])
                .flatten()
                .collect(),
        }
    }
}

/// Size in bytes of an IFD with these entries, including its out-of-line data.
fn ifd_size(entries: &[(u16, Val)]) -> usize {
    let extra: usize = entries
        .iter()
        .map(|(_, v)| {
            let n = v.bytes().len();
            if n > 4 { n + n % 2 } else { 0 }
        })
        .sum();
    2 + 12 * entries.len() + 4 + extra
}

/// Serializes an IFD placed at `at` (entries sorted by tag here).
fn ifd_bytes(entries: &[(u16, Val)], at: usize, next: u32) -> Vec<u8> {
    let mut entries = entries.to_vec();
    entries.sort_by_key(|(t, _)| *t);
    let mut head = Vec::new();
    let mut data = Vec::new();
    let data_at = at + 2 + 12 * entries.len() + 4;
    head.extend((entries.len() as u16).to_le_bytes());
    for (tag, val) in &entries {
        let (typ, count) = val.type_and_count();
        head.extend(tag.to_le_bytes());
        head.extend(typ.to_le_bytes());
        head.extend((count as u32).to_le_bytes());
        let b = val.bytes();
        if b.len() <= 4 {
            let mut inline = [0u8; 4];
            inline[..b.len()].copy_from_slice(&b);
            head.extend(inline);
        } else {
            head.extend(((data_at + data.len()) as u32).to_le_bytes());
            data.extend(&b);
            if data.len() % 2 == 1 {
                data.push(0);
            }
        }
    }
    head.extend(next.to_le_bytes());
    head.extend(data);
    head
}

/// `v` as an unsigned rational with a denominator that keeps 6 significant digits.
fn rational(v: f64) -> (u32, u32) {
    let den: u32 = if v < 4000.0 { 1_000_000 } else { 1 };
    ((v * f64::from(den)).round().clamp(0.0, f64::from(u32::MAX)) as u32, den)
}

fn srational(v: f64) -> (i32, i32) {
    ((v * 10_000.0).round() as i32, 10_000)
}

/// The raw IFD's own tags (pixel layout, CFA, levels).
fn raw_tags(m: &BayerMosaic, strip_offset: u32) -> Vec<(u16, Val)> {
    vec![
        (254, Val::Long(vec![0])),
        (256, Val::Long(vec![m.width as u32])),
        (257, Val::Long(vec![m.height as u32])),
        (258, Val::Short(vec![16])),
        (259, Val::Short(vec![1])),
        (262, Val::Short(vec![32803])),
        (273, Val::Long(vec![strip_offset])),
        (277, Val::Short(vec![1])),
        (278, Val::Long(vec![m.height as u32])),
        (279, Val::Long(vec![(m.width * m.height * 2) as u32])),
        (284, Val::Short(vec![1])),
        (33421, Val::Short(vec![2, 2])),
        (33422, Val::Byte(m.pattern.colors().to_vec())),
        (50710, Val::Byte(vec![0, 1, 2])),
        (50711, Val::Short(vec![1])),
        (50713, Val::Short(vec![2, 2])),
        (50714, Val::Long(m.black_levels.iter().map(|&b| u32::from(b)).collect())),
        (50717, Val::Long(vec![u32::from(m.white_level)])),
        (50719, Val::Long(vec![0, 0])),
        (50720, Val::Long(vec![m.width as u32, m.height as u32])),
    ]
}

/// Camera-wide tags (IFD0).
fn global_tags(meta: &DngMetadata, exif_offset: u32) -> Vec<(u16, Val)> {
    let cm = meta.xyz_to_camera.iter().flatten().map(|&v| srational(v)).collect();
    vec![
        (271, Val::Ascii(meta.make.clone())),
        (272, Val::Ascii(meta.model.clone())),
        (274, Val::Short(vec![1])),
        (305, Val::Ascii("campanile".into())),
        (34665, Val::Long(vec![exif_offset])),
        (50706, Val::Byte(vec![1, 4, 0, 0])),
        (50707, Val::Byte(vec![1, 1, 0, 0])),
        (50708, Val::Ascii(format!("{} {}", meta.make, meta.model))),
        (50721, Val::SRational(cm)),
        (
            50728,
            Val::Rational(meta.as_shot_neutral.iter().map(|&v| rational(v)).collect()),
        ),
        (50778, Val::Short(vec![meta.calibration_illuminant])),
    ]
}

fn exif_tags(e: &Exposure) -> Vec<(u16, Val)> {
    vec![
        (33434, Val::Rational(vec![rational(e.time_s)])),
        (33437, Val::Rational(vec![rational(e.f_number)])),
        (34855, Val::Short(vec![e.iso.round().clamp(0.0, 65535.0) as u16])),
        (36864, Val::Byte(b"0231".to_vec())),
    ]
}

/// A crude 8-bit RGB preview of the mosaic, one pixel per 8×8 block (at least 1×1).
fn thumbnail(m: &BayerMosaic) -> (usize, usize, Vec<u8>) {
    let (tw, th) = ((m.width / 8).max(1), (m.height / 8).max(1));
    let range = f64::from(m.white_level).max(1.0);
    let mut px = Vec::with_capacity(tw * th * 3);
    for ty in 0..th {
        for tx in 0..tw {
            let mut rgb = [0.0f64; 3];
            for (dy, dx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                let (x, y) = ((tx * 8 + dx).min(m.width - 1), (ty * 8 + dy).min(m.height - 1));
                let c = m.pattern.color_at(x, y);
                rgb[c] = rgb[c].max(f64::from(m.data[y * m.width + x]) / range);
            }
            px.extend(rgb.map(|v| (255.0 * v.clamp(0.0, 1.0).sqrt()).round() as u8));
        }
    }
    (tw, th, px)
}

fn thumb_tags(tw: usize, th: usize, offset: u32) -> Vec<(u16, Val)> {
    vec![
        (254, Val::Long(vec![1])),
        (256, Val::Long(vec![tw as u32])),
        (257, Val::Long(vec![th as u32])),
        (258, Val::Short(vec![8, 8, 8])),
        (259, Val::Short(vec![1])),
        (262, Val::Short(vec![2])),
        (273, Val::Long(vec![offset])),
        (277, Val::Short(vec![3])),
        (278, Val::Long(vec![th as u32])),
        (279, Val::Long(vec![(tw * th * 3) as u32])),
        (284, Val::Short(vec![1])),
    ]
}

/// The bytes of a DNG holding `mosaic`.
pub fn dng_bytes(mosaic: &BayerMosaic, meta: &DngMetadata, layout: DngLayout) -> Vec<u8> {
    let pixels: Vec<u8> = mosaic.data.iter().flat_map(|v| v.to_le_bytes()).collect();
    let exif = exif_tags(&meta.exposure);
    let mut out = vec![b'I', b'I', 42, 0, 8, 0, 0, 0];
    match layout {
        DngLayout::SingleIfd => {
            // [header][IFD0][EXIF IFD][pixels]
            let build = |exif_at: u32, strip_at: u32| {
                let mut t = raw_tags(mosaic, strip_at);
                t.extend(global_tags(meta, exif_at));
                t
            };
            let ifd0_at = 8;
            let exif_at = ifd0_at + ifd_size(&build(0, 0));
            let strip_at = exif_at + ifd_size(&exif);
            out.extend(ifd_bytes(&build(exif_at as u32, strip_at as u32), ifd0_at, 0));
            out.extend(ifd_bytes(&exif, exif_at, 0));
            out.extend(pixels);
        }
        DngLayout::ThumbnailAndSubIfd => {
            // [header][IFD0 = thumbnail + globals][raw SubIFD][EXIF IFD][thumbnail pixels][raw pixels]
            let (tw, th, thumb) = thumbnail(mosaic);
            let build0 = |sub_at: u32, exif_at: u32, thumb_at: u32| {
                let mut t = thumb_tags(tw, th, thumb_at);
                t.extend(global_tags(meta, exif_at));
                t.push((330, Val::Long(vec![sub_at])));
                t
            };
            let ifd0_at = 8;
            let sub_at = ifd0_at + ifd_size(&build0(0, 0, 0));
            let exif_at = sub_at + ifd_size(&raw_tags(mosaic, 0));
            let thumb_at = exif_at + ifd_size(&exif);
            let strip_at = thumb_at + thumb.len() + thumb.len() % 2;
            out.extend(ifd_bytes(
                &build0(sub_at as u32, exif_at as u32, thumb_at as u32),
                ifd0_at,
                0,
            ));
            out.extend(ifd_bytes(&raw_tags(mosaic, strip_at as u32), sub_at, 0));
            out.extend(ifd_bytes(&exif, exif_at, 0));
            out.extend(&thumb);
            if thumb.len() % 2 == 1 {
                out.push(0);
            }
            out.extend(pixels);
        }
    }
    out
}

/// The bytes of a DNG that holds only an 8-bit RGB thumbnail of
/// `width`×`height` (NewSubFileType 1) and no raw image — what some tools
/// leave when they strip a DNG's pixel data. Readers must refuse it.
pub fn thumbnail_only_dng_bytes(width: usize, height: usize, meta: &DngMetadata) -> Vec<u8> {
    let thumb = vec![128u8; width * height * 3];
    let exif = exif_tags(&meta.exposure);
    let build = |exif_at: u32, thumb_at: u32| {
        let mut t = thumb_tags(width, height, thumb_at);
        t.extend(global_tags(meta, exif_at));
        t
    };
    let exif_at = 8 + ifd_size(&build(0, 0));
    let thumb_at = exif_at + ifd_size(&exif);
    let mut out = vec![b'I', b'I', 42, 0, 8, 0, 0, 0];
    out.extend(ifd_bytes(&build(exif_at as u32, thumb_at as u32), 8, 0));
    out.extend(ifd_bytes(&exif, exif_at, 0));
    out.extend(thumb);
    out
}

/// Writes `mosaic` as a DNG at `path`.
pub fn write_dng(path: &Path, mosaic: &BayerMosaic, meta: &DngMetadata, layout: DngLayout) -> Result<(), RawError> {
    std::fs::write(path, dng_bytes(mosaic, meta, layout)).map_err(|cause| RawError::Write {
        path: path.to_path_buf(),
        cause,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::bayer::CfaPattern;
    use crate::hdr::tiff_structure::{self, PHOTOMETRIC_CFA, TAG_DNG_VERSION, TAG_PHOTOMETRIC};

    fn meta() -> DngMetadata {
        DngMetadata {
            make: "Campanile".into(),
            model: "Simulated".into(),
            exposure: Exposure {
                time_s: 1.0 / 64.0,
                f_number: 5.6,
                iso: 200.0,
            },
            xyz_to_camera: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            as_shot_neutral: [0.5, 1.0, 0.7],
            calibration_illuminant: 21,
        }
    }

    #[test]
    fn both_layouts_have_one_cfa_ifd_of_the_mosaic_size_and_pixels_at_the_end() {
        let m = BayerMosaic {
            width: 6,
            height: 4,
            data: (0..24).collect(),
            pattern: CfaPattern::Gbrg,
            bits: 14,
            black_levels: [1, 2, 3, 4],
            white_level: 16383,
        };
        for layout in [DngLayout::SingleIfd, DngLayout::ThumbnailAndSubIfd] {
            let b = dng_bytes(&m, &meta(), layout);
            let s = tiff_structure::parse(&b).expect("parses");
            assert_eq!(s.ifd0.get(TAG_DNG_VERSION), Some(&[1u64, 4, 0, 0][..]));
            let raws: Vec<_> = s
                .all()
                .filter(|i| i.first(TAG_PHOTOMETRIC) == Some(PHOTOMETRIC_CFA))
                .collect();
            assert_eq!(raws.len(), 1, "{layout:?}");
            assert_eq!(raws[0].size(), (6, 4));
            assert_eq!(raws[0].get(33422), Some(&[1u64, 2, 0, 1][..]));
            // Last sample (23) is the file's last two bytes.
            assert_eq!(&b[b.len() - 2..], &[23, 0]);
        }
    }
}
