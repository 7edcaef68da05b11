//! GenICam buffers as the [`Frame`](crate::device::Frame)'s RGB codes, and
//! GenICam exposure and gain features as the [`Camera`](crate::device::Camera)
//! trait's units: the pure half of the Aravis driver (`aravis_camera`),
//! tested in every build without the library.
//!
//! **Pixel formats** (GenICam PFNC names and codes; see
//! [`campanile_config::camera::GENICAM_PIXEL_FORMATS`]):
//!
//! | format | bytes per pixel | codes |
//! | --- | --- | --- |
//! | `Mono8` | 1 | copied to r = g = b, 8 bits |
//! | `Mono10`, `Mono12`, `Mono16` | 2, little-endian | copied to r = g = b, 10, 12 or 16 bits |
//! | `Bayer{RG,GR,GB,BG}8` | 1 | demosaiced, 8 bits |
//! | `Bayer{RG,GR,GB,BG}{10,12,16}` | 2, little-endian | demosaiced, 10, 12 or 16 bits |
//! | `RGB8` (also named `RGB8Packed`) | 3 | r, g, b, 8 bits |
//!
//! GenICam's unpacked 10- and 12-bit formats hold the value in the LOW
//! bits of each 16-bit container (unlike V4L2's `Y16 `, whose significant
//! bits sit high): a sample beyond its depth is refused, not wrapped. The
//! packed formats (`Mono12Packed`, `Mono12p`, …) and YUV are not read.
//!
//! **Demosaicing** ([`demosaic_bilinear`]) is the bilinear rule of
//! `campanile_process::hdr::raw_file` (each missing colour is the mean of
//! the same-colour photosites in the 3×3 neighbourhood, the own colour is
//! the photosite itself) on integer codes, rounded to the nearest code, so
//! the frame keeps the sensor's depth; the 2×2 pattern is
//! [`CfaPattern`] of the Bayer sensor model.
//!
//! **Exposure** ([`ExposureScale`]): GenICam's `ExposureTime` (or the older
//! `ExposureTimeAbs`) is a float in µs with bounds and, sometimes, an
//! increment; a request outside the bounds by more than half a step is
//! [`DeviceError::OutOfRange`].
//!
//! **Gain** ([`GainScale`]): a `Gain` feature whose unit is `dB` is used as
//! it is (its own bounds, no mapping). A gain without a dB unit (`GainRaw`
//! integers, or a unitless `Gain`) has no physical scale: its range is
//! spread linearly over the station's configured dB range, as the V4L2
//! drivers do ([`super::exposure_control::GainMap`]); a camera whose raw
//! gain is not linear in dB needs that range calibrated. A camera with no
//! gain feature keeps its own gain, stated as the configured minimum.

use crate::device::{DeviceError, ExposureRange, ExposureTime, Gain, GainRange};
use campanile_process::camera::bayer::CfaPattern;
use thiserror::Error;

/// A GenICam pixel format the Aravis driver reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GenicamFormat {
    /// Unpacked monochrome of 8, 10, 12 or 16 bits.
    Mono {
        /// Significant bits.
        bits: u8,
    },
    /// An unpacked Bayer mosaic of 8, 10, 12 or 16 bits.
    Bayer {
        /// The 2×2 pattern, from the top-left photosite.
        pattern: CfaPattern,
        /// Significant bits.
        bits: u8,
    },
    /// Packed 8-bit RGB.
    Rgb8,
}

const DEPTHS: [u8; 4] = [8, 10, 12, 16];

fn pattern_letters(p: CfaPattern) -> &'static str {
    match p {
        CfaPattern::Rggb => "RG",
        CfaPattern::Grbg => "GR",
        CfaPattern::Gbrg => "GB",
        CfaPattern::Bggr => "BG",
    }
}

impl GenicamFormat {
    /// The format of a GenICam pixel format name (`RGB8Packed`, the
    /// pre-PFNC name, is `RGB8`), if the driver reads it.
    pub fn from_name(name: &str) -> Option<Self> {
        if name == "RGB8" || name == "RGB8Packed" {
            return Some(Self::Rgb8);
        }
        let depth = |s: &str| s.parse::<u8>().ok().filter(|b| DEPTHS.contains(b));
        if let Some(bits) = name.strip_prefix("Mono").and_then(depth) {
            return Some(Self::Mono { bits });
        }
        let rest = name.strip_prefix("Bayer")?;
        let pattern = CfaPattern::ALL
            .into_iter()
            .find(|p| rest.starts_with(pattern_letters(*p)))?;
        let bits = depth(&rest[2..])?;
        Some(Self::Bayer { pattern, bits })
    }

