//! A statistic of resampling (downscaling, filtering) in 8-bit images,
//! kept as a measurement only: nothing is refused or graded by it.
//!
//! A resampled 8-bit image averages codes in the camera's *nonlinear* code
//! domain, which breaks the relation `Z = f(E·t)` that response recovery fits.
//!
//! **The statistic.** Sensor noise is independent from pixel to pixel. The
//! second difference `d(x) = Z(x−1) − 2 Z(x) + Z(x+1)` of white noise has a
//! lag-1 autocorrelation of exactly `−4/6 = −2/3`; smooth image content adds
//! almost nothing to `d` (it cancels linear trends), and edges are excluded
//! (|d| above 6× the median |d|; clipped codes are excluded too). Every
//! resampling filter that mixes neighbouring pixels with overlapping kernels
//! (bilinear, bicubic, Lanczos, area at non-integer factors) correlates the
//! noise and raises this autocorrelation toward 0 or above.
//!
//! **Why it is not a check.** Calibration used to refuse 8-bit brackets
//! whose middle exposure scored above −0.5. On real files
//! (`validation/hdr/README.md`, "The resampling detector on real files")
//! that refused 75 of 82 camera files: a camera's demosaicing, noise
//! reduction, sharpening and JPEG coding correlate its noise as much as a
//! later resize does (a phone's JPEGs score −0.06 to +0.12, resampled copies
//! −0.57 to +0.30), and no threshold separates the two. So calibration no
//! longer looks at it, and `--allow-resampled` is accepted and ignored.

use crate::camera::image::CodeImage;

/// The former refusal limit (mean lag-1 autocorrelation of second
/// differences); kept for the measurements, which report the rate at it.
pub const RESAMPLED_THRESHOLD: f64 = -0.5;

/// Side of the central crop that the check examines.
const CHECK_SIZE: usize = 512;

/// Fewest second-difference pairs for a verdict.
const MIN_PAIRS: usize = 500;

/// Lag-1 autocorrelation of the second differences of channel `c` of `img`,
/// along rows and along columns, with the number of pairs used; `None` when
/// there are fewer than `MIN_PAIRS` usable pairs.
pub fn second_difference_autocorrelation(img: &CodeImage, c: usize) -> Option<(f64, f64, usize)> {
    let (w, h) = (img.width, img.height);
    let maxc = i32::from(img.max_code());
    let (lo, hi) = (maxc / 25, maxc - maxc / 25);
    let z = |x: usize, y: usize| i32::from(img.data[(y * w + x) * 3 + c]);
    let mut out = [(0.0f64, 0.0f64, 0usize); 2];
    for (dir, o) in out.iter_mut().enumerate() {
        let (len, lines) = if dir == 0 { (w, h) } else { (h, w) };
        let at = |i: usize, line: usize| if dir == 0 { z(i, line) } else { z(line, i) };
        // Second differences along each line, None where clipped.
        let mut all: Vec<Vec<Option<i32>>> = Vec::with_capacity(lines);
        let mut mags = Vec::new();
        for line in 0..lines {
            let mut d = vec![None; len];
            for (i, di) in d.iter_mut().enumerate().take(len.saturating_sub(1)).skip(1) {
                let (a, b, cc) = (at(i - 1, line), at(i, line), at(i + 1, line));
                if [a, b, cc].iter().all(|v| (lo..=hi).contains(v)) {
                    let v = a - 2 * b + cc;
                    *di = Some(v);
                    mags.push(v.unsigned_abs());
                }
            }
            all.push(d);
        }
        if mags.is_empty() {
            return None;
        }
        let mid = mags.len() / 2;
        let med = *mags.select_nth_unstable(mid).1;
        let edge = f64::from(6 * med.max(1));
        for d in &all {
            for pair in d.windows(2) {
                if let [Some(a), Some(b)] = pair {
                    let (a, b) = (f64::from(*a), f64::from(*b));
                    if a.abs() <= edge && b.abs() <= edge {
                        o.0 += a * b;
                        o.1 += 0.5 * (a * a + b * b);
                        o.2 += 1;
                    }
                }
            }
        }
    }
    let n = out[0].2.min(out[1].2);
    if n < MIN_PAIRS || out[0].1 <= 0.0 || out[1].1 <= 0.0 {
        return None;
    }
    Some((out[0].0 / out[0].1, out[1].0 / out[1].1, n))
}

