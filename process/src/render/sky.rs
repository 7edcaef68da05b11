//! What the renderer needs from the sky: radiance in any direction, and
//! the solar disc, which is sampled explicitly because it is far too small
//! for BRDF-sampled rays to find.

use nalgebra::Vector3;

/// The sun as seen from the ground: a uniform disc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolarDisc {
    /// Unit direction toward the disc's centre.
    pub direction: Vector3<f64>,
    /// Angular radius, radians (0.2666° for the mean sun).
    pub angular_radius_rad: f64,
    /// Radiance of the disc per channel, W·m⁻²·sr⁻¹.
    pub radiance: [f64; 3],
}

impl SolarDisc {
    /// Solid angle of the disc, sr: `2π (1 − cos r)`.
    pub fn solid_angle(&self) -> f64 {
        std::f64::consts::TAU * (1.0 - self.angular_radius_rad.cos())
    }

    /// Irradiance on a surface facing the sun, per channel, W·m⁻².
    pub fn normal_irradiance(&self) -> [f64; 3] {
        let omega = self.solid_angle();
        self.radiance.map(|l| l * omega)
    }

    /// Whether `d` (unit) falls on the disc.
    pub fn contains(&self, d: &Vector3<f64>) -> bool {
        d.dot(&self.direction) >= self.angular_radius_rad.cos()
    }
}

/// The sky dome, as the renderer sees it.
pub trait Sky: Sync {
    /// Radiance arriving from unit direction `d` (pointing from the scene
    /// toward the sky), per channel, W·m⁻²·sr⁻¹, without the solar disc.
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3];

    /// The solar disc, if the sun is up and not hidden.
    fn sun(&self) -> Option<SolarDisc>;

    /// A uniform radiance below the horizon, per channel: the distant
    /// landscape beyond the scene's geometry (RADIANCE's ground glow).
    /// [`Sky::radiance`] gives it for directions below the horizon. Zero
    /// by default: nothing but the scene's own ground lies below.
    fn below_horizon(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// A sky of the same radiance in every direction above the horizon and
/// none below: the analytic case of a Lambertian plane under a uniform sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniformSky {
    /// Radiance above the horizon.
    pub radiance: [f64; 3],
}

impl Sky for UniformSky {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        if d.z > 0.0 { self.radiance } else { [0.0; 3] }
    }

    fn sun(&self) -> Option<SolarDisc> {
        None
    }
}
