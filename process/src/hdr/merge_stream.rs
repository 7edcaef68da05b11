//! The merge of [`super::merge`] over a bracket on disk, one frame at a
//! time, in bounded memory.
//!
//! Each frame is decoded once ([`BracketFiles::scan`]) and added to
//! per-pixel sums `Σ_j w_j` and `Σ_j w_j X_j` (two `f32` a sample, 24 bytes
//! a pixel: 0.5 GB for 21 MP), through the same tables as the in-memory
//! merge; the sums then become the radiance and its variance in place. The
//! samples a pile-up may clip wait for the white points
//! ([`PileUpSamples`]): a sample of a frame whose pile-up is confirmed is
//! clipped (no weight; in the shortest exposure it marks the channel
//! saturated), any other is added then. Up to that summation order, the map
//! is the in-memory [`merge`](super::merge::merge) of the same files.

use rayon::prelude::*;

use super::HdrError;
use super::bracket_files::{BracketFiles, FrameVisitor, PileUpSamples};
use super::curve::ResponseCurve;
use super::lens::normalized_r2;
use super::merge::{MergeOptions, RadianceMap, Tables, build_tables, check_inputs, finish_pixel, gains};
use super::white_point::{WhitePoint, WhitePoints};
use crate::camera::image::CodeImage;

/// Merges the bracket in `files` through `curve`, one frame at a time;
/// `progress(k)` after the `k`-th frame. Returns the map and each frame's
/// white points.
pub fn merge_files(
    files: &BracketFiles,
    curve: &ResponseCurve,
    opts: &MergeOptions,
    progress: &dyn Fn(usize),
) -> Result<(RadianceMap, WhitePoints), HdrError> {
    let mut sums = Sums {
        curve,
        opts,
        times_s: files.times_s(),
        state: None,
        held: PileUpSamples::default(),
        map: None,
    };
    let white = files.scan(&mut sums, progress)?;
    let map = sums.map.ok_or(HdrError::NoImages)?;
    Ok((map, white))
}

struct State {
    tables: Tables,
    width: usize,
    height: usize,
    max: u16,
    /// `Σ w` per sample, then the variance.
    sw: Vec<f32>,
    /// `Σ w·X` per sample, then the radiance.
    swx: Vec<f32>,
    /// Per pixel: bit `c` set when the shortest exposure's code is the largest.
    saturated: Vec<u8>,
}

struct Sums<'a> {
    curve: &'a ResponseCurve,
    opts: &'a MergeOptions,
    times_s: Vec<f64>,
    state: Option<State>,
    held: PileUpSamples,
    map: Option<RadianceMap>,
}

