//! A scene description (RON + OBJ, as the processing pipeline reads it)
//! turned into a renderable scene with the simulator's true materials.

use std::path::{Path, PathBuf};

use campanile_process::render::{Material, Scene, Texture};
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
    let base = loaded.source.base_dir();
    let obj = base.join(&loaded.value.geometry);
    let targets = loaded.value.targets.as_ref().map(|t| base.join(t));
    let scene = from_description(loaded.value, &obj)?;
    // The surveyed targets, painted on their plates.
    match targets {
        Some(t) => {
            let survey = campanile_config::load_targets(&t).map_err(|e| WorldError::Config {
                path: t.clone(),
                message: e.to_string(),
            })?;
            super::target_photos::with_survey(&scene, &survey.value)
        }
        None => Ok(scene),
    }
}

/// Builds the scene of `description` with geometry from `obj`.
pub fn from_description(description: campanile_config::Scene, obj: &Path) -> Result<LoadedScene, WorldError> {
    let geometry =
        campanile_process::scene_geometry::load_obj(&description, obj).map_err(|e| WorldError::Geometry {
            path: obj.to_path_buf(),
            message: e.to_string(),
        })?;
    if geometry.degenerate > 0 {
        tracing::warn!(path = %obj.display(), degenerate = geometry.degenerate, "skipped degenerate triangles");
    }
    let campanile_process::scene_geometry::SceneGeometry {
        triangles,
        surface_names,
        material_names,
        ..
    } = geometry;
    let appearances: Vec<Appearance> = material_names
        .iter()
        .map(|m| {
            // A material whose albedo the scene file gives is that constant
            // diffuse albedo; the others, the simulator's appearance.
            match description
                .materials
                .iter()
                .find(|g| &g.name == m)
                .and_then(|g| g.albedo)
            {
                Some((r, g, b)) => Appearance::diffuse(Texture::Constant([r, g, b])),
                None => appearance(&description.name, m),
            }
        })
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
