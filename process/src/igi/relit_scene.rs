//! The room as recovered: the solver's triangles with each surface's
//! recovered Ward material (constant ρd), as a render scene, and the side
//! of each triangle the cameras see.

use nalgebra::Vector3;

use super::error::IgiError;
use super::input::{IgiInput, IgiLight};
use super::recover::IgiResult;
use crate::render::{Material, PointLight, Ray, Scene, Texture};

/// The albedo given to a surface no pixel saw (nothing was recovered).
pub const UNOBSERVED_ALBEDO: f64 = 0.5;

/// A render scene of `input`'s triangles (material index = surface index)
/// with `result`'s recovered materials; unobserved surfaces get a grey
/// [`UNOBSERVED_ALBEDO`].
pub fn recovered_scene(input: &IgiInput, result: &IgiResult) -> Result<Scene, IgiError> {
    let materials = input
        .surfaces
        .iter()
        .enumerate()
        .map(|(s, name)| {
            let m = result.surfaces.get(s).and_then(|r| r.material);
            Material {
                name: name.clone(),
                albedo: Texture::Constant(m.map_or([UNOBSERVED_ALBEDO; 3], |m| m.rho_d)),
                specular: m.and_then(|m| m.lobe),
                emission: [0.0; 3],
            }
        })
        .collect();
    let triangles = input
        .triangles
        .iter()
        .map(|t| crate::render::Triangle {
            material: t.surface,
            ..*t
        })
        .collect();
    Ok(Scene::new(triangles, materials, input.surfaces.clone())?)
}

/// The lights as point lights at their centres (their light on surfaces).
pub fn point_lights(lights: &[IgiLight]) -> Vec<PointLight> {
    lights
        .iter()
        .map(|l| PointLight {
            position: l.position,
            intensity: l.intensity,
        })
        .collect()
}

/// Per triangle, the unit normal of the side most cameras see unoccluded
/// (the geometric normal when none does).
pub fn seen_sides(scene: &Scene, cameras: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    scene
        .triangles()
        .iter()
        .map(|t| {
            let c = (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0;
            let mut vote = 0i64;
            for p in cameras {
                let d = p - c;
                let len = d.norm();
                if len == 0.0 {
                    continue;
                }
                let side = d.dot(&t.normal).signum();
                let origin = c + t.normal * side * 1e-6 * (1.0 + c.norm());
                let ray = Ray {
                    origin,
                    direction: d / len,
                };
                if !scene.occluded(&ray, len * (1.0 - 1e-6)) {
                    vote += side as i64;
                }
            }
            if vote >= 0 { t.normal } else { -t.normal }
        })
        .collect()
}
