//! An exposure bracket: images of one static scene at different exposure
//! times, validated and sorted from the shortest to the longest exposure.

use super::HdrError;
use super::white_point::{WhitePoint, apply_white_points, detect_white_points};
use crate::camera::image::CodeImage;

/// A validated bracket: at least one image, all the same size and bit depth,
/// codes within range, distinct finite positive times, sorted by time, and
/// brightness that rises with time. Codes at or above a frame's effective
/// white point ([`super::white_point`]) are mapped to the largest code, so
/// that every consumer treats them as clipped.
#[derive(Debug, Clone)]
pub struct Bracket {
    images: Vec<CodeImage>,
    times_s: Vec<f64>,
    white_points: Vec<[Option<WhitePoint>; 3]>,
}

impl Bracket {
    /// Validates and sorts `images` with their exposure times `times_s` (seconds).
    ///
    /// Unsorted times are accepted (the pairs are sorted), duplicates are an
    /// error, and so is a bracket whose brightness falls as time rises (times
    /// listed in the wrong order).
    pub fn new(images: Vec<CodeImage>, times_s: Vec<f64>) -> Result<Self, HdrError> {
        if images.is_empty() {
            return Err(HdrError::NoImages);
        }
        if images.len() != times_s.len() {
            return Err(HdrError::TimeCountMismatch {
                images: images.len(),
                times: times_s.len(),
            });
        }
        let first = &images[0];
        for (img, &t) in images.iter().zip(&times_s) {
            if !(t.is_finite() && t > 0.0) {
                return Err(HdrError::InvalidTime {
                    image: img.label.clone(),
                    time_s: t,
                });
            }
            check_image(img, first)?;
        }
        let mut order: Vec<usize> = (0..images.len()).collect();
        order.sort_by(|&a, &b| times_s[a].total_cmp(&times_s[b]));
        for w in order.windows(2) {
            if times_s[w[0]] == times_s[w[1]] {
                return Err(HdrError::DuplicateTime {
                    first: images[w[0]].label.clone(),
                    second: images[w[1]].label.clone(),
                    time_s: times_s[w[0]],
                });
            }
        }
        // Brightness must not fall as time rises (tolerance: 0.5 % of full scale,
        // which absorbs noise in fully saturated or fully black frames).
        let means: Vec<f64> = images
            .iter()
            .map(|im| im.data.iter().map(|&z| f64::from(z)).sum::<f64>() / im.data.len() as f64)
            .collect();
        let tol = 0.005 * f64::from(first.max_code());
        for w in order.windows(2) {
            if means[w[0]] > means[w[1]] + tol {
                return Err(HdrError::TimesContradictBrightness {
                    brighter: images[w[0]].label.clone(),
                    brighter_time_s: times_s[w[0]],
                    darker: images[w[1]].label.clone(),
                    darker_time_s: times_s[w[1]],
                });
            }
        }
        let mut slots: Vec<Option<CodeImage>> = images.into_iter().map(Some).collect();
        let mut images: Vec<CodeImage> = order
            .iter()
            .map(|&i| slots[i].take().expect("each index once"))
            .collect();
        let times_s = order.iter().map(|&i| times_s[i]).collect();
        let white_points = detect_white_points(&images);
        apply_white_points(&mut images, &white_points);
        Ok(Self {
            images,
            times_s,
            white_points,
        })
    }

    /// Per image (shortest exposure first) and channel, the white point found
    /// below the largest code, if any; its codes were mapped to the largest.
    pub fn white_points(&self) -> &[[Option<WhitePoint>; 3]] {
        &self.white_points
    }

    /// The same exposure times with `images` in place of the images (for
    /// resampled versions of them, e.g. aligned ones): one image per
    /// exposure, of the same size and bit depth, codes within range. The
    /// brightness order is not checked again (a resampled image may have
    /// uncovered, black borders).
    pub fn with_images(&self, images: Vec<CodeImage>) -> Result<Self, HdrError> {
        if images.len() != self.images.len() {
            return Err(HdrError::TimeCountMismatch {
                images: images.len(),
                times: self.times_s.len(),
            });
        }
        let first = &self.images[0];
        for img in &images {
            check_image(img, first)?;
        }
        Ok(Self {
            images,
            times_s: self.times_s.clone(),
            white_points: self.white_points.clone(),
        })
    }

    /// The images, shortest exposure first.
    pub fn images(&self) -> &[CodeImage] {
        &self.images
    }

    /// The exposure times in seconds, ascending.
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Bits per sample.
    pub fn bits(&self) -> u8 {
        self.images[0].bits
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.images[0].width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.images[0].height
    }

