//! FITS images as astronomical and all-sky cameras deliver them (INDI's
//! `CCD1` BLOBs, most astro capture programs): the primary HDU's header and
//! its integer image, read as camera codes.
//!
//! What is read (FITS Standard 4.0, §3–5): 80-character header cards in
//! 2880-byte blocks up to `END`; `SIMPLE = T`, `BITPIX`, `NAXIS` (2 for a
//! grey image, 3 with `NAXIS3 = 3` for R, G, B planes), `NAXISn`; the data
//! big-endian, physical value = `BZERO + BSCALE · stored` (so `BITPIX = 16`
//! with `BZERO = 32768` is the usual unsigned 16-bit image). Only integer
//! images become codes (`BITPIX` 8 or 16; floating-point images are not
//! camera codes and are refused). Rows are taken first-stored-first (INDI
//! drivers store the sensor's first read-out row first) unless `ROWORDER =
//! 'BOTTOM-UP'` says the first stored row is the bottom one.

use crate::camera::image::CodeImage;

/// One header card: its keyword and its value as written (strings
/// without their quotes, `''` read as `'`; comments dropped).
#[derive(Debug, Clone, PartialEq)]
pub struct Card {
    /// The keyword, e.g. `EXPTIME`.
    pub keyword: String,
    /// The value's text, e.g. `0.5` or `2026-11-26T23:10:00.123`.
    pub value: String,
}

/// A FITS image read as camera codes, with its header.
#[derive(Debug, Clone, PartialEq)]
pub struct FitsImage {
    /// The codes (grey images repeated into R, G and B).
    pub image: CodeImage,
    /// Every valued card of the primary header, in order.
    pub cards: Vec<Card>,
}

impl FitsImage {
    /// The value of `keyword`, if the header has it.
    pub fn value(&self, keyword: &str) -> Option<&str> {
        card_value(&self.cards, keyword)
    }

    /// The number `keyword` holds, if it holds one.
    pub fn number(&self, keyword: &str) -> Option<f64> {
        self.value(keyword).and_then(parse_number)
    }
}

/// Why a file is not a FITS image Campanile can read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{label}: {reason}")]
pub struct FitsError {
    /// The file or frame.
    pub label: String,
    /// What is wrong, with the value found and what was expected.
    pub reason: String,
}

const BLOCK: usize = 2880;
const CARD: usize = 80;

/// The value of `keyword` among `cards`.
fn card_value<'a>(cards: &'a [Card], keyword: &str) -> Option<&'a str> {
    cards.iter().find(|c| c.keyword == keyword).map(|c| c.value.as_str())
}

/// A FITS number (integers, reals, with `E` or `D` exponents).
fn parse_number(text: &str) -> Option<f64> {
    text.trim()
        .replace(['D', 'd'], "E")
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
}

/// The value of a card's value field (columns 11–80): a quoted string, or
/// the text before a `/` comment.
fn card_field(field: &str) -> String {
    let field = field.trim_start();
    if let Some(rest) = field.strip_prefix('\'') {
        let mut out = String::new();
        let mut chars = rest.chars().peekable();
        while let Some(c) = chars.next() {
            if c == '\'' {
                if chars.peek() == Some(&'\'') {
                    out.push('\'');
                    chars.next();
                } else {
                    break;
                }
            } else {
                out.push(c);
            }
        }
        return out.trim_end().to_owned();
    }
    field.split('/').next().unwrap_or_default().trim().to_owned()
}

