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

/// A sky element's angles as eq. (5.9) takes them, with the trigonometry
/// every channel's model shares worked out once: cos ξ (floored at
/// [`COS_XI_FLOOR`]), |γ| and cos γ, and γ^h for the last exponent asked.
/// Three channels (and an overcast blend) at one direction then cost two
/// cosines, not six to twelve; the numbers are the same to the last bit.
#[derive(Debug, Clone)]
pub struct SkyAngles {
    cos_xi: f64,
    gamma: f64,
    cos_gamma: f64,
    /// The last `(h, |γ|^h)` worked out.
    power: std::cell::Cell<(f64, f64)>,
}

impl SkyAngles {
    /// The angles of the element at zenith angle `xi` and angle `gamma`
    /// from the sun, radians.
    pub fn new(xi: f64, gamma: f64) -> SkyAngles {
        let g = gamma.abs();
        SkyAngles {
            cos_xi: xi.cos().max(COS_XI_FLOOR),
            gamma: g,
            cos_gamma: g.cos(),
            // γ¹ is γ (pow is exact there).
            power: std::cell::Cell::new((1.0, g)),
        }
    }

    /// |γ|^h.
    fn gamma_pow(&self, h: f64) -> f64 {
        let (last, value) = self.power.get();
        if h == last {
            return value;
        }
        let value = self.gamma.powf(h);
        self.power.set((h, value));
        value
    }
}

impl SkyModel {
    /// `Bg(ξ) = 1 + a exp(b / cos ξ)`, with cos ξ floored at [`COS_XI_FLOOR`].
    pub fn background(&self, xi: f64) -> f64 {
        self.background_at(&SkyAngles::new(xi, 0.0))
    }

    /// `Sa(γ) = 1 + c exp(d γ^h) + e cos² γ`.
    pub fn aureole(&self, gamma: f64) -> f64 {
        self.aureole_at(&SkyAngles::new(0.0, gamma))
    }

    /// [`SkyModel::background`] at angles worked out once.
    pub fn background_at(&self, at: &SkyAngles) -> f64 {
        1.0 + self.a * (self.b / at.cos_xi).exp()
    }

    /// [`SkyModel::aureole`] at angles worked out once.
    pub fn aureole_at(&self, at: &SkyAngles) -> f64 {
        let cg = at.cos_gamma;
        1.0 + self.c * (self.d * at.gamma_pow(self.h)).exp() + self.e * cg * cg
    }

    /// Radiance of the sky element at zenith angle ξ and angle γ from the
    /// sun, eq. (5.9).
    pub fn radiance(&self, xi: f64, gamma: f64) -> f64 {
        self.radiance_at(&SkyAngles::new(xi, gamma))
    }

    /// [`SkyModel::radiance`] at angles worked out once (for several
    /// channels at one direction).
    pub fn radiance_at(&self, at: &SkyAngles) -> f64 {
        self.lz * self.background_at(at) * self.aureole_at(at)
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

    /// The shared angles give eq. (5.9) as written, per channel, bit for
    /// bit: exponents of 1 (the Perez form, where γ^h is γ itself), shared
    /// and differing exponents, below the horizon, γ < 0 and γ = 0.
    #[test]
    fn shared_angles_give_the_per_channel_formula_to_the_last_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let formula = |m: &SkyModel, xi: f64, gamma: f64| {
            let g = gamma.abs();
            let bg = 1.0 + m.a * (m.b / xi.cos().max(COS_XI_FLOOR)).exp();
            let sa = 1.0 + m.c * (m.d * g.powf(m.h)).exp() + m.e * g.cos() * g.cos();
            m.lz * bg * sa
        };
        for k in 0..20_000 {
            let h = |rng: &mut rand_chacha::ChaCha8Rng| if k % 3 == 0 { 1.0 } else { 0.5 + rng.random::<f64>() };
            let shared = h(&mut rng);
            let models: Vec<SkyModel> = (0..4)
                .map(|c| SkyModel {
                    lz: 1.0 + rng.random::<f64>(),
                    a: rng.random::<f64>() * 2.0 - 1.0,
                    b: rng.random::<f64>() - 0.7,
                    c: 20.0 * rng.random::<f64>(),
                    d: -4.0 * rng.random::<f64>(),
                    e: rng.random::<f64>(),
                    h: if c == 3 { h(&mut rng) } else { shared },
                })
                .collect();
            let xi = rng.random::<f64>() * 3.2;
            let gamma = match k % 5 {
                0 => 0.0,
                1 => -rng.random::<f64>(),
                _ => rng.random::<f64>() * std::f64::consts::PI,
            };
            let at = SkyAngles::new(xi, gamma);
            for m in &models {
                assert_eq!(
                    m.radiance_at(&at).to_bits(),
                    formula(m, xi, gamma).to_bits(),
                    "{m:?} ξ {xi} γ {gamma}"
                );
                assert_eq!(m.radiance(xi, gamma).to_bits(), formula(m, xi, gamma).to_bits());
            }
        }
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
