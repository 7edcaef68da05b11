//! The fifteen CIE standard general skies (CIE S 011/E:2003, ISO
//! 15469:2004): relative luminance
//!
//! `L(ξ, γ) / Lz = f(γ) φ(ξ) / (f(Zs) φ(0))`
//!
//! with the gradation `φ(ξ) = 1 + a exp(b / cos ξ)` (φ = 1 at the
//! horizon), the indicatrix `f(χ) = 1 + c [exp(d χ) − exp(d π/2)] + e cos² χ`,
//! Zs the sun's zenith angle and Lz the zenith luminance. The thesis notes
//! these are fixed distributions, not fitting models; the station uses them
//! as candidate models and as test skies.

use super::seven_parameter::{COS_XI_FLOOR, SkyModel};

/// Gradation groups I–VI: (a, b).
const GRADATION: [(f64, f64); 6] = [
    (4.0, -0.70),
    (1.1, -0.8),
    (0.0, -1.0),
    (-1.0, -0.55),
    (-1.0, -0.32),
    (-1.0, -0.15),
];

/// Indicatrix groups 1–6: (c, d, e).
const INDICATRIX: [(f64, f64, f64); 6] = [
    (0.0, -1.0, 0.0),
    (2.0, -1.5, 0.15),
    (5.0, -2.5, 0.30),
    (10.0, -3.0, 0.45),
    (16.0, -3.0, 0.30),
    (24.0, -2.8, 0.15),
];

/// The fifteen types as (gradation group, indicatrix group), 1-based, with
/// the standard's descriptions.
const TYPES: [(usize, usize, &str); 15] = [
    (1, 1, "CIE standard overcast sky, steep gradation, azimuthal uniformity"),
    (1, 2, "overcast, steep gradation, slight brightening toward the sun"),
    (2, 1, "overcast, moderately graded, azimuthal uniformity"),
    (2, 2, "overcast, moderately graded, slight brightening toward the sun"),
    (3, 1, "sky of uniform luminance"),
    (
        3,
        2,
        "partly cloudy, no gradation toward the zenith, slight brightening toward the sun",
    ),
    (
        3,
        3,
        "partly cloudy, no gradation toward the zenith, brighter circumsolar region",
    ),
    (
        3,
        4,
        "partly cloudy, no gradation toward the zenith, distinct solar corona",
    ),
    (4, 2, "partly cloudy, with the obscured sun"),
    (4, 3, "partly cloudy, with brighter circumsolar region"),
    (4, 4, "white-blue sky with distinct solar corona"),
    (5, 4, "CIE standard clear sky, low luminance turbidity"),
    (5, 5, "CIE standard clear sky, polluted atmosphere"),
    (6, 5, "cloudless turbid sky with broad solar corona"),
    (6, 6, "white-blue turbid sky with broad solar corona"),
];

/// A CIE standard sky type, 1 to 15.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CieSkyType(u8);

impl CieSkyType {
    /// Type `n`, or `None` outside 1–15.
    pub fn new(n: u8) -> Option<Self> {
        (1..=15).contains(&n).then_some(CieSkyType(n))
    }

    /// All fifteen.
    pub fn all() -> impl Iterator<Item = CieSkyType> {
        (1..=15).map(CieSkyType)
    }

    /// The type's number.
    pub fn number(self) -> u8 {
        self.0
    }

    /// The standard's description.
    pub fn description(self) -> &'static str {
        TYPES[usize::from(self.0) - 1].2
    }
}

/// A CIE standard sky for one sun position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CieSky {
    /// Which type.
    pub kind: CieSkyType,
    /// Zenith luminance (or radiance), the scale.
    pub lz: f64,
    /// The sun's zenith angle Zs, radians.
    pub sun_zenith: f64,
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    e: f64,
}

impl CieSky {
    /// The standard sky of `kind` with zenith value `lz` and the sun at
    /// zenith angle `sun_zenith` (radians).
    pub fn new(kind: CieSkyType, lz: f64, sun_zenith: f64) -> CieSky {
        let (g, i, _) = TYPES[usize::from(kind.0) - 1];
        let (a, b) = GRADATION[g - 1];
        let (c, d, e) = INDICATRIX[i - 1];
        CieSky {
            kind,
            lz,
            sun_zenith,
            a,
            b,
            c,
            d,
            e,
        }
    }

    /// The gradation φ(ξ), cos ξ floored at [`COS_XI_FLOOR`].
    fn gradation(&self, xi: f64) -> f64 {
        1.0 + self.a * (self.b / xi.cos().max(COS_XI_FLOOR)).exp()
    }