    /// Number of exposures.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// Always false: a bracket holds at least one image.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

/// One image of a bracket whose first image is `first`: its shape
/// ([`check_shape`]) and every code within its depth.
pub(super) fn check_image(img: &CodeImage, first: &CodeImage) -> Result<(), HdrError> {
    check_shape(img, first)?;
    check_codes(img)
}

/// 8 to 16 bits, not empty, a buffer of `width · height · 3` codes, the
/// size and depth of `first` (whose codes are not read).
pub(super) fn check_shape(img: &CodeImage, first: &CodeImage) -> Result<(), HdrError> {
    if !matches!(img.bits, 8..=16) {
        return Err(HdrError::BadImage {
            image: img.label.clone(),
            what: format!("{} bits per sample: expected 8 to 16", img.bits),
        });
    }
    if img.width == 0 || img.height == 0 {
        return Err(HdrError::BadImage {
            image: img.label.clone(),
            what: "image is empty (0 pixels)".into(),
        });
    }
    let expected = img.width * img.height * 3;
    if img.data.len() != expected {
        return Err(HdrError::BufferLength {
            image: img.label.clone(),
            len: img.data.len(),
            width: img.width,
            height: img.height,
            expected,
        });
    }
    if (img.width, img.height) != (first.width, first.height) {
        return Err(HdrError::SizeMismatch {
            image: img.label.clone(),
            width: img.width,
            height: img.height,
            first: first.label.clone(),
            first_width: first.width,
            first_height: first.height,
        });
    }
    if img.bits != first.bits {
        return Err(HdrError::BitDepthMismatch {
            image: img.label.clone(),
            bits: img.bits,
            first: first.label.clone(),
            first_bits: first.bits,
        });
    }
    check_codes(img)
}

/// Every code of `img` within its depth (the first one beyond named).
pub(super) fn check_codes(img: &CodeImage) -> Result<(), HdrError> {
    let max = img.max_code();
    if let Some(i) = img.data.iter().position(|&z| z > max) {
        let p = i / 3;
        return Err(HdrError::CodeOutOfRange {
            image: img.label.clone(),
            x: p % img.width,
            y: p / img.width,
            channel: i % 3,
            code: img.data[i],
            bits: img.bits,
            max,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(label: &str, w: usize, h: usize, v: u16) -> CodeImage {
        CodeImage {
            width: w,
            height: h,
            bits: 8,
            data: vec![v; w * h * 3],
            label: label.into(),
        }
    }

    #[test]
    fn sorts_unsorted_times_with_their_images() {
        let b = Bracket::new(vec![img("b", 4, 4, 200), img("a", 4, 4, 20)], vec![1.0, 0.1]).unwrap();
        assert_eq!(b.times_s(), &[0.1, 1.0]);
        assert_eq!(b.images()[0].label, "a");
    }

    #[test]
    fn rejects_duplicates_naming_both_files() {
        let e = Bracket::new(vec![img("a", 4, 4, 20), img("b", 4, 4, 30)], vec![0.5, 0.5]).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("'a'") && msg.contains("'b'") && msg.contains("0.5"),
            "{msg}"
        );
    }

    #[test]
    fn rejects_times_in_wrong_order() {
        let e = Bracket::new(vec![img("long", 4, 4, 20), img("short", 4, 4, 200)], vec![1.0, 0.1]).unwrap_err();
        assert!(matches!(e, HdrError::TimesContradictBrightness { .. }), "{e}");
    }

    #[test]
    fn rejects_size_mismatch_and_bad_times() {
        let e = Bracket::new(vec![img("a", 4, 4, 20), img("b", 5, 4, 30)], vec![0.1, 0.2]).unwrap_err();
        assert!(e.to_string().contains("'b' is 5×4"), "{e}");
        let e = Bracket::new(vec![img("a", 4, 4, 20)], vec![f64::NAN]).unwrap_err();
        assert!(matches!(e, HdrError::InvalidTime { .. }));
        let e = Bracket::new(vec![img("a", 4, 4, 20)], vec![0.1, 0.2]).unwrap_err();
        assert!(matches!(e, HdrError::TimeCountMismatch { .. }));
        assert!(matches!(Bracket::new(vec![], vec![]).unwrap_err(), HdrError::NoImages));
    }

    #[test]
    fn rejects_code_above_bit_depth() {
        let mut a = img("a", 4, 4, 20);
        a.data[5] = 300;
        let e = Bracket::new(vec![a], vec![0.1]).unwrap_err();
        assert!(e.to_string().contains("pixel (1, 0) channel 2 has code 300"), "{e}");
    }
}
