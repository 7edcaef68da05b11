//! Shutter-speed series: the exposure times a camera with a stepped
//! shutter offers.
//!
//! DSLRs and mirrorless bodies do not take any exposure time: they step
//! through a table of nominal speeds, in thirds, halves or whole stops
//! (ISO 2721's marked values; 1/125 s is the nominal of 2⁻⁷ s). A camera's
//! report (EXIF `ExposureTime`, INDI's `EXPTIME`) gives the nominal value,
//! so these tables hold the nominals, as the cameras print them.

use serde::{Deserialize, Serialize};

/// How a camera steps its exposure time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum ShutterSteps {
    /// Any time within the limits (machine-vision, astro and webcam
    /// sensors, rounded to their own fine step).
    #[default]
    Continuous,
    /// The ⅓-stop series 1/8000 s … 30 s (most DSLRs' default).
    Thirds,
    /// The ½-stop series 1/8000 s … 30 s.
    Halves,
    /// Whole stops 1/8000 s … 30 s.
    Whole,
}

/// The ⅓-stop nominal shutter speeds, seconds, 1/8000 s to 30 s (55
/// values: 18 stops).
pub const THIRD_STOPS_S: [f64; 55] = [
    1.0 / 8000.0,
    1.0 / 6400.0,
    1.0 / 5000.0,
    1.0 / 4000.0,
    1.0 / 3200.0,
    1.0 / 2500.0,
    1.0 / 2000.0,
    1.0 / 1600.0,
    1.0 / 1250.0,
    1.0 / 1000.0,
    1.0 / 800.0,
    1.0 / 640.0,
    1.0 / 500.0,
    1.0 / 400.0,
    1.0 / 320.0,
    1.0 / 250.0,
    1.0 / 200.0,
    1.0 / 160.0,
    1.0 / 125.0,
    1.0 / 100.0,
    1.0 / 80.0,
    1.0 / 60.0,
    1.0 / 50.0,
    1.0 / 40.0,
    1.0 / 30.0,
    1.0 / 25.0,
    1.0 / 20.0,
    1.0 / 15.0,
    1.0 / 13.0,
    1.0 / 10.0,
    1.0 / 8.0,
    1.0 / 6.0,
    1.0 / 5.0,
    1.0 / 4.0,
    0.3,
    0.4,
    0.5,
    0.6,
    0.8,
    1.0,
    1.3,
    1.6,
    2.0,
    2.5,
    3.2,
    4.0,
    5.0,
    6.0,
    8.0,
    10.0,
    13.0,
    15.0,
    20.0,
    25.0,
    30.0,
];

/// The ½-stop nominal shutter speeds, seconds, 1/8000 s to 30 s (37
/// values).
pub const HALF_STOPS_S: [f64; 37] = [
    1.0 / 8000.0,
    1.0 / 6000.0,
    1.0 / 4000.0,
    1.0 / 3000.0,
    1.0 / 2000.0,
    1.0 / 1500.0,
    1.0 / 1000.0,
    1.0 / 750.0,
    1.0 / 500.0,
    1.0 / 350.0,
    1.0 / 250.0,
    1.0 / 180.0,
    1.0 / 125.0,
    1.0 / 90.0,
    1.0 / 60.0,
    1.0 / 45.0,
    1.0 / 30.0,
    1.0 / 20.0,
    1.0 / 15.0,
    1.0 / 10.0,
    1.0 / 8.0,
    1.0 / 6.0,
    1.0 / 4.0,
    1.0 / 3.0,
    0.5,
    0.7,
    1.0,
    1.5,
    2.0,
    3.0,
    4.0,
    6.0,
    8.0,
    10.0,
    15.0,
    20.0,
    30.0,
];

/// Whole-stop nominal shutter speeds, seconds, 1/8000 s to 30 s (19
/// values).
pub const WHOLE_STOPS_S: [f64; 19] = [
    1.0 / 8000.0,
    1.0 / 4000.0,
    1.0 / 2000.0,
    1.0 / 1000.0,
    1.0 / 500.0,
    1.0 / 250.0,
    1.0 / 125.0,
    1.0 / 60.0,
    1.0 / 30.0,
    1.0 / 15.0,
    1.0 / 8.0,
    1.0 / 4.0,
    0.5,
    1.0,
    2.0,
    4.0,
    8.0,
    15.0,
    30.0,
];

impl ShutterSteps {
    /// The series' nominal speeds in seconds, shortest first; `None` for a
    /// continuous shutter.
    pub fn series(self) -> Option<&'static [f64]> {
        match self {
            Self::Continuous => None,
            Self::Thirds => Some(&THIRD_STOPS_S),
            Self::Halves => Some(&HALF_STOPS_S),
            Self::Whole => Some(&WHOLE_STOPS_S),
        }
    }

    /// The series' speeds within `min_s..=max_s` (with a 1 % margin for
    /// nominal rounding), or `None` for a continuous shutter.
    pub fn within(self, min_s: f64, max_s: f64) -> Option<Vec<f64>> {
        self.series().map(|s| {
            s.iter()
                .copied()
                .filter(|&t| t >= min_s * 0.99 && t <= max_s * 1.01)
                .collect()
        })
    }

    /// Whether this is the default continuous shutter (for serde).
    pub fn is_continuous(&self) -> bool {
        *self == Self::Continuous
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each nominal lies within 0.2 stop of the exact power of two it
    /// stands for, 2^(k·step) s counted from 1 s (the worst is the ½-stop
    /// 1/10 s for 2^−3.5 = 1/11.3 s, 0.18 stop; the ½-stop series takes
    /// Nikon's 1/3 s for 2^−1.5, where Canon's 0.3 s is 0.24 stop off), and the series spans the
    /// 18 stops from 1/8000 s (2^−13) to 30 s (2^5).
    #[test]
    fn each_nominal_stands_for_its_power_of_two() {
        for (steps, stop) in [
            (ShutterSteps::Thirds, 1.0 / 3.0),
            (ShutterSteps::Halves, 0.5),
            (ShutterSteps::Whole, 1.0),
        ] {
            let s = steps.series().unwrap();
            assert_eq!((s.len() - 1) as f64 * stop, 18.0, "{steps:?}: {} values", s.len());
            let one = s.iter().position(|&t| t == 1.0).unwrap();
            for (i, &t) in s.iter().enumerate() {
                let exact = (i as f64 - one as f64) * stop;
                let off = t.log2() - exact;
                assert!(off.abs() < 0.2, "{steps:?}: {t} s is {off:.3} stop from 2^{exact:.3}");
            }
        }
    }

    #[test]
    fn within_keeps_the_speeds_between_the_limits() {
        let t = ShutterSteps::Thirds.within(1.0 / 4000.0, 1.0).unwrap();
        assert_eq!(t.first().copied(), Some(1.0 / 4000.0));
        assert_eq!(t.last().copied(), Some(1.0));
        assert_eq!(t.len(), 37);
        assert_eq!(ShutterSteps::Continuous.within(0.001, 1.0), None);
    }
}