    /// Its GenICam (PFNC) name.
    pub fn name(self) -> String {
        match self {
            Self::Mono { bits } => format!("Mono{bits}"),
            Self::Bayer { pattern, bits } => format!("Bayer{}{bits}", pattern_letters(pattern)),
            Self::Rgb8 => "RGB8".to_owned(),
        }
    }

    /// Its PFNC code, as a buffer reports it (`ArvPixelFormat`): bits
    /// 16–23 hold the bits per pixel of the container.
    pub fn pfnc(self) -> u32 {
        let bayer = |pattern: CfaPattern, base: [u32; 4]| -> u32 {
            // PFNC numbers each depth's patterns in the order GR, RG, GB, BG.
            base[match pattern {
                CfaPattern::Grbg => 0,
                CfaPattern::Rggb => 1,
                CfaPattern::Gbrg => 2,
                CfaPattern::Bggr => 3,
            }]
        };
        match self {
            Self::Mono { bits: 8 } => 0x0108_0001,
            Self::Mono { bits: 10 } => 0x0110_0003,
            Self::Mono { bits: 12 } => 0x0110_0005,
            Self::Mono { .. } => 0x0110_0007,
            Self::Bayer { pattern, bits: 8 } => bayer(pattern, [0x0108_0008, 0x0108_0009, 0x0108_000A, 0x0108_000B]),
            Self::Bayer { pattern, bits: 10 } => bayer(pattern, [0x0110_000C, 0x0110_000D, 0x0110_000E, 0x0110_000F]),
            Self::Bayer { pattern, bits: 12 } => bayer(pattern, [0x0110_0010, 0x0110_0011, 0x0110_0012, 0x0110_0013]),
            Self::Bayer { pattern, .. } => bayer(pattern, [0x0110_002E, 0x0110_002F, 0x0110_0030, 0x0110_0031]),
            Self::Rgb8 => 0x0218_0014,
        }
    }

    /// Significant bits of the codes it gives.
    pub fn bits(self) -> u8 {
        match self {
            Self::Mono { bits } | Self::Bayer { bits, .. } => bits,
            Self::Rgb8 => 8,
        }
    }

    /// Bytes per pixel in the buffer.
    pub fn bytes_per_pixel(self) -> usize {
        match self {
            Self::Rgb8 => 3,
            f if f.bits() > 8 => 2,
            _ => 1,
        }
    }

    /// Preference when a camera offers several (lower first): deeper
    /// first; at one depth the raw mosaic, then RGB (converted in the
    /// camera, but colour), then monochrome.
    pub fn preference(self) -> u8 {
        let kind = match self {
            Self::Bayer { .. } => 0,
            Self::Rgb8 => 1,
            Self::Mono { .. } => 2,
        };
        (16 - self.bits()) * 4 + kind
    }
}

/// The name among `offered` (a camera's `PixelFormat` entries) to capture
/// in: `wanted` if given (matched by format, so `RGB8` finds a camera's
/// `RGB8Packed`), else the preferred readable one. `Err` says why none fits.
pub fn choose<'a>(offered: &[&'a str], wanted: Option<&str>) -> Result<(&'a str, GenicamFormat), String> {
    let readable: Vec<(&str, GenicamFormat)> = offered
        .iter()
        .filter_map(|n| GenicamFormat::from_name(n).map(|f| (*n, f)))
        .collect();
    match wanted {
        Some(w) => {
            let Some(format) = GenicamFormat::from_name(w) else {
                return Err(format!(
                    "pixel format {w:?} is not one campanile reads ({})",
                    campanile_config::camera::GENICAM_PIXEL_FORMATS.join(", ")
                ));
            };
            readable.into_iter().find(|(_, f)| *f == format).ok_or_else(|| {
                format!(
                    "pixel format {w:?} is not offered by the camera (it offers {})",
                    offered.join(", ")
                )
            })
        }
        None => readable.into_iter().min_by_key(|(_, f)| f.preference()).ok_or_else(|| {
            format!(
                "offers only {}; campanile reads unpacked Mono 8/10/12/16, Bayer 8/10/12/16 and RGB8",
                offered.join(", ")
            )
        }),
    }
}

