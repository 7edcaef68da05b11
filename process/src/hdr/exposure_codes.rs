//! What response recovery reads of a bracket: the codes of a pixel across
//! the exposures, and the range of their sums. [`Bracket`] holds every
//! pixel; [`SampledBracket`](super::sampled_bracket::SampledBracket), read
//! from files one frame at a time, holds only the pixels that sample
//! selection can look at for given [`SampleOptions`].

use rayon::prelude::*;

use super::bracket::Bracket;
use super::sampling::SampleOptions;

/// The codes of a bracket, sorted by exposure time, as response recovery
/// reads them (white points applied: see [`super::white_point`]).
pub trait ExposureCodes: Sync {
    /// Number of exposures.
    fn exposures(&self) -> usize;
    /// Bits per sample.
    fn bits(&self) -> u8;
    /// Width in pixels.
    fn width(&self) -> usize;
    /// Height in pixels.
    fn height(&self) -> usize;
    /// Exposure times in seconds, ascending.
    fn times_s(&self) -> &[f64];
    /// The codes of pixel `p` (`y · width + x`), channel `c`, in every
    /// exposure (shortest first), into `out` (cleared first).
    fn pixel_codes(&self, p: usize, c: usize, out: &mut Vec<u16>);
    /// The smallest and largest sum of a pixel's channel-`c` codes over the
    /// exposures, over all pixels.
    fn code_sum_range(&self, c: usize) -> (u32, u32);
    /// `None` when every pixel can be read; otherwise the sample selection
    /// whose pixels alone are held.
    fn sampled_for(&self) -> Option<&SampleOptions>;

    /// The largest code.
    fn max_code(&self) -> u16 {
        crate::camera::image::max_code(self.bits())
    }
}

impl ExposureCodes for Bracket {
    fn exposures(&self) -> usize {
        self.len()
    }

    fn bits(&self) -> u8 {
        Bracket::bits(self)
    }

    fn width(&self) -> usize {
        Bracket::width(self)
    }

    fn height(&self) -> usize {
        Bracket::height(self)
    }

    fn times_s(&self) -> &[f64] {
        Bracket::times_s(self)
    }

    fn pixel_codes(&self, p: usize, c: usize, out: &mut Vec<u16>) {
        out.clear();
        out.extend(self.images().iter().map(|im| im.data[p * 3 + c]));
    }

    fn code_sum_range(&self, c: usize) -> (u32, u32) {
        let images = self.images();
        (0..Bracket::width(self) * Bracket::height(self))
            .into_par_iter()
            .map(|p| images.iter().map(|im| u32::from(im.data[p * 3 + c])).sum::<u32>())
            .fold(|| (u32::MAX, 0), |a, s| (a.0.min(s), a.1.max(s)))
            .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)))
    }

    fn sampled_for(&self) -> Option<&SampleOptions> {
        None
    }
}
