//! Daylight for rendering: a sky per channel (eq. 5.9), the solar disc
//! through the atmosphere (§5.5.1), sunrise and sunset reddening (§5.5.1)
//! and cloud cover (§5.6.3). This is what the simulator's world is lit by,
//! and what the relighting stage renders a novel time with.
//!
//! The aureole is the sky model's circumsolar factor `Sa(γ)`; the disc is a
//! uniform 0.533° disc whose radiance is the direct normal irradiance
//! `E₀ exp(−β m)` spread over its solid angle.

use nalgebra::Vector3;

use super::cie::{CieSky, CieSkyType};
use super::geometry::angle_between;
use super::predict::redden;
use super::seven_parameter::{SkyAngles, SkyModel};
use crate::render::sky::{Sky, SolarDisc};
use crate::sun::air_mass;

/// The mean angular radius of the sun, radians (0.2666°).
pub const SUN_ANGULAR_RADIUS_RAD: f64 = 0.2666 * std::f64::consts::PI / 180.0;

/// The air mass below which the sky keeps its daytime colour; lower suns
/// are reddened by the extra air (§5.5.1). `m(60°) ≈ 2.0`.
pub const REDDENING_ONSET_AIR_MASS: f64 = 2.0;

/// A clear atmosphere: how bright and what colour the sun and sky are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Atmosphere {
    /// Direct normal irradiance outside the atmosphere per channel, W·m⁻².
    pub e0: [f64; 3],
    /// Extinction per unit air mass per channel (§5.5.1).
    pub beta: [f64; 3],
    /// The CIE standard sky giving the sky's shape.
    pub sky_type: CieSkyType,
    /// Zenith radiance per channel with the sun at the zenith, W·m⁻²·sr⁻¹;
    /// it scales as `√cos Zs` with the sun's zenith angle Zs.
    pub zenith_radiance: [f64; 3],
}

impl Atmosphere {
    /// A clear, low-turbidity day (CIE type 12) in camera channels of
    /// roughly equal width: sun 190–200 W·m⁻² per channel outside the
    /// atmosphere, blue extinguished most, a blue zenith.
    pub fn clear() -> Atmosphere {
        Atmosphere {
            e0: [195.0, 200.0, 190.0],
            beta: [0.10, 0.15, 0.25],
            sky_type: CieSkyType::new(12).unwrap_or_else(|| unreachable!("CIE type 12 exists")),
            zenith_radiance: [3.0, 5.0, 9.0],
        }
    }
}

/// Sun and sky at one moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Daylight {
    /// Unit vector toward the sun (world frame, z up).
    pub sun_direction: [f64; 3],
    /// The sky per channel, eq. (5.9), already blended with any overcast.
    pub sky: [SkyModel; 3],
    /// The overcast sky blended in, per channel, and the fraction of sunlight blocked (§5.6.3).
    pub overcast: Option<([SkyModel; 3], f64)>,
    /// Radiance of the solar disc per channel, W·m⁻²·sr⁻¹ (after extinction and clouds).
    pub sun_radiance: [f64; 3],
    /// Angular radius of the disc, radians.
    pub sun_angular_radius_rad: f64,
}

impl Daylight {
    /// Clear daylight for the sun at unit direction `sun` through `atmosphere`.
    /// Below the horizon there is no disc and the sky fades to zero at −6°
    /// (civil twilight).
    pub fn clear(sun: [f64; 3], atmosphere: &Atmosphere) -> Daylight {
        let zenith = sun[2].clamp(-1.0, 1.0).acos();
        let elevation = std::f64::consts::FRAC_PI_2 - zenith;
        // Day: √cos Zs; twilight: a linear fade to zero at −6°.
        let twilight = (1.0 + elevation / 6f64.to_radians()).clamp(0.0, 1.0);
        let scale = if elevation > 0.0 { sun[2].sqrt().max(0.0) } else { 0.0 }.max(0.02 * twilight);
        let shape_zenith = zenith.min(std::f64::consts::FRAC_PI_2);
        let mut sky = atmosphere
            .zenith_radiance
            .map(|lz| CieSky::new(atmosphere.sky_type, lz * scale, shape_zenith).as_seven_parameter());
        let m = air_mass(shape_zenith);
        if m > REDDENING_ONSET_AIR_MASS {
            sky = redden(sky, atmosphere.beta, m - REDDENING_ONSET_AIR_MASS);
        }
        let omega = std::f64::consts::TAU * (1.0 - SUN_ANGULAR_RADIUS_RAD.cos());
        let sun_radiance = if elevation > -SUN_ANGULAR_RADIUS_RAD {
            [0, 1, 2].map(|c| atmosphere.e0[c] * (-atmosphere.beta[c] * m).exp() / omega)
        } else {
            [0.0; 3]
        };
        Daylight {
            sun_direction: sun,
            sky,
            overcast: None,
            sun_radiance,
            sun_angular_radius_rad: SUN_ANGULAR_RADIUS_RAD,
        }
    }

