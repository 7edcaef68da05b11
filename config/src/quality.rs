//! Quality gates: the thresholds that every product's figures are held to.
//!
//! Each product that processing writes (the response curve, a merged
//! radiance map, a sun measurement, a sky fit, an environment map, a
//! recovered BRDF) gets a verdict, `ok`, `poor` or `failed`, from its
//! figures and these thresholds. They are data, in one place, with the
//! defaults documented here:
//! - a plan may carry them (`quality: Some(Quality(...))`, any subset of
//!   fields; the rest keep their defaults);
//! - a command takes them from a file (`--thresholds FILE.ron`, a
//!   `Quality(...)` value), which wins over the plan's.
//!
//! A [`Gate`] holds one figure to two bounds. For a figure where less is
//! better it is `ok` up to `poor`, `poor` up to `failed`, and `failed`
//! beyond; where more is better (a fraction of pixels valid), the other way
//! round. Which way each figure goes is fixed by its meaning and stated on
//! its field; validation checks that the two bounds are in that order.

use serde::{Deserialize, Serialize};

use crate::validate::{Validate, Validator};

/// Two bounds on one figure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gate {
    /// Beyond this the product is `poor`.
    pub poor: f64,
    /// Beyond this it is `failed`.
    pub failed: f64,
}

/// Which way a figure is better.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Better {
    /// Less is better: `ok` while the figure is at most `poor`.
    Lower,
    /// More is better: `ok` while the figure is at least `poor`.
    Higher,
}

impl Gate {
    /// A gate with these bounds.
    pub const fn new(poor: f64, failed: f64) -> Gate {
        Gate { poor, failed }
    }

    fn validate_as(&self, better: Better, v: &mut Validator) {
        let finite = |v: &mut Validator, name: &str, x: f64| {
            if !x.is_finite() {
                v.invalid(name, crate::validate::fmt_f64(x), "a finite number");
            }
        };
        finite(v, "poor", self.poor);
        finite(v, "failed", self.failed);
        let ordered = match better {
            Better::Lower => self.poor <= self.failed,
            Better::Higher => self.poor >= self.failed,
        };
        if !ordered && self.poor.is_finite() && self.failed.is_finite() {
            v.invalid(
                "failed",
                crate::validate::fmt_f64(self.failed),
                match better {
                    Better::Lower => "a bound at least `poor` (less is better for this figure)",
                    Better::Higher => "a bound at most `poor` (more is better for this figure)",
                },
            );
        }
    }
}

/// Every threshold, by product.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields, rename = "Quality")]
pub struct Quality {
    /// The camera response curve.
    pub response: ResponseGates,
    /// Each merged radiance map.
    pub merge: MergeGates,
    /// Each sun measurement (a triplet of filtered frames).
    pub sun: SunGates,
    /// Each sky fit, per channel.
    pub sky: SkyGates,
    /// Each environment map.
    pub environment: EnvironmentGates,
    /// Each surface's recovered BRDF (inverse global illumination).
    pub igi: IgiGates,
    /// The outdoor pseudo-albedos and their re-renders (thesis ch. 5).
    pub outdoor: OutdoorGates,
}

/// Gates on the response curve (Debevec–Malik).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ResponseGates {
    /// The solve's condition estimate, worst channel (lower is better).
    /// Default poor 2e7, failed 2e8: the quick plan's full 12-exposure
    /// bracket gives 4.4e6 on the simulated station; the same bracket with
    /// half its exposures lost to camera faults, 1.3e9.
    pub condition: Gate,
    /// Exposures in the bracket used, over those the plan asked for
    /// (higher is better). Default poor 1 (any exposure missing), failed
    /// 0.75.
    pub exposures_used: Gate,
    /// Fraction of the codes between the darkest and the brightest code
    /// that the samples observe, worst channel (higher is better). Default
    /// poor 0.8, failed 0.5.
    pub code_coverage: Gate,
    /// Fraction of curve nodes that had to be made monotone, worst channel
    /// (lower is better). Default poor 0.02, failed 0.1.
    pub non_monotone: Gate,
}

impl Default for ResponseGates {
    fn default() -> Self {
        ResponseGates {
            condition: Gate::new(2e7, 2e8),
            exposures_used: Gate::new(1.0, 0.75),
            code_coverage: Gate::new(0.8, 0.5),
            non_monotone: Gate::new(0.02, 0.1),
        }
    }
}

/// Gates on a merged radiance map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MergeGates {
    /// Fraction of pixels with a radiance in every channel (higher is
    /// better). Default poor 0.9, failed 0.5.
    pub valid: Gate,
    /// Fraction of pixels saturated in every exposure, any channel (lower is
    /// better). Default poor 0.05, failed 0.5.
    pub clipped: Gate,
    /// Fraction of pixels below the noise floor in every exposure, any
    /// channel (lower is better). Default poor 0.1, failed 0.5.
    pub dark: Gate,
}