/// The primary header's valued cards and the offset of the data after it.
pub fn read_header(bytes: &[u8], label: &str) -> Result<(Vec<Card>, usize), FitsError> {
    let bad = |reason: String| FitsError {
        label: label.to_owned(),
        reason,
    };
    if !bytes.starts_with(b"SIMPLE  =") {
        let head: Vec<String> = bytes.iter().take(9).map(|b| format!("{b:02x}")).collect();
        return Err(bad(format!(
            "{} bytes starting [{}]: expected a FITS file (it begins \"SIMPLE  =\")",
            bytes.len(),
            head.join(" ")
        )));
    }
    let mut cards = Vec::new();
    let mut at = 0;
    loop {
        let Some(card) = bytes.get(at..at + CARD) else {
            return Err(bad(format!(
                "the header has no END card in its {} bytes: the file is cut short",
                bytes.len()
            )));
        };
        at += CARD;
        let text: String = card
            .iter()
            .map(|&b| if b.is_ascii() { b as char } else { '?' })
            .collect();
        let keyword = text[..8].trim_end().to_owned();
        if keyword == "END" {
            break;
        }
        if &text[8..10] == "= " {
            cards.push(Card {
                keyword,
                value: card_field(&text[10..]),
            });
        }
    }
    let data_at = at.div_ceil(BLOCK) * BLOCK;
    if card_value(&cards, "SIMPLE") != Some("T") {
        return Err(bad(format!(
            "SIMPLE = {}: expected T (a file that conforms to the standard)",
            card_value(&cards, "SIMPLE").unwrap_or("")
        )));
    }
    Ok((cards, data_at))
}

/// Reads the FITS file `bytes` (named `label` in errors) as camera codes.
pub fn read_fits(bytes: &[u8], label: &str) -> Result<FitsImage, FitsError> {
    let bad = |reason: String| FitsError {
        label: label.to_owned(),
        reason,
    };
    let (cards, data_at) = read_header(bytes, label)?;
    let integer = |key: &str| -> Result<i64, FitsError> {
        let v = card_value(&cards, key).ok_or_else(|| bad(format!("no {key} card: expected one")))?;
        v.parse::<i64>()
            .map_err(|_| bad(format!("{key} = {v}: expected an integer")))
    };
    let bitpix = integer("BITPIX")?;
    let naxis = integer("NAXIS")?;
    let (width, height, planes) = match naxis {
        2 => (integer("NAXIS1")?, integer("NAXIS2")?, 1),
        3 => (integer("NAXIS1")?, integer("NAXIS2")?, integer("NAXIS3")?),
        n => {
            return Err(bad(format!(
                "NAXIS = {n}: expected 2 (a grey image) or 3 (R, G, B planes)"
            )));
        }
    };
    if !(1..=65_536).contains(&width) || !(1..=65_536).contains(&height) {
        return Err(bad(format!(
            "NAXIS1 × NAXIS2 = {width} × {height}: expected 1 to 65536 pixels each"
        )));
    }
    if planes != 1 && planes != 3 {
        return Err(bad(format!("NAXIS3 = {planes}: expected 3 planes (R, G, B)")));
    }
    let (bytes_per, bits) = match bitpix {
        8 => (1, 8u8),
        16 => (2, 16u8),
        -32 | -64 | 32 | 64 => {
            return Err(bad(format!(
                "BITPIX = {bitpix}: expected 8 or 16 (camera codes); a {} image is not a camera's raw frame",
                if bitpix < 0 {
                    "floating-point"
                } else {
                    "32- or 64-bit integer"
                }
            )));
        }
        other => return Err(bad(format!("BITPIX = {other}: expected 8 or 16"))),
    };
    let bzero = card_value(&cards, "BZERO").map_or(Some(0.0), parse_number);
    let bscale = card_value(&cards, "BSCALE").map_or(Some(1.0), parse_number);
    let (Some(bzero), Some(bscale)) = (bzero, bscale) else {
        return Err(bad("BZERO or BSCALE is not a number".into()));
    };
    let (w, h, p) = (width as usize, height as usize, planes as usize);
    let need = w * h * p * bytes_per;
    let data = bytes.get(data_at..data_at + need).ok_or_else(|| {
        bad(format!(
            "the image needs {need} data bytes after the {data_at}-byte header, the file has {}: it is cut short",
            bytes.len().saturating_sub(data_at)
        ))
    })?;
    let top = (1u32 << bits) - 1;
    let mut clipped = 0usize;
    let samples: Vec<u16> = (0..w * h * p)
        .map(|i| {
            let stored = match bytes_per {
                1 => f64::from(data[i]),
                _ => f64::from(i16::from_be_bytes([data[2 * i], data[2 * i + 1]])),
            };
            let physical = (bzero + bscale * stored).round();
            if physical < 0.0 || physical > f64::from(top) {
                clipped += 1;
            }
            physical.clamp(0.0, f64::from(top)) as u16
        })
        .collect();
    let bottom_up = card_value(&cards, "ROWORDER").is_some_and(|r| r.eq_ignore_ascii_case("BOTTOM-UP"));
    let mut rgb = vec![0u16; w * h * 3];
    for y in 0..h {
        let row = if bottom_up { h - 1 - y } else { y };
        for x in 0..w {
            for c in 0..3 {
                let plane = if p == 3 { c } else { 0 };
                rgb[(y * w + x) * 3 + c] = samples[plane * w * h + row * w + x];
            }
        }
    }
    if clipped > 0 {
        return Err(bad(format!(
            "{clipped} samples lie outside 0..{top} after BZERO {bzero} and BSCALE {bscale}: expected camera codes"
        )));
    }
    Ok(FitsImage {
        image: CodeImage {
            width: w,
            height: h,
            bits,
            data: rgb,
            label: label.to_owned(),
        },
        cards,
    })
}

