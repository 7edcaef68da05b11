//! Units carried in types: angles, angular speeds, light levels, exposure
//! times and gains.

/// A plane angle, stored in radians (the project's internal unit).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct Angle(f64);

impl Angle {
    /// Zero.
    pub const ZERO: Angle = Angle(0.0);

    /// From radians.
    pub const fn from_radians(rad: f64) -> Self {
        Self(rad)
    }

    /// From degrees.
    pub fn from_degrees(deg: f64) -> Self {
        Self(deg.to_radians())
    }

    /// In radians.
    pub const fn radians(self) -> f64 {
        self.0
    }

    /// In degrees.
    pub fn degrees(self) -> f64 {
        self.0.to_degrees()
    }

    /// Absolute difference to `other`.
    pub fn distance(self, other: Angle) -> Angle {
        Angle((self.0 - other.0).abs())
    }
}

/// An angular speed, stored in radians per second.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct AngularSpeed(f64);

impl AngularSpeed {
    /// From radians per second.
    pub const fn from_radians_per_second(v: f64) -> Self {
        Self(v)
    }

    /// From degrees per second.
    pub fn from_degrees_per_second(v: f64) -> Self {
        Self(v.to_radians())
    }

    /// In radians per second.
    pub const fn radians_per_second(self) -> f64 {
        self.0
    }
}

/// A head pose: pan and tilt as the head reports them (the mount's
/// calibrated offset is applied by the controller, not here).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Pan (azimuth-like axis).
    pub pan: Angle,
    /// Tilt (elevation-like axis).
    pub tilt: Angle,
}

impl Pose {
    /// A pose from two angles in degrees.
    pub fn from_degrees(pan: f64, tilt: f64) -> Self {
        Self {
            pan: Angle::from_degrees(pan),
            tilt: Angle::from_degrees(tilt),
        }
    }

    /// Whether both axes are within `tolerance` of `other`.
    pub fn within(&self, other: &Pose, tolerance: Angle) -> bool {
        self.pan.distance(other.pan) <= tolerance && self.tilt.distance(other.tilt) <= tolerance
    }
}

/// A light level as a fraction of full output, 0.0..=1.0.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct Level(f64);

impl Level {
    /// Off.
    pub const OFF: Level = Level(0.0);
    /// Full output.
    pub const FULL: Level = Level(1.0);

    /// A fraction of full output; `None` outside 0..=1 or NaN.
    pub fn new(fraction: f64) -> Option<Self> {
        (0.0..=1.0).contains(&fraction).then_some(Self(fraction))
    }

    /// The fraction of full output.
    pub const fn fraction(self) -> f64 {
        self.0
    }
}

/// An exposure (integration) time, stored in seconds.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct ExposureTime(f64);

impl ExposureTime {
    /// From seconds; `None` unless finite and > 0.
    pub fn from_seconds(s: f64) -> Option<Self> {
        (s.is_finite() && s > 0.0).then_some(Self(s))
    }

    /// From whole microseconds; `None` for 0.
    pub fn from_micros(us: u64) -> Option<Self> {
        Self::from_seconds(us as f64 * 1e-6)
    }

    /// In seconds.
    pub const fn seconds(self) -> f64 {
        self.0
    }

    /// As a [`std::time::Duration`] (rounded to the nanosecond).
    pub fn duration(self) -> std::time::Duration {
        std::time::Duration::from_secs_f64(self.0)
    }
}

/// An analogue gain in decibels of signal amplitude (0 dB = unity):
/// the linear factor is `10^(dB/20)`.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct Gain(f64);

impl Gain {
    /// Unity gain.
    pub const UNITY: Gain = Gain(0.0);

    /// From decibels; `None` unless finite.
    pub fn from_db(db: f64) -> Option<Self> {
        db.is_finite().then_some(Self(db))
    }

    /// In decibels.
    pub const fn db(self) -> f64 {
        self.0
    }

    /// The linear amplitude factor, `10^(dB/20)`.
    pub fn linear(self) -> f64 {
        10f64.powf(self.0 / 20.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degrees_and_radians_agree() {
        assert!((Angle::from_degrees(180.0).radians() - std::f64::consts::PI).abs() < 1e-15);
        assert!((Angle::from_radians(std::f64::consts::FRAC_PI_2).degrees() - 90.0).abs() < 1e-12);
        assert!(Level::new(1.5).is_none());
        assert!(Level::new(f64::NAN).is_none());
        assert_eq!(Level::new(0.25).unwrap().fraction(), 0.25);
    }

    #[test]
    fn exposure_and_gain_units() {
        assert_eq!(ExposureTime::from_micros(2500).unwrap().seconds(), 0.0025);
        assert!(ExposureTime::from_seconds(0.0).is_none());
        assert!(ExposureTime::from_seconds(f64::NAN).is_none());
        // 20 dB is ten times the amplitude; 6.0206 dB is twice.
        assert!((Gain::from_db(20.0).unwrap().linear() - 10.0).abs() < 1e-12);
        assert!((Gain::from_db(6.020_599_913).unwrap().linear() - 2.0).abs() < 1e-9);
        assert_eq!(Gain::UNITY.linear(), 1.0);
    }
}