    /// The same moment under a cloud layer blocking `blocked` (0–1) of the
    /// sunlight (§5.6.3): the sky becomes `(1 − p) clear + p overcast` (CIE
    /// type 1 of zenith radiance `overcast_zenith` per channel) and the disc
    /// is dimmed by `1 − p`.
    pub fn with_clouds(mut self, blocked: f64, overcast_zenith: [f64; 3]) -> Daylight {
        let p = if blocked.is_finite() {
            blocked.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let kind = CieSkyType::new(1).unwrap_or_else(|| unreachable!("CIE type 1 exists"));
        let zs = self.sun_direction[2]
            .clamp(-1.0, 1.0)
            .acos()
            .min(std::f64::consts::FRAC_PI_2);
        let overcast = overcast_zenith.map(|lz| CieSky::new(kind, lz, zs).as_seven_parameter());
        self.overcast = Some((overcast, p));
        self.sun_radiance = self.sun_radiance.map(|l| l * (1.0 - p));
        self
    }

    /// Sky radiance (without the disc) from unit direction `d` per channel;
    /// zero below the horizon, where the scene's ground is.
    pub fn sky_radiance(&self, d: [f64; 3]) -> [f64; 3] {
        if d[2] <= 0.0 {
            return [0.0; 3];
        }
        let xi = d[2].min(1.0).acos();
        let gamma = angle_between(d, self.sun_direction);
        let at = SkyAngles::new(xi, gamma);
        [0, 1, 2].map(|c| {
            let clear = self.sky[c].radiance_at(&at);
            match &self.overcast {
                Some((o, p)) => (1.0 - p) * clear + p * o[c].radiance_at(&at),
                None => clear,
            }
        })
    }

    /// Direct normal irradiance of the sun per channel, W·m⁻².
    pub fn sun_irradiance(&self) -> [f64; 3] {
        let omega = std::f64::consts::TAU * (1.0 - self.sun_angular_radius_rad.cos());
        self.sun_radiance.map(|l| l * omega)
    }
}

impl Sky for Daylight {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        self.sky_radiance([d.x, d.y, d.z])
    }

    fn sun(&self) -> Option<SolarDisc> {
        (self.sun_radiance.iter().any(|l| *l > 0.0)).then(|| SolarDisc {
            direction: Vector3::new(self.sun_direction[0], self.sun_direction[1], self.sun_direction[2]).normalize(),
            angular_radius_rad: self.sun_angular_radius_rad,
            radiance: self.sun_radiance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::geometry::direction;

    #[test]
    fn disc_carries_the_extinguished_normal_irradiance() {
        let atm = Atmosphere::clear();
        let zs = 40f64.to_radians();
        let day = Daylight::clear(direction(zs, 1.0), &atm);
        let e = day.sun_irradiance();
        for (c, e) in e.iter().enumerate() {
            let expected = atm.e0[c] * (-atm.beta[c] * air_mass(zs)).exp();
            assert!((e / expected - 1.0).abs() < 1e-12);
        }
        // The zenith radiance is the configured one scaled by √cos Zs.
        let z = day.sky_radiance([0.0, 0.0, 1.0]);
        for c in 0..3 {
            assert!(
                (z[c] / (atm.zenith_radiance[c] * zs.cos().sqrt()) - 1.0).abs() < 1e-9,
                "{z:?}"
            );
        }
    }

    #[test]
    fn low_sun_is_redder_and_night_is_dark() {
        let atm = Atmosphere::clear();
        let high = Daylight::clear(direction(30f64.to_radians(), 0.0), &atm);
        let low = Daylight::clear(direction(87f64.to_radians(), 0.0), &atm);
        let ratio = |d: &Daylight| d.sun_radiance[0] / d.sun_radiance[2];
        assert!(ratio(&low) > 3.0 * ratio(&high), "{} vs {}", ratio(&low), ratio(&high));
        // The aureole reddens with the sun.
        let near_sun = |d: &Daylight| {
            let s = d.sun_direction;
            let v = direction(s[2].acos() - 0.05, s[0].atan2(s[1]));
            let l = d.sky_radiance(v);
            l[0] / l[2]
        };
        assert!(near_sun(&low) > 1.5 * near_sun(&high));
        let night = Daylight::clear(direction(100f64.to_radians(), 0.0), &atm);
        assert_eq!(night.sun(), None);
        assert_eq!(night.sky_radiance([0.0, 0.0, 1.0]), [0.0; 3]);
    }

    #[test]
    fn full_cloud_removes_the_sun_and_gives_the_overcast_sky() {
        let atm = Atmosphere::clear();
        let day = Daylight::clear(direction(35f64.to_radians(), 2.0), &atm).with_clouds(1.0, [4.0; 3]);
        assert!(day.sun().is_none());
        let zen = day.sky_radiance([0.0, 0.0, 1.0]);
        assert!(zen.iter().all(|l| (l - 4.0).abs() < 1e-9), "{zen:?}");
        // CIE overcast: the horizon is a third of the zenith.
        let hor = day.sky_radiance(direction(89.9f64.to_radians(), 0.5));
        assert!((hor[0] / 4.0 - 1.0 / 3.0).abs() < 0.02, "{hor:?}");
    }
}