/// `image` as a FITS file: unsigned 16-bit codes (`BITPIX = 16`, `BZERO =
/// 32768`), R, G and B planes (`NAXIS3 = 3`), the first row first, with
/// `cards` (keyword, value as FITS writes it: strings quoted) after the
/// structural ones. What an astro camera's driver writes, for simulated
/// cameras and tests.
pub fn fits_bytes(image: &CodeImage, cards: &[(&str, String)]) -> Vec<u8> {
    const BLOCK: usize = 2880;
    let (w, h) = (image.width, image.height);
    let mut header = String::new();
    // Values right-aligned to column 30 as FITS writes numbers; a longer
    // one (a string) runs on, and the card is cut at 80 characters.
    let mut card = |k: &str, v: &str| header.push_str(&format!("{:<80.80}", format!("{k:<8}= {v:>20}")));
    for (k, v) in [
        ("SIMPLE", "T".to_owned()),
        ("BITPIX", "16".to_owned()),
        ("NAXIS", "3".to_owned()),
        ("NAXIS1", w.to_string()),
        ("NAXIS2", h.to_string()),
        ("NAXIS3", "3".to_owned()),
        ("BZERO", "32768".to_owned()),
        ("BSCALE", "1".to_owned()),
    ] {
        card(k, &v);
    }
    for (k, v) in cards {
        card(k, v);
    }
    header.push_str(&format!("{:<80}", "END"));
    let mut bytes = header.into_bytes();
    bytes.resize(bytes.len().div_ceil(BLOCK) * BLOCK, b' ');
    for c in 0..3 {
        for p in 0..w * h {
            let stored = (i32::from(image.data[p * 3 + c]) - 32768) as i16;
            bytes.extend_from_slice(&stored.to_be_bytes());
        }
    }
    bytes.resize(bytes.len().div_ceil(BLOCK) * BLOCK, 0);
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FITS file with `cards` (keyword, value) and `data` after them.
    fn fits(cards: &[(&str, &str)], data: &[u8]) -> Vec<u8> {
        let mut header = String::new();
        for (k, v) in cards {
            let card = format!("{k:<8}= {v:>20}");
            header += &format!("{card:<80}");
        }
        header += &format!("{:<80}", "END");
        let mut bytes = header.into_bytes();
        bytes.resize(bytes.len().div_ceil(BLOCK) * BLOCK, b' ');
        bytes.extend_from_slice(data);
        bytes.resize(bytes.len().div_ceil(BLOCK) * BLOCK, 0);
        bytes
    }

    #[test]
    fn a_written_rgb_file_reads_back_code_for_code() {
        let image = CodeImage {
            width: 3,
            height: 2,
            bits: 12,
            data: (0..18).map(|i| (i * 241) as u16).collect(),
            label: "sim".into(),
        };
        let bytes = fits_bytes(
            &image,
            &[
                ("EXPTIME", "2.5E-01".into()),
                ("INSTRUME", "'campanile simulated camera'".into()),
            ],
        );
        assert_eq!(bytes.len() % 2880, 0);
        let back = read_fits(&bytes, "sim.fits").unwrap();
        assert_eq!(back.image.data, image.data);
        assert_eq!((back.image.width, back.image.height), (3, 2));
        assert_eq!(back.number("EXPTIME"), Some(0.25));
        assert_eq!(back.value("INSTRUME"), Some("campanile simulated camera"));
    }

    #[test]
    fn unsigned_sixteen_bit_grey_is_read_with_its_header() {
        // Stored signed values −32768, 0, 32767 with BZERO 32768: 0, 32768, 65535.
        let mut data = Vec::new();
        for v in [-32768i16, 0, 32767, 1] {
            data.extend_from_slice(&v.to_be_bytes());
        }
        let f = fits(
            &[
                ("SIMPLE", "T"),
                ("BITPIX", "16"),
                ("NAXIS", "2"),
                ("NAXIS1", "2"),
                ("NAXIS2", "2"),
                ("BZERO", "32768"),
                ("BSCALE", "1"),
                ("EXPTIME", "1.25D-1"),
                ("DATE-OBS", "'2026-11-26T23:10:00.500'"),
                ("OBJECT", "'it''s'"),
            ],
            &data,
        );
        let img = read_fits(&f, "t.fits").unwrap();
        assert_eq!((img.image.width, img.image.height, img.image.bits), (2, 2, 16));
        assert_eq!(
            img.image.data,
            vec![0, 0, 0, 32768, 32768, 32768, 65535, 65535, 65535, 32769, 32769, 32769]
        );
        assert_eq!(img.number("EXPTIME"), Some(0.125));
        assert_eq!(img.value("DATE-OBS"), Some("2026-11-26T23:10:00.500"));
        assert_eq!(img.value("OBJECT"), Some("it's"));
    }

    #[test]
    fn colour_planes_and_bottom_up_rows() {
        // 1 × 2, three 8-bit planes; BOTTOM-UP puts the second stored row first.
        let data = [10u8, 11, 20, 21, 30, 31];
        let f = fits(
            &[
                ("SIMPLE", "T"),
                ("BITPIX", "8"),
                ("NAXIS", "3"),
                ("NAXIS1", "1"),
                ("NAXIS2", "2"),
                ("NAXIS3", "3"),
                ("ROWORDER", "'BOTTOM-UP'"),
            ],
            &data,
        );
        let img = read_fits(&f, "rgb.fits").unwrap();
        assert_eq!(img.image.data, vec![11, 21, 31, 10, 20, 30]);
        assert_eq!(img.image.bits, 8);
    }

    #[test]
    fn bad_files_are_named_with_what_was_expected() {
        let e = read_fits(b"GIF89a", "x.fits").unwrap_err().to_string();
        assert!(e.starts_with("x.fits: 6 bytes") && e.contains("SIMPLE"), "{e}");
        let float = fits(
            &[
                ("SIMPLE", "T"),
                ("BITPIX", "-32"),
                ("NAXIS", "2"),
                ("NAXIS1", "1"),
                ("NAXIS2", "1"),
            ],
            &[0; 4],
        );
        let e = read_fits(&float, "f.fits").unwrap_err().to_string();
        assert!(e.contains("BITPIX = -32") && e.contains("floating-point"), "{e}");
        let mut short = fits(
            &[
                ("SIMPLE", "T"),
                ("BITPIX", "16"),
                ("NAXIS", "2"),
                ("NAXIS1", "100"),
                ("NAXIS2", "100"),
            ],
            &[],
        );
        short.truncate(BLOCK + 10);
        let e = read_fits(&short, "s.fits").unwrap_err().to_string();
        assert!(e.contains("needs 20000 data bytes") && e.contains("cut short"), "{e}");
        let no_end = b"SIMPLE  =                    T".to_vec();
        let e = read_fits(&no_end, "n.fits").unwrap_err().to_string();
        assert!(e.contains("no END card"), "{e}");
        let signed = fits(
            &[
                ("SIMPLE", "T"),
                ("BITPIX", "16"),
                ("NAXIS", "2"),
                ("NAXIS1", "1"),
                ("NAXIS2", "1"),
            ],
            &(-5i16).to_be_bytes(),
        );
        let e = read_fits(&signed, "neg.fits").unwrap_err().to_string();
        assert!(e.contains("1 samples lie outside 0..65535"), "{e}");
    }
}
