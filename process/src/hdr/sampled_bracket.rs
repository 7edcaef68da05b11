//! A bracket read from files for response recovery, keeping only the
//! pixels that sample selection can look at.
//!
//! Sample selection ([`super::sampling`]) draws its pixels from a seeded
//! stream before reading any code ([`draw_plan`]), so while the frames are
//! decoded one at a time ([`BracketFiles::scan`]) only those pixels and
//! their 4-neighbours are kept (about 0.4 M a channel for 4000 samples, a
//! few MB over 18 frames), with the per-pixel code sums whose range sets
//! the intensity strata (4 bytes a sample, dropped once the range is
//! known). Recovery on a [`SampledBracket`] selects the same samples and
//! solves the same system as on the whole [`Bracket`](super::bracket::Bracket).

use rayon::prelude::*;

use super::HdrError;
use super::bracket_files::{BracketFiles, FrameVisitor, PileUpSamples};
use super::exposure_codes::ExposureCodes;
use super::sampling::{SampleOptions, draw_plan};
use super::white_point::{WhitePoint, WhitePoints};
use crate::camera::image::CodeImage;

/// The sampled pixels of a bracket read from files (white points applied).
#[derive(Debug, Clone)]
pub struct SampledBracket {
    width: usize,
    height: usize,
    bits: u8,
    times_s: Vec<f64>,
    options: SampleOptions,
    /// Per channel: the pixels held, ascending.
    positions: [Vec<u32>; 3],
    /// Per channel: their codes, `[i · exposures + j]`.
    codes: [Vec<u16>; 3],
    sum_range: [(u32, u32); 3],
}

impl SampledBracket {
    /// Reads `files` for the sample selection `options`; `progress(k)` after
    /// the `k`-th frame. Returns the bracket and each frame's white points.
    pub fn read(
        files: &BracketFiles,
        options: &SampleOptions,
        progress: &dyn Fn(usize),
    ) -> Result<(Self, WhitePoints), HdrError> {
        let mut reader = Reader {
            frames: files.len(),
            options: *options,
            state: None,
            held: PileUpSamples::default(),
            sum_range: [(0, 0); 3],
        };
        let white = files.scan(&mut reader, progress)?;
        let state = reader.state.ok_or(HdrError::NoImages)?;
        Ok((
            Self {
                width: state.width,
                height: state.height,
                bits: state.bits,
                times_s: files.times_s(),
                options: *options,
                positions: state.positions,
                codes: state.codes,
                sum_range: reader.sum_range,
            },
            white,
        ))
    }
}

impl ExposureCodes for SampledBracket {
    fn exposures(&self) -> usize {
        self.times_s.len()
    }

    fn bits(&self) -> u8 {
        self.bits
    }

    fn width(&self) -> usize {
        self.width
    }

    fn height(&self) -> usize {
        self.height
    }

    fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// The codes of a held pixel. Only pixels of [`draw_plan`] for the
    /// options read are held (calibration checks the options first); any
    /// other reads as black in every exposure, which no selection accepts.
    fn pixel_codes(&self, p: usize, c: usize, out: &mut Vec<u16>) {
        out.clear();
        let f = self.times_s.len();
        match u32::try_from(p)
            .ok()
            .and_then(|p| self.positions[c].binary_search(&p).ok())
        {
            Some(i) => out.extend_from_slice(&self.codes[c][i * f..(i + 1) * f]),
            None => {
                debug_assert!(false, "pixel {p} channel {c} not held");
                out.resize(f, 0);
            }
        }
    }

    fn code_sum_range(&self, c: usize) -> (u32, u32) {
        self.sum_range[c]
    }

    fn sampled_for(&self) -> Option<&SampleOptions> {
        Some(&self.options)
    }
}

/// What the scan builds.
struct State {
    width: usize,
    height: usize,
    bits: u8,
    positions: [Vec<u32>; 3],
    codes: [Vec<u16>; 3],
    /// Per sample (`[p · 3 + c]`): Σ_j code, as decoded.
    sums: Vec<u32>,
}

struct Reader {
    frames: usize,
    options: SampleOptions,
    state: Option<State>,
    held: PileUpSamples,
    sum_range: [(u32, u32); 3],
}

/// The pixels [`draw_plan`] can look at in channel `c`, and the
/// 4-neighbours of the interior ones, ascending.
fn held_pixels(width: usize, height: usize, c: usize, options: &SampleOptions) -> Vec<u32> {
    let plan = draw_plan(width, height, c, options);
    let mut v: Vec<u32> = Vec::with_capacity(5 * (plan.edge_pixels.len() + plan.draws.len()));
    for &p in plan.edge_pixels.iter().chain(&plan.draws) {
        v.push(p as u32);
        let (x, y) = (p % width, p / width);
        if x > 0 && y > 0 && x + 1 < width && y + 1 < height {
            v.extend([p - 1, p + 1, p - width, p + width].map(|q| q as u32));
        }
    }
    v.sort_unstable();
    v.dedup();
    v
}

