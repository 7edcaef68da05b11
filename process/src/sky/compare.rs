//! A fitted sky against measured samples: measured / fitted − 1 per
//! sample and channel, and its median and 95th percentile.

use crate::error_figures::quantile;

use super::file::{SampleTable, SkyFile};
use super::geometry::{angle_between, direction};

impl SkyFile {
    /// The radiance of each channel toward (`zenith`, `azimuth`), radians.
    pub fn radiance(&self, zenith: f64, azimuth: f64) -> Vec<f64> {
        let sun = direction(self.sun_zenith_deg.to_radians(), self.sun_azimuth_deg.to_radians());
        let gamma = angle_between(direction(zenith, azimuth), sun);
        self.channels.iter().map(|c| c.model.radiance(zenith, gamma)).collect()
    }
}

/// One channel's fit against the samples.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelComparison {
    /// The channel.
    pub channel: String,
    /// measured / fitted − 1, per sample (row order).
    pub ratio_minus_1: Vec<f64>,
    /// Median of |measured / fitted − 1| over the samples.
    pub median_abs: f64,
    /// 95th percentile (nearest rank) of |measured / fitted − 1|.
    pub p95_abs: f64,
}

/// `sky`'s channels against `samples`', which are the same channels in the
/// same order (read with `ChannelSelection::Named` of the sky's names).
/// A sample where the model gives 0 has an infinite or NaN ratio; it
/// counts as the largest.
pub fn compare_with_samples(sky: &SkyFile, samples: &SampleTable) -> Vec<ChannelComparison> {
    let fitted: Vec<Vec<f64>> = samples.directions.iter().map(|&(z, a)| sky.radiance(z, a)).collect();
    sky.channels
        .iter()
        .zip(&samples.values)
        .enumerate()
        .map(|(c, (ch, measured))| {
            let ratio_minus_1: Vec<f64> = measured.iter().zip(&fitted).map(|(m, f)| m / f[c] - 1.0).collect();
            let mut abs: Vec<f64> = ratio_minus_1
                .iter()
                .map(|r| if r.is_nan() { f64::INFINITY } else { r.abs() })
                .collect();
            ChannelComparison {
                channel: ch.channel.clone(),
                median_abs: quantile(&mut abs, 0.5),
                p95_abs: quantile(&mut abs, 0.95),
                ratio_minus_1,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::{ChannelSky, SkyModel};

    #[test]
    fn ratios_are_measured_over_the_model_minus_one() {
        let model = SkyModel {
            lz: 0.07,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.5,
            h: 0.9,
        };
        let sky = SkyFile {
            sun_zenith_deg: 40.0,
            sun_azimuth_deg: 180.0,
            channels: vec![ChannelSky {
                channel: "g".into(),
                model,
                chosen: "SevenParameter".into(),
                reason: "test".into(),
                rms_relative: 0.0,
                samples: 0,
                masked_fraction: 0.0,
                masked: None,
                convergence: None,
            }],
        };
        let dirs: Vec<(f64, f64)> = (0..20)
            .map(|i| (f64::from(i * 4).to_radians(), f64::from(i * 17).to_radians()))
            .collect();
        // Sample i is the model times 1 + i/100: |ratio − 1| = 0, 0.01, … 0.19.
        let values = vec![
            dirs.iter()
                .enumerate()
                .map(|(i, &(z, a))| sky.radiance(z, a)[0] * (1.0 + i as f64 / 100.0))
                .collect(),
        ];
        let table = SampleTable {
            channels: vec!["g".into()],
            directions: dirs,
            values,
        };
        let [c] = compare_with_samples(&sky, &table).try_into().expect("one channel");
        assert!((c.ratio_minus_1[7] - 0.07).abs() < 1e-12, "{:?}", c.ratio_minus_1);
        // Nearest rank of 20: median index round(9.5) = 10, p95 index round(18.05) = 18.
        assert!((c.median_abs - 0.10).abs() < 1e-12, "{}", c.median_abs);
        assert!((c.p95_abs - 0.18).abs() < 1e-12, "{}", c.p95_abs);
        // At the zenith (sun at 40°): Lz φ(0) f(40°) by hand.
        let g = 40f64.to_radians();
        let want = 0.07 * (1.0 - (-0.4f64).exp()) * (1.0 + 12.0 * (-3.2 * g.powf(0.9)).exp() + 0.5 * g.cos().powi(2));
        assert!((sky.radiance(0.0, 0.0)[0] / want - 1.0).abs() < 1e-12);
    }
}
