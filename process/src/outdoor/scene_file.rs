//! The scene of `campanile outdoor recover|render` from its plain files: the
//! scene description (RON, as the station's: geometry, materials, surfaces)
//! and its OBJ. The surfaces whose material is `PseudoBrdf` are the
//! targets whose pseudo-albedos are recovered (thesis §5.2); every other
//! material is the environment, which lights the targets by one bounce
//! (§5.4) with the albedo the file gives it (`albedo: (r, g, b)`). No
//! albedo is guessed: a non-target material without one is refused.

use std::path::{Path, PathBuf};

use campanile_config::scene::MaterialModel;

use crate::igi::scene_file::SceneFileError;
use crate::render::{Material, Scene};
use crate::scene_geometry::load_obj;

/// A scene read from its description and geometry.
#[derive(Debug, Clone)]
pub struct OutdoorScene {
    /// The description as read.
    pub description: campanile_config::Scene,
    /// The description's file.
    pub path: PathBuf,
    /// Triangles and materials (targets' albedo 0: the pseudo-albedos
    /// replace them).
    pub scene: Scene,
    /// Indices of the target surfaces in `scene`.
    pub targets: Vec<usize>,
    /// Zero-area triangles the OBJ held, skipped.
    pub degenerate: usize,
}

/// Reads and checks the scene description at `path` and its OBJ.
pub fn load_scene(path: &Path) -> Result<OutdoorScene, SceneFileError> {
    let loaded = campanile_config::document::load_scene(path).map_err(|e| SceneFileError::File {
        path: path.to_path_buf(),
        message: format!("{e} (expected a Scene(...) description: README, \"Outdoor files\")"),
    })?;
    let description = loaded.value;
    let obj = loaded.source.base_dir().join(&description.geometry);
    let geometry = load_obj(&description, &obj).map_err(|e| SceneFileError::File {
        path: obj.clone(),
        message: e.to_string(),
    })?;
    let field = |field: String, value: String, expected: &str| SceneFileError::Field {
        path: path.to_path_buf(),
        field,
        value,
        expected: expected.to_string(),
    };
    let mut materials = Vec::new();
    for name in &geometry.material_names {
        let entry = description.materials.iter().enumerate().find(|(_, m)| &m.name == name);
        let albedo = match entry {
            Some((_, m)) if m.model == MaterialModel::PseudoBrdf => [0.0; 3],
            Some((i, m)) => {
                let (r, g, b) = m.albedo.ok_or_else(|| {
                    field(
                        format!("materials[{i}].albedo"),
                        "absent".into(),
                        &format!(
                            "the known diffuse albedo (r, g, b) of {:?}: it is not recovered (model {:?}, not \
                             PseudoBrdf), so it lights the targets as environment with the albedo given",
                            m.name, m.model
                        ),
                    )
                })?;
                [r, g, b]
            }
            // Groups no surface lists: surfaces of their own, lit and
            // lighting nothing known; refused so that nothing is guessed.
            None => {
                return Err(field(
                    "surfaces".into(),
                    format!("no surface lists the OBJ group of material {name:?}"),
                    &format!(
                        "every OBJ group of {} in a surface (a target with a PseudoBrdf material, or environment \
                         with an albedo)",
                        obj.display()
                    ),
                ));
            }
        };
        materials.push(Material::diffuse(name, albedo));
    }
    let targets: Vec<usize> = description
        .surfaces
        .iter()
        .enumerate()
        .filter(|(_, s)| {
            description
                .materials
                .iter()
                .any(|m| m.name == s.material && m.model == MaterialModel::PseudoBrdf)
        })
        .map(|(i, _)| i)
        .collect();
    if targets.is_empty() {
        return Err(field(
            "materials".into(),
            "no PseudoBrdf material on any surface".into(),
            "at least one surface whose material has model: PseudoBrdf (the surfaces to recover)",
        ));
    }
    let scene =
        Scene::new(geometry.triangles, materials, geometry.surface_names).map_err(|e| SceneFileError::File {
            path: obj.clone(),
            message: e.to_string(),
        })?;
    Ok(OutdoorScene {
        description,
        path: path.to_path_buf(),
        scene,
        targets,
        degenerate: geometry.degenerate,
    })
}
