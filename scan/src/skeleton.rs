//! The scene-file skeleton: the `name`, `geometry`, `materials` and
//! `surfaces` of a `campanile_config::Scene` (the file `campanile igi`,
//! `process` and `render` take), written for a meshed scan. Each object is
//! a surface listing its OBJ groups, with a material of its own name (the
//! fitter's `Auto` model) until the user groups materials (thesis §4.4).
//!
//! The structs mirror the config crate's public fields (this crate does
//! not depend on it), so that an edited full scene file keeps its
//! materials' models and albedos, its camera poses and its targets; tests
//! read skeletons and edited scenes back through
//! `campanile_config::load_scene`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The reflectance model of a material group
/// (`campanile_config::scene::MaterialModel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum SkeletonModel {
    /// The fitter chooses.
    #[default]
    Auto,
    /// Lambertian only.
    Diffuse,
    /// Isotropic Ward.
    WardIsotropic,
    /// Anisotropic Ward.
    WardAnisotropic,
    /// Outdoor pseudo-BRDFs.
    PseudoBrdf,
}

fn is_auto(m: &SkeletonModel) -> bool {
    *m == SkeletonModel::Auto
}

/// A material group of the skeleton (`campanile_config::scene::MaterialGroup`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "MaterialGroup")]
pub struct SkeletonMaterial {
    /// Name.
    pub name: String,
    /// Model to fit.
    #[serde(default, skip_serializing_if = "is_auto")]
    pub model: SkeletonModel,
    /// A known diffuse albedo (r, g, b).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub albedo: Option<(f64, f64, f64)>,
}

impl SkeletonMaterial {
    /// A material to be fitted (`Auto`), with no known albedo.
    pub fn named(name: &str) -> SkeletonMaterial {
        SkeletonMaterial {
            name: name.to_string(),
            model: SkeletonModel::Auto,
            albedo: None,
        }
    }
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A named camera pose (`campanile_config::scene::CameraPose`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "CameraPose")]
pub struct SkeletonPose {
    /// Name.
    pub name: String,
    /// Position, scene frame, metres.
    pub position_m: (f64, f64, f64),
    /// Azimuth of the optical axis, degrees from north through east.
    pub azimuth_deg: f64,
    /// Elevation of the optical axis, degrees.
    pub elevation_deg: f64,
    /// Roll about the optical axis, degrees.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub roll_deg: f64,
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

/// A scene file (`campanile_config::Scene`); a meshed scan's has no poses
/// or targets.
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
    /// Named camera poses.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub poses: Vec<SkeletonPose>,
    /// The surveyed targets file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub targets: Option<PathBuf>,
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
            materials: objects.iter().map(|(name, _)| SkeletonMaterial::named(name)).collect(),
            surfaces: objects
                .iter()
                .map(|(name, groups)| SkeletonSurface {
                    name: name.clone(),
                    groups: groups.clone(),
                    material: name.clone(),
                })
                .collect(),
            poses: Vec::new(),
            targets: None,
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

    /// Reads a skeleton or a full scene file.
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
