//! The light of one time as the renderer and the outdoor solver take it
//! ([`crate::render::Sky`]): the eq. 5.9 sky per channel, fitted or
//! predicted, and the solar disc at the measured or predicted irradiance.

use nalgebra::Vector3;

use super::OccurrenceLight;
use crate::render::{Sky, SolarDisc};
use crate::sky::{
    KnownSky, OvercastSky, PredictError, SUN_ANGULAR_RADIUS_RAD, SkyAngles, SkyModel, angle_between, predict_sky,
};
use crate::sun::{Extinction, SunPosition, air_mass, fit_extinction};

/// A sky of three eq. (5.9) models and a solar disc.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSky {
    /// Unit vector toward the sun.
    pub sun_direction: [f64; 3],
    /// The sky per channel.
    pub models: [SkyModel; 3],
    /// Irradiance normal to the sun per channel, W·m⁻² (0 when the sun is
    /// hidden or unmeasured).
    pub sun_irradiance: [f64; 3],
    /// A cloud layer (§5.6.3): the fraction of sunlight it blocks, and the
    /// overcast sky (CIE type 1) per channel blended in by that fraction.
    pub overcast: Option<(f64, [SkyModel; 3])>,
}

impl MeasuredSky {
    /// This sky under a uniform cloud layer blocking `blocked` (0–1) of the
    /// sunlight (§5.6.3): the sun's irradiance times 1 − p, the sky
    /// `(1 − p) clear + p overcast`, the overcast sky the CIE standard
    /// overcast (type 1) holding the blocked direct light as diffuse light:
    /// its horizontal irradiance, `7π/9 · Lz` (exact for the Moon–Spencer
    /// sky, within 0.3% for CIE type 1), equals the sun's on the ground,
    /// `E_sun cos θs`.
    pub fn overcast(&self, blocked: f64) -> MeasuredSky {
        let p = blocked.clamp(0.0, 1.0);
        let cos_zs = self.sun_direction[2].max(0.0);
        let sun_zenith = cos_zs.acos();
        let models = [0, 1, 2].map(|c| {
            let lz = self.sun_irradiance[c] * cos_zs / (7.0 * std::f64::consts::PI / 9.0);
            OvercastSky::new(self.models[c], lz.max(1e-12), sun_zenith, p).overcast
        });
        MeasuredSky {
            overcast: Some((p, models)),
            ..self.clone()
        }
    }
}

impl Sky for MeasuredSky {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        if d.z <= 0.0 {
            return [0.0; 3];
        }
        let d = [d.x, d.y, d.z];
        let (xi, gamma) = (d[2].clamp(-1.0, 1.0).acos(), angle_between(d, self.sun_direction));
        let at = SkyAngles::new(xi, gamma);
        let clear = [0, 1, 2].map(|c| self.models[c].radiance_at(&at).max(0.0));
        match &self.overcast {
            None => clear,
            Some((p, o)) => [0, 1, 2].map(|c| (1.0 - p) * clear[c] + p * o[c].radiance_at(&at).max(0.0)),
        }
    }

    fn sun(&self) -> Option<SolarDisc> {
        if self.sun_direction[2] <= 0.0 || self.sun_irradiance.iter().all(|&e| e <= 0.0) {
            return None;
        }
        let disc = SolarDisc {
            direction: Vector3::from(self.sun_direction),
            angular_radius_rad: SUN_ANGULAR_RADIUS_RAD,
            radiance: [0.0; 3],
        };
        let omega = disc.solid_angle();
        let kept = 1.0 - self.overcast.as_ref().map_or(0.0, |(p, _)| *p);
        if kept <= 0.0 {
            return None;
        }
        Some(SolarDisc {
            radiance: self.sun_irradiance.map(|e| kept * e / omega),
            ..disc
        })
    }
}

/// Why the light at a time could not be had.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LightError {
    /// The occurrence has no fitted sky.
    #[error("{0}: no sky was fitted (see its notes)")]
    NoSky(String),
    /// The sky could not be predicted.
    #[error("predicting the sky: {0}")]
    Predict(#[from] PredictError),
    /// Fewer than two sun measurements: no extinction law.
    #[error(
        "the sun's irradiance at a new time needs sun shots at two or more times with different air masses ({0} given)"
    )]
    TooFewSuns(usize),
}

/// The sky measured at an occurrence.
pub fn measured_sky(l: &OccurrenceLight) -> Result<MeasuredSky, LightError> {
    let fits = l.sky.as_ref().ok_or_else(|| LightError::NoSky(l.occurrence.clone()))?;
    Ok(MeasuredSky {
        sun_direction: l.sun.direction(),
        models: [0, 1, 2].map(|c| fits[c].fit.model),
        sun_irradiance: l.sun_irradiance.as_ref().map_or([0.0; 3], |s| s.irradiance),
        overcast: None,
    })
}

