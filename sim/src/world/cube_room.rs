//! The thesis's simulated cube (§4.7.1): a unit cube room whose six walls
//! carry the six materials of Table 4.1, lit by six point lights so that
//! each wall shows a highlight to a camera at the centre. The last two
//! walls have 20% and 10% zero-mean white noise in their diffuse albedo.

use campanile_process::brdf::{WardMaterial, table_4_1};
use campanile_process::igi::{IgiInput, IgiLight, View, ViewCamera};
use campanile_process::render::{Material, PointLight, Scene, Texture, shapes};
use nalgebra::Vector3;

use super::igi_photograph::{PhotoSettings, photograph};

/// Unit direction from the cube's centre toward each wall, in [`WALLS`] order.
const TOWARD_WALL: [[f64; 3]; 6] = [
    [-1.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, -1.0],
    [0.0, 0.0, 1.0],
];

/// Vertical field of view of the six wide views: 100°, so each sees its
/// whole wall (90° from the centre) and a strip of the four next to it.
pub const WIDE_VFOV_DEG: f64 = 100.0;

/// Vertical field of view of the six highlight views: 30°.
pub const HIGHLIGHT_VFOV_DEG: f64 = 30.0;

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

    /// The cube's centre, where every camera stands (§4.7.1).
    pub fn centre() -> Vector3<f64> {
        Vector3::repeat(0.5)
    }

    /// The twelve cameras of §4.7.1, named: six wide views from the centre,
    /// each facing one wall (`wide_px` square), then six zoomed views
    /// (`highlight_px` square), each aimed at the point of wall i where the
    /// light i's mirror reflection reaches the centre.
    pub fn igi_cameras(&self, wide_px: usize, highlight_px: usize) -> Vec<(String, ViewCamera)> {
        let c = Self::centre();
        let up_for = |d: &Vector3<f64>| if d.z.abs() > 0.5 { Vector3::y() } else { Vector3::z() };
        let mut out = Vec::new();
        for (i, d) in TOWARD_WALL.iter().enumerate() {
            let d = Vector3::from(*d);
            out.push((
                format!("wide-{}", WALLS[i]),
                ViewCamera {
                    position: c,
                    look: d,
                    up: up_for(&d),
                    vfov_rad: WIDE_VFOV_DEG.to_radians(),
                    width: wide_px,
                    height: wide_px,
                },
            ));
        }
        for (i, d) in TOWARD_WALL.iter().enumerate() {
            let d = Vector3::from(*d);
            let (p0, n) = (c + d * 0.5, -d);
            let mirrored = c - n * (2.0 * (c - p0).dot(&n));
            let l = self.lights[i].position;
            let t = (p0 - l).dot(&n) / (mirrored - l).dot(&n);
            let m = l + (mirrored - l) * t;
            out.push((
                format!("highlight-{}", WALLS[i]),
                ViewCamera {
                    position: c,
                    look: m - c,
                    up: up_for(&d),
                    vfov_rad: HIGHLIGHT_VFOV_DEG.to_radians(),
                    width: highlight_px,
                    height: highlight_px,
                },
            ));
        }
        out
    }

    /// The solver's input for the cube: its geometry and lights, and the
    /// twelve views of [`CubeRoom::igi_cameras`] photographed by
    /// [`photograph`] (exact direct light, path-traced interreflection).
    pub fn igi_input(&self, wide_px: usize, highlight_px: usize, settings: &PhotoSettings) -> IgiInput {
        let views = self
            .igi_cameras(wide_px, highlight_px)
            .into_iter()
            .enumerate()
            .map(|(k, (name, camera))| View {
                name,
                camera,
                image: photograph(
                    &self.scene,
                    &self.lights,
                    &[],
                    &camera,
                    &PhotoSettings {
                        seed: settings.seed.wrapping_add(k as u64 * 1000),
                        ..*settings
                    },
                ),
                mask: None,
            })
            .collect();
        IgiInput {
            triangles: self.scene.triangles().to_vec(),
            surfaces: self.scene.surfaces().to_vec(),
            lights: self
                .lights
                .iter()
                .map(|l| IgiLight {
                    position: l.position,
                    radius: 0.0,
                    intensity: l.intensity,
                })
                .collect(),
            views,
        }
    }
}
