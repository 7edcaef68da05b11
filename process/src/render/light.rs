//! Light sources other than the sky: point lights (thesis §4.7.1, the
//! simulated cube) and small spherical lamps (§4.7.2, the room's bulbs).

use nalgebra::Vector3;

/// An isotropic point light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    /// Position, world frame, metres.
    pub position: Vector3<f64>,
    /// Radiant intensity per channel, W·sr⁻¹.
    pub intensity: [f64; 3],
}

/// A sphere of uniform emitted radiance: a lamp's bulb.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereLight {
    /// Centre, world frame, metres.
    pub center: Vector3<f64>,
    /// Radius, metres.
    pub radius: f64,
    /// Emitted radiance per channel, W·m⁻²·sr⁻¹.
    pub radiance: [f64; 3],
}

impl SphereLight {
    /// The sphere that has radiant intensity `intensity` (W·sr⁻¹) in every
    /// direction: a uniform sphere of radiance L shows the disc area π r², so
    /// `I = L π r²`.
    pub fn with_intensity(center: Vector3<f64>, radius: f64, intensity: [f64; 3]) -> SphereLight {
        let area = std::f64::consts::PI * radius * radius;
        SphereLight {
            center,
            radius,
            radiance: intensity.map(|i| i / area),
        }
    }

    /// Distance along a ray (`origin`, unit `direction`) to the sphere's
    /// near surface, if hit in `(t_min, t_max)`.
    pub fn intersect(&self, origin: &Vector3<f64>, direction: &Vector3<f64>, t_min: f64, t_max: f64) -> Option<f64> {
        let oc = origin - self.center;
        let b = oc.dot(direction);
        let c = oc.norm_squared() - self.radius * self.radius;
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        [-b - root, -b + root].into_iter().find(|t| *t > t_min && *t < t_max)
    }
}
