//! Irradiance from environment regions (Appendix B: "we calculate the
//! irradiance from the environment in the same way except that we do not
//! subdivide each environment region adaptively"): each region has one
//! radiance, so its irradiance is `L · (F · n)` with `F` the vector flux
//! (eq. B.1) of the region clipped by the tangent plane.

use nalgebra::Vector3;

use super::IrradianceError;
use super::clip::clip_to_hemisphere;
use super::spherical_polygon::SphericalPolygon;

/// Irradiance per channel (W·m⁻²) on the side `normal` from a region of
/// uniform `radiance` (W·m⁻²·sr⁻¹ per channel), eq. (B.1).
pub fn region_irradiance(
    normal: &Vector3<f64>,
    region: &SphericalPolygon,
    radiance: [f64; 3],
) -> Result<[f64; 3], IrradianceError> {
    let n = super::unit_normal(normal)?;
    let Some(seen) = clip_to_hemisphere(region, &n)? else {
        return Ok([0.0; 3]);
    };
    let cos_flux = seen.vector_flux().dot(&n);
    Ok(radiance.map(|l| if l.is_finite() { l * cos_flux } else { 0.0 }))
}

/// The sum of [`region_irradiance`] over regions and their radiances.
pub fn environment_irradiance(
    normal: &Vector3<f64>,
    regions: &[(SphericalPolygon, [f64; 3])],
) -> Result<[f64; 3], IrradianceError> {
    let mut e = [0.0; 3];
    for (region, radiance) in regions {
        let r = region_irradiance(normal, region, *radiance)?;
        for ch in 0..3 {
            e[ch] += r[ch];
        }
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    #[test]
    fn ground_and_sky_halves_give_the_tilted_view_factors() {
        // Upper hemisphere of radiance 2, lower of 1 (the ground), plane tilted by β:
        // E = 2 π (1 + cos β)/2 + π (1 − cos β)/2.
        let ring = [Vector3::x(), Vector3::y(), -Vector3::x(), -Vector3::y()];
        let upper = SphericalPolygon::new(ring.to_vec()).unwrap();
        let lower = SphericalPolygon::new(ring.iter().rev().copied().collect()).unwrap();
        for beta_deg in [0.0_f64, 45.0, 90.0, 135.0, 180.0] {
            let beta = beta_deg.to_radians();
            let n = Vector3::new(beta.sin(), 0.0, beta.cos());
            let e = environment_irradiance(&n, &[(upper.clone(), [2.0; 3]), (lower.clone(), [1.0; 3])]).unwrap();
            let exact = 2.0 * PI * (1.0 + beta.cos()) / 2.0 + PI * (1.0 - beta.cos()) / 2.0;
            assert!((e[0] - exact).abs() < 1e-12, "β {beta_deg}: {} vs {exact}", e[0]);
        }
    }
}