impl FrameVisitor for Reader {
    fn frame(&mut self, j: usize, image: &CodeImage, pile_up: [Option<u16>; 3]) -> Result<(), HdrError> {
        let frames = self.frames;
        let options = self.options;
        let state = self.state.get_or_insert_with(|| {
            let positions: [Vec<u32>; 3] = std::array::from_fn(|c| held_pixels(image.width, image.height, c, &options));
            State {
                width: image.width,
                height: image.height,
                bits: image.bits,
                codes: std::array::from_fn(|c| vec![0u16; positions[c].len() * frames]),
                positions,
                sums: vec![0u32; image.data.len()],
            }
        });
        for c in 0..3 {
            for (i, &p) in state.positions[c].iter().enumerate() {
                state.codes[c][i * frames + j] = image.data[p as usize * 3 + c];
            }
        }
        state
            .sums
            .par_chunks_mut(1 << 16)
            .zip(image.data.par_chunks(1 << 16))
            .for_each(|(s, z)| {
                for (s, &z) in s.iter_mut().zip(z) {
                    *s += u32::from(z);
                }
            });
        self.held.hold(j, image, pile_up);
        Ok(())
    }

    fn finish(&mut self, white_points: &[[Option<WhitePoint>; 3]]) -> Result<(), HdrError> {
        let Some(state) = self.state.as_mut() else {
            return Ok(());
        };
        let max = crate::camera::image::max_code(state.bits);
        let frames = self.frames;
        for (j, wp) in white_points.iter().enumerate() {
            for (c, w) in wp.iter().enumerate() {
                let Some(w) = w else { continue };
                for z in state.codes[c].iter_mut().skip(j).step_by(frames) {
                    if *z >= w.clipped_from && *z < max {
                        *z = max;
                    }
                }
                for &(p, z) in self.held.of(j, c) {
                    state.sums[p as usize * 3 + c] += u32::from(max - z);
                }
            }
        }
        for c in 0..3 {
            self.sum_range[c] = state.sums[c..]
                .par_iter()
                .step_by(3)
                .fold(|| (u32::MAX, 0), |a, &s| (a.0.min(s), a.1.max(s)))
                .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        }
        state.sums = Vec::new();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::bracket::Bracket;
    use crate::hdr::bracket_files::fixture;
    use crate::hdr::debevec::{DebevecOptions, calibrate_debevec};
    use crate::hdr::robertson::{RobertsonOptions, calibrate_robertson};
    use crate::hdr::sampling::select_samples;

    #[test]
    fn recovery_from_the_sampled_files_is_recovery_from_the_whole_bracket() {
        let dir = tempfile::tempdir().unwrap();
        let (paths, times, images) = fixture::written(dir.path());
        let bracket = Bracket::new(images, times.iter().rev().copied().collect()).unwrap();
        let files = BracketFiles::open(&paths, Some(&times)).unwrap();
        let sampling = SampleOptions {
            samples: 600,
            seed: 3,
            ..Default::default()
        };
        let (sampled, white) = SampledBracket::read(&files, &sampling, &|_| {}).unwrap();
        assert_eq!(white, bracket.white_points());
        for c in 0..3 {
            assert_eq!(sampled.code_sum_range(c), bracket.code_sum_range(c), "channel {c}");
            let s = select_samples(&sampled, c, &sampling);
            assert!(s.len() >= 300, "channel {c}: {} samples", s.len());
            assert_eq!(s, select_samples(&bracket, c, &sampling), "channel {c}");
        }
        let opts = DebevecOptions {
            sampling,
            ..Default::default()
        };
        let (a, b) = (
            calibrate_debevec(&bracket, &opts).unwrap(),
            calibrate_debevec(&sampled, &opts).unwrap(),
        );
        assert_eq!(a.curve, b.curve);
        let r = RobertsonOptions {
            sampling,
            ..Default::default()
        };
        assert_eq!(
            calibrate_robertson(&bracket, &r).unwrap(),
            calibrate_robertson(&sampled, &r).unwrap()
        );
        // Other sample options would read pixels that were never kept.
        let other = DebevecOptions {
            sampling: SampleOptions { seed: 4, ..sampling },
            ..Default::default()
        };
        let e = calibrate_debevec(&sampled, &other).unwrap_err().to_string();
        assert!(e.contains("sampling"), "{e}");
    }
}
