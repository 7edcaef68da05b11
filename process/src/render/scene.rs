//! A renderable scene: triangles with materials and named surfaces, and
//! the hierarchy over them.

use nalgebra::Vector3;
use thiserror::Error;

use super::accel::Accel;
use super::material::Material;
use super::mesh::{Ray, Triangle};

/// Why a scene could not be assembled.
#[derive(Debug, Error, PartialEq)]
pub enum SceneError {
    /// A triangle names a material the scene does not have.
    #[error("triangle {triangle} uses material {material}, but the scene has {count} materials")]
    UnknownMaterial {
        /// Index of the triangle.
        triangle: usize,
        /// Material index it names.
        material: u32,
        /// Number of materials.
        count: usize,
    },
    /// A triangle names a surface the scene does not have.
    #[error("triangle {triangle} is in surface {surface}, but the scene has {count} surfaces")]
    UnknownSurface {
        /// Index of the triangle.
        triangle: usize,
        /// Surface index it names.
        surface: u32,
        /// Number of surfaces.
        count: usize,
    },
    /// An albedo outside [0, 1] would create energy.
    #[error("material {name:?}: albedo {value} is outside [0, 1]")]
    Albedo {
        /// Material name.
        name: String,
        /// The offending value.
        value: f64,
    },
}

/// Where a ray met a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the ray, metres.
    pub t: f64,
    /// The point, world frame.
    pub point: Vector3<f64>,
    /// Index of the triangle.
    pub triangle: usize,
}

/// Triangles, their materials and the named surfaces they belong to.
#[derive(Debug, Clone)]
pub struct Scene {
    triangles: Vec<Triangle>,
    materials: Vec<Material>,
    surfaces: Vec<String>,
    accel: Accel,
}

impl Scene {
    /// Assembles and indexes a scene, checking every index and albedo.
    pub fn new(triangles: Vec<Triangle>, materials: Vec<Material>, surfaces: Vec<String>) -> Result<Scene, SceneError> {
        for (i, t) in triangles.iter().enumerate() {
            if t.material as usize >= materials.len() {
                return Err(SceneError::UnknownMaterial {
                    triangle: i,
                    material: t.material,
                    count: materials.len(),
                });
            }
            if t.surface as usize >= surfaces.len() {
                return Err(SceneError::UnknownSurface {
                    triangle: i,
                    surface: t.surface,
                    count: surfaces.len(),
                });
            }
        }
        for m in &materials {
            for v in m.albedo.mean_albedo() {
                if !(0.0..=1.0).contains(&v) {
                    return Err(SceneError::Albedo {
                        name: m.name.clone(),
                        value: v,
                    });
                }
            }
        }
        let accel = Accel::build(&triangles);
        Ok(Scene {
            triangles,
            materials,
            surfaces,
            accel,
        })
    }

    /// The triangles.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The materials.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Names of the surfaces.
    pub fn surfaces(&self) -> &[String] {
        &self.surfaces
    }

    /// Index of the surface called `name`.
    pub fn surface_index(&self, name: &str) -> Option<usize> {
        self.surfaces.iter().position(|s| s == name)
    }

    /// The nearest surface along `ray` closer than `t_max`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let hit = self.accel.nearest(&self.triangles, ray, RAY_EPSILON, t_max)?;
        Some(SurfaceHit {
            t: hit.t,
            point: ray.origin + ray.direction * hit.t,
            triangle: hit.triangle,
        })
    }

    /// Whether anything lies on `ray` before `t_max`.
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.accel.occluded(&self.triangles, ray, RAY_EPSILON, t_max)
    }

    /// Whether the segment from `a` to `b` is clear: nothing between them
    /// (the last millionth of its length excluded, so that a surface at `b`
    /// does not count). A segment of zero length is not clear.
    pub fn segment_clear(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        let d = b - a;
        let len = d.norm();
        len > 0.0
            && !self.occluded(
                &Ray {
                    origin: *a,
                    direction: d / len,
                },
                len * (1.0 - 1e-6),
            )
    }

    /// The diffuse albedo at `point` on triangle `triangle`: the ground truth
    /// of the per-texel albedo.
    pub fn albedo_at(&self, triangle: usize, point: &Vector3<f64>) -> [f64; 3] {
        let tri = &self.triangles[triangle];
        self.materials[tri.material as usize]
            .albedo
            .albedo(tri.texture_coordinates(point))
    }

    /// Bounding radius about the origin (for scale-aware offsets).
    pub fn extent(&self) -> f64 {
        self.triangles
            .iter()
            .flat_map(|t| t.vertices.iter())
            .map(|v| v.norm())
            .fold(0.0, f64::max)
    }
}

/// Nearest distance a ray may hit at, metres: keeps a ray leaving a surface
/// from hitting that surface again.
pub const RAY_EPSILON: f64 = 1e-7;