impl Default for MergeGates {
    fn default() -> Self {
        MergeGates {
            valid: Gate::new(0.9, 0.5),
            clipped: Gate::new(0.05, 0.5),
            dark: Gate::new(0.1, 0.5),
        }
    }
}

/// Gates on a sun measurement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SunGates {
    /// Relative spread of the triplet's irradiances, worst channel (lower
    /// is better). Default poor 0.03 (the sky series' "clouds near the
    /// sun"), failed 0.15.
    pub triplet_spread: Gate,
    /// Frames of the triplet refused (saturated disc, no disc found), over
    /// those taken (lower is better). Default poor 0 (any refused), failed
    /// 0.5.
    pub refused: Gate,
}

impl Default for SunGates {
    fn default() -> Self {
        SunGates {
            triplet_spread: Gate::new(0.03, 0.15),
            refused: Gate::new(0.0, 0.5),
        }
    }
}

/// Gates on a sky fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkyGates {
    /// RMS relative residual of the fit, worst channel (lower is better).
    /// Default poor 0.05, failed 0.15 (the sky series flags a poor fit
    /// at 0.10).
    pub residual: Gate,
    /// Fraction of the samples masked (sun, clipped, outliers), worst
    /// channel (lower is better). Default poor 0.3, failed 0.7.
    pub masked: Gate,
}

impl Default for SkyGates {
    fn default() -> Self {
        SkyGates {
            residual: Gate::new(0.05, 0.15),
            masked: Gate::new(0.3, 0.7),
        }
    }
}

/// Gates on an environment map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnvironmentGates {
    /// Fraction of the map's azimuth sectors in which some frame saw at
    /// least one region: a panorama that lost tiles has gaps (higher is
    /// better). Default poor 0.9, failed 0.5.
    pub azimuth_coverage: Gate,
    /// RMS relative residual of a region's radiance model (eq. 5.15,
    /// `campanile env fit`; lower is better). Default poor 0.1, failed 0.3.
    pub region_residual: Gate,
}

impl Default for EnvironmentGates {
    fn default() -> Self {
        EnvironmentGates {
            azimuth_coverage: Gate::new(0.9, 0.5),
            region_residual: Gate::new(0.1, 0.3),
        }
    }
}

/// Gates on a surface's recovered BRDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IgiGates {
    /// RMS relative residual of the surface's fit (lower is better).
    /// Default poor 0.5, failed 2. It is a weak figure: one BRDF per
    /// surface leaves the surface's texture (which the albedo maps take up,
    /// §4.6) and the photographs' noise in it. Measured in the quick demo's
    /// room (8-path photographs): 0.15–0.57 for wood, paper, plastic and
    /// metal, 1.08 for the paint, whose recovered ρd is within 0.4% on the
    /// simulated room; beyond 2 the model explains less than the noise.
    pub residual: Gate,
    /// Directional albedo ρd + ρs, worst channel: reflecting more than
    /// falls on it breaks energy conservation (lower is better). Default
    /// poor 0.95, failed 1.0.
    pub energy: Gate,
    /// How much worse the interreflection assumed (modelled, or
    /// `--direct-only`) fits the images' diffuse pixels than the other
    /// assumption: the pooled weighted residual's ratio less one
    /// (`process::igi::interreflection_check`; lower is better). Default
    /// poor 0.02, failed 0.1: a wrong assumption puts ρd off by the
    /// indirect share (19–45 % on single-bounce renders solved as
    /// interreflected).
    pub interreflection: Gate,
    /// The share of a relit view's 4 × 4-pixel blocks whose estimated
    /// relative standard error stayed above the `--error` target at the
    /// most paths a pixel (`process::igi::error_target`; lower is better).
    /// Default poor 0 (any block), failed 0.5: most of the image is then
    /// noisier than was asked for.
    pub relit_blocks: Gate,
}

impl Default for IgiGates {
    fn default() -> Self {
        IgiGates {
            residual: Gate::new(0.5, 2.0),
            energy: Gate::new(0.95, 1.0),
            interreflection: Gate::new(0.02, 0.1),
            relit_blocks: Gate::new(0.0, 0.5),
        }
    }
}

