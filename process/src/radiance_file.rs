//! Reading an HDR radiance image in any of the formats users render or merge
//! to: OpenEXR (`R`, `G`, `B`, as `campanile hdr merge` writes it, plain or
//! with its variance), RADIANCE RGBE (`.hdr`, `.pic`) and PFM. The format is
//! chosen by the file's first bytes, not by its name.
//!
//! - **RGBE**: a `#?` header (`#?RADIANCE`, `#?RGBE`, ...) up to an empty
//!   line, `FORMAT=32-bit_rle_rgbe` (XYZE is refused), the resolution line
//!   (all eight orientations; `-Y H +X W` is the standard one, first scan
//!   line at the top), then new-style run-length encoded, flat or old-style
//!   run-length scan lines. A pixel `(r, g, b, e)` is `(m + 0.5) · 2^(e−136)`
//!   per channel (RADIANCE's `colr_color`; `e = 0` is black), divided by the
//!   product of the `EXPOSURE=` values and by `COLORCORR=` per channel, so
//!   the result is in the units the renderer computed (pfilt multiplies the
//!   pixels and records the factor there). The `VIEW=` lines are kept
//!   (later options win, as in RADIANCE) for the camera.
//! - **PFM**: `PF` (colour) or `Pf` (grey, copied to R, G, B), width and
//!   height, then the scale whose sign gives the byte order (negative: little
//!   endian) and whose magnitude is ignored (every writer we know writes 1);
//!   rows bottom to top.
//!
//! The image comes back top row first, `R, G, B` interleaved.

use std::path::{Path, PathBuf};

use crate::camera::image::RadianceImage;
use crate::exr_io::read_rgb_exr;
use crate::hdr::HdrError;

/// The formats [`read_radiance_image`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadianceFormat {
    /// OpenEXR.
    Exr,
    /// RADIANCE RGBE.
    Rgbe,
    /// Portable float map.
    Pfm,
}

/// A radiance image and what its file says about it.
#[derive(Debug, Clone)]
pub struct RadianceFile {
    /// The pixels, W·m⁻²·sr⁻¹ (or the renderer's units), top row first.
    pub image: RadianceImage,
    /// The file's format.
    pub format: RadianceFormat,
    /// RGBE: the `VIEW=` options of the header, joined in order.
    pub view: Option<String>,
    /// RGBE: the product of the header's `EXPOSURE=` values (1 without).
    pub exposure: f64,
    /// RGBE: `PIXASPECT=` (pixel height / width; 1 without).
    pub pixel_aspect: f64,
}

/// Why a radiance image could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct RadianceFileError {
    /// The file.
    pub path: PathBuf,
    /// What was wrong and what was expected.
    pub message: String,
}

const EXPECTED: &str = "expected an HDR radiance image: OpenEXR (starts with bytes 76 2f 31 01), \
                        RADIANCE RGBE (.hdr/.pic, starts with \"#?\") or PFM (starts with \"PF\" or \"Pf\")";

/// Reads the radiance image at `path` in any of the formats of the module.
pub fn read_radiance_image(path: &Path) -> Result<RadianceFile, RadianceFileError> {
    let err = |message: String| RadianceFileError {
        path: path.to_path_buf(),
        message,
    };
    let bytes = std::fs::read(path).map_err(|e| err(format!("{e} ({EXPECTED})")))?;
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let image = read_rgb_exr(path).map_err(|e| {
            // The message without the path, which `err` adds.
            let what = match e {
                HdrError::Exr { cause, .. } => cause.to_string(),
                HdrError::BadImage { what, .. } => what,
                e => e.to_string(),
            };
            err(format!("{what} (expected an OpenEXR file with R, G, B)"))
        })?;
        return Ok(RadianceFile {
            image,
            format: RadianceFormat::Exr,
            view: None,
            exposure: 1.0,
            pixel_aspect: 1.0,
        });
    }
    if bytes.starts_with(b"#?") {
        return parse_rgbe(&bytes).map_err(err);
    }
    if bytes.starts_with(b"PF") || bytes.starts_with(b"Pf") {
        return parse_pfm(&bytes).map_err(err);
    }
    let start: Vec<String> = bytes.iter().take(4).map(|b| format!("{b:02x}")).collect();
    Err(err(format!(
        "unknown format (first bytes {}): {EXPECTED}",
        if start.is_empty() {
            "none, the file is empty".to_string()
        } else {
            start.join(" ")
        }
    )))
}

