//! The effective white point of each frame and channel: the code at which a
//! camera's processed output (JPEG above all) stops rising.
//!
//! A camera that clips a channel does not always write the largest code: a
//! phone's JPEG may write 254 for a green channel clipped in every exposure.
//! Taken as valid, such codes are read through the top of the response curve
//! as a finite radiance, favoured in the long exposures, and the clipped
//! channel comes out far too dark against the others (a magenta moon).
//!
//! **Detection.** Per frame and channel, on a 256-bin histogram (16-bit codes
//! are binned by their top 8 bits), the fullest bin `z*` of the top fifth
//! below the largest code is a *pile-up* when it holds at least
//! [`MIN_PILE_UP_PIXELS`] pixels (and 1e-4 of the frame) and at least
//! [`PILE_UP_RATIO`] times the median count of the 16 bins below it (8 to 24
//! bins down, past JPEG's spread). A pile-up can also be a flat bright
//! surface, so it must be **confirmed**: clipping holds the same pixels at
//! the same code in the next longer exposure (or, for the longest frame, the
//! next shorter one, when they are clipped there too), whereas a real surface
//! moves up the codes with exposure. At least [`CONFIRM_FRACTION`] of the
//! pile-up's pixels must sit within one bin of `z*` in that neighbour. An
//! unconfirmed pile-up at a code that another frame of the bracket confirmed
//! for the same channel is accepted too (the camera's white point is a
//! property of the camera).
//!
//! **Effect.** Codes from one bin below `z*` up are treated as clipped: the
//! bracket maps them to the largest code, which the curve recovery gives no
//! weight and the merge flags as saturated.

use rayon::prelude::*;

use crate::camera::image::CodeImage;

/// Fewest pixels in a pile-up.
pub const MIN_PILE_UP_PIXELS: usize = 16;

/// How many times fuller than the bins below a pile-up must be.
pub const PILE_UP_RATIO: f64 = 8.0;

/// Fraction of a pile-up's pixels that must stay at its code in the
/// neighbouring exposure.
pub const CONFIRM_FRACTION: f64 = 0.5;

/// Per frame (shortest exposure first) and channel, the white point found, if any.
pub type WhitePoints = Vec<[Option<WhitePoint>; 3]>;

/// A detected white point below the largest code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WhitePoint {
    /// The code where the histogram piles up.
    pub code: u16,
    /// Codes from here up are treated as clipped.
    pub clipped_from: u16,
    /// Pixels whose code is at or above `clipped_from` (below the largest code).
    pub pixels: usize,
}

/// Per frame (in the order given, which must be by ascending exposure) and
/// channel, the white point when one below the largest code is detected and
/// confirmed (module doc).
pub fn detect_white_points(images: &[CodeImage]) -> WhitePoints {
    let Some(first) = images.first() else {
        return Vec::new();
    };
    let mut scan = WhitePointScan::new(images.len(), first.bits);
    for im in images {
        scan.push(im);
    }
    scan.finish()
}

/// [`detect_white_points`] one frame at a time, for brackets read from
/// files: frames are pushed by ascending exposure, and only the previous
/// frame's histogram bins (one byte per sample) are kept for the
/// confirmation. A frame's pile-up is known when it is pushed, whether it
/// is accepted only at [`WhitePointScan::finish`].
pub struct WhitePointScan {
    frames: usize,
    shift: u32,
    top: usize,
    hists: Vec<[Vec<usize>; 3]>,
    candidates: Vec<[Option<usize>; 3]>,
    confirmed: Vec<[bool; 3]>,
    /// The previous frame's bins, interleaved RGB.
    previous: Vec<u8>,
}

impl WhitePointScan {
    /// A scan of `frames` frames of `bits` bits per sample.
    pub fn new(frames: usize, bits: u8) -> Self {
        let shift = u32::from(bits.saturating_sub(8));
        let max = (1u32 << bits.clamp(1, 16)) - 1;
        Self {
            frames,
            shift,
            top: (max >> shift) as usize,
            hists: Vec::with_capacity(frames),
            candidates: Vec::with_capacity(frames),
            confirmed: Vec::with_capacity(frames),
            previous: Vec::new(),
        }
    }

