//! Camera buffers as the [`Frame`](crate::device::Frame)'s interleaved RGB
//! codes: raw formats kept as they are, YUV converted once.
//!
//! | format | V4L2 fourcc | codes |
//! | --- | --- | --- |
//! | [`PixelFormat::Grey`] | `GREY` | 8-bit luminance, copied to r = g = b |
//! | [`PixelFormat::Y16`] | `Y16 ` | 16-bit little-endian luminance, shifted down to `bits` |
//! | [`PixelFormat::Rgb24`] | `RGB3` | 8-bit r, g, b |
//! | [`PixelFormat::Yuyv`] | `YUYV` | 4:2:2 Y′CbCr, BT.601, to 8-bit R′G′B′ |
//!
//! YUV is not raw: the camera has already applied its tone curve, and the
//! conversion rounds. The response recovery (`process::hdr`) takes the
//! codes as they are, so what matters is that the same buffer always gives
//! the same codes; the matrix is ITU-R BT.601's, with limited range
//! (Y′ 16–235, Cb/Cr 16–240: what UVC webcams send) or full range
//! (JFIF), as the driver reports its quantization.

use thiserror::Error;

/// A buffer layout the drivers can turn into RGB codes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelFormat {
    /// 8-bit luminance (`GREY`).
    Grey,
    /// 16-bit little-endian luminance (`Y16 `), `bits` significant bits in
    /// the high end of each sample (V4L2's convention).
    Y16,
    /// Packed 8-bit RGB (`RGB3`).
    Rgb24,
    /// Packed 4:2:2 `Y0 Cb Y1 Cr` (`YUYV`).
    Yuyv,
}

impl PixelFormat {
    /// The format of a V4L2 fourcc, if supported.
    pub fn from_fourcc(fourcc: [u8; 4]) -> Option<Self> {
        match &fourcc {
            b"GREY" => Some(Self::Grey),
            b"Y16 " => Some(Self::Y16),
            b"RGB3" => Some(Self::Rgb24),
            b"YUYV" => Some(Self::Yuyv),
            _ => None,
        }
    }

    /// Its V4L2 fourcc.
    pub fn fourcc(self) -> [u8; 4] {
        *match self {
            Self::Grey => b"GREY",
            Self::Y16 => b"Y16 ",
            Self::Rgb24 => b"RGB3",
            Self::Yuyv => b"YUYV",
        }
    }

    /// Bytes per row of a `width`-pixel image, tightly packed.
    pub fn row_bytes(self, width: usize) -> usize {
        match self {
            Self::Grey => width,
            Self::Y16 | Self::Yuyv => 2 * width,
            Self::Rgb24 => 3 * width,
        }
    }

    /// Whether the buffer holds sensor values (not converted from YUV).
    pub fn is_raw(self) -> bool {
        !matches!(self, Self::Yuyv)
    }

    /// Preference when a camera offers several: raw before YUV, deeper first.
    pub fn preference(self) -> u8 {
        match self {
            Self::Y16 => 0,
            Self::Rgb24 => 1,
            Self::Grey => 2,
            Self::Yuyv => 3,
        }
    }
}

/// The preferred format among those a camera offers (by fourcc), if any
/// is supported: raw before YUV, deeper first.
pub fn choose(offered: &[[u8; 4]]) -> Option<PixelFormat> {
    offered
        .iter()
        .filter_map(|f| PixelFormat::from_fourcc(*f))
        .min_by_key(|f| f.preference())
}

/// How Y′CbCr codes span their range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum YuvRange {
    /// Y′ 16–235, Cb/Cr 16–240 (studio swing; the V4L2 default for YUV).
    #[default]
    Limited,
    /// Y′, Cb, Cr 0–255 (JFIF).
    Full,
}

/// A buffer that does not match its stated layout.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PixelError {
    /// Too few bytes for the image.
    #[error(
        "a {format:?} frame of {width}×{height} with {stride} bytes per row needs {needed} bytes; the buffer has {got}"
    )]
    ShortBuffer {
        /// The format.
        format: PixelFormat,
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Bytes per row.
        stride: usize,
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// Rows shorter than the pixels they hold, or an odd YUYV width.
    #[error("a {format:?} frame {width} pixels wide cannot have {stride} bytes per row{}", if *format == PixelFormat::Yuyv && width % 2 == 1 { " (YUYV needs an even width)" } else { "" })]
    BadStride {
        /// The format.
        format: PixelFormat,
        /// Width, pixels.
        width: usize,
        /// Bytes per row.
        stride: usize,
    },
    /// Sample depth outside 1..=16 bits (or above 8 for an 8-bit format).
    #[error("{bits} significant bits cannot be stored in a {format:?} buffer")]
    BadBits {
        /// The format.
        format: PixelFormat,
        /// Bits asked for.
        bits: u8,
    },
}

/// A buffer's layout: format, size, bytes per row (V4L2's `bytesperline`,
/// at least the packed row) and significant bits per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// The format.
    pub format: PixelFormat,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Bytes per row.
    pub stride: usize,
    /// Significant bits per sample of the codes produced (8 for 8-bit
    /// formats and YUV; the sensor's depth for `Y16`).
    pub bits: u8,
    /// YUV range (ignored by other formats).
    pub range: YuvRange,
}