/// Parses an RGBE file's bytes; the error is the message without the path.
pub fn parse_rgbe(bytes: &[u8]) -> Result<RadianceFile, String> {
    // Header: lines up to the first empty line.
    let mut pos = 0;
    let mut exposure = 1.0f64;
    let mut colorcorr = [1.0f64; 3];
    let mut pixel_aspect = 1.0f64;
    let mut views: Vec<String> = Vec::new();
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err("the header ends before its empty line: expected a RADIANCE header, \
                        an empty line, then the resolution line"
                .into());
        };
        let line = String::from_utf8_lossy(&bytes[pos..pos + len])
            .trim_end_matches('\r')
            .to_string();
        pos += len + 1;
        if line.is_empty() {
            break;
        }
        let value = |key: &str| line.strip_prefix(key).map(str::trim);
        if let Some(f) = value("FORMAT=") {
            if f != "32-bit_rle_rgbe" {
                return Err(format!(
                    "header FORMAT={f}: expected FORMAT=32-bit_rle_rgbe (XYZE pictures can be converted with `ra_xyze -r`)"
                ));
            }
        } else if let Some(e) = value("EXPOSURE=") {
            match e.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => exposure *= v,
                _ => return Err(format!("header EXPOSURE={e}: expected a positive number")),
            }
        } else if let Some(c) = value("COLORCORR=") {
            let v: Vec<f64> = c.split_whitespace().filter_map(|t| t.parse().ok()).collect();
            if v.len() != 3 || !v.iter().all(|x| x.is_finite() && *x > 0.0) {
                return Err(format!("header COLORCORR={c}: expected three positive numbers"));
            }
            for k in 0..3 {
                colorcorr[k] *= v[k];
            }
        } else if let Some(a) = value("PIXASPECT=") {
            match a.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => pixel_aspect *= v,
                _ => return Err(format!("header PIXASPECT={a}: expected a positive number")),
            }
        } else if let Some(v) = value("VIEW=") {
            views.push(v.to_string());
        }
    }
    // A header without FORMAT= is RGBE, as RADIANCE reads it.

    // Resolution line.
    let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
        return Err("no resolution line after the header: expected e.g. \"-Y 480 +X 640\"".into());
    };
    let res = String::from_utf8_lossy(&bytes[pos..pos + len]).to_string();
    pos += len + 1;
    let bad_res =
        || format!("resolution line {res:?}: expected \"-Y height +X width\" or another RADIANCE orientation");
    let t: Vec<&str> = res.split_whitespace().collect();
    if t.len() != 4 {
        return Err(bad_res());
    }
    let axis = |sign_axis: &str| -> Option<(bool, char)> {
        let mut c = sign_axis.chars();
        let sign = c.next()?;
        let axis = c.next()?;
        if c.next().is_some() || !matches!(sign, '+' | '-') || !matches!(axis, 'X' | 'Y') {
            return None;
        }
        Some((sign == '+', axis))
    };
    let ((major_plus, major), (minor_plus, _)) = match (axis(t[0]), axis(t[2])) {
        (Some(a), Some(b)) if a.1 != b.1 => (a, b),
        _ => return Err(bad_res()),
    };
    let (Ok(n_major), Ok(n_minor)) = (t[1].parse::<usize>(), t[3].parse::<usize>()) else {
        return Err(bad_res());
    };
    if n_major == 0 || n_minor == 0 || n_major.saturating_mul(n_minor) > 1 << 28 {
        return Err(format!("{}: expected a size between 1x1 and 2^28 pixels", bad_res()));
    }
    let (width, height) = if major == 'Y' {
        (n_minor, n_major)
    } else {
        (n_major, n_minor)
    };
    // Where scan line `s`, pixel `i` goes. Y increases upward in RADIANCE,
    // X to the right.
    let (y_plus, x_plus) = if major == 'Y' {
        (major_plus, minor_plus)
    } else {
        (minor_plus, major_plus)
    };
    let place = |s: usize, i: usize| -> (usize, usize) {
        let (xi, yi) = if major == 'Y' { (i, s) } else { (s, i) };
        let x = if x_plus { xi } else { width - 1 - xi };
        let y = if y_plus { height - 1 - yi } else { yi };
        (x, y)
    };

    let mut data = vec![0.0f32; width * height * 3];
    let scale: [f64; 3] = std::array::from_fn(|c| 1.0 / (exposure * colorcorr[c]));
    let mut line = vec![[0u8; 4]; n_minor];
    for s in 0..n_major {
        read_scanline(bytes, &mut pos, &mut line)
            .map_err(|what| format!("scan line {s} of {n_major} ({width}x{height} picture): {what}"))?;
        for (i, p) in line.iter().enumerate() {
            let (x, y) = place(s, i);
            let o = (y * width + x) * 3;
            if p[3] != 0 {
                let f = 2f64.powi(i32::from(p[3]) - 136);
                for c in 0..3 {
                    data[o + c] = ((f64::from(p[c]) + 0.5) * f * scale[c]) as f32;
                }
            }
        }
    }
    Ok(RadianceFile {
        image: RadianceImage { width, height, data },
        format: RadianceFormat::Rgbe,
        view: if views.is_empty() { None } else { Some(views.join(" ")) },
        exposure,
        pixel_aspect,
    })
}