    /// Takes the next frame (by ascending exposure); returns per channel the
    /// first code its pile-up would clip (`None`: no pile-up, nothing of this
    /// frame can become clipped at [`finish`](Self::finish)).
    pub fn push(&mut self, im: &CodeImage) -> [Option<u16>; 3] {
        let j = self.hists.len();
        let (shift, top) = (self.shift, self.top);
        let bin = move |z: u16| usize::from(z >> shift).min(top);
        let hist = im
            .data
            .par_chunks(3 * 4096)
            .fold(
                || -> [Vec<usize>; 3] { std::array::from_fn(|_| vec![0usize; top + 1]) },
                |mut h, chunk| {
                    for px in chunk.chunks_exact(3) {
                        for c in 0..3 {
                            h[c][bin(px[c])] += 1;
                        }
                    }
                    h
                },
            )
            .reduce(
                || std::array::from_fn(|_| vec![0usize; top + 1]),
                |mut a, b| {
                    for c in 0..3 {
                        for (x, y) in a[c].iter_mut().zip(&b[c]) {
                            *x += y;
                        }
                    }
                    a
                },
            );
        let n = im.width * im.height;
        let cand: [Option<usize>; 3] = std::array::from_fn(|c| pile_up(&hist[c], n));
        let here = |i: usize| bin(im.data[i]);
        let previous = &self.previous;
        let before = |i: usize| usize::from(previous[i]);
        if j > 0 {
            // The previous frame's pile-ups, against this (longer) exposure.
            for c in 0..3 {
                if let Some(z) = self.candidates[j - 1][c] {
                    self.confirmed[j - 1][c] = stays(n, c, z, before, here);
                }
            }
        }
        let mut confirmed = [false; 3];
        if j + 1 == self.frames && j > 0 {
            // The longest frame's pile-ups, against the next shorter one.
            for c in 0..3 {
                if let Some(z) = cand[c] {
                    confirmed[c] = stays(n, c, z, here, before);
                }
            }
        }
        if j + 1 < self.frames {
            self.previous.resize(im.data.len(), 0);
            self.previous
                .par_iter_mut()
                .zip(im.data.par_iter())
                .for_each(|(b, &z)| *b = bin(z) as u8);
        }
        self.hists.push(hist);
        self.candidates.push(cand);
        self.confirmed.push(confirmed);
        cand.map(|z| z.map(|z| ((z - 1) << self.shift) as u16))
    }

    /// The white points of the frames pushed (module doc: confirmed, or at a
    /// code another frame confirmed for the same channel).
    pub fn finish(self) -> WhitePoints {
        let m = self.hists.len();
        let mut out = vec![[None; 3]; m];
        for (j, wp) in out.iter_mut().enumerate() {
            for (c, slot) in wp.iter_mut().enumerate() {
                let Some(z) = self.candidates[j][c] else { continue };
                let accepted = self.confirmed[j][c]
                    || (0..m)
                        .any(|k| self.confirmed[k][c] && self.candidates[k][c].is_some_and(|zk| zk.abs_diff(z) <= 1));
                if !accepted {
                    continue;
                }
                let clipped_bin = z - 1;
                let pixels = self.hists[j][c][clipped_bin..self.top].iter().sum();
                *slot = Some(WhitePoint {
                    code: (z << self.shift) as u16,
                    clipped_from: (clipped_bin << self.shift) as u16,
                    pixels,
                });
            }
        }
        out
    }
}

/// Whether at least [`CONFIRM_FRACTION`] of the `n` pixels whose channel-`c`
/// bin `a` is within one of `z` stay within one of it in `b`.
fn stays(n: usize, c: usize, z: usize, a: impl Fn(usize) -> usize + Sync, b: impl Fn(usize) -> usize + Sync) -> bool {
    let near = |v: usize| v.abs_diff(z) <= 1;
    let (inside, stayed) = (0..n)
        .into_par_iter()
        .map(|p| {
            let i = p * 3 + c;
            if near(a(i)) {
                (1usize, usize::from(near(b(i))))
            } else {
                (0, 0)
            }
        })
        .reduce(|| (0, 0), |x, y| (x.0 + y.0, x.1 + y.1));
    inside > 0 && stayed as f64 >= CONFIRM_FRACTION * inside as f64
}