/// Gates on the outdoor pseudo-albedos (thesis §5.4) and on a re-render
/// compared with a photograph of the same view (§5.5–5.6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutdoorGates {
    /// Median over the solved cells of each cell's weighted RMS relative
    /// residual of eqs. (5.11)–(5.12) (lower is better). Default poor
    /// 0.05, failed 0.15: what is left beyond the photographs' noise (1–2 %
    /// on the simulated station) is light the model does not explain
    /// (a wrong sky or sun, a wrong pose, non-Lambertian surfaces).
    pub residual: Gate,
    /// Relative RMSE of 4 × 4-pixel block means of a re-render against the
    /// photograph of that view, over the target pixels (lower is better).
    /// Default poor 0.03 (the thesis-level figure: 1.9–2.5 % on the
    /// simulated station's held-out views), failed 0.10.
    pub render: Gate,
    /// Where the sun or the sky was estimated rather than measured (no sun
    /// shot, no sky scan: a clear-sky model and the photographs'
    /// sunlit/shadowed ratio), the stated relative standard uncertainty of
    /// the light the pseudo-albedos are divided by (lower is better).
    /// Default poor 0.02 (the thesis-level pseudo-albedo figure: light
    /// known less well than that cannot give it), failed 0.5.
    pub estimated_light: Gate,
    /// Of a zoom photograph's pixels on the target surfaces, the fraction
    /// given high-resolution pseudo-albedos by eq. (5.16) (higher is
    /// better); the others keep the grid's (a face's outline, a shadow
    /// edge, invalid radiance). Default poor 0.5, failed 0.1.
    pub zoom_coverage: Gate,
}

impl Default for OutdoorGates {
    fn default() -> Self {
        OutdoorGates {
            residual: Gate::new(0.05, 0.15),
            render: Gate::new(0.03, 0.10),
            estimated_light: Gate::new(0.02, 0.5),
            zoom_coverage: Gate::new(0.5, 0.1),
        }
    }
}

impl Validate for Quality {
    fn validate(&self, v: &mut Validator) {
        use Better::{Higher, Lower};
        let gates: [(&str, &str, &Gate, Better); 21] = [
            ("response", "condition", &self.response.condition, Lower),
            ("response", "exposures_used", &self.response.exposures_used, Higher),
            ("response", "code_coverage", &self.response.code_coverage, Higher),
            ("response", "non_monotone", &self.response.non_monotone, Lower),
            ("merge", "valid", &self.merge.valid, Higher),
            ("merge", "clipped", &self.merge.clipped, Lower),
            ("merge", "dark", &self.merge.dark, Lower),
            ("sun", "triplet_spread", &self.sun.triplet_spread, Lower),
            ("sun", "refused", &self.sun.refused, Lower),
            ("sky", "residual", &self.sky.residual, Lower),
            ("sky", "masked", &self.sky.masked, Lower),
            (
                "environment",
                "azimuth_coverage",
                &self.environment.azimuth_coverage,
                Higher,
            ),
            (
                "environment",
                "region_residual",
                &self.environment.region_residual,
                Lower,
            ),
            ("igi", "residual", &self.igi.residual, Lower),
            ("igi", "energy", &self.igi.energy, Lower),
            ("igi", "interreflection", &self.igi.interreflection, Lower),
            ("igi", "relit_blocks", &self.igi.relit_blocks, Lower),
            ("outdoor", "residual", &self.outdoor.residual, Lower),
            ("outdoor", "render", &self.outdoor.render, Lower),
            ("outdoor", "estimated_light", &self.outdoor.estimated_light, Lower),
            ("outdoor", "zoom_coverage", &self.outdoor.zoom_coverage, Higher),
        ];
        for (product, figure, gate, better) in gates {
            v.at(product, |v| v.at(figure, |v| gate.validate_as(better, v)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn issues(q: &Quality) -> Vec<String> {
        let mut v = Validator::new(".");
        q.validate(&mut v);
        v.into_issues()
            .iter()
            .map(|i| format!("{}: {}", i.path, i.expected))
            .collect()
    }

    #[test]
    fn defaults_are_valid_and_a_partial_file_keeps_the_rest() {
        assert!(issues(&Quality::default()).is_empty());
        let q: Quality = ron::from_str("Quality(sun: (triplet_spread: (poor: 0.05, failed: 0.2)))").unwrap();
        assert_eq!(q.sun.triplet_spread, Gate::new(0.05, 0.2));
        assert_eq!(q.sun.refused, SunGates::default().refused);
        assert_eq!(q.response, ResponseGates::default());
    }

    #[test]
    fn bounds_in_the_wrong_order_are_refused_by_name() {
        let mut q = Quality::default();
        q.merge.valid = Gate::new(0.5, 0.9);
        q.sky.residual = Gate::new(0.2, 0.1);
        q.igi.energy = Gate::new(f64::NAN, 1.0);
        let found = issues(&q);
        assert_eq!(found.len(), 3, "{found:?}");
        assert!(found[0].starts_with("merge.valid.failed: a bound at most"), "{found:?}");
        assert!(
            found[1].starts_with("sky.residual.failed: a bound at least"),
            "{found:?}"
        );
        assert!(found[2].starts_with("igi.energy.poor: a finite number"), "{found:?}");
    }
}
