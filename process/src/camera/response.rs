//! A parametric camera response curve: the ground truth that the simulator
//! photographs through and that response recovery is tested against.

use std::f64::consts::TAU;

/// Error for response parameters outside their valid range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResponseParamError {
    /// `gamma` must be finite and positive.
    #[error("response gamma = {0}: expected a finite value > 0")]
    Gamma(f64),
    /// `s_strength` must lie in `[0, 1)` for the curve to stay strictly monotone.
    #[error("response s_strength = {0}: expected 0 ≤ s_strength < 1 (monotone curve)")]
    SStrength(f64),
}

/// A smooth, strictly monotone, invertible response `f: [0, 1] → [0, 1]` from
/// normalized sensor exposure `x` (1 = full well) to normalized code `y`.
///
/// `f(x) = s(x^(1/γ))` with the S-shaped tone curve
/// `s(u) = u − c · sin(2πu) / (2π)`, `0 ≤ c < 1`.
///
/// `s'(u) = 1 − c·cos(2πu) ≥ 1 − c > 0`, so `f` is strictly increasing, with
/// `f(0) = 0` and `f(1) = 1`. `c` flattens the toe and the shoulder (slope
/// `1 − c`) and steepens the mid-tones (slope `1 + c`), like the film-like
/// curves of consumer cameras; `γ` is the usual display gamma (≈ 2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParametricResponse {
    gamma: f64,
    s_strength: f64,
}

impl ParametricResponse {
    /// A response with gamma `gamma` (> 0) and S-curve strength `s_strength` (in `[0, 1)`).
    pub fn new(gamma: f64, s_strength: f64) -> Result<Self, ResponseParamError> {
        if !(gamma.is_finite() && gamma > 0.0) {
            return Err(ResponseParamError::Gamma(gamma));
        }
        if !(0.0..1.0).contains(&s_strength) {
            return Err(ResponseParamError::SStrength(s_strength));
        }
        Ok(Self { gamma, s_strength })
    }

    /// Gamma `γ`.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// S-curve strength `c`.
    pub fn s_strength(&self) -> f64 {
        self.s_strength
    }

    /// `f(x)`: normalized code for normalized exposure `x` (clamped to `[0, 1]`).
    pub fn code_fraction(&self, exposure: f64) -> f64 {
        let u = exposure.clamp(0.0, 1.0).powf(1.0 / self.gamma);
        (u - self.s_strength * (TAU * u).sin() / TAU).clamp(0.0, 1.0)
    }

    /// `f⁻¹(y)`: normalized exposure that gives normalized code `y` (clamped to `[0, 1]`).
    ///
    /// Newton iterations on `s(u) = y` (safeguarded by bisection), then `x = u^γ`.
    pub fn exposure(&self, code_fraction: f64) -> f64 {
        let y = code_fraction.clamp(0.0, 1.0);
        let c = self.s_strength;
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        let mut u = y;
        for _ in 0..100 {
            let s = u - c * (TAU * u).sin() / TAU - y;
            if s > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            if s.abs() < 1e-15 {
                break;
            }
            let ds = 1.0 - c * (TAU * u).cos();
            let next = u - s / ds;
            u = if next > lo && next < hi { next } else { 0.5 * (lo + hi) };
        }
        u.clamp(0.0, 1.0).powf(self.gamma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_points_and_monotone() {
        let f = ParametricResponse::new(2.2, 0.6).unwrap();
        assert_eq!(f.code_fraction(0.0), 0.0);
        assert!((f.code_fraction(1.0) - 1.0).abs() < 1e-12);
        let mut prev = -1.0;
        for i in 0..=10_000 {
            let y = f.code_fraction(i as f64 / 10_000.0);
            assert!(y > prev, "not strictly increasing at {i}");
            prev = y;
        }
    }

    #[test]
    fn inverse_round_trips_to_1e_12() {
        let f = ParametricResponse::new(1.8, 0.45).unwrap();
        for i in 1..1000 {
            let x = (i as f64 / 1000.0).powi(3);
            let back = f.exposure(f.code_fraction(x));
            assert!((back - x).abs() <= 1e-12 * x.max(1e-3), "x = {x}, back = {back}");
        }
    }

    #[test]
    fn rejects_non_monotone_parameters() {
        assert!(ParametricResponse::new(2.2, 1.0).is_err());
        assert!(ParametricResponse::new(0.0, 0.5).is_err());
        assert!(ParametricResponse::new(f64::NAN, 0.5).is_err());
    }
}