/// Reads one scan line of `line.len()` pixels at `*pos`: new-style
/// run-length encoded, or flat with old-style runs.
fn read_scanline(bytes: &[u8], pos: &mut usize, line: &mut [[u8; 4]]) -> Result<(), String> {
    let n = line.len();
    let truncated = |at: usize| format!("the file ends at byte {at}: expected {n} pixels (the file is truncated)");
    let head = bytes.get(*pos..*pos + 4).ok_or_else(|| truncated(bytes.len()))?;
    if (8..0x8000).contains(&n) && head[0] == 2 && head[1] == 2 && head[2] & 0x80 == 0 {
        let len = usize::from(head[2]) << 8 | usize::from(head[3]);
        if len != n {
            return Err(format!("run-length scan line of {len} pixels: expected {n}"));
        }
        *pos += 4;
        for c in 0..4 {
            let mut i = 0;
            while i < n {
                let &count = bytes.get(*pos).ok_or_else(|| truncated(bytes.len()))?;
                *pos += 1;
                if count > 128 {
                    let run = usize::from(count - 128);
                    let &v = bytes.get(*pos).ok_or_else(|| truncated(bytes.len()))?;
                    *pos += 1;
                    if i + run > n {
                        return Err(format!(
                            "a run of {run} at pixel {i} overruns the {n}-pixel line: the data is corrupt"
                        ));
                    }
                    line[i..i + run].iter_mut().for_each(|p| p[c] = v);
                    i += run;
                } else {
                    let run = usize::from(count);
                    if run == 0 || i + run > n {
                        return Err(format!(
                            "a literal of {run} at pixel {i} of a {n}-pixel line: the data is corrupt"
                        ));
                    }
                    let src = bytes.get(*pos..*pos + run).ok_or_else(|| truncated(bytes.len()))?;
                    for (p, &v) in line[i..i + run].iter_mut().zip(src) {
                        p[c] = v;
                    }
                    *pos += run;
                    i += run;
                }
            }
        }
        return Ok(());
    }
    // Flat pixels; (1, 1, 1, k) repeats the previous pixel k << shift times.
    let mut i = 0;
    let mut shift = 0u32;
    while i < n {
        let p = bytes.get(*pos..*pos + 4).ok_or_else(|| truncated(bytes.len()))?;
        *pos += 4;
        if p[0] == 1 && p[1] == 1 && p[2] == 1 {
            if i == 0 || shift > 24 {
                return Err(format!("an old-style run at pixel {i}: the data is corrupt"));
            }
            let run = usize::from(p[3]) << shift;
            if i + run > n {
                return Err(format!(
                    "a run of {run} at pixel {i} overruns the {n}-pixel line: the data is corrupt"
                ));
            }
            let prev = line[i - 1];
            line[i..i + run].iter_mut().for_each(|q| *q = prev);
            i += run;
            shift += 8;
        } else {
            line[i] = [p[0], p[1], p[2], p[3]];
            i += 1;
            shift = 0;
        }
    }
    Ok(())
}

