//! A scene description (RON + OBJ, as the processing pipeline reads it)
//! turned into a renderable scene with the simulator's true materials.

use std::path::{Path, PathBuf};

use campanile_process::render::{Material, Scene, Triangle};
use nalgebra::Vector3;

use super::WorldError;
use super::truth::{Appearance, appearance};

/// A loaded scene: its description, the renderable triangles, and the true
/// appearance of each material (in the render scene's material order).
#[derive(Debug, Clone)]
pub struct LoadedScene {
    /// The scene description.
    pub description: campanile_config::Scene,
    /// Triangles with materials and surfaces.
    pub scene: Scene,
    /// The truth per material, in `scene.materials()` order.
    pub appearances: Vec<Appearance>,
}

/// Reads scene file `path` and its OBJ geometry. Each OBJ group becomes
/// part of the surface that lists it, with that surface's material; a group
/// no surface lists becomes a surface of its own name with a default grey.
pub fn load_scene(path: &Path) -> Result<LoadedScene, WorldError> {
    let loaded = campanile_config::document::load_scene(path).map_err(|e| WorldError::Config {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let obj = loaded.source.base_dir().join(&loaded.value.geometry);
    from_description(loaded.value, &obj)
}

/// Builds the scene of `description` with geometry from `obj`.
pub fn from_description(description: campanile_config::Scene, obj: &Path) -> Result<LoadedScene, WorldError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(obj, &opts).map_err(|e| WorldError::Geometry {
        path: obj.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut material_names: Vec<String> = description.materials.iter().map(|m| m.name.clone()).collect();
    let mut surface_names: Vec<String> = description.surfaces.iter().map(|s| s.name.clone()).collect();
    let mut triangles = Vec::new();
    let mut degenerate = 0usize;
    for model in &models {
        let (surface, material) = match description.surfaces.iter().position(|s| s.groups.contains(&model.name)) {
            Some(i) => {
                let m = &description.surfaces[i].material;
                let mi = material_names.iter().position(|n| n == m).unwrap_or_else(|| {
                    material_names.push(m.clone());
                    material_names.len() - 1
                });
                (i, mi)
            }
            None => {
                surface_names.push(model.name.clone());
                material_names.push(format!("{} (no material)", model.name));
                (surface_names.len() - 1, material_names.len() - 1)
            }
        };
        let p = &model.mesh.positions;
        let vertex = |i: u32| -> Result<Vector3<f64>, WorldError> {
            let i = i as usize * 3;
            p.get(i..i + 3)
                .map(|v| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
                .ok_or_else(|| WorldError::Geometry {
                    path: obj.to_path_buf(),
                    message: format!("group {:?}: a face refers to missing vertex {}", model.name, i / 3 + 1),
                })
        };
        for f in model.mesh.indices.chunks_exact(3) {
            let corners = [vertex(f[0])?, vertex(f[1])?, vertex(f[2])?];
            match Triangle::new(corners, material as u32, surface as u32) {
                Some(t) => triangles.push(t),
                None => degenerate += 1,
            }
        }
    }
    if degenerate > 0 {
        tracing::warn!(path = %obj.display(), degenerate, "skipped degenerate triangles");
    }
    if triangles.is_empty() {
        return Err(WorldError::Geometry {
            path: obj.to_path_buf(),
            message: "no triangles".into(),
        });
    }
    let appearances: Vec<Appearance> = material_names
        .iter()
        .map(|m| appearance(&description.name, m))
        .collect();
    let materials = material_names
        .iter()
        .zip(&appearances)
        .map(|(name, a)| {
            Ok(Material {
                name: name.clone(),
                albedo: a.albedo.clone(),
                specular: a.lobe().map_err(|e| WorldError::Geometry {
                    path: obj.to_path_buf(),
                    message: format!("material {name:?}: {e}"),
                })?,
                emission: [0.0; 3],
            })
        })
        .collect::<Result<Vec<_>, WorldError>>()?;
    let scene = Scene::new(triangles, materials, surface_names).map_err(|e| WorldError::Geometry {
        path: obj.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(LoadedScene {
        description,
        scene,
        appearances,
    })
}

/// The examples directory of this repository (for tests and the demo).
pub fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

impl LoadedScene {
    /// An undistorted pinhole view from each of the scene's named poses
    /// (azimuth from north through east, elevation above the horizon, the
    /// image upright), with vertical field of view `vfov_rad` and
    /// `width × height` pixels: the views visibility processing (thesis
    /// §3.5) is checked on.
    pub fn pinhole_views(
        &self,
        vfov_rad: f64,
        width: usize,
        height: usize,
    ) -> Result<Vec<campanile_process::visibility::PinholeView>, campanile_process::visibility::VisibilityError> {
        self.description
            .poses
            .iter()
            .map(|p| {
                let (az, el) = (p.azimuth_deg.to_radians(), p.elevation_deg.to_radians());
                let look = Vector3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin());
                campanile_process::visibility::PinholeView::look_at(
                    &p.name,
                    Vector3::new(p.position_m.0, p.position_m.1, p.position_m.2),
                    look,
                    Vector3::z(),
                    vfov_rad,
                    width,
                    height,
                )
            })
            .collect()
    }
}
