//! The directional albedo of a Ward lobe, `∫ ρs K(wi, wo) cos θi dωi`, by
//! quadrature over the half vector instead of over `wi`.
//!
//! Over `wi` a narrow lobe at a grazing `wo` is hard to resolve: the lobe
//! is squeezed in azimuth by `cos θi + cos θo` and cut by the horizon. Over
//! the half vector h (polar angle δ, azimuth φ from `wo`'s azimuth) the lobe
//! is `exp(−E)` with E ≈ δ²/α², whatever `wo`, and the horizon is a curve
//! with a closed form: `wi = 2 (wo·h) h − wo` has
//!
//! `cos θi = R cos(2δ − β)`, `tan β = sin θo cos φ / cos θo`,
//!
//! so `wi` is above the horizon exactly for `δ < δmax(φ) = (π/2 + β) / 2`
//! (and then `wo·h > 0` too). With `dωi = 4 (wo·h) dωh`,
//!
//! `a(wo) = ∫_0^{2π} ∫_0^{δmax(φ)} ρs K(wi, wo) cos θi 4 (wo·h) sin δ dδ dφ`,
//!
//! integrated by Gauss–Legendre in δ on two panels, `[0, min(δmax, 8 α_max)]`
//! (the lobe, where E reaches 64 at the latest) and the rest, and the
//! midpoint rule in φ (the inner integral is smooth and periodic in φ).

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::Vector3;

use super::frame::above_horizon;
use super::quadrature::gauss_legendre;
use super::ward::WardLobe;

/// Beyond this many α_max in δ the lobe's `exp(−E)` is below e⁻⁶⁴.
const LOBE_WIDTHS: f64 = 8.0;

impl WardLobe {
    /// The lobe's directional albedo `∫ ρs K(wi, wo) cos θi dωi` per channel
    /// (module doc: half-vector quadrature, `n_theta` Gauss–Legendre nodes
    /// per δ panel, `n_phi` azimuths). Deterministic. Measured against
    /// 1024 × 2048: 256 × 512 agrees within 2e-6 in every case tried (α from
    /// 0.03 to 0.6, anisotropic, θo up to 89°, all variants); 64 × 128
    /// within 1e-6 for isotropic lobes up to 80°, but only 2e-2 for the
    /// (αx, αy) = (0.6, 0.03) lobe at 89°. Zero when `wo` is at or below the
    /// horizon.
    pub fn directional_albedo(&self, wo: &Vector3<f64>, n_theta: usize, n_phi: usize) -> [f64; 3] {
        let k = self.kernel_albedo(wo, n_theta, n_phi);
        self.rho_s.map(|r| r * k)
    }

    /// [`WardLobe::directional_albedo`] per unit ρs.
    fn kernel_albedo(&self, wo: &Vector3<f64>, n_theta: usize, n_phi: usize) -> f64 {
        if !above_horizon(wo) || n_theta == 0 || n_phi == 0 {
            return 0.0;
        }
        let rule = gauss_legendre(n_theta);
        let sin_o = wo.x.hypot(wo.y);
        let (cos_o, phi_o) = (wo.z, wo.y.atan2(wo.x));
        let lobe_end = LOBE_WIDTHS * self.alpha_x.max(self.alpha_y);
        let dphi = 2.0 * PI / n_phi as f64;
        let mut total = 0.0;
        for j in 0..n_phi {
            let phi = (j as f64 + 0.5) * dphi;
            let beta = (sin_o * phi.cos()).atan2(cos_o);
            let delta_max = 0.5 * (FRAC_PI_2 + beta);
            let split = delta_max.min(lobe_end);
            let (sp, cp) = (phi_o + phi).sin_cos();
            let mut ring = 0.0;
            for (a, b) in [(0.0, split), (split, delta_max)] {
                if b <= a {
                    continue;
                }
                let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                for &(x, w) in &rule {
                    let (sd, cd) = (mid + half * x).sin_cos();
                    let h = Vector3::new(sd * cp, sd * sp, cd);
                    let wo_h = wo.dot(&h);
                    let wi = h * (2.0 * wo_h) - wo;
                    ring += w * half * self.kernel(&wi, wo) * wi.z * 4.0 * wo_h * sd;
                }
            }
            total += ring * dphi;
        }
        total
    }
}
