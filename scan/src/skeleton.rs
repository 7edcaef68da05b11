//! The scene-file skeleton: the `name`, `geometry`, `materials` and
//! `surfaces` of a `campanile_config::Scene` (the file `campanile igi`,
//! `process` and `render` take), written for a meshed scan. Each object is
//! a surface listing its OBJ groups, with a material of its own name (the
//! fitter's `Auto` model) until the user groups materials (thesis §4.4).
//!
//! The structs mirror the config crate's public fields (this crate does
//! not depend on it); a test reads the skeleton back through
//! `campanile_config::load_scene`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// A material group of the skeleton (`campanile_config::scene::MaterialGroup`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "MaterialGroup")]
pub struct SkeletonMaterial {
    /// Name.
    pub name: String,
}

/// An object: a named surface made of OBJ groups
/// (`campanile_config::scene::Surface`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Surface")]
pub struct SkeletonSurface {
    /// The object's name.
    pub name: String,
    /// Its OBJ groups.
    pub groups: Vec<String>,
    /// Its material group.
    pub material: String,
}

/// A scene file without camera poses or targets (`campanile_config::Scene`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Scene")]
pub struct SceneSkeleton {
    /// The scene's name.
    pub name: String,
    /// The OBJ file, relative to the scene file.
    pub geometry: PathBuf,
    /// Material groups.
    pub materials: Vec<SkeletonMaterial>,
    /// Objects.
    pub surfaces: Vec<SkeletonSurface>,
}

/// Why a skeleton could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum SkeletonError {
    /// The file could not be written or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The file is not a scene file.
    #[error("{}: {message} (expected a Scene(name, geometry, materials, surfaces) file)", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message, with its line and column.
        message: String,
    },
}

impl SceneSkeleton {
    /// A skeleton with one object and one material per `(object, groups)`.
    pub fn new(name: &str, geometry: &Path, objects: &[(String, Vec<String>)]) -> SceneSkeleton {
        SceneSkeleton {
            name: name.to_string(),
            geometry: geometry.to_path_buf(),
            materials: objects
                .iter()
                .map(|(name, _)| SkeletonMaterial { name: name.clone() })
                .collect(),
            surfaces: objects
                .iter()
                .map(|(name, groups)| SkeletonSurface {
                    name: name.clone(),
                    groups: groups.clone(),
                    material: name.clone(),
                })
                .collect(),
        }
    }

    /// Writes the skeleton as RON.
    pub fn write(&self, path: &Path) -> Result<(), SkeletonError> {
        let config = ron::ser::PrettyConfig::new().struct_names(true);
        let text = ron::ser::to_string_pretty(self, config).map_err(|e| SkeletonError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        std::fs::write(path, text + "\n").map_err(|source| SkeletonError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a skeleton, or a full scene file's `name`, `geometry`,
    /// `materials` (their names) and `surfaces`: other fields are ignored.
    pub fn read(path: &Path) -> Result<SceneSkeleton, SkeletonError> {
        let text = std::fs::read_to_string(path).map_err(|source| SkeletonError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        ron::from_str(&text).map_err(|e| SkeletonError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}
