//! The scene: its geometry (an OBJ file), the named surfaces and material
//! groups that solvers report on, and the named camera poses plans refer to.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::validate::{Validate, Validator};

/// The reflectance model a material group is fitted with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum MaterialModel {
    /// Let the fitter choose the smallest model the data supports.
    #[default]
    Auto,
    /// Lambertian only.
    Diffuse,
    /// Isotropic Ward (thesis eq. A.1).
    WardIsotropic,
    /// Anisotropic Ward (thesis eq. A.2).
    WardAnisotropic,
    /// Outdoor pseudo-BRDFs for sun and for sky + environment (thesis §5.2).
    PseudoBrdf,
}

/// Surfaces that share specular parameters (thesis §4.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct MaterialGroup {
    /// Name, referred to by surfaces.
    pub name: String,
    /// Model to fit.
    #[serde(default)]
    pub model: MaterialModel,
    /// The known diffuse albedo per channel (r, g, b), each in [0, 1], of a
    /// material that is not recovered: the environment (ground, a
    /// neighbouring building) that lights the recovered surfaces by one
    /// bounce (thesis §5.4). `campanile outdoor recover` needs it on every
    /// material that is not `PseudoBrdf`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::albedo()"))]
    pub albedo: Option<(f64, f64, f64)>,
}

/// A named surface: one or more OBJ groups, e.g. a wall of the tower.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Surface {
    /// Name, referred to by plan triggers ("face becomes sunlit").
    pub name: String,
    /// OBJ group or object names (`g` or `o` lines) that make up the surface.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub groups: Vec<String>,
    /// The material group it belongs to.
    pub material: String,
}

/// A named place and direction to photograph from. The direction is in the
/// world frame, so that the same scene serves any station: each station's
/// mount calibration turns it into head angles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct CameraPose {
    /// Name, referred to by plan steps.
    pub name: String,
    /// Where the head stands, in the scene frame (x east, y north, z up), metres.
    pub position_m: (f64, f64, f64),
    /// Azimuth of the optical axis, degrees from north through east, in [0, 360).
    pub azimuth_deg: f64,
    /// Elevation of the optical axis above the horizon, degrees, in [-90, 90].
    pub elevation_deg: f64,
    /// Roll about the optical axis, degrees in [-180, 180], positive when
    /// the image turns clockwise as seen by the photographer: a hand-held
    /// photograph's (`campanile register` writes it). Zero (the default)
    /// for the head, whose views are level up to its mount calibration.
    #[serde(default, skip_serializing_if = "is_zero")]
    #[cfg_attr(test, proptest(value = "0.0"))]
    pub roll_deg: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// A scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name for reports.
    pub name: String,
    /// Wavefront OBJ geometry, relative to this file. Units are metres.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::path()"))]
    pub geometry: PathBuf,
    /// Material groups.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub materials: Vec<MaterialGroup>,
    /// Named surfaces.
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub surfaces: Vec<Surface>,
    /// Named camera poses.
    #[serde(default)]
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::small_vec()"))]
    pub poses: Vec<CameraPose>,
    /// The surveyed targets hung in the scene: a `Targets(...)` file,
    /// relative to this file. The simulator paints them on their plates;
    /// `campanile register` and `station calibrate-mount` find them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(value = "None"))]
    pub targets: Option<PathBuf>,
}

impl Scene {
    /// The pose called `name`.
    pub fn pose(&self, name: &str) -> Option<&CameraPose> {
        self.poses.iter().find(|p| p.name == name)
    }

    /// The surface called `name`.
    pub fn surface(&self, name: &str) -> Option<&Surface> {
        self.surfaces.iter().find(|s| s.name == name)
    }
}

/// Names of the groups and objects in an OBJ file.
fn obj_group_names(path: &std::path::Path) -> Result<Vec<String>, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj(path, &opts).map_err(|e| e.to_string())?;
    Ok(models.into_iter().map(|m| m.name).collect())
}

impl Validate for Scene {
    fn validate(&self, v: &mut Validator) {
        v.non_empty("name", &self.name);
        let obj = v.base_dir().join(&self.geometry);
        let groups = if obj.is_file() {
            match obj_group_names(&obj) {
                Ok(g) => Some(g),
                Err(e) => {
                    v.invalid(
                        "geometry",
                        format!("{:?}", self.geometry.display().to_string()),
                        &format!("a readable Wavefront OBJ file ({}: {e})", obj.display()),
                    );
                    None
                }
            }
        } else {
            v.existing_file("geometry", &self.geometry, "a Wavefront OBJ file");
            None
        };
        if let Some(t) = &self.targets {
            v.existing_file("targets", t, "a Targets(...) file of surveyed targets");
        }
        v.unique_names("materials", self.materials.iter().map(|m| m.name.as_str()));
        v.at("materials", |v| {
            for (i, m) in self.materials.iter().enumerate() {
                v.at(i, |v| {
                    v.non_empty("name", &m.name);
                    if let Some((r, g, b)) = m.albedo {
                        v.at("albedo", |v| {
                            for (k, c) in [r, g, b].into_iter().enumerate() {
                                v.range(k, c, 0.0, 1.0, "a diffuse albedo in [0, 1]");
                            }
                        });
                    }
                });
            }
        });
        v.unique_names("surfaces", self.surfaces.iter().map(|s| s.name.as_str()));
        v.at("surfaces", |v| {
            for (i, s) in self.surfaces.iter().enumerate() {
                v.at(i, |v| {
                    v.non_empty("name", &s.name);
                    if s.groups.is_empty() {
                        v.invalid("groups", "an empty list".into(), "at least one OBJ group name");
                    }
                    if let Some(groups) = &groups {
                        v.at("groups", |v| {
                            for (k, g) in s.groups.iter().enumerate() {
                                if !groups.contains(g) {
                                    v.invalid(
                                        k,
                                        format!("{g:?}"),
                                        &format!(
                                            "a group of {} (it has: {})",
                                            self.geometry.display(),
                                            groups.join(", ")
                                        ),
                                    );
                                }
                            }
                        });
                    }
                    if !self.materials.iter().any(|m| m.name == s.material) {
                        let names: Vec<_> = self.materials.iter().map(|m| m.name.as_str()).collect();
                        v.invalid(
                            "material",
                            format!("{:?}", s.material),
                            &format!("one of this scene's materials: {}", names.join(", ")),
                        );
                    }
                });
            }
        });
        v.unique_names("poses", self.poses.iter().map(|p| p.name.as_str()));
        v.at("poses", |v| {
            for (i, p) in self.poses.iter().enumerate() {
                v.at(i, |v| {
                    v.non_empty("name", &p.name);
                    let (x, y, z) = p.position_m;
                    v.at("position_m", |v| {
                        for (k, c) in [x, y, z].into_iter().enumerate() {
                            v.range(k, c, -1e5, 1e5, "a coordinate in metres");
                        }
                    });
                    v.range_open_high("azimuth_deg", p.azimuth_deg, 0.0, 360.0, "an azimuth in degrees");
                    v.range("elevation_deg", p.elevation_deg, -90.0, 90.0, "an elevation in degrees");
                    v.range(
                        "roll_deg",
                        p.roll_deg,
                        -180.0,
                        180.0,
                        "a roll about the optical axis in degrees",
                    );
                });
            }
        });
    }
}