/// A buffer that does not match its stated layout.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum GenicamError {
    /// Too few bytes for the image.
    #[error(
        "a {format} frame of {width}×{height} with {stride} bytes per row needs {needed} bytes; the buffer has {got}"
    )]
    ShortBuffer {
        /// The format's name.
        format: String,
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
    /// Rows shorter than their pixels.
    #[error("a {format} frame {width} pixels wide cannot have {stride} bytes per row")]
    BadStride {
        /// The format's name.
        format: String,
        /// Width, pixels.
        width: usize,
        /// Bytes per row.
        stride: usize,
    },
    /// A sample above the format's depth (an MSB-aligned or packed buffer
    /// sent as an unpacked format).
    #[error(
        "sample {value} at ({x}, {y}) exceeds the {bits} bits of {format} (GenICam's unpacked formats are LSB-aligned)"
    )]
    SampleTooLarge {
        /// The format's name.
        format: String,
        /// Depth, bits.
        bits: u8,
        /// The sample.
        value: u16,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
    },
}

/// A buffer's layout: format, size and bytes per row (the packed row plus
/// the buffer's `x_padding`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GenicamLayout {
    /// The format.
    pub format: GenicamFormat,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Bytes per row.
    pub stride: usize,
}

impl GenicamLayout {
    /// A tightly packed layout.
    pub fn packed(format: GenicamFormat, width: usize, height: usize) -> Self {
        Self {
            format,
            width,
            height,
            stride: width * format.bytes_per_pixel(),
        }
    }

