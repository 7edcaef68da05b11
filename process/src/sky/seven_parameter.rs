//! The seven-parameter sky model of the thesis, eq. (5.9):
//!
//! `L(ξ, γ) = Lz [1 + a exp(b / cos ξ)] [1 + c exp(d γ^h) + e cos² γ]`
//!
//! with Lz a scale, `Bg(ξ) = 1 + a exp(b / cos ξ)` the sky background and
//! `Sa(γ) = 1 + c exp(d γ^h) + e cos² γ` the solar aureole (§5.5.1).
//! It generalizes the Perez all-weather form (eq. 5.8), to which it reduces
//! for h = 1.

use serde::{Deserialize, Serialize};

/// The smallest cos ξ the background term is evaluated at. `b / cos ξ`
/// diverges at the horizon: with b > 0 (overcast-like gradations) the
/// exponential overflows, with b < 0 it underflows harmlessly. Like
/// RADIANCE's gendaylit, cos ξ is clamped at 0.01 (ξ ≈ 89.43°); directions
/// below the horizon take the horizon's value.
pub const COS_XI_FLOOR: f64 = 0.01;

/// One channel's sky, eq. (5.9). Radiance in W·m⁻²·sr⁻¹ (of whatever the
/// channel is), scaled by `lz`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SkyModel {
    /// Overall scale Lz.
    pub lz: f64,
    /// Background gradation coefficient a.
    pub a: f64,
    /// Background gradation exponent b.
    pub b: f64,
    /// Aureole strength c.
    pub c: f64,
    /// Aureole decay d.
    pub d: f64,
    /// Forward-scattering term e.
    pub e: f64,
    /// Exponent h of γ in the aureole (h = 1: the Perez form).
    pub h: f64,
}

impl SkyModel {
    /// `Bg(ξ) = 1 + a exp(b / cos ξ)`, with cos ξ floored at [`COS_XI_FLOOR`].
    pub fn background(&self, xi: f64) -> f64 {
        1.0 + self.a * (self.b / xi.cos().max(COS_XI_FLOOR)).exp()
    }

    /// `Sa(γ) = 1 + c exp(d γ^h) + e cos² γ`.
    pub fn aureole(&self, gamma: f64) -> f64 {
        let g = gamma.abs();
        let cg = g.cos();
        1.0 + self.c * (self.d * g.powf(self.h)).exp() + self.e * cg * cg
    }

    /// Radiance of the sky element at zenith angle ξ and angle γ from the
    /// sun, eq. (5.9).
    pub fn radiance(&self, xi: f64, gamma: f64) -> f64 {
        self.lz * self.background(xi) * self.aureole(gamma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_5_9_factorizes_into_scale_background_and_aureole() {
        let m = SkyModel {
            lz: 2.0,
            a: -1.0,
            b: -0.32,
            c: 10.0,
            d: -3.0,
            e: 0.45,
            h: 1.0,
        };
        let (xi, gamma) = (0.7_f64, 0.3_f64);
        let direct =
            2.0 * (1.0 - (-0.32 / xi.cos()).exp()) * (1.0 + 10.0 * (-3.0 * gamma).exp() + 0.45 * gamma.cos().powi(2));
        assert!((m.radiance(xi, gamma) - direct).abs() < 1e-14);
    }

    #[test]
    fn the_horizon_is_finite_for_every_sign_of_b() {
        for b in [-1.0, -0.15, 0.0, 0.5, 3.0] {
            let m = SkyModel {
                lz: 1.0,
                a: 1.0,
                b,
                c: 1.0,
                d: -1.0,
                e: 0.1,
                h: 1.0,
            };
            for xi in [1.5, std::f64::consts::FRAC_PI_2, 1.6, 3.0] {
                let l = m.radiance(xi, 0.5);
                assert!(l.is_finite(), "b {b} ξ {xi}: {l}");
            }
            // Below the horizon the value is the horizon's.
            assert_eq!(m.radiance(2.0, 0.5), m.radiance(std::f64::consts::FRAC_PI_2, 0.5));
        }
    }
}