/// Parses a PFM file's bytes; the error is the message without the path.
pub fn parse_pfm(bytes: &[u8]) -> Result<RadianceFile, String> {
    // Three whitespace-separated tokens, then one whitespace byte.
    let mut pos = 0;
    let mut tokens = Vec::new();
    for _ in 0..4 {
        while bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
            pos += 1;
        }
        let start = pos;
        while bytes.get(pos).is_some_and(|b| !b.is_ascii_whitespace()) && pos - start < 32 {
            pos += 1;
        }
        if pos == start || !bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
            return Err("bad PFM header: expected \"PF\" or \"Pf\", width, height and scale, \
                        each followed by white space"
                .into());
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..pos]).to_string());
    }
    pos += 1;
    let channels = if tokens[0] == "PF" { 3 } else { 1 };
    let (Ok(width), Ok(height), Ok(scale)) = (
        tokens[1].parse::<usize>(),
        tokens[2].parse::<usize>(),
        tokens[3].parse::<f64>(),
    ) else {
        return Err(format!(
            "PFM header \"{} {} {}\": expected a width, a height and a non-zero scale",
            tokens[1], tokens[2], tokens[3]
        ));
    };
    if width == 0 || height == 0 || width.saturating_mul(height) > 1 << 28 || scale == 0.0 || !scale.is_finite() {
        return Err(format!(
            "PFM header \"{width} {height} {scale}\": expected a size between 1x1 and 2^28 pixels and a non-zero scale"
        ));
    }
    let need = width * height * channels * 4;
    let have = bytes.len() - pos;
    if have != need {
        return Err(format!(
            "{have} bytes of pixels: expected {need} for a {width}x{height} {} PFM ({} float{} per pixel){}",
            if channels == 3 { "colour" } else { "grey" },
            channels,
            if channels == 3 { "s" } else { "" },
            if have < need {
                " (the file is truncated or its size is wrong)"
            } else {
                ""
            }
        ));
    }
    let little = scale < 0.0;
    let mut data = vec![0.0f32; width * height * 3];
    for (k, b) in bytes[pos..].chunks_exact(4).enumerate() {
        let b = [b[0], b[1], b[2], b[3]];
        let v = if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        let (p, c) = (k / channels, k % channels);
        let (row, x) = (p / width, p % width);
        let o = ((height - 1 - row) * width + x) * 3;
        if channels == 3 {
            data[o + c] = v;
        } else {
            data[o..o + 3].fill(v);
        }
    }
    Ok(RadianceFile {
        image: RadianceImage { width, height, data },
        format: RadianceFormat::Pfm,
        view: None,
        exposure: 1.0,
        pixel_aspect: 1.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exr_io::{ExrPrecision, write_radiance_exr, write_rgb_exr};
    use crate::hdr::merge::RadianceMap;
    use crate::rgbe_file::write_rgbe;

    fn fixtures() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../validation/radiance-inputs/fixtures")
    }

    /// Rows of numbers of a fixture's text file, comments and label words skipped.
    fn numbers(name: &str) -> Vec<Vec<f64>> {
        std::fs::read_to_string(fixtures().join(name))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| {
                l.split_whitespace()
                    .filter_map(|t| t.parse().ok())
                    .collect::<Vec<f64>>()
            })
            .filter(|v| !v.is_empty())
            .collect()
    }

    fn map(width: usize, height: usize, rgb: Vec<f32>) -> RadianceMap {
        RadianceMap {
            width,
            height,
            variance: rgb.iter().map(|v| v * 0.01).collect(),
            mask: vec![0; width * height],
            rgb,
        }
    }

    #[test]
    fn rgbe_written_by_write_rgbe_reads_back_within_its_mantissa() {
        // 40 wide: run-length encoded scan lines; 5 wide: flat ones.
        for (w, h) in [(40, 3), (5, 4)] {
            let rgb: Vec<f32> = (0..w * h * 3).map(|i| 1e-3 * 1.7f32.powi(i as i32 % 30)).collect();
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("m.hdr");
            write_rgbe(&map(w, h, rgb.clone()), &path).unwrap();
            let back = read_radiance_image(&path).unwrap();
            assert_eq!(back.format, RadianceFormat::Rgbe);
            assert_eq!((back.image.width, back.image.height), (w, h));
            for p in 0..w * h {
                let peak = (0..3).map(|c| rgb[p * 3 + c]).fold(0.0f32, f32::max);
                for c in 0..3 {
                    let (got, want) = (back.image.data[p * 3 + c], rgb[p * 3 + c]);
                    assert!(
                        (got - want).abs() <= peak / 128.0,
                        "{w}x{h} pixel {p} channel {c}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn rgbe_made_by_radiance_reads_as_pvalue_reads_it_exposure_undone() {
        // pvalue -r then pfilt -e 2: flat scan lines, EXPOSURE=2.
        let f = read_radiance_image(&fixtures().join("pvalue-4x3.hdr")).unwrap();
        assert_eq!((f.image.width, f.image.height, f.exposure), (4, 3, 2.0));
        let want = numbers("pvalue-4x3.txt");
        assert_eq!(want.len(), 12);
        for (p, w) in want.iter().enumerate() {
            for (c, &want) in w.iter().enumerate() {
                let got = f64::from(f.image.data[p * 3 + c]);
                // pvalue prints 4 significant digits.
                assert!(
                    (got / want - 1.0).abs() < 1e-3,
                    "pixel {p} channel {c}: {got} vs pvalue {want}"
                );
            }
        }
    }

    #[test]
    fn rgbe_rendered_by_rpict_has_its_view_and_run_length_lines() {
        let f = read_radiance_image(&fixtures().join("sphere-48x30.hdr")).unwrap();
        assert_eq!((f.image.width, f.image.height), (48, 30));
        let view = f.view.unwrap();
        assert!(view.contains("-vh 60 -vv 39.71") && view.starts_with("-vtv"), "{view}");
        // The light sphere's radiance (100, 60, 30) reaches a pixel it
        // covers; black elsewhere.
        let peak = f.image.data.chunks_exact(3).map(|p| p[0]).fold(0.0f32, f32::max);
        assert!(peak > 50.0 && peak <= 101.0, "{peak}");
        let black = f.image.data.chunks_exact(3).filter(|p| p[0] == 0.0).count();
        assert!(black > 48 * 30 - 40, "{black}");
    }

    #[test]
    fn rgbe_orientations_and_old_style_runs() {
        let header = |res: &str| format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n{res}\n").into_bytes();
        // 2x2 with mantissas 10, 20, 30, 40 (exponent 129 -> (m + 0.5) / 128),
        // stored in file order.
        let px = |m: u8| [m, m, m, 129];
        let body: Vec<u8> = [10, 20, 30, 40].iter().flat_map(|&m| px(m)).collect();
        let value = |m: u8| ((f64::from(m) + 0.5) / 128.0) as f32;
        let top_left = |res: &str| {
            let mut b = header(res);
            b.extend(&body);
            let img = parse_rgbe(&b).unwrap().image;
            [0, 1, 2, 3].map(|p| img.data[p * 3])
        };
        let v = [10, 20, 30, 40].map(value);
        assert_eq!(top_left("-Y 2 +X 2"), [v[0], v[1], v[2], v[3]]);
        assert_eq!(top_left("+Y 2 +X 2"), [v[2], v[3], v[0], v[1]]);
        assert_eq!(top_left("-Y 2 -X 2"), [v[1], v[0], v[3], v[2]]);
        // X-major: scan lines are columns, left to right, top down.
        assert_eq!(top_left("+X 2 -Y 2"), [v[0], v[2], v[1], v[3]]);
        // Old-style run: (1, 1, 1, 3) repeats the previous pixel 3 times.
        let mut b = header("-Y 1 +X 5");
        b.extend(px(10));
        b.extend([1, 1, 1, 3]);
        b.extend(px(40));
        let img = parse_rgbe(&b).unwrap().image;
        let row: Vec<f32> = (0..5).map(|x| img.data[x * 3 + 1]).collect();
        assert_eq!(row, [v[0], v[0], v[0], v[0], v[3]]);
    }

    #[test]
    fn pfm_written_by_opencv_reads_top_row_first() {
        let f = read_radiance_image(&fixtures().join("opencv-4x3.pfm")).unwrap();
        assert_eq!((f.format, f.image.width, f.image.height), (RadianceFormat::Pfm, 4, 3));
        let want = numbers("opencv-4x3.txt");
        for (p, w) in want.iter().enumerate() {
            for (c, &want) in w.iter().enumerate() {
                assert_eq!(
                    f64::from(f.image.data[p * 3 + c]),
                    f64::from(want as f32),
                    "pixel {p} channel {c}"
                );
            }
        }
    }

    #[test]
    fn grey_big_endian_pfm_is_copied_to_rgb() {
        let mut b = b"Pf\n2 2\n1.0\n".to_vec();
        // Bottom row first: bottom 1, 2; top 3, 4.
        for v in [1.0f32, 2.0, 3.0, 4.0] {
            b.extend(v.to_be_bytes());
        }
        let img = parse_pfm(&b).unwrap().image;
        assert_eq!(img.data, [3.0, 3.0, 3.0, 4.0, 4.0, 4.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0]);
    }

    #[test]
    fn hdr_merge_outputs_read_plain_and_with_variance() {
        let rgb: Vec<f32> = (0..6 * 4 * 3).map(|i| 0.25 + i as f32).collect();
        let m = map(6, 4, rgb.clone());
        let dir = tempfile::tempdir().unwrap();
        for (name, write) in [
            ("variance.exr", 0),
            ("float.exr", 1),
            ("half.exr", 2),
            // An EXR whatever its name.
            ("named.hdr", 1),
        ] {
            let p = dir.path().join(name);
            match write {
                0 => write_radiance_exr(&m, &p).unwrap(),
                1 => write_rgb_exr(&m, &p, ExrPrecision::Float).unwrap(),
                _ => write_rgb_exr(&m, &p, ExrPrecision::Half).unwrap(),
            }
            let f = read_radiance_image(&p).unwrap();
            assert_eq!((f.format, f.image.width, f.image.height), (RadianceFormat::Exr, 6, 4));
            // Half keeps 11 bits: 0.25 + 71 = 71.25 exactly.
            assert_eq!(f.image.data, rgb, "{name}");
        }
    }

    #[test]
    fn bad_files_are_refused_naming_the_file_and_what_was_expected() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, bytes: &[u8]| {
            let p = dir.path().join(name);
            std::fs::write(&p, bytes).unwrap();
            read_radiance_image(&p).unwrap_err().to_string()
        };
        let e = write("a.hdr", b"P6\n2 2\n255\n");
        assert!(
            e.contains("a.hdr") && e.contains("first bytes 50 36 0a 32") && e.contains("RADIANCE RGBE"),
            "{e}"
        );
        let e = write("b.hdr", b"");
        assert!(e.contains("b.hdr") && e.contains("empty"), "{e}");
        // Truncated: the sphere render cut in half.
        let sphere = std::fs::read(fixtures().join("sphere-48x30.hdr")).unwrap();
        let e = write("c.hdr", &sphere[..sphere.len() / 2]);
        assert!(e.contains("c.hdr: scan line") && e.contains("truncated"), "{e}");
        let e = write("d.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\0\0\0\0");
        assert!(
            e.contains("FORMAT=32-bit_rle_xyze") && e.contains("expected FORMAT=32-bit_rle_rgbe"),
            "{e}"
        );
        let e = write("e.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 *X 1\n\0\0\0\0");
        assert!(
            e.contains("resolution line \"-Y 1 *X 1\"") && e.contains("expected"),
            "{e}"
        );
        let e = write("f.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
        assert!(e.contains("header ends"), "{e}");
        let e = write("g.pfm", b"PF\n2 2\n-1.0\n\0\0\0\0");
        assert!(
            e.contains("g.pfm: 4 bytes of pixels: expected 48 for a 2x2 colour PFM"),
            "{e}"
        );
        let e = write("h.pfm", b"PF\n2 x\n-1.0\n");
        assert!(e.contains("h.pfm") && e.contains("expected a width"), "{e}");
        let e = write("i.exr", &[0x76, 0x2f, 0x31, 0x01, 2, 0, 0]);
        assert!(
            e.contains("i.exr: ") && !e.contains("i.exr: /") && e.contains("OpenEXR"),
            "{e}"
        );
        let e = read_radiance_image(&dir.path().join("none.hdr"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("none.hdr") && e.contains("expected an HDR radiance image"),
            "{e}"
        );
    }
}
