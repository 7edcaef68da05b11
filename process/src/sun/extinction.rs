//! Atmospheric extinction of sunlight (thesis §5.5.1): sunlight through an
//! air mass m arrives attenuated as `E = E₀ exp(−β m)`, with a β per
//! channel; fitted to solar irradiance measured through a day, it gives the
//! sun's (and aureole's) colour at any elevation, reddened near sunrise and
//! sunset.

/// Relative optical air mass at apparent solar zenith angle `zenith_rad`
/// (Kasten & Young 1989): `1 / (cos Z + 0.50572 (96.07995° − Z)^−1.6364)`,
/// Z in degrees; about 38 at the horizon ("the optical depth at the
/// horizon is about 38 times that at the zenith", §5.5.1).
pub fn air_mass(zenith_rad: f64) -> f64 {
    let z = zenith_rad.to_degrees().clamp(0.0, 90.0);
    1.0 / (z.to_radians().cos() + 0.50572 * (96.07995 - z).powf(-1.6364))
}

/// A fitted extinction law for one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extinction {
    /// Irradiance outside the atmosphere (m = 0), W·m⁻².
    pub e0: f64,
    /// Extinction coefficient per unit air mass.
    pub beta: f64,
    /// RMS residual of ln E.
    pub rms_log: f64,
    /// Span of air masses measured (max − min).
    pub air_mass_span: f64,
}

impl Extinction {
    /// The irradiance at apparent zenith angle `zenith_rad`.
    pub fn irradiance(&self, zenith_rad: f64) -> f64 {
        self.e0 * (-self.beta * air_mass(zenith_rad)).exp()
    }
}

/// Why extinction could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExtinctionError {
    /// Too few measurements.
    #[error("{0} sun measurements; at least 2 at different elevations are needed")]
    TooFew(usize),
    /// A measurement is not a positive, finite irradiance at a valid zenith.
    #[error(
        "measurement {index}: irradiance {irradiance} at zenith {zenith_deg}° is not usable (need a positive irradiance and a zenith in [0, 90]°)"
    )]
    Invalid {
        /// Index.
        index: usize,
        /// Irradiance.
        irradiance: f64,
        /// Zenith, degrees.
        zenith_deg: f64,
    },
    /// The air masses are too close together to separate E₀ from β.
    #[error(
        "the measurements span only {span:.3} air masses (need ≥ {needed}): extinction is ill-conditioned; add a morning or evening sun shot"
    )]
    IllConditioned {
        /// The span.
        span: f64,
        /// The minimum.
        needed: f64,
    },
}

/// The smallest air-mass span that separates E₀ from β.
pub const MIN_AIR_MASS_SPAN: f64 = 0.3;

/// Fits `ln E = ln E₀ − β m` by least squares to `(zenith_rad, irradiance)`
/// pairs of one channel (the Langley method).
pub fn fit_extinction(measurements: &[(f64, f64)]) -> Result<Extinction, ExtinctionError> {
    if measurements.len() < 2 {
        return Err(ExtinctionError::TooFew(measurements.len()));
    }
    let mut pts = Vec::with_capacity(measurements.len());
    for (index, &(z, e)) in measurements.iter().enumerate() {
        if !(e > 0.0 && e.is_finite() && (0.0..=std::f64::consts::FRAC_PI_2).contains(&z)) {
            return Err(ExtinctionError::Invalid {
                index,
                irradiance: e,
                zenith_deg: z.to_degrees(),
            });
        }
        pts.push((air_mass(z), e.ln()));
    }
    let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    if hi - lo < MIN_AIR_MASS_SPAN {
        return Err(ExtinctionError::IllConditioned {
            span: hi - lo,
            needed: MIN_AIR_MASS_SPAN,
        });
    }
    let n = pts.len() as f64;
    let (slope, intercept) = line_fit(&pts);
    let rms_log = (pts.iter().map(|p| (p.1 - intercept - slope * p.0).powi(2)).sum::<f64>() / n).sqrt();
    Ok(Extinction {
        e0: intercept.exp(),
        beta: -slope,
        rms_log,
        air_mass_span: hi - lo,
    })
}

/// The least-squares line `y = slope x + intercept` through `pts`
/// (`(x, y)`; non-finite when the x are all equal or there are none).
pub(crate) fn line_fit(pts: &[(f64, f64)]) -> (f64, f64) {
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    (slope, my - slope * mx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kasten_young_air_mass_published_values() {
        assert!((air_mass(0.0) - 0.99978).abs() < 1e-4, "{}", air_mass(0.0));
        assert!(
            (air_mass(60f64.to_radians()) - 1.9943).abs() < 1e-3,
            "{}",
            air_mass(60f64.to_radians())
        );
        // Kasten & Young: 37.92 at the horizon — the thesis's "about 38".
        assert!(
            (air_mass(std::f64::consts::FRAC_PI_2) - 37.92).abs() < 0.05,
            "{}",
            air_mass(std::f64::consts::FRAC_PI_2)
        );
    }

    #[test]
    fn langley_fit_recovers_beta_within_2_percent_from_noisy_day() {
        let (e0, beta) = (1360.0, 0.21);
        let mut k = 17u64;
        let pts: Vec<(f64, f64)> = [20.0, 35.0, 50.0, 62.0, 71.0, 78.0, 83.0]
            .iter()
            .map(|&zd: &f64| {
                k = k.wrapping_mul(6364136223846793005).wrapping_add(1);
                let noise = 1.0 + 0.01 * (((k >> 33) as f64 / f64::from(1u32 << 31)) * 2.0 - 1.0);
                let z = zd.to_radians();
                (z, e0 * (-beta * air_mass(z)).exp() * noise)
            })
            .collect();
        let fit = fit_extinction(&pts).expect("fits");
        assert!((fit.beta / beta - 1.0).abs() < 0.02, "{fit:?}");
        assert!((fit.e0 / e0 - 1.0).abs() < 0.02, "{fit:?}");
    }

    #[test]
    fn a_single_elevation_is_ill_conditioned_not_a_guess() {
        let z = 0.5;
        let e = fit_extinction(&[(z, 900.0), (z + 0.01, 899.0)]);
        assert!(matches!(e, Err(ExtinctionError::IllConditioned { .. })), "{e:?}");
        assert_eq!(fit_extinction(&[(0.5, 900.0)]), Err(ExtinctionError::TooFew(1)));
        assert!(matches!(
            fit_extinction(&[(0.5, 900.0), (1.0, f64::NAN)]),
            Err(ExtinctionError::Invalid { index: 1, .. })
        ));
    }
}
