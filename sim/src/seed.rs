//! Seeds: every random process of the simulated station draws from a seed
//! derived from the station's one seed (`simulation.seed` in the station
//! config), the process's purpose and an index (a frame's sequence number,
//! a link's connection count), so that the same station seed gives the
//! same world, frames and faults, and no two processes share a stream.

/// What a derived seed is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Purpose {
    /// The renderer's Monte Carlo for one frame ([`crate::camera::View::seed`]).
    Render,
    /// The sensor noise of one frame.
    SensorNoise,
    /// Camera fault draws.
    CameraFaults,
    /// Byte faults on one connection of the head's link.
    HeadLink,
    /// Byte faults on one connection of the filter wheel's link.
    WheelLink,
    /// Byte faults on one connection of the lights' link.
    LightsLink,
    /// The head's encoder noise.
    Encoder,
    /// The simulated range scanner's noise, dropouts and mixed pixels
    /// (one stream per scan, then per row).
    RangeScan,
}

impl Purpose {
    fn code(self) -> u64 {
        match self {
            Purpose::Render => 1,
            Purpose::SensorNoise => 2,
            Purpose::CameraFaults => 3,
            Purpose::HeadLink => 4,
            Purpose::WheelLink => 5,
            Purpose::LightsLink => 6,
            Purpose::Encoder => 7,
            Purpose::RangeScan => 8,
        }
    }
}

/// The seed for `purpose` and `index`, derived from `seed` (SplitMix64
/// finalizer over the three).
pub fn derive(seed: u64, purpose: Purpose, index: u64) -> u64 {
    let a = mix(seed ^ mix(purpose.code()));
    mix(a ^ mix(index.wrapping_add(0x5851_F42D_4C95_7F2D)))
}

/// A uniform draw in [0, 1) from a seed.
pub fn uniform(seed: u64) -> f64 {
    (mix(seed) >> 11) as f64 / (1u64 << 53) as f64
}

fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_seeds_differ_by_purpose_and_index_and_uniforms_average_one_half() {
        assert_ne!(derive(1, Purpose::Render, 0), derive(1, Purpose::SensorNoise, 0));
        assert_ne!(derive(1, Purpose::Render, 0), derive(1, Purpose::Render, 1));
        assert_ne!(derive(1, Purpose::Render, 0), derive(2, Purpose::Render, 0));
        assert_eq!(derive(7, Purpose::Encoder, 3), derive(7, Purpose::Encoder, 3));
        // Mean of 10 000 uniforms: 0.5 ± 3σ (σ = 1/√(12·10⁴) ≈ 0.0029).
        let n = 10_000u64;
        let mean = (0..n)
            .map(|i| uniform(derive(9, Purpose::CameraFaults, i)))
            .sum::<f64>()
            / n as f64;
        assert!((mean - 0.5).abs() < 0.009, "{mean}");
    }
}
