//! The thesis's simulated cube (§4.7.1): a unit cube room whose six walls
//! carry the six materials of Table 4.1, lit by six point lights so that
//! each wall shows a highlight to a camera at the centre. The last two
//! walls have 20% and 10% zero-mean white noise in their diffuse albedo.

use campanile_process::brdf::{WardMaterial, table_4_1};
use campanile_process::render::{Material, PointLight, Scene, Texture, shapes};
use nalgebra::Vector3;

/// Wall names, in the order of Table 4.1's rows.
pub const WALLS: [&str; 6] = ["west", "east", "south", "north", "floor", "ceiling"];

/// Relative amplitude of the albedo noise per wall (§4.7.1).
pub const ALBEDO_NOISE: [f64; 6] = [0.0, 0.0, 0.0, 0.0, 0.2, 0.1];

/// Side of one noise cell, metres.
pub const NOISE_CELL_M: f64 = 0.01;

/// The cube, its lights and its true materials.
#[derive(Debug, Clone)]
pub struct CubeRoom {
    /// The six walls (inward normals) from (0,0,0) to (1,1,1).
    pub scene: Scene,
    /// The six point lights.
    pub lights: Vec<PointLight>,
    /// The true BRDF of each wall (Table 4.1), mean albedo for the noisy ones.
    pub materials: [WardMaterial; 6],
}

impl CubeRoom {
    /// The cube with lights of `intensity` W·sr⁻¹ each, 0.3 m from the
    /// centre toward each wall.
    pub fn new(intensity: f64) -> CubeRoom {
        let materials = table_4_1();
        let render_materials = materials
            .iter()
            .zip(WALLS)
            .enumerate()
            .map(|(i, (m, name))| Material {
                name: name.to_string(),
                albedo: if ALBEDO_NOISE[i] > 0.0 {
                    Texture::Noise {
                        mean: m.rho_d,
                        amplitude: ALBEDO_NOISE[i],
                        cell_m: NOISE_CELL_M,
                        seed: 41 + i as u64,
                    }
                } else {
                    Texture::Constant(m.rho_d)
                },
                specular: m.lobe,
                emission: [0.0; 3],
            })
            .collect();
        let tris = shapes::cuboid(
            Vector3::zeros(),
            Vector3::repeat(1.0),
            true,
            [0, 1, 2, 3, 4, 5],
            [0, 1, 2, 3, 4, 5],
        );
        let scene = Scene::new(tris, render_materials, WALLS.iter().map(|w| w.to_string()).collect())
            .unwrap_or_else(|e| unreachable!("the built-in cube is valid: {e}"));
        let c = Vector3::repeat(0.5);
        let lights = [
            -Vector3::x(),
            Vector3::x(),
            -Vector3::y(),
            Vector3::y(),
            -Vector3::z(),
            Vector3::z(),
        ]
        .into_iter()
        .enumerate()
        .map(|(i, d)| PointLight {
            // Offset sideways a little so that no two lights share a highlight.
            position: c + d * 0.3 + Vector3::new(0.05, -0.04, 0.03) * (i as f64 - 2.5) / 2.5,
            intensity: [intensity; 3],
        })
        .collect();
        CubeRoom {
            scene,
            lights,
            materials,
        }
    }
}