    fn check(&self, len: usize) -> Result<(), GenicamError> {
        let row = self.width * self.format.bytes_per_pixel();
        if self.stride < row {
            return Err(GenicamError::BadStride {
                format: self.format.name(),
                width: self.width,
                stride: self.stride,
            });
        }
        // The last row need only hold its pixels.
        let needed = match self.height {
            0 => 0,
            h => self.stride * (h - 1) + row,
        };
        if len < needed {
            return Err(GenicamError::ShortBuffer {
                format: self.format.name(),
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

/// The samples of a one-sample-per-pixel buffer, row-major, checked
/// against the depth.
fn samples(buf: &[u8], layout: &GenicamLayout) -> Result<Vec<u16>, GenicamError> {
    let (w, h, bits) = (layout.width, layout.height, layout.format.bits());
    let bpp = layout.format.bytes_per_pixel();
    let top = ((1u32 << bits) - 1) as u16;
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let line = &buf[y * layout.stride..y * layout.stride + w * bpp];
        if bpp == 1 {
            out.extend(line.iter().map(|&v| u16::from(v)));
        } else {
            for (x, s) in line.chunks_exact(2).enumerate() {
                let value = u16::from_le_bytes([s[0], s[1]]);
                if value > top {
                    return Err(GenicamError::SampleTooLarge {
                        format: layout.format.name(),
                        bits,
                        value,
                        x,
                        y,
                    });
                }
                out.push(value);
            }
        }
    }
    Ok(out)
}

/// Bilinear demosaic of a `width × height` mosaic of `pattern` into
/// interleaved RGB codes of the same depth (see the module's notes).
pub fn demosaic_bilinear(mosaic: &[u16], width: usize, height: usize, pattern: CfaPattern) -> Vec<u16> {
    let mut out = vec![0u16; width * height * 3];
    for y in 0..height {
        for x in 0..width {
            let own = pattern.color_at(x, y);
            let mut sum = [0u32; 3];
            let mut n = [0u32; 3];
            for yy in y.saturating_sub(1)..(y + 2).min(height) {
                for xx in x.saturating_sub(1)..(x + 2).min(width) {
                    let c = pattern.color_at(xx, yy);
                    if c == own && (xx != x || yy != y) {
                        continue;
                    }
                    sum[c] += u32::from(mosaic[yy * width + xx]);
                    n[c] += 1;
                }
            }
            for c in 0..3 {
                // Every colour has a photosite in a 3×3 block of a 2×2
                // pattern once the image is 2×2; a 1-pixel image lacks some.
                out[(y * width + x) * 3 + c] = match n[c] {
                    0 => 0,
                    k => ((sum[c] + k / 2) / k) as u16,
                };
            }
        }
    }
    out
}

/// The buffer's pixels as interleaved RGB codes (`width · height · 3`,
/// at the format's depth), after checking it against `layout`.
pub fn to_rgb_codes(buf: &[u8], layout: &GenicamLayout) -> Result<Vec<u16>, GenicamError> {
    layout.check(buf.len())?;
    let (w, h) = (layout.width, layout.height);
    match layout.format {
        GenicamFormat::Rgb8 => {
            let mut out = Vec::with_capacity(w * h * 3);
            for y in 0..h {
                let line = &buf[y * layout.stride..y * layout.stride + w * 3];
                out.extend(line.iter().map(|&v| u16::from(v)));
            }
            Ok(out)
        }
        GenicamFormat::Mono { .. } => Ok(samples(buf, layout)?.into_iter().flat_map(|v| [v, v, v]).collect()),
        GenicamFormat::Bayer { pattern, .. } => Ok(demosaic_bilinear(&samples(buf, layout)?, w, h, pattern)),
    }
}

/// A GenICam exposure feature (`ExposureTime` or `ExposureTimeAbs`) in µs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureScale {
    /// Lowest value, µs.
    pub min_us: f64,
    /// Highest value, µs.
    pub max_us: f64,
    /// The camera's increment, µs; when it states none (or one below
    /// 1 ns: Aravis answers `G_MINDOUBLE` for a float without `<Inc>`),
    /// 1 µs, the feature's unit.
    pub inc_us: f64,
}

impl ExposureScale {
    /// The scale of a feature's bounds and stated increment (`None` or
    /// ≤ 0: none stated). `None` when the bounds are not a range of
    /// positive times.
    pub fn new(min_us: f64, max_us: f64, inc_us: Option<f64>) -> Option<Self> {
        let ok = min_us.is_finite() && max_us.is_finite() && max_us >= min_us && max_us > 0.0;
        ok.then(|| Self {
            // A minimum of 0 µs is a camera's way of saying "as short as
            // it goes": 1 µs is the shortest time stated.
            min_us: min_us.max(1.0),
            max_us,
            inc_us: inc_us.filter(|i| i.is_finite() && *i >= 1e-3).unwrap_or(1.0),
        })
    }

    /// The range as the camera trait states it.
    pub fn range(&self) -> ExposureRange {
        let t = |us: f64| ExposureTime::from_seconds(us / 1e6).unwrap_or_default();
        ExposureRange {
            min: t(self.min_us),
            max: t(self.max_us),
            step: t(self.inc_us),
        }
    }

    /// The value to write for `requested`, µs (within the bounds), or
    /// [`DeviceError::OutOfRange`] (in seconds) beyond half an increment
    /// outside them.
    pub fn value(&self, requested: ExposureTime) -> Result<f64, DeviceError> {
        let us = requested.seconds() * 1e6;
        let half = self.inc_us / 2.0;
        if us < self.min_us - half || us > self.max_us + half {
            return Err(DeviceError::OutOfRange {
                what: "exposure (s)",
                requested: requested.seconds(),
                min: self.min_us / 1e6,
                max: self.max_us / 1e6,
            });
        }
        Ok(us.clamp(self.min_us, self.max_us))
    }

    /// The exposure of a value read back, µs; `None` unless positive.
    pub fn time(value_us: f64) -> Option<ExposureTime> {
        ExposureTime::from_seconds(value_us / 1e6)
    }
}

/// How a camera's gain feature maps onto dB (see the module's notes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GainScale {
    /// A feature in dB, used as it is.
    Db {
        /// Lowest, dB.
        min: f64,
        /// Highest, dB.
        max: f64,
        /// Increment, dB (0: continuous).
        inc: f64,
    },
    /// A feature without a dB unit, spread linearly over the station's
    /// configured range: `min` ↔ `min_db`, `max` ↔ `max_db`.
    Linear {
        /// Lowest raw value.
        min: f64,
        /// Highest raw value.
        max: f64,
        /// Raw increment (0: continuous).
        inc: f64,
        /// dB at `min`.
        min_db: f64,
        /// dB at `max`.
        max_db: f64,
    },
    /// No gain feature: the camera's own gain, stated as this many dB.
    Fixed {
        /// The stated gain, dB.
        db: f64,
    },
}

impl GainScale {
    /// The scale of a feature with bounds `min..=max`, increment `inc`
    /// (continuous when not finite or below a millionth of the span, as
    /// Aravis's `G_MINDOUBLE` for a float without `<Inc>`) and unit
    /// `unit`: in dB when the unit says so (any case), else spread over
    /// `min_db..=max_db`.
    pub fn of_feature(unit: &str, min: f64, max: f64, inc: f64, min_db: f64, max_db: f64) -> Self {
        let tiny = 1e-6 * (max - min).abs().max(1e-3);
        let inc = if inc.is_finite() && inc >= tiny { inc } else { 0.0 };
        if unit.trim().eq_ignore_ascii_case("db") {
            Self::Db { min, max, inc }
        } else {
            Self::Linear {
                min,
                max,
                inc,
                min_db,
                max_db,
            }
        }
    }

    fn db_range(&self) -> (f64, f64) {
        match *self {
            Self::Db { min, max, .. } => (min, max),
            Self::Linear { min_db, max_db, .. } => (min_db, max_db),
            Self::Fixed { db } => (db, db),
        }
    }

    fn db_per_unit(&self) -> f64 {
        match *self {
            Self::Db { .. } => 1.0,
            Self::Linear {
                min,
                max,
                min_db,
                max_db,
                ..
            } if max > min => (max_db - min_db) / (max - min),
            _ => 0.0,
        }
    }

    /// The range as the camera trait states it.
    pub fn range(&self) -> GainRange {
        let (lo, hi) = self.db_range();
        let inc = match *self {
            Self::Db { inc, .. } | Self::Linear { inc, .. } => inc,
            Self::Fixed { .. } => 0.0,
        };
        GainRange {
            min: Gain::from_db(lo).unwrap_or(Gain::UNITY),
            max: Gain::from_db(hi).unwrap_or(Gain::UNITY),
            step_db: inc * self.db_per_unit(),
        }
    }

    /// The feature value for `gain` (rounded to the increment, within the
    /// bounds), `None` for a camera without gain, or
    /// [`DeviceError::OutOfRange`] (in dB).
    pub fn value(&self, gain: Gain) -> Result<Option<f64>, DeviceError> {
        let (lo, hi) = self.db_range();
        let g = gain.db();
        let tol = 1e-9 * (1.0 + hi.abs());
        if !(lo - tol..=hi + tol).contains(&g) {
            return Err(DeviceError::OutOfRange {
                what: "gain (dB)",
                requested: g,
                min: lo,
                max: hi,
            });
        }
        let (min, max, inc, v) = match *self {
            Self::Fixed { .. } => return Ok(None),
            Self::Db { min, max, inc } => (min, max, inc, g),
            Self::Linear { min, max, inc, .. } => {
                let k = self.db_per_unit();
                (min, max, inc, if k > 0.0 { min + (g - lo) / k } else { min })
            }
        };
        let snapped = if inc > 0.0 {
            min + ((v - min) / inc).round() * inc
        } else {
            v
        };
        Ok(Some(snapped.clamp(min, max)))
    }

    /// The gain of a feature value read back (`None`: no feature).
    pub fn gain(&self, value: Option<f64>) -> Gain {
        let db = match (*self, value) {
            (Self::Fixed { db }, _) => db,
            (Self::Db { .. }, Some(v)) => v,
            (Self::Linear { min, min_db, .. }, Some(v)) => min_db + (v - min) * self.db_per_unit(),
            (_, None) => self.db_range().0,
        };
        Gain::from_db(db).unwrap_or(Gain::UNITY)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_codes_round_trip_for_every_listed_format() {
        for name in campanile_config::camera::GENICAM_PIXEL_FORMATS {
            let f = GenicamFormat::from_name(name).unwrap_or_else(|| panic!("{name}"));
            assert_eq!(f.name(), name);
        }
        // Codes as Aravis's arvbuffer.h and the fake camera's XML state them.
        for (name, code) in [
            ("Mono8", 17_301_505),
            ("Mono16", 17_825_799),
            ("BayerBG8", 17_301_515),
            ("BayerGB8", 17_301_514),
            ("BayerGR8", 17_301_512),
            ("BayerRG8", 17_301_513),
            ("RGB8", 35_127_316),
            ("Mono12", 0x0110_0005),
            ("BayerRG12", 0x0110_0011),
            ("BayerBG16", 0x0110_0031),
            ("BayerGR10", 0x0110_000C),
        ] {
            assert_eq!(GenicamFormat::from_name(name).unwrap().pfnc(), code, "{name}");
        }
        assert_eq!(GenicamFormat::from_name("RGB8Packed"), Some(GenicamFormat::Rgb8));
        for bad in [
            "Mono12Packed",
            "Mono12p",
            "Mono14",
            "BayerXY8",
            "YUV422_8",
            "Bayer",
            "Mono",
        ] {
            assert_eq!(GenicamFormat::from_name(bad), None, "{bad}");
        }
        let f = GenicamFormat::from_name("BayerGB12").unwrap();
        assert_eq!(
            (f.bits(), f.bytes_per_pixel()),
            (12, 2),
            "a 12-bit mosaic in 16-bit containers"
        );
    }

    #[test]
    fn the_deepest_raw_format_is_chosen_and_a_wanted_one_must_be_offered() {
        // Aravis's fake camera.
        let fake = [
            "BayerBG8", "BayerGB8", "BayerGR8", "BayerRG8", "Mono8", "RGB8", "Mono16",
        ];
        assert_eq!(choose(&fake, None).unwrap().0, "Mono16");
        // A colour camera: the 12-bit mosaic over its 8-bit ones and RGB.
        let colour = ["Mono8", "BayerRG8", "BayerRG12", "BayerRG12Packed", "RGB8Packed"];
        assert_eq!(choose(&colour, None).unwrap().0, "BayerRG12");
        assert_eq!(choose(&["Mono8", "RGB8Packed"], None).unwrap().0, "RGB8Packed");
        assert_eq!(choose(&["Mono8", "BayerGR8", "RGB8"], None).unwrap().0, "BayerGR8");
        // Asked for RGB8, a camera naming it RGB8Packed has it.
        assert_eq!(choose(&colour, Some("RGB8")).unwrap().0, "RGB8Packed");
        let e = choose(&colour, Some("BayerBG8")).unwrap_err();
        assert!(
            e.contains("not offered by the camera") && e.contains("BayerRG12Packed"),
            "{e}"
        );
        let e = choose(&colour, Some("YUV422_8")).unwrap_err();
        assert!(e.contains("not one campanile reads"), "{e}");
        let e = choose(&["Mono12Packed", "YUV422_8"], None).unwrap_err();
        assert!(e.starts_with("offers only Mono12Packed, YUV422_8"), "{e}");
    }

    #[test]
    fn mono_and_rgb_buffers_keep_their_codes() {
        let mono12 = GenicamFormat::Mono { bits: 12 };
        // 0x0ABC and 0x0001, little-endian, LSB-aligned.
        let codes = to_rgb_codes(&[0xBC, 0x0A, 0x01, 0x00], &GenicamLayout::packed(mono12, 2, 1)).unwrap();
        assert_eq!(codes, [0xABC, 0xABC, 0xABC, 1, 1, 1]);
        // Mono10: 1023 is its top code, 1024 is beyond it.
        let mono10 = GenicamLayout::packed(GenicamFormat::Mono { bits: 10 }, 1, 1);
        assert_eq!(to_rgb_codes(&[0xFF, 0x03], &mono10).unwrap(), [1023; 3]);
        assert!(matches!(
            to_rgb_codes(&[0x00, 0x04], &mono10),
            Err(GenicamError::SampleTooLarge { value: 1024, .. })
        ));
        let mono16 = GenicamFormat::Mono { bits: 16 };
        let codes = to_rgb_codes(&[0xFF, 0xFF], &GenicamLayout::packed(mono16, 1, 1)).unwrap();
        assert_eq!(codes, [65535; 3]);
        let codes = to_rgb_codes(&[7, 200], &GenicamLayout::packed(GenicamFormat::Mono { bits: 8 }, 1, 2)).unwrap();
        assert_eq!(codes, [7, 7, 7, 200, 200, 200]);
        let codes = to_rgb_codes(&[1, 2, 3, 4, 5, 6], &GenicamLayout::packed(GenicamFormat::Rgb8, 2, 1)).unwrap();
        assert_eq!(codes, [1, 2, 3, 4, 5, 6]);
        // Rows padded to 4 bytes; the last row without its padding.
        let l = GenicamLayout {
            stride: 4,
            ..GenicamLayout::packed(GenicamFormat::Mono { bits: 8 }, 2, 2)
        };
        assert_eq!(
            to_rgb_codes(&[1, 2, 99, 99, 3, 4], &l).unwrap(),
            [1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4]
        );
    }

    #[test]
    fn bad_buffers_are_refused_with_their_sizes() {
        let mono12 = GenicamFormat::Mono { bits: 12 };
        // 0xABC0: a 12-bit value left in the high bits (V4L2's way), not GenICam's.
        let e = to_rgb_codes(&[0xC0, 0xAB], &GenicamLayout::packed(mono12, 1, 1)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "sample 43968 at (0, 0) exceeds the 12 bits of Mono12 (GenICam's unpacked formats are LSB-aligned)"
        );
        let rg8 = GenicamFormat::from_name("BayerRG8").unwrap();
        let e = to_rgb_codes(&[0; 10], &GenicamLayout::packed(rg8, 4, 4)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "a BayerRG8 frame of 4×4 with 4 bytes per row needs 16 bytes; the buffer has 10"
        );
        let l = GenicamLayout {
            stride: 5,
            ..GenicamLayout::packed(GenicamFormat::Rgb8, 2, 1)
        };
        assert!(matches!(to_rgb_codes(&[0; 6], &l), Err(GenicamError::BadStride { .. })));
    }

    /// A flat colour patch, R = 1000, G = 2000, B = 3000 at 12 bits (and
    /// R = 65535, G = 0, B = 40000 at 16), in each of the four patterns,
    /// comes back exactly everywhere (including the borders, which average
    /// fewer photosites).
    #[test]
    fn a_flat_patch_demosaics_to_its_colour_in_every_pattern() {
        let (w, h) = (6, 4);
        for (pattern, bits) in CfaPattern::ALL.into_iter().flat_map(|p| [(p, 12u8), (p, 16)]) {
            let format = GenicamFormat::Bayer { pattern, bits };
            let colour = if bits == 12 {
                [1000u16, 2000, 3000]
            } else {
                [65535, 0, 40000]
            };
            let mosaic: Vec<u16> = (0..w * h).map(|i| colour[pattern.color_at(i % w, i / w)]).collect();
            let bytes: Vec<u8> = mosaic.iter().flat_map(|v| v.to_le_bytes()).collect();
            let codes = to_rgb_codes(&bytes, &GenicamLayout::packed(format, w, h)).unwrap();
            assert_eq!(codes.len(), w * h * 3);
            for px in codes.chunks_exact(3) {
                assert_eq!(px, colour, "{}", format.name());
            }
        }
    }

    /// Interpolated values are the rounded means of the neighbours: an
    /// RGGB mosaic with green photosites 10, 11, 20, 21 around the red
    /// one at (2, 2) gives green (10 + 11 + 20 + 21) / 4 = 15.5 → 16, and
    /// red photosites are kept as they are.
    #[test]
    fn interpolated_codes_are_rounded_means_and_own_codes_are_kept() {
        let (w, h) = (4, 4);
        let p = CfaPattern::Rggb;
        let mut m = vec![0u16; w * h];
        // Reds at (0,0), (2,0), (0,2), (2,2).
        for (x, y, v) in [(0, 0, 100), (2, 0, 102), (0, 2, 120), (2, 2, 122)] {
            m[y * w + x] = v;
        }
        // Greens around (2, 2): (2,1), (1,2), (3,2), (2,3).
        for (x, y, v) in [(2, 1, 10), (1, 2, 11), (3, 2, 20), (2, 3, 21)] {
            m[y * w + x] = v;
        }
        // Blues at (1,1), (3,1), (1,3), (3,3).
        for (x, y, v) in [(1, 1, 40), (3, 1, 42), (1, 3, 44), (3, 3, 47)] {
            m[y * w + x] = v;
        }
        let rgb = demosaic_bilinear(&m, w, h, p);
        let at = |x: usize, y: usize| &rgb[(y * w + x) * 3..(y * w + x) * 3 + 3];
        // Blue at (2,2): mean of 40, 42, 44, 47 = 43.25 → 43.
        assert_eq!(at(2, 2), [122, 16, 43]);
        // The blue photosite (1, 1): red from its four diagonal reds
        // (100 + 102 + 120 + 122) / 4 = 111, green from (1,0), (0,1),
        // (2,1), (1,2) = (0 + 0 + 10 + 11) / 4 = 5.25 → 5.
        assert_eq!(at(1, 1), [111, 5, 40]);
        // The corner (0, 0): green from (1,0) and (0,1), blue from (1,1).
        assert_eq!(at(0, 0), [100, 0, 40]);
    }

    #[test]
    fn exposure_requests_are_checked_against_the_bounds() {
        // Aravis's fake camera: ExposureTimeAbs 10 µs to 10 s, no increment.
        let s = ExposureScale::new(10.0, 1e7, None).unwrap();
        let r = s.range();
        assert_eq!((r.min.seconds(), r.max.seconds(), r.step.seconds()), (1e-5, 10.0, 1e-6));
        let t = |x: f64| ExposureTime::from_seconds(x).unwrap();
        assert_eq!(s.value(t(0.0125)).unwrap(), 12_500.0);
        // Within half an increment of a bound: the bound.
        assert_eq!(s.value(t(9.5e-6)).unwrap(), 10.0);
        let e = s.value(t(20.0)).unwrap_err();
        assert_eq!(e.to_string(), "exposure (s) = 20 is outside 0.00001..=10");
        assert!(matches!(s.value(t(9e-6)), Err(DeviceError::OutOfRange { .. })));
        // A stated increment of 20 µs is the step; 0 or NaN are none.
        assert_eq!(ExposureScale::new(20.0, 1e6, Some(20.0)).unwrap().inc_us, 20.0);
        assert_eq!(ExposureScale::new(0.0, 1e6, Some(f64::NAN)).unwrap().min_us, 1.0);
        assert_eq!(
            ExposureScale::new(10.0, 1e6, Some(f64::MIN_POSITIVE)).unwrap().inc_us,
            1.0
        );
        assert!(ExposureScale::new(100.0, 10.0, None).is_none());
        assert!(ExposureScale::new(0.0, f64::INFINITY, None).is_none());
        assert_eq!(ExposureScale::time(1234.0).unwrap().seconds(), 0.001234);
        assert!(ExposureScale::time(0.0).is_none());
    }

    #[test]
    fn gain_in_db_is_used_as_it_is_and_raw_gain_is_spread_over_the_configured_range() {
        // A Gain feature in dB, 0 to 24 dB by 0.1 dB; the configured
        // range plays no part.
        let db = GainScale::of_feature("dB", 0.0, 24.0, 0.1, 0.0, 6.0);
        assert!(matches!(db, GainScale::Db { .. }));
        let g = |x: f64| Gain::from_db(x).unwrap();
        let v = db.value(g(12.34)).unwrap().unwrap();
        assert!((v - 12.3).abs() < 1e-9, "{v}");
        assert_eq!(db.gain(Some(12.3)).db(), 12.3);
        assert_eq!(db.range().max.db(), 24.0);
        assert!((db.range().step_db - 0.1).abs() < 1e-12);
        assert!(matches!(db.value(g(25.0)), Err(DeviceError::OutOfRange { .. })));
        // The fake camera's GainRaw 0..=10 (no unit) over a station's 0 to
        // 20 dB: 2 dB a step, 5 dB asks for 2.5 → 3 (rounded half away
        // from zero), which reads back as 6 dB.
        let raw = GainScale::of_feature("", 0.0, 10.0, 1.0, 0.0, 20.0);
        assert!(matches!(raw, GainScale::Linear { .. }));
        assert_eq!(raw.value(g(2.0)).unwrap(), Some(1.0));
        assert_eq!(raw.value(g(5.0)).unwrap(), Some(3.0));
        assert_eq!(raw.gain(Some(3.0)).db(), 6.0);
        assert_eq!(raw.range().step_db, 2.0);
        let e = raw.value(g(21.0)).unwrap_err();
        assert_eq!(e.to_string(), "gain (dB) = 21 is outside 0..=20");
        // No gain feature: only the stated gain is accepted.
        let fixed = GainScale::Fixed { db: 0.0 };
        assert_eq!(fixed.value(Gain::UNITY).unwrap(), None);
        assert!(fixed.value(g(1.0)).is_err());
        assert_eq!(fixed.gain(None), Gain::UNITY);
        // Aravis's increment for a float without one is G_MINDOUBLE:
        // continuous, not a step that overflows.
        let cont = GainScale::of_feature("dB", 0.0, 24.0, f64::MIN_POSITIVE, 0.0, 0.0);
        assert_eq!(cont.value(g(3.3)).unwrap(), Some(3.3));
        assert_eq!(cont.range().step_db, 0.0);
        // "DB" or " dB " are dB too; "x" is not.
        assert!(matches!(
            GainScale::of_feature(" DB ", 0.0, 1.0, 0.0, 0.0, 0.0),
            GainScale::Db { .. }
        ));
        assert!(matches!(
            GainScale::of_feature("x", 0.0, 1.0, 0.0, 0.0, 0.0),
            GainScale::Linear { .. }
        ));
    }
}
