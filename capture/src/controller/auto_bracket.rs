//! Auto-bracketing: the fewest exposures that leave every pixel well
//! exposed in at least one frame (DESIGN.md: "a bracket only as long as
//! the metered dynamic range requires").
//!
//! A pixel is well exposed in a frame when its brightest channel lies in
//! [`WELL_EXPOSED`] of full scale. The first data frame is taken at the
//! metered exposure; each next one, [`SPACING_STOPS`] shorter than the
//! shortest so far while some pixel is still too bright in it, else
//! longer than the longest while some pixel is still too dark, until every
//! pixel is covered, the camera's range ends or `max_frames` are taken.
//! The spacing is well inside the ~10 stops a 12-bit gamma-2.2 sensor
//! exposes well, so a pixel cannot fall between two frames. The decision
//! depends only on the frames taken, so a resumed session re-reads them
//! from the store and decides exactly as before.

use super::metering::{Codes, pixel_peaks};

/// Brightest channel between these fractions of full scale: well exposed.
pub const WELL_EXPOSED: (f64, f64) = (0.04, 0.92);
/// Stops between consecutive frames.
pub const SPACING_STOPS: f64 = 4.0;

/// Coverage of a set of frames of one target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Coverage {
    /// Pixels well exposed in no frame and too bright in the shortest.
    pub too_bright: usize,
    /// Pixels well exposed in no frame and too dark in the longest.
    pub too_dark: usize,
}

impl Coverage {
    /// Pixels without a well-exposed frame.
    pub fn uncovered(&self) -> usize {
        self.too_bright + self.too_dark
    }
}

/// Coverage of `frames` (each with its exposure in seconds), all the same size.
pub fn coverage(frames: &[(f64, Codes<'_>)]) -> Coverage {
    let peaks: Vec<(f64, Vec<f64>)> = frames.iter().map(|(t, f)| (*t, pixel_peaks(*f))).collect();
    let n = peaks.iter().map(|(_, p)| p.len()).min().unwrap_or(0);
    let shortest = peaks.iter().min_by(|a, b| a.0.total_cmp(&b.0));
    let longest = peaks.iter().max_by(|a, b| a.0.total_cmp(&b.0));
    let mut c = Coverage {
        too_bright: 0,
        too_dark: 0,
    };
    let (Some(shortest), Some(longest)) = (shortest, longest) else {
        return c;
    };
    for i in 0..n {
        let covered = peaks
            .iter()
            .any(|(_, p)| (WELL_EXPOSED.0..=WELL_EXPOSED.1).contains(&p[i]));
        if covered {
            continue;
        }
        if shortest.1[i] > WELL_EXPOSED.1 {
            c.too_bright += 1;
        } else if longest.1[i] < WELL_EXPOSED.0 {
            c.too_dark += 1;
        }
    }
    c
}

/// The exposure of the next data frame after `taken` (exposure, frame), or
/// `None` when every pixel is covered or the camera's range `(min, max)`
/// is exhausted in the direction needed.
pub fn next_exposure(taken: &[(f64, Codes<'_>)], range: (f64, f64)) -> Option<f64> {
    let c = coverage(taken);
    let shortest = taken.iter().map(|t| t.0).fold(f64::INFINITY, f64::min);
    let longest = taken.iter().map(|t| t.0).fold(0.0, f64::max);
    let step = 2f64.powf(SPACING_STOPS);
    if c.too_bright > 0 && shortest > range.0 * 1.000_001 {
        return Some((shortest / step).max(range.0));
    }
    if c.too_dark > 0 && longest < range.1 / 1.000_001 {
        return Some((longest * step).min(range.1));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{ExposureTime, Frame, Gain};

    /// A frame of a gamma-2.2 camera seeing `radiance` per pixel for `t` s.
    fn frame(radiance: &[f64], t: f64) -> Frame {
        let data = radiance
            .iter()
            .flat_map(|l| {
                let code = ((l * t).min(1.0).powf(1.0 / 2.2) * 4095.0).round() as u16;
                [code; 3]
            })
            .collect();
        Frame {
            width: radiance.len(),
            height: 1,
            bits: 12,
            data,
            exposure_requested: ExposureTime::from_seconds(t).unwrap(),
            exposure_actual: ExposureTime::from_seconds(t).unwrap(),
            gain: Gain::UNITY,
            sequence: 0,
            timestamp: chrono::DateTime::default(),
            temperature_c: None,
            file: None,
        }
    }

    /// Fourteen stops of scene take three frames at 4-stop spacing; a
    /// scene of four stops takes one.
    #[test]
    fn covers_a_wide_scene_in_few_frames_and_a_narrow_one_in_one() {
        let wide: Vec<f64> = (0..=14).map(|s| 2f64.powi(s)).collect();
        let mut frames = vec![(2f64.powi(-10), frame(&wide, 2f64.powi(-10)))];
        while let Some(t) = next_exposure(
            &frames.iter().map(|(t, f)| (*t, Codes::from(f))).collect::<Vec<_>>(),
            (1e-6, 30.0),
        ) {
            frames.push((t, frame(&wide, t)));
            assert!(frames.len() <= 7);
        }
        let refs: Vec<_> = frames.iter().map(|(t, f)| (*t, Codes::from(f))).collect();
        assert_eq!(coverage(&refs).uncovered(), 0);
        assert!(frames.len() <= 3, "{} frames", frames.len());
        let narrow: Vec<f64> = (0..=4).map(|s| 2f64.powi(s)).collect();
        let f = frame(&narrow, 2f64.powi(-5));
        assert_eq!(next_exposure(&[(2f64.powi(-5), Codes::from(&f))], (1e-6, 30.0)), None);
    }
}