impl Layout {
    /// Check the layout against a buffer of `len` bytes.
    pub fn check(&self, len: usize) -> Result<(), PixelError> {
        let f = self.format;
        if self.stride < f.row_bytes(self.width) || (f == PixelFormat::Yuyv && self.width % 2 == 1) {
            return Err(PixelError::BadStride {
                format: f,
                width: self.width,
                stride: self.stride,
            });
        }
        let max_bits = if f == PixelFormat::Y16 { 16 } else { 8 };
        if self.bits == 0 || self.bits > max_bits || (f == PixelFormat::Yuyv && self.bits != 8) {
            return Err(PixelError::BadBits {
                format: f,
                bits: self.bits,
            });
        }
        // The last row need only hold its pixels.
        let needed = match self.height {
            0 => 0,
            h => self.stride * (h - 1) + f.row_bytes(self.width),
        };
        if len < needed {
            return Err(PixelError::ShortBuffer {
                format: f,
                width: self.width,
                height: self.height,
                stride: self.stride,
                needed,
                got: len,
            });
        }
        Ok(())
    }
}

/// BT.601 Y′CbCr → 8-bit R′G′B′, rounded and clipped to 0..=255.
///
/// With Kr = 0.299 and Kb = 0.114 (ITU-R BT.601): E′Y and the colour
/// differences are normalized (limited range: (Y′−16)/219 and
/// (C−128)/224; full range: Y′/255 and (C−128)/255), then
/// R′ = E′Y + 2(1−Kr)·Pr, B′ = E′Y + 2(1−Kb)·Pb, G′ = (E′Y − Kr R′ − Kb B′)/Kg.
/// In limited range this is the familiar R′ = 1.164 (Y′−16) + 1.596 (Cr−128).
pub fn yuv_to_rgb(y: u8, cb: u8, cr: u8, range: YuvRange) -> [u16; 3] {
    const KR: f64 = 0.299;
    const KB: f64 = 0.114;
    const KG: f64 = 1.0 - KR - KB;
    let (yn, pb, pr) = match range {
        YuvRange::Limited => (
            (f64::from(y) - 16.0) / 219.0,
            (f64::from(cb) - 128.0) / 224.0,
            (f64::from(cr) - 128.0) / 224.0,
        ),
        YuvRange::Full => (
            f64::from(y) / 255.0,
            (f64::from(cb) - 128.0) / 255.0,
            (f64::from(cr) - 128.0) / 255.0,
        ),
    };
    let r = yn + 2.0 * (1.0 - KR) * pr;
    let b = yn + 2.0 * (1.0 - KB) * pb;
    let g = (yn - KR * r - KB * b) / KG;
    let code = |v: f64| (v * 255.0).round().clamp(0.0, 255.0) as u16;
    [code(r), code(g), code(b)]
}