    /// The indicatrix f(χ).
    fn indicatrix(&self, chi: f64) -> f64 {
        let c2 = chi.cos();
        1.0 + self.c * ((self.d * chi).exp() - (self.d * std::f64::consts::FRAC_PI_2).exp()) + self.e * c2 * c2
    }

    /// Luminance (or radiance) at zenith angle ξ and angle γ from the sun.
    pub fn radiance(&self, xi: f64, gamma: f64) -> f64 {
        self.lz * self.indicatrix(gamma.abs()) * self.gradation(xi)
            / (self.indicatrix(self.sun_zenith) * self.gradation(0.0))
    }

    /// The same sky exactly as an eq. (5.9) model with h = 1: the
    /// indicatrix's constant `1 − c exp(dπ/2)` (positive for every type)
    /// moves into the scale, and the normalization into Lz.
    pub fn as_seven_parameter(&self) -> SkyModel {
        let k = 1.0 - self.c * (self.d * std::f64::consts::FRAC_PI_2).exp();
        let norm = self.lz / (self.indicatrix(self.sun_zenith) * self.gradation(0.0));
        SkyModel {
            lz: norm * k,
            a: self.a,
            b: self.b,
            c: self.c / k,
            d: self.d,
            e: self.e / k,
            h: 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn grid() -> impl Iterator<Item = (f64, f64)> {
        (0..=18).flat_map(|i| (0..=36).map(move |j| (f64::from(i) * FRAC_PI_2 / 18.0, f64::from(j) * PI / 36.0)))
    }

    #[test]
    fn every_type_is_one_at_the_zenith_for_every_sun() {
        for kind in CieSkyType::all() {
            for zs in [0.0, 0.5, 1.2, 1.55] {
                let sky = CieSky::new(kind, 1.0, zs);
                // At the zenith, γ equals the sun's zenith angle.
                assert!(
                    (sky.radiance(0.0, zs) - 1.0).abs() < 1e-12,
                    "type {} Zs {zs}",
                    kind.number()
                );
            }
        }
    }

    #[test]
    fn type_1_is_the_moon_spencer_overcast_sky_a_third_at_the_horizon() {
        // CIE overcast: the horizon is about a third as bright as the zenith
        // (1 / (1 + 4 e^-0.7) = 0.3349).
        let sky = CieSky::new(CieSkyType::new(1).expect("type"), 1.0, 0.6);
        assert!((sky.radiance(FRAC_PI_2, 1.0) - 1.0 / (1.0 + 4.0 * (-0.7f64).exp())).abs() < 1e-12);
        assert!((sky.radiance(FRAC_PI_2, 2.0) - 0.3349).abs() < 1e-4);
    }

    #[test]
    fn type_12_is_the_classic_cie_clear_sky_formula() {
        // Kittler's clear sky: (0.91 + 10 e^{-3γ} + 0.45 cos²γ)(1 − e^{-0.32/cos ξ})
        // normalized at the zenith.
        let zs = 0.8_f64;
        let sky = CieSky::new(CieSkyType::new(12).expect("type"), 1.0, zs);
        let f = |g: f64| 0.91 + 10.0 * (-3.0 * g).exp() + 0.45 * g.cos().powi(2);
        let phi = |x: f64| 1.0 - (-0.32 / x.cos()).exp();
        for (xi, gamma) in grid().filter(|(xi, _)| *xi < 1.5) {
            let want = f(gamma) * phi(xi) / (f(zs) * phi(0.0));
            // 0.91 is the standard's rounding of 1 − 10 e^{-3π/2} = 0.91018.
            assert!((sky.radiance(xi, gamma) / want - 1.0).abs() < 3e-3, "ξ {xi} γ {gamma}");
        }
    }

    #[test]
    fn every_type_is_exactly_a_seven_parameter_sky() {
        for kind in CieSkyType::all() {
            for zs in [0.1, 0.9, 1.5] {
                let cie = CieSky::new(kind, 3.7, zs);
                let m = cie.as_seven_parameter();
                for (xi, gamma) in grid() {
                    let (x, y) = (cie.radiance(xi, gamma), m.radiance(xi, gamma));
                    assert!(
                        (x - y).abs() <= 1e-12 * x.abs().max(1.0),
                        "type {} ξ {xi} γ {gamma}: {x} vs {y}",
                        kind.number()
                    );
                }
            }
        }
    }

    #[test]
    fn out_of_range_types_are_refused() {
        assert!(CieSkyType::new(0).is_none() && CieSkyType::new(16).is_none());
        assert_eq!(
            CieSkyType::new(15).map(CieSkyType::description),
            Some("white-blue turbid sky with broad solar corona")
        );
    }
}
