//! Quality flags of one scan: clouds near the sun (the sun triplet
//! disagrees or the disc cannot be measured), a poor sky fit, a large
//! masked fraction. A flagged scan stays in the time series (with its flag
//! in the CSV); flagged suns are left out of the Langley fit.

use serde::{Deserialize, Serialize};

use crate::pipeline::TRIPLET_AGREEMENT;

/// Largest RMS relative residual of a channel's sky fit that is not a poor
/// fit (10%: a clear sky fits eq. 5.9 within a few percent; broken cloud
/// does not).
pub const POOR_FIT_RMS: f64 = 0.10;

/// Largest fraction of sky samples the robust fit may leave out before the
/// scan is flagged (30%: occluders and the horizon usually cost 5–20%).
pub const HIGH_MASKED_FRACTION: f64 = 0.30;

/// The flags of one scan, with the figures they were decided on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QualityFlags {
    /// The sun triplet disagrees by more than [`TRIPLET_AGREEMENT`] in a
    /// channel, or no sun frame could be measured: clouds near the sun.
    pub clouds_near_sun: bool,
    /// Largest (max − min)/mean of the sun frames over the channels, if measured.
    pub triplet_spread: Option<f64>,
    /// A channel's sky fit has an RMS relative residual above [`POOR_FIT_RMS`], or no sky was fitted.
    pub poor_fit: bool,
    /// Largest RMS relative residual over the channels, if fitted.
    pub worst_rms_relative: Option<f64>,
    /// More than [`HIGH_MASKED_FRACTION`] of the sky samples were masked out.
    pub high_masked_fraction: bool,
    /// Largest masked fraction over the channels, if fitted.
    pub masked_fraction: Option<f64>,
}

/// The larger of two figures; NaN if either is (a NaN must raise a flag, not vanish).
fn largest(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

impl QualityFlags {
    /// The flags for a sun spread per channel (`None`: not measured) and a
    /// sky fit's `(rms_relative, masked_fraction)` per channel (`None`: not fitted).
    pub fn judge(spread: Option<[f64; 3]>, sky: Option<&[(f64, f64)]>) -> QualityFlags {
        let triplet_spread = spread.map(|s| s.iter().copied().fold(0.0, largest));
        let worst = |f: fn(&(f64, f64)) -> f64| sky.map(|s| s.iter().map(f).fold(0.0, largest));
        let worst_rms_relative = worst(|c| c.0);
        let masked_fraction = worst(|c| c.1);
        QualityFlags {
            clouds_near_sun: triplet_spread.is_none_or(|s| s.is_nan() || s > TRIPLET_AGREEMENT),
            triplet_spread,
            poor_fit: worst_rms_relative.is_none_or(|r| r.is_nan() || r > POOR_FIT_RMS),
            worst_rms_relative,
            high_masked_fraction: masked_fraction.is_some_and(|m| m.is_nan() || m > HIGH_MASKED_FRACTION),
            masked_fraction,
        }
    }

    /// The raised flags' names, `;`-separated (empty when none).
    pub fn names(&self) -> String {
        [
            (self.clouds_near_sun, "clouds_near_sun"),
            (self.poor_fit, "poor_fit"),
            (self.high_masked_fraction, "high_masked_fraction"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect::<Vec<_>>()
        .join(";")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_follow_their_thresholds() {
        let clear = QualityFlags::judge(
            Some([0.01, 0.02, 0.005]),
            Some(&[(0.03, 0.1), (0.04, 0.12), (0.05, 0.1)]),
        );
        assert!(!clear.clouds_near_sun && !clear.poor_fit && !clear.high_masked_fraction);
        assert_eq!(clear.triplet_spread, Some(0.02));
        assert_eq!(clear.names(), "");
        let cloudy = QualityFlags::judge(Some([0.01, 0.08, 0.0]), Some(&[(0.03, 0.1), (0.15, 0.45), (0.05, 0.1)]));
        assert!(cloudy.clouds_near_sun && cloudy.poor_fit && cloudy.high_masked_fraction);
        assert_eq!(cloudy.names(), "clouds_near_sun;poor_fit;high_masked_fraction");
        let nothing = QualityFlags::judge(None, None);
        assert!(nothing.clouds_near_sun && nothing.poor_fit && !nothing.high_masked_fraction);
        // A NaN spread is not agreement.
        assert!(QualityFlags::judge(Some([f64::NAN, 0.0, 0.0]), None).clouds_near_sun);
    }
}
