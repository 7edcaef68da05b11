//! The reflectance at one surface point, in world coordinates: the
//! material's albedo texture evaluated there and its Ward lobe (thesis
//! eq. A.1/A.2, in the lobe's named variant), in the shading frame of the
//! side the light arrives on. The frame's tangent is the face's texture
//! `s` axis, so an anisotropic lobe's orientation γ is measured from the
//! horizontal direction along the face.

use nalgebra::Vector3;

use super::material::Material;
use super::mesh::Triangle;
use crate::brdf::{ShadingFrame, WardMaterial};

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
    frame: ShadingFrame,
    material: WardMaterial,
}

/// The frame with `normal` and a tangent near `tangent`; `normal` is a unit
/// face normal, so the fallback only guards against a corrupted triangle.
fn frame(normal: Vector3<f64>, tangent: Vector3<f64>) -> ShadingFrame {
    ShadingFrame::new(normal, tangent).unwrap_or(ShadingFrame {
        normal: Vector3::z(),
        tangent: Vector3::x(),
        bitangent: Vector3::y(),
    })
}

impl SurfaceBsdf {
    /// The BRDF of `material` at `point` on `triangle`, seen from the side of `normal`.
    pub fn at(material: &Material, triangle: &Triangle, point: &Vector3<f64>, normal: Vector3<f64>) -> SurfaceBsdf {
        SurfaceBsdf {
            frame: frame(normal, triangle.texture_axes[0]),
            material: WardMaterial {
                rho_d: material.albedo.albedo(triangle.texture_coordinates(point)),
                lobe: material.specular,
            },
        }
    }

    /// A white Lambertian surface facing `normal` (irradiance probes).
    pub fn white_probe(normal: Vector3<f64>) -> SurfaceBsdf {
        SurfaceBsdf {
            frame: frame(normal, Vector3::x()),
            material: WardMaterial {
                rho_d: [1.0; 3],
                lobe: None,
            },
        }
    }

    /// The BRDF for light from `wi` leaving toward `wo` (both unit, away
    /// from the surface), sr⁻¹; zero when either is below the surface.
    pub fn eval(&self, wi: &Vector3<f64>, wo: &Vector3<f64>) -> [f64; 3] {
        self.material.eval(&self.frame.to_local(wi), &self.frame.to_local(wo))
    }

    /// Samples an incoming direction for light leaving toward `wo`, from
    /// three uniform numbers (lobe choice, then the direction).
    pub fn sample(&self, wo: &Vector3<f64>, u: [f64; 3]) -> Option<BsdfSample> {
        let s = self.material.sample(&self.frame.to_local(wo), u)?;
        Some(BsdfSample {
            direction: self.frame.to_world(&s.wi),
            pdf: s.pdf,
            value: s.value,
        })
    }
}