/// The buffer's pixels as interleaved RGB codes (`width · height · 3`),
/// after checking it against `layout`.
pub fn to_rgb_codes(buf: &[u8], layout: &Layout) -> Result<Vec<u16>, PixelError> {
    layout.check(buf.len())?;
    let (w, h) = (layout.width, layout.height);
    let mut out = Vec::with_capacity(w * h * 3);
    for row in 0..h {
        let line = &buf[row * layout.stride..row * layout.stride + layout.format.row_bytes(w)];
        match layout.format {
            PixelFormat::Grey => {
                for &v in line {
                    let v = u16::from(v) >> (8 - layout.bits);
                    out.extend([v, v, v]);
                }
            }
            PixelFormat::Y16 => {
                for s in line.chunks_exact(2) {
                    let v = u16::from_le_bytes([s[0], s[1]]) >> (16 - layout.bits);
                    out.extend([v, v, v]);
                }
            }
            PixelFormat::Rgb24 => {
                out.extend(line.iter().map(|&v| u16::from(v) >> (8 - layout.bits)));
            }
            PixelFormat::Yuyv => {
                for q in line.chunks_exact(4) {
                    let (y0, cb, y1, cr) = (q[0], q[1], q[2], q[3]);
                    out.extend(yuv_to_rgb(y0, cb, cr, layout.range));
                    out.extend(yuv_to_rgb(y1, cb, cr, layout.range));
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(format: PixelFormat, width: usize, height: usize, bits: u8) -> Layout {
        Layout {
            format,
            width,
            height,
            stride: format.row_bytes(width),
            bits,
            range: YuvRange::Limited,
        }
    }

    /// Reference white, black and the BT.601 primaries: limited-range
    /// (Y′, Cb, Cr) of 100% red is (81, 90, 240), green (145, 54, 34),
    /// blue (41, 240, 110) (ITU-R BT.601 colour bars, rounded), which come
    /// back within 2 codes.
    #[test]
    fn bt601_reference_colours_come_back() {
        let l = YuvRange::Limited;
        assert_eq!(yuv_to_rgb(235, 128, 128, l), [255, 255, 255]);
        assert_eq!(yuv_to_rgb(16, 128, 128, l), [0, 0, 0]);
        assert_eq!(yuv_to_rgb(126, 128, 128, l), [128, 128, 128]);
        for (yuv, rgb) in [
            ((81, 90, 240), [255, 0, 0]),
            ((145, 54, 34), [0, 255, 0]),
            ((41, 240, 110), [0, 0, 255]),
        ] {
            let got = yuv_to_rgb(yuv.0, yuv.1, yuv.2, l);
            for c in 0..3 {
                assert!(
                    (i32::from(got[c]) - rgb[c]).abs() <= 2,
                    "{yuv:?} → {got:?}, expected {rgb:?}"
                );
            }
        }
        // Full range (JFIF): Y′ 255 is white; red is (76, 85, 255).
        assert_eq!(yuv_to_rgb(255, 128, 128, YuvRange::Full), [255, 255, 255]);
        let red = yuv_to_rgb(76, 85, 255, YuvRange::Full);
        assert!(red[0] >= 253 && red[1] <= 2 && red[2] <= 2, "{red:?}");
        // Below black and above white clip, never wrap.
        assert_eq!(yuv_to_rgb(0, 128, 128, l), [0, 0, 0]);
        // (255, 255, 255): E′Y = 1.091, Pb = Pr = 0.567, so R′ = 1.886 and
        // B′ = 2.096 clip to 255, and G′ = 0.4906 → 125.
        assert_eq!(yuv_to_rgb(255, 255, 255, l), [255, 125, 255]);
    }

    #[test]
    fn yuyv_pairs_share_their_chroma() {
        // Two pixels: white and black luminance over neutral chroma, then a
        // red pair.
        let buf = [235, 128, 16, 128, 81, 90, 81, 240];
        let codes = to_rgb_codes(&buf, &layout(PixelFormat::Yuyv, 4, 1, 8)).unwrap();
        assert_eq!(&codes[..6], &[255, 255, 255, 0, 0, 0]);
        assert_eq!(codes[6..9], codes[9..12]);
        assert!(codes[6] >= 253 && codes[7] <= 2 && codes[8] <= 2, "{codes:?}");
    }

    #[test]
    fn raw_formats_keep_their_codes() {
        // Y16 with 12 significant bits in the high end: 0xABC0 → 0xABC.
        let buf = [0xC0, 0xAB, 0x10, 0x00];
        assert_eq!(
            to_rgb_codes(&buf, &layout(PixelFormat::Y16, 2, 1, 12)).unwrap(),
            [0xABC, 0xABC, 0xABC, 0x001, 0x001, 0x001]
        );
        assert_eq!(
            to_rgb_codes(&[7, 200], &layout(PixelFormat::Grey, 1, 2, 8)).unwrap(),
            [7, 7, 7, 200, 200, 200]
        );
        assert_eq!(
            to_rgb_codes(&[1, 2, 3, 4, 5, 6], &layout(PixelFormat::Rgb24, 2, 1, 8)).unwrap(),
            [1, 2, 3, 4, 5, 6]
        );
    }

    #[test]
    fn padded_rows_skip_their_padding() {
        // Two rows of 2 grey pixels, each padded to 4 bytes; the last row
        // need not carry its padding.
        let l = Layout {
            stride: 4,
            ..layout(PixelFormat::Grey, 2, 2, 8)
        };
        assert_eq!(
            to_rgb_codes(&[1, 2, 99, 99, 3, 4], &l).unwrap(),
            [1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4]
        );
    }

    #[test]
    fn bad_buffers_are_refused_with_sizes() {
        let e = to_rgb_codes(&[0; 10], &layout(PixelFormat::Yuyv, 4, 2, 8)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a Yuyv frame of 4×2 with 8 bytes per row needs 16 bytes; the buffer has 10"
        );
        assert!(matches!(
            to_rgb_codes(&[0; 12], &layout(PixelFormat::Yuyv, 3, 2, 8)),
            Err(PixelError::BadStride { .. })
        ));
        let l = Layout {
            stride: 3,
            ..layout(PixelFormat::Rgb24, 2, 1, 8)
        };
        assert!(matches!(to_rgb_codes(&[0; 6], &l), Err(PixelError::BadStride { .. })));
        assert!(matches!(
            to_rgb_codes(&[0; 2], &layout(PixelFormat::Grey, 2, 1, 12)),
            Err(PixelError::BadBits { .. })
        ));
        assert_eq!(PixelFormat::from_fourcc(*b"YUYV"), Some(PixelFormat::Yuyv));
        assert_eq!(PixelFormat::from_fourcc(*b"MJPG"), None);
        assert_eq!(PixelFormat::Y16.fourcc(), *b"Y16 ");
        // A webcam offering MJPEG and YUYV gets YUYV; a machine-vision
        // camera offering GREY and Y16 gets Y16; MJPEG alone, nothing.
        assert_eq!(choose(&[*b"MJPG", *b"YUYV"]), Some(PixelFormat::Yuyv));
        assert_eq!(choose(&[*b"GREY", *b"Y16 ", *b"YUYV"]), Some(PixelFormat::Y16));
        assert_eq!(choose(&[*b"MJPG"]), None);
    }
}
