//! One sampled incident direction, as a path tracer consumes it.

use nalgebra::Vector3;

/// A direction drawn from a material's sampling density, with what the
/// estimator `value · cos θi / pdf` needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The incident direction (local frame, unit, toward the light).
    pub wi: Vector3<f64>,
    /// Its probability density per unit solid angle, > 0.
    pub pdf: f64,
    /// The BRDF `f(wi, wo)` per channel, sr⁻¹.
    pub value: [f64; 3],
}
