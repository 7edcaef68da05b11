//! The directional albedo of a Ward lobe per unit ρs, tabulated over the
//! viewing direction: `a(ωo) = ∫ K(α, ωi, ωo) cos θi dωi`. The solver
//! needs it for the light a glossy surface reflects of its own indirect
//! illumination (second order in [`super::radiosity`]); for the 1992 lobe
//! it is far from 1 away from the normal (about cos θo for a narrow lobe,
//! see `brdf::ward`), so it cannot be taken as 1.

use nalgebra::Vector3;

use crate::brdf::WardLobe;

/// Polar steps of the table, 0 to 90°.
const N_THETA: usize = 16;
/// Azimuth steps over [0, π) (the lobe is symmetric under φ → φ + π).
const N_PHI: usize = 8;

/// `a(θo, φo)` on a grid, linear in θ, nearest in φ.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SpecularAlbedo {
    values: Vec<f64>,
}

impl SpecularAlbedo {
    /// Tabulates the lobe's albedo by quadrature (32 × 64 nodes per entry).
    pub fn new(lobe: &WardLobe) -> SpecularAlbedo {
        let unit = WardLobe {
            rho_s: [1.0; 3],
            ..*lobe
        };
        let mut values = Vec::with_capacity((N_THETA + 1) * N_PHI);
        for i in 0..=N_THETA {
            let theta = (i as f64 / N_THETA as f64 * 90.0).min(89.5).to_radians();
            for j in 0..N_PHI {
                let phi = j as f64 / N_PHI as f64 * std::f64::consts::PI;
                let wo = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                values.push(unit.directional_albedo(&wo, 32, 64)[0]);
            }
        }
        SpecularAlbedo { values }
    }

    /// The albedo toward local direction `wo` (0 below the horizon).
    pub fn at(&self, wo: &Vector3<f64>) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let t = wo.z.clamp(0.0, 1.0).acos() / std::f64::consts::FRAC_PI_2 * N_THETA as f64;
        let i = (t.floor() as usize).min(N_THETA - 1);
        let f = (t - i as f64).clamp(0.0, 1.0);
        let phi = wo.y.atan2(wo.x).rem_euclid(std::f64::consts::PI);
        let j = ((phi / std::f64::consts::PI * N_PHI as f64).round() as usize) % N_PHI;
        self.values[i * N_PHI + j] * (1.0 - f) + self.values[(i + 1) * N_PHI + j] * f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::WardVariant;

    #[test]
    fn the_table_matches_the_quadrature_and_the_normal_incidence_series() {
        let lobe = WardLobe::isotropic([0.3; 3], 0.1, WardVariant::Ward1992).unwrap();
        let t = SpecularAlbedo::new(&lobe);
        // 1 − 3α² + 11α⁴ at normal incidence (brdf::ward's measured series).
        let a0 = t.at(&Vector3::z());
        assert!((a0 - (1.0 - 0.03 + 0.0011)).abs() < 2e-3, "{a0}");
        let wo = Vector3::new(0.5f64.sqrt(), 0.0, 0.5f64.sqrt());
        let q = lobe.directional_albedo(&wo, 64, 128)[0] / 0.3;
        assert!((t.at(&wo) - q).abs() < 0.01 * q, "{} vs {q}", t.at(&wo));
    }
}