/// The extinction law per channel fitted to the sun measurements of the
/// occurrences `use_it` accepts (Langley, against Kasten–Young air mass).
pub fn extinction(
    light: &[OccurrenceLight],
    use_it: impl Fn(&OccurrenceLight) -> bool,
) -> Result<[Extinction; 3], LightError> {
    let pts: Vec<(f64, [f64; 3])> = light
        .iter()
        .filter(|l| use_it(l))
        .filter_map(|l| l.sun_irradiance.as_ref().map(|s| (l.sun.zenith_rad, s.irradiance)))
        .collect();
    let fit = |c: usize| fit_extinction(&pts.iter().map(|&(z, e)| (z, e[c])).collect::<Vec<_>>());
    match (fit(0), fit(1), fit(2)) {
        (Ok(r), Ok(g), Ok(b)) => Ok([r, g, b]),
        _ => Err(LightError::TooFewSuns(pts.len())),
    }
}

/// The light predicted for a sun at `sun` from the training occurrences
/// (those not held out): the sky interpolated as §5.5.1 and
/// [`predict_sky`] do, the sun's irradiance from the extinction law.
pub fn predicted_sky(light: &[OccurrenceLight], sun: &SunPosition) -> Result<MeasuredSky, LightError> {
    let training: Vec<&OccurrenceLight> = light.iter().filter(|l| !l.held_out && l.sky.is_some()).collect();
    let dir = sun.direction();
    let mut models = Vec::with_capacity(3);
    for c in 0..3 {
        let known: Vec<KnownSky> = training
            .iter()
            .filter_map(|l| {
                l.sky.as_ref().map(|f| KnownSky {
                    sun: l.sun.direction(),
                    model: f[c].fit.model,
                })
            })
            .collect();
        models.push(predict_sky(&known, dir, 5.0)?.model);
    }
    let ext = extinction(light, |l| !l.held_out)?;
    let m = air_mass(sun.zenith_rad);
    Ok(MeasuredSky {
        sun_direction: dir,
        models: [models[0], models[1], models[2]],
        sun_irradiance: [0, 1, 2].map(|c| ext[c].e0 * (-ext[c].beta * m).exp()),
        overcast: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_disc_carries_the_irradiance_and_the_ground_is_dark() {
        let flat = SkyModel {
            lz: 2.0,
            a: 0.0,
            b: -1.0,
            c: 0.0,
            d: -1.0,
            e: 0.0,
            h: 1.0,
        };
        let sky = MeasuredSky {
            sun_direction: [0.0, 0.6, 0.8],
            models: [flat; 3],
            sun_irradiance: [800.0, 700.0, 600.0],
            overcast: None,
        };
        let disc = sky.sun().unwrap();
        for c in 0..3 {
            let e = disc.radiance[c] * disc.solid_angle();
            assert!((e / sky.sun_irradiance[c] - 1.0).abs() < 1e-12);
        }
        // Bg = 1 + 0·…, aureole 1 + 0·…: a uniform Lz above the horizon.
        assert_eq!(sky.radiance(&Vector3::new(0.0, 0.0, 1.0)), [2.0; 3]);
        assert_eq!(sky.radiance(&Vector3::new(0.0, 0.0, -1.0)), [0.0; 3]);
        let night = MeasuredSky {
            sun_direction: [0.0, 0.6, -0.8],
            ..sky
        };
        assert!(night.sun().is_none());
    }

    #[test]
    fn a_full_overcast_keeps_the_suns_light_on_the_ground_as_diffuse_light() {
        let flat = SkyModel {
            lz: 0.0,
            a: 0.0,
            b: -1.0,
            c: 0.0,
            d: -1.0,
            e: 0.0,
            h: 1.0,
        };
        let sky = MeasuredSky {
            sun_direction: [0.0, 0.6, 0.8],
            models: [flat; 3],
            sun_irradiance: [800.0, 700.0, 600.0],
            overcast: None,
        };
        let cloudy = sky.overcast(1.0);
        assert!(cloudy.sun().is_none());
        // Horizontal irradiance of the sky by quadrature: E_sun cos θs.
        let n = 400;
        for c in 0..3 {
            let mut e = 0.0;
            for i in 0..n {
                let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..2 * n {
                    let phi = (j as f64 + 0.5) / (2 * n) as f64 * std::f64::consts::TAU;
                    let d = Vector3::new(theta.sin() * phi.sin(), theta.sin() * phi.cos(), theta.cos());
                    e += cloudy.radiance(&d)[c] * theta.cos() * theta.sin();
                }
            }
            e *= (std::f64::consts::FRAC_PI_2 / n as f64) * (std::f64::consts::TAU / (2 * n) as f64);
            let want = sky.sun_irradiance[c] * 0.8;
            // 7π/9 is exact for the Moon–Spencer overcast (1 + 2 cos θ)/3;
            // CIE type 1's gradation differs from it by 0.3% here.
            assert!((e / want - 1.0).abs() < 0.005, "channel {c}: {e} vs {want}");
        }
        // Half blocked: half the disc, half the overcast.
        let half = sky.overcast(0.5);
        let d = half.sun().unwrap();
        assert!((d.radiance[0] * d.solid_angle() - 400.0).abs() < 1e-9);
    }
}
