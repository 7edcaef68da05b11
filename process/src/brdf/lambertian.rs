//! The Lambertian (ideal diffuse) BRDF `f = ρ / π` (thesis §4.4, the
//! diffuse term of eq. A.3), and cosine-weighted hemisphere sampling, whose
//! density `cos θi / π` makes the estimator `f cos θi / pdf = ρ` constant.

use std::f64::consts::{FRAC_1_PI, PI};

use nalgebra::Vector3;

use super::error::BrdfError;
use super::frame::{HORIZON_COS, above_horizon};
use super::quadrature::HemisphereQuadrature;
use super::sample::Sample;

/// An ideal diffuse reflector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lambertian {
    /// Reflectance ρ per channel, in [0, 1].
    pub albedo: [f64; 3],
}

impl Lambertian {
    /// The reflector of albedo ρ, checked by [`Lambertian::validate`].
    pub fn new(albedo: [f64; 3]) -> Result<Lambertian, BrdfError> {
        let l = Lambertian { albedo };
        l.validate()?;
        Ok(l)
    }

    /// Errors: [`BrdfError::InvalidReflectance`] when a channel is outside
    /// [0, 1] or not finite.
    pub fn validate(&self) -> Result<(), BrdfError> {
        check_reflectance("albedo", &self.albedo)
    }

    /// The BRDF `f(wi, wo) = ρ / π`, sr⁻¹; zero when either direction is at
    /// or below the horizon ([`HORIZON_COS`]).
    pub fn eval(&self, wi: &Vector3<f64>, wo: &Vector3<f64>) -> [f64; 3] {
        if above_horizon(wi) && above_horizon(wo) {
            self.albedo.map(|r| r * FRAC_1_PI)
        } else {
            [0.0; 3]
        }
    }

    /// A cosine-weighted direction from the uniform numbers `u` in [0, 1)²
    /// (see [`cosine_direction`]), or `None` when `wo` is below the horizon.
    pub fn sample(&self, wo: &Vector3<f64>, u: [f64; 2]) -> Option<Sample> {
        if !above_horizon(wo) {
            return None;
        }
        let wi = cosine_direction(u)?;
        Some(Sample {
            wi,
            pdf: cosine_pdf(&wi),
            value: self.eval(&wi, wo),
        })
    }

    /// The density of [`Lambertian::sample`] at `wi`, per unit solid angle:
    /// `cos θi / π` (zero at or below the horizon, or when `wo` is).
    pub fn pdf(&self, wi: &Vector3<f64>, wo: &Vector3<f64>) -> f64 {
        if above_horizon(wo) { cosine_pdf(wi) } else { 0.0 }
    }

    /// `∫ f(wi, wo) cos θi dωi` by [`HemisphereQuadrature`] with
    /// `n_theta × n_phi` nodes: ρ (exactly, up to rounding, for any n ≥ 1).
    pub fn directional_albedo(&self, wo: &Vector3<f64>, n_theta: usize, n_phi: usize) -> [f64; 3] {
        HemisphereQuadrature::new(n_theta, n_phi).integrate_rgb(|wi| self.eval(wi, wo).map(|f| f * wi.z))
    }
}

/// The cosine-weighted direction (Malley's method on the polar map of the
/// disc) `(√u₀ cos 2πu₁, √u₀ sin 2πu₁, √(1 − u₀))` for `u` in [0, 1)², or
/// `None` when it would lie at the horizon (u₀ ≥ 1, or `u` not finite).
pub fn cosine_direction(u: [f64; 2]) -> Option<Vector3<f64>> {
    // `max` drops a NaN, so a NaN u₀ gives z = 0 and no direction.
    let z = (1.0 - u[0]).max(0.0).sqrt();
    if z <= HORIZON_COS {
        return None;
    }
    let r = u[0].max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u[1]).sin_cos();
    let w = Vector3::new(r * c, r * s, z);
    w.iter().all(|x| x.is_finite()).then_some(w)
}

/// The density of [`cosine_direction`], `cos θ / π` per unit solid angle,
/// zero at or below the horizon.
pub fn cosine_pdf(wi: &Vector3<f64>) -> f64 {
    if above_horizon(wi) { wi.z * FRAC_1_PI } else { 0.0 }
}

/// Checks each channel of a reflectance lies in [0, 1].
pub(crate) fn check_reflectance(name: &'static str, rho: &[f64; 3]) -> Result<(), BrdfError> {
    for (channel, &value) in rho.iter().enumerate() {
        if !(0.0..=1.0).contains(&value) {
            return Err(BrdfError::InvalidReflectance { name, channel, value });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn directional_albedo_is_rho() {
        let l = Lambertian::new([0.2, 0.5, 0.9]).unwrap();
        for theta_deg in [0.0_f64, 45.0, 89.0] {
            let t = theta_deg.to_radians();
            let wo = Vector3::new(t.sin(), 0.0, t.cos());
            let a = l.directional_albedo(&wo, 64, 64);
            for c in 0..3 {
                assert!((a[c] - l.albedo[c]).abs() < 1e-3, "θo = {theta_deg}: {a:?}");
            }
        }
        // Below the surface there is nothing to reflect.
        assert_eq!(l.directional_albedo(&Vector3::new(0.0, 0.6, -0.8), 16, 16), [0.0; 3]);
    }

    #[test]
    fn cosine_sampling_pdf_is_f_cos_over_rho() {
        let l = Lambertian::new([0.3, 0.3, 0.3]).unwrap();
        let wo = Vector3::new(0.6, 0.0, 0.8);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for _ in 0..1000 {
            let s = l.sample(&wo, [rng.random(), rng.random()]).unwrap();
            assert!((s.wi.norm() - 1.0).abs() < 1e-12);
            let expected = s.value[0] * s.wi.z / l.albedo[0];
            assert!((s.pdf - expected).abs() < 1e-12 * expected, "{} vs {expected}", s.pdf);
            assert_eq!(s.pdf, l.pdf(&s.wi, &wo));
        }
    }

    #[test]
    fn cosine_sampling_has_the_cosine_moments() {
        // E[cos θ] = ∫ cos θ · cos θ / π dω = 2/3 under the cosine density;
        // 100k samples: standard error √(1/18 / 1e5) ≈ 7.5e-4, tolerance 4σ.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n = 100_000;
        let mean = (0..n)
            .map(|_| cosine_direction([rng.random(), rng.random()]).unwrap().z)
            .sum::<f64>()
            / f64::from(n);
        assert!((mean - 2.0 / 3.0).abs() < 3e-3, "{mean}");
    }

    #[test]
    fn invalid_albedo_is_a_typed_error_and_edge_inputs_stay_finite() {
        for bad in [[-0.1, 0.5, 0.5], [0.5, 1.2, 0.5], [0.5, 0.5, f64::NAN]] {
            assert!(matches!(
                Lambertian::new(bad),
                Err(BrdfError::InvalidReflectance { .. })
            ));
        }
        assert_eq!(cosine_direction([1.0, 0.3]), None);
        assert_eq!(cosine_direction([f64::NAN, 0.3]), None);
        let l = Lambertian::new([0.5; 3]).unwrap();
        let horizon = Vector3::new(1.0, 0.0, 0.0);
        let up = Vector3::z();
        assert_eq!(l.eval(&horizon, &up), [0.0; 3]);
        assert_eq!(l.eval(&up, &-up), [0.0; 3]);
        assert!(l.sample(&-up, [0.5, 0.5]).is_none());
    }
}