impl FrameVisitor for Sums<'_> {
    fn frame(&mut self, j: usize, image: &CodeImage, pile_up: [Option<u16>; 3]) -> Result<(), HdrError> {
        if self.state.is_none() {
            check_inputs(image.bits, self.curve, self.opts)?;
            let n = image.width * image.height;
            self.state = Some(State {
                tables: build_tables(image.bits, &self.times_s, self.curve, &self.opts.noise),
                width: image.width,
                height: image.height,
                max: image.max_code(),
                sw: vec![0.0; n * 3],
                swx: vec![0.0; n * 3],
                saturated: vec![0; n],
            });
        }
        let Some(s) = self.state.as_mut() else {
            return Ok(());
        };
        let (codes, max) = (s.tables.codes, s.max);
        let luts: [&[[f32; 2]]; 3] =
            std::array::from_fn(|c| &s.tables.lut[(j * 3 + c) * codes..(j * 3 + c + 1) * codes]);
        let w = s.width;
        let pass = |((sw, swx), sat): ((&mut [f32], &mut [f32]), &mut [u8]), row: &[u16]| {
            for (((z, sw), swx), sat) in row
                .chunks_exact(3)
                .zip(sw.chunks_exact_mut(3))
                .zip(swx.chunks_exact_mut(3))
                .zip(sat.iter_mut())
            {
                let mut saturated = 0u8;
                for c in 0..3 {
                    let waits = PileUpSamples::waits(pile_up[c], z[c], max);
                    let [wj, wxj] = if waits {
                        [0.0, 0.0]
                    } else {
                        luts[c][usize::from(z[c]).min(codes - 1)]
                    };
                    if j == 0 {
                        // The sums' first write: fresh (untouched) pages are
                        // written before they are ever read, so each costs one
                        // page fault and no copy-on-write of the zero page.
                        saturated |= u8::from(z[c] >= max) << c;
                        sw[c] = wj;
                        swx[c] = wxj;
                    } else if !waits {
                        sw[c] += wj;
                        swx[c] += wxj;
                    }
                }
                if j == 0 {
                    *sat = saturated;
                }
            }
        };
        s.sw.par_chunks_mut(w * 3)
            .zip(s.swx.par_chunks_mut(w * 3))
            .zip(s.saturated.par_chunks_mut(w))
            .zip(image.data.par_chunks(w * 3))
            .for_each(|(sums, row)| pass(sums, row));
        self.held.hold(j, image, pile_up);
        Ok(())
    }

    fn finish(&mut self, white_points: &[[Option<WhitePoint>; 3]]) -> Result<(), HdrError> {
        let Some(mut s) = self.state.take() else {
            return Ok(());
        };
        let codes = s.tables.codes;
        for (j, wp) in white_points.iter().enumerate() {
            for (c, w) in wp.iter().enumerate() {
                let held = self.held.of(j, c);
                if w.is_some() {
                    if j == 0 {
                        for &(p, _) in held {
                            s.saturated[p as usize] |= 1 << c;
                        }
                    }
                    continue;
                }
                let lut = &s.tables.lut[(j * 3 + c) * codes..(j * 3 + c + 1) * codes];
                for &(p, z) in held {
                    let [wj, wxj] = lut[usize::from(z).min(codes - 1)];
                    s.sw[p as usize * 3 + c] += wj;
                    s.swx[p as usize * 3 + c] += wxj;
                }
            }
        }
        self.held = PileUpSamples::default();
        let (w, h) = (s.width, s.height);
        let g = gains(&s.tables, self.opts);
        let falloff = self.opts.falloff;
        let t = &s.tables;
        let mut mask = vec![0u8; w * h];
        s.sw.par_chunks_mut(w * 3)
            .zip(s.swx.par_chunks_mut(w * 3))
            .zip(s.saturated.par_chunks(w))
            .zip(mask.par_chunks_mut(w))
            .enumerate()
            .for_each(|(y, (((sw, swx), sat), mask))| {
                for (x, m) in mask.iter_mut().enumerate() {
                    let k = x * 3;
                    let sums = ([sw[k], sw[k + 1], sw[k + 2]], [swx[k], swx[k + 1], swx[k + 2]]);
                    let f = falloff.map_or(1.0, |f| f.at_r2(normalized_r2(x, y, w, h)).max(1e-6) as f32);
                    *m = finish_pixel(
                        t,
                        sums,
                        std::array::from_fn(|c| sat[x] & (1 << c) != 0),
                        g,
                        f,
                        &mut swx[k..k + 3],
                        &mut sw[k..k + 3],
                    );
                }
            });
        self.map = Some(RadianceMap {
            width: w,
            height: h,
            rgb: s.swx,
            variance: s.sw,
            mask,
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::sensor::CameraModel;
    use crate::hdr::bracket::Bracket;
    use crate::hdr::bracket_files::fixture;
    use crate::hdr::merge::tests::true_curve;
    use crate::hdr::merge::{MASK_SATURATED, merge};
    use crate::hdr::white_point::WhitePointScan;

    #[test]
    fn the_streamed_merge_is_the_in_memory_merge() {
        let dir = tempfile::tempdir().unwrap();
        let (paths, times, images) = fixture::written(dir.path());
        // Both pile-ups are seen; the moon's is confirmed, the patch's is not.
        let mut scan = WhitePointScan::new(images.len(), 8);
        let piles: Vec<_> = images.iter().map(|im| scan.push(im)).collect();
        let white = scan.finish();
        assert!(
            piles[0][0].is_some() && white[0][0].is_none(),
            "{:?} {:?}",
            piles[0],
            white[0]
        );
        assert!(white.iter().all(|w| w[1].is_some_and(|p| p.code == 254)), "{white:?}");

        let curve = true_curve(&CameraModel::typical(8));
        let opts = MergeOptions::default();
        let bracket = Bracket::new(images, times.iter().rev().copied().collect()).unwrap();
        let whole = merge(&bracket, &curve, &opts).unwrap();
        let files = BracketFiles::open(&paths, Some(&times)).unwrap();
        let frames = std::cell::Cell::new(0);
        let (streamed, streamed_white) = merge_files(&files, &curve, &opts, &|k| frames.set(k)).unwrap();
        assert_eq!(frames.get(), 7);
        assert_eq!(streamed_white, white);
        assert_eq!(streamed.mask, whole.mask);
        assert!(streamed.mask.iter().any(|&m| m & (MASK_SATURATED << 1) != 0));
        for (name, a, b) in [
            ("radiance", &streamed.rgb, &whole.rgb),
            ("variance", &streamed.variance, &whole.variance),
        ] {
            let worst = a
                .iter()
                .zip(b)
                .map(|(x, y)| if x == y { 0.0 } else { ((x - y) / y).abs() })
                .fold(0.0f32, f32::max);
            assert!(worst <= 1e-6, "{name}: largest relative difference {worst}");
        }
    }
}