/// The pile-up bin of histogram `h` (bins `0..=top`, top excluded from the
/// search), if any, for a frame of `n` pixels.
fn pile_up(h: &[usize], n: usize) -> Option<usize> {
    let top = h.len() - 1;
    let lo = (top * 4).div_ceil(5).max(25);
    let (z, &count) = h[lo..top].iter().enumerate().max_by_key(|&(i, &v)| (v, i))?;
    let z = z + lo;
    let min_count = MIN_PILE_UP_PIXELS.max(n / 10_000);
    if count < min_count {
        return None;
    }
    let mut below: Vec<usize> = h[z - 24..z - 8].to_vec();
    below.sort_unstable();
    let median = below[below.len() / 2].max(1);
    (count as f64 >= PILE_UP_RATIO * median as f64).then_some(z)
}

/// Maps every code at or above each frame's `clipped_from` to the largest
/// code; returns how many samples changed per frame.
pub fn apply_white_points(images: &mut [CodeImage], points: &[[Option<WhitePoint>; 3]]) -> Vec<usize> {
    images
        .par_iter_mut()
        .zip(points)
        .map(|(im, wp)| {
            let max = im.max_code();
            let mut changed = 0;
            for px in im.data.chunks_exact_mut(3) {
                for (c, p) in wp.iter().enumerate() {
                    if let Some(p) = p
                        && px[c] >= p.clipped_from
                        && px[c] < max
                    {
                        px[c] = max;
                        changed += 1;
                    }
                }
            }
            changed
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame of `w × h` whose pixel `i` has codes `f(i)`.
    fn frame(w: usize, h: usize, f: impl Fn(usize) -> [u16; 3]) -> CodeImage {
        CodeImage {
            width: w,
            height: h,
            bits: 8,
            data: (0..w * h).flat_map(f).collect(),
            label: "t".into(),
        }
    }

    /// A ramp background (codes spread over 0–240 with exposure) and a
    /// "moon" of 400 pixels whose green is clipped at 254 in every frame
    /// while red and blue rise to 255 and clip properly.
    fn phone_bracket() -> Vec<CodeImage> {
        (0..4)
            .map(|j| {
                let gain = 1u32 << j;
                frame(100, 100, move |i| {
                    let bg = ((i as u32 % 97) * gain).min(255) as u16;
                    if i < 400 {
                        let rb = (200 * gain).min(255) as u16;
                        [rb, 254, rb]
                    } else {
                        [bg, bg, bg]
                    }
                })
            })
            .collect()
    }

    #[test]
    fn clipped_green_at_254_is_found_in_every_frame() {
        let mut imgs = phone_bracket();
        let wp = detect_white_points(&imgs);
        for (j, w) in wp.iter().enumerate() {
            let g = w[1].unwrap_or_else(|| panic!("frame {j}: no green white point"));
            assert_eq!((g.code, g.clipped_from), (254, 253), "frame {j}");
            assert!(g.pixels >= 400, "frame {j}: {}", g.pixels);
            assert!(w[0].is_none() && w[2].is_none(), "frame {j}: {w:?}");
        }
        let changed = apply_white_points(&mut imgs, &wp);
        assert!(changed.iter().all(|&n| n >= 400), "{changed:?}");
        assert_eq!(imgs[0].data[1], 255);
    }

    #[test]
    fn a_flat_bright_surface_is_not_clipping() {
        // A 400-pixel patch at code 240 in the shortest frame that rises (and
        // clips at 255) in the longer ones: a pile-up, but not confirmed.
        let imgs: Vec<CodeImage> = (0..3)
            .map(|j| {
                frame(100, 100, move |i| {
                    let v = if i < 400 {
                        (240u32 << j).min(255) as u16
                    } else {
                        ((i as u32 % 97) << j).min(255) as u16
                    };
                    [v, v, v]
                })
            })
            .collect();
        let wp = detect_white_points(&imgs);
        assert!(wp.iter().all(|w| w.iter().all(Option::is_none)), "{wp:?}");
    }
}
