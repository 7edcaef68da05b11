//! Irradiance from the solar disc (§5.4: "the irradiance from the sun [from]
//! the surface normal, the color and solid angle of the sun"):
//! `E = L_disc · Ω · max(0, cos θ) · V`, with θ the angle between the normal
//! and the disc's centre and V the fraction of shadow rays toward the disc
//! that reach it (penumbra).
//!
//! The cosine is taken at the disc's centre, so a disc straddling the
//! tangent plane (within 0.27° of grazing) is counted by its centre only.

use nalgebra::Vector3;

use super::IrradianceError;
use super::sky::SHADOW_RAY_OFFSET;
use crate::render::{Ray, Scene, SolarDisc};

/// The golden angle, radians: successive shadow rays turn by it.
const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;

/// Irradiance from the sun and how much of the disc was visible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunIrradiance {
    /// Irradiance per channel, W·m⁻².
    pub rgb: [f64; 3],
    /// `max(0, cos θ)` between the normal and the disc's centre.
    pub cosine: f64,
    /// Fraction of the disc visible from the point, 0–1.
    pub visibility: f64,
}

/// Irradiance from the solar disc at `point` on the side `normal`.
/// Visibility: `rays` shadow rays (at least one) toward points spread
/// evenly over the disc (a golden-angle spiral of equal areas); `None`
/// occluders means an unobstructed sun. Deterministic.
pub fn sun_irradiance(
    point: &Vector3<f64>,
    normal: &Vector3<f64>,
    disc: &SolarDisc,
    occluders: Option<&Scene>,
    rays: u32,
) -> Result<SunIrradiance, IrradianceError> {
    let n = super::unit_normal(normal)?;
    let d = super::unit_normal(&disc.direction)?;
    let r = disc.angular_radius_rad;
    if !(r.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&r)) {
        return Err(IrradianceError::BadDisc { angular_radius_rad: r });
    }
    if !point.iter().all(|x| x.is_finite()) {
        return Err(IrradianceError::BadPoint {
            point: [point.x, point.y, point.z],
        });
    }
    let cosine = n.dot(&d).max(0.0);
    if cosine == 0.0 {
        return Ok(SunIrradiance {
            rgb: [0.0; 3],
            cosine,
            visibility: 0.0,
        });
    }
    let visibility = match occluders {
        None => 1.0,
        Some(scene) => {
            let origin = point + n * SHADOW_RAY_OFFSET * (1.0 + point.norm() * 1e-3);
            let helper = if d.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
            let e1 = d.cross(&helper).normalize();
            let e2 = d.cross(&e1);
            let k = rays.max(1);
            let seen = (0..k)
                .filter(|&j| {
                    let rho = r * ((f64::from(j) + 0.5) / f64::from(k)).sqrt();
                    let (s, c) = (GOLDEN_ANGLE * f64::from(j)).sin_cos();
                    let (sr, cr) = rho.sin_cos();
                    let direction = d * cr + (e1 * c + e2 * s) * sr;
                    !scene.occluded(&Ray { origin, direction }, f64::INFINITY)
                })
                .count();
            seen as f64 / f64::from(k)
        }
    };
    let omega = disc.solid_angle();
    Ok(SunIrradiance {
        rgb: disc.radiance.map(|l| l * omega * cosine * visibility),
        cosine,
        visibility,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Material, Triangle};

    fn disc(direction: Vector3<f64>) -> SolarDisc {
        SolarDisc {
            direction,
            angular_radius_rad: 0.2666_f64.to_radians(),
            radiance: [1.0e6, 2.0e6, 3.0e6],
        }
    }

    #[test]
    fn unobstructed_sun_is_radiance_times_solid_angle_times_cosine() {
        let sun = disc(Vector3::new(0.0, 0.6, 0.8));
        let n = Vector3::new(0.0, 0.0, 1.0);
        let e = sun_irradiance(&Vector3::zeros(), &n, &sun, None, 16).unwrap();
        let omega = std::f64::consts::TAU * (1.0 - sun.angular_radius_rad.cos());
        for ch in 0..3 {
            assert!((e.rgb[ch] - sun.radiance[ch] * omega * 0.8).abs() < 1e-12 * e.rgb[ch]);
        }
        let back = sun_irradiance(&Vector3::zeros(), &-n, &sun, None, 16).unwrap();
        assert_eq!(back.rgb, [0.0; 3]);
    }

    #[test]
    fn a_screen_over_half_the_disc_gives_half_the_sun() {
        // The sun at the zenith; a screen at height 1 m covering x < 0.
        let sun = disc(Vector3::z());
        let big = 10.0;
        let tris = vec![
            Triangle::new(
                [
                    Vector3::new(-big, -big, 1.0),
                    Vector3::new(0.0, -big, 1.0),
                    Vector3::new(0.0, big, 1.0),
                ],
                0,
                0,
            )
            .unwrap(),
            Triangle::new(
                [
                    Vector3::new(-big, -big, 1.0),
                    Vector3::new(0.0, big, 1.0),
                    Vector3::new(-big, big, 1.0),
                ],
                0,
                0,
            )
            .unwrap(),
        ];
        let scene = Scene::new(tris, vec![Material::diffuse("screen", [0.5; 3])], vec!["screen".into()]).unwrap();
        let e = sun_irradiance(&Vector3::zeros(), &Vector3::z(), &sun, Some(&scene), 256).unwrap();
        assert!((e.visibility - 0.5).abs() < 0.02, "{}", e.visibility);
        assert!(e.rgb.iter().all(|x| x.is_finite()));
    }
}
