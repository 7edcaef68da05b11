//! The reflectance at one surface point, in world coordinates: the
//! material's albedo texture evaluated there, in the shading frame of the
//! side the light arrives on.

use nalgebra::Vector3;

use super::material::Material;
use super::mesh::Triangle;

/// A sampled incoming direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// Unit direction toward where the light comes from.
    pub direction: Vector3<f64>,
    /// Probability density of `direction`, per steradian.
    pub pdf: f64,
    /// The BRDF value for this direction, sr⁻¹.
    pub value: [f64; 3],
}

/// The BRDF at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceBsdf {
    normal: Vector3<f64>,
    albedo: [f64; 3],
}

impl SurfaceBsdf {
    /// The BRDF of `material` at `point` on `triangle`, seen from the side of `normal`.
    pub fn at(material: &Material, triangle: &Triangle, point: &Vector3<f64>, normal: Vector3<f64>) -> SurfaceBsdf {
        SurfaceBsdf {
            normal,
            albedo: material.albedo.albedo(triangle.texture_coordinates(point)),
        }
    }

    /// A white Lambertian surface facing `normal` (irradiance probes).
    pub fn white_probe(normal: Vector3<f64>) -> SurfaceBsdf {
        SurfaceBsdf {
            normal,
            albedo: [1.0; 3],
        }
    }

    /// The BRDF for light from `wi` leaving toward `wo` (both unit, away
    /// from the surface), sr⁻¹; zero when either is below the surface.
    pub fn eval(&self, wi: &Vector3<f64>, wo: &Vector3<f64>) -> [f64; 3] {
        if wi.dot(&self.normal) <= 0.0 || wo.dot(&self.normal) <= 0.0 {
            return [0.0; 3];
        }
        self.albedo.map(|a| a * std::f64::consts::FRAC_1_PI)
    }

    /// Samples an incoming direction for light leaving toward `wo`, from
    /// three uniform numbers.
    pub fn sample(&self, wo: &Vector3<f64>, u: [f64; 3]) -> Option<BsdfSample> {
        if wo.dot(&self.normal) <= 0.0 {
            return None;
        }
        let r = u[0].sqrt();
        let phi = std::f64::consts::TAU * u[1];
        let n = self.normal;
        let helper = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
        let a = n.cross(&helper).normalize();
        let b = n.cross(&a);
        let cos = (1.0 - u[0]).max(0.0).sqrt();
        let direction = (a * (r * phi.cos()) + b * (r * phi.sin()) + n * cos).normalize();
        let pdf = direction.dot(&n).max(0.0) * std::f64::consts::FRAC_1_PI;
        (pdf > 0.0).then(|| BsdfSample {
            direction,
            pdf,
            value: self.eval(&direction, wo),
        })
    }
}