/// The resampling statistic of an image.
#[derive(Debug, Clone, PartialEq)]
pub struct ResamplingEvidence {
    /// The image examined.
    pub image: String,
    /// Lag-1 autocorrelation of second differences along rows.
    pub rows: f64,
    /// The same along columns.
    pub columns: f64,
    /// Their mean: −2/3 for white sensor noise, toward 0 or above when resampled.
    pub mean: f64,
    /// Pairs of second differences used (the fewer of rows and columns).
    pub pairs: usize,
}

impl ResamplingEvidence {
    /// Whether the mean exceeds [`RESAMPLED_THRESHOLD`].
    pub fn looks_resampled(&self) -> bool {
        self.mean > RESAMPLED_THRESHOLD
    }
}

/// The statistic of one image: the green channel of its central crop (at
/// most 512² pixels); `None` for images without enough noise to judge.
pub fn central_crop_statistic(img: &CodeImage) -> Option<ResamplingEvidence> {
    // A central crop of at most CHECK_SIZE² pixels is plenty of evidence.
    let (cw, ch) = (img.width.min(CHECK_SIZE), img.height.min(CHECK_SIZE));
    let (x0, y0) = ((img.width - cw) / 2, (img.height - ch) / 2);
    let mut data = Vec::with_capacity(cw * ch * 3);
    for y in y0..y0 + ch {
        data.extend_from_slice(&img.data[(y * img.width + x0) * 3..(y * img.width + x0 + cw) * 3]);
    }
    let crop = CodeImage {
        width: cw,
        height: ch,
        bits: img.bits,
        data,
        label: img.label.clone(),
    };
    let (rows, columns, pairs) = second_difference_autocorrelation(&crop, 1)?;
    Some(ResamplingEvidence {
        image: img.label.clone(),
        rows,
        columns,
        mean: 0.5 * (rows + columns),
        pairs,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
    use image::imageops::FilterType;

    fn downscale(img: &CodeImage, w: u32, h: u32, filter: FilterType) -> CodeImage {
        let buf: Vec<u8> = img.data.iter().map(|&z| z as u8).collect();
        let rgb = image::RgbImage::from_raw(img.width as u32, img.height as u32, buf).unwrap();
        let small = image::imageops::resize(&rgb, w, h, filter);
        CodeImage {
            width: w as usize,
            height: h as usize,
            bits: 8,
            data: small.into_raw().into_iter().map(u16::from).collect(),
            label: format!("{} resized", img.label),
        }
    }

    #[test]
    fn native_noise_is_white_and_resampled_is_flagged() {
        let cam = CameraModel::typical(8);
        let scene = hdr_chart(192, 128);
        let native: Vec<CodeImage> = SEVEN_STOP_TIMES_S
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, j as u64))
            .collect();
        let (rh, rv, _) = second_difference_autocorrelation(&native[3], 1).unwrap();
        assert!(
            (rh + 2.0 / 3.0).abs() < 0.12 && (rv + 2.0 / 3.0).abs() < 0.12,
            "native: {rh} {rv}"
        );
        let e = central_crop_statistic(&native[3]).unwrap();
        assert!(!e.looks_resampled(), "native: {e:?}");
        for (w, h, f) in [
            (96, 64, FilterType::Triangle),
            (128, 85, FilterType::CatmullRom),
            (120, 80, FilterType::Lanczos3),
        ] {
            let small: Vec<CodeImage> = native.iter().map(|im| downscale(im, w, h, f)).collect();
            let e = central_crop_statistic(&small[3]).unwrap();
            assert!(e.looks_resampled(), "{w}x{h} {f:?}: {e:?}");
        }
    }
}
