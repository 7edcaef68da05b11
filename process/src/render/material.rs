//! Materials: an albedo texture, an optional Ward specular lobe, and
//! optional emission (for the furnace test and glowing surfaces).

use super::texture::Texture;
use crate::brdf::WardLobe;

/// How a surface reflects and emits.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name, as in the scene description.
    pub name: String,
    /// Diffuse albedo ρd per channel, varying over the surface.
    pub albedo: Texture,
    /// Ward specular lobe ρs, α, γ (thesis eq. A.1/A.2, in its named variant), if any.
    pub specular: Option<WardLobe>,
    /// Emitted radiance per channel, W·m⁻²·sr⁻¹ (zero for ordinary surfaces).
    pub emission: [f64; 3],
}

impl Material {
    /// A Lambertian material of constant albedo.
    pub fn diffuse(name: &str, albedo: [f64; 3]) -> Material {
        Material {
            name: name.to_string(),
            albedo: Texture::Constant(albedo),
            specular: None,
            emission: [0.0; 3],
        }
    }
}
