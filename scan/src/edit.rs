//! Scene editing (thesis §2.5.2): objects are groups of surfaces, and a
//! small RON edit file merges groups into named objects, then moves,
//! copies and deletes objects, on the meshes of a scene directory (the
//! OBJ and skeleton [`crate::reconstruction`] writes), writing a new one.
//!
//! ```ron
//! SceneEdit(
//!     // Merged first, in order: OBJ groups, or whole objects, by name.
//!     objects: [
//!         Object(name: "cabinet", members: ["cabinet_top", "cabinet_west", "surface_8"]),
//!     ],
//!     // Then applied in order.
//!     operations: [
//!         Copy(object: "cabinet", name: "cabinet_2", offset_m: (-2.0, 1.2, 0.0)),
//!         Move(object: "cabinet_2", translate_m: (0.0, 0.3, 0.0), rotate_z_deg: 90.0),
//!         Delete(object: "wall_east"),
//!     ],
//! )
//! ```
//!
//! - `Move` turns the object by `rotate_z_deg` (counter-clockwise seen
//!   from above) about the vertical line through the centre of its
//!   bounding box, then translates it by `translate_m`.
//! - `Copy` makes a new object `name` of the object's meshes moved by
//!   `offset_m`, in new OBJ groups `GROUP_NAME`, sharing its material.
//! - `Delete` removes the object and its meshes.
//!
//! A merged object keeps its members' material when they share one, and
//! otherwise gets a new one of its own name (model `Auto`). A full scene
//! file keeps its materials, camera poses and targets. Every error names
//! the object or group that does not exist and lists those that do.

use std::path::{Path, PathBuf};

use nalgebra::{Rotation3, Vector3};
use serde::Deserialize;

use crate::obj_file::{NamedMesh, ObjError, read_obj, write_obj};
use crate::skeleton::{SceneSkeleton, SkeletonError, SkeletonMaterial, SkeletonPose, SkeletonSurface};

/// A merge: the members (OBJ groups or objects) become one object.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    /// The new object's name.
    pub name: String,
    /// OBJ group names or object names.
    pub members: Vec<String>,
}

/// One edit of an object.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Operation {
    /// Turn about the vertical through the object's centre, then translate.
    Move {
        /// The object.
        object: String,
        /// Translation, metres.
        #[serde(default)]
        translate_m: (f64, f64, f64),
        /// Turn about z, degrees, counter-clockwise seen from above.
        #[serde(default)]
        rotate_z_deg: f64,
    },
    /// A copy at an offset.
    Copy {
        /// The object copied.
        object: String,
        /// The copy's name.
        name: String,
        /// Where the copy goes relative to the object, metres.
        offset_m: (f64, f64, f64),
    },
    /// Removal.
    Delete {
        /// The object.
        object: String,
    },
}

/// An edit file.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SceneEdit {
    /// Merges, applied first.
    #[serde(default)]
    pub objects: Vec<Object>,
    /// Operations, applied in order after the merges.
    #[serde(default)]
    pub operations: Vec<Operation>,
}

/// Why an edit could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    /// The edit file is not a `SceneEdit(...)`.
    #[error("{}: {message} (expected SceneEdit(objects: [...], operations: [...]))", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// ron's message, with line and column.
        message: String,
    },
    /// A name that is neither an object nor an OBJ group.
    #[error("{place}: no {what} named {name:?} (the scene has: {known})")]
    Unknown {
        /// Where in the edit file (`objects[0]`, `operations[2]`).
        place: String,
        /// "object" or "object or OBJ group".
        what: &'static str,
        /// The name.
        name: String,
        /// The names there are.
        known: String,
    },
    /// A new object or group name that is already taken.
    #[error("{place}: the name {name:?} is already taken (expected a new object name)")]
    Taken {
        /// Where in the edit file.
        place: String,
        /// The name.
        name: String,
    },
    /// A value that is not finite.
    #[error("{place}: {field} is {value} (expected a finite number)")]
    NotFinite {
        /// Where in the edit file.
        place: String,
        /// The field.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// The scene's OBJ could not be read.
    #[error("reading the scene: {0}")]
    SceneObj(ObjError),
    /// The scene file could not be read.
    #[error("reading the scene: {0}")]
    SceneFile(SkeletonError),
    /// The edited OBJ could not be written.
    #[error("writing the edited scene: {0}")]
    Obj(ObjError),
    /// The edited scene file could not be written.
    #[error("writing the edited scene: {0}")]
    Skeleton(SkeletonError),
    /// The output directory.
    #[error("{}: {source}", path.display())]
    Io {
        /// The directory.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
}

impl EditError {
    /// Whether the edit file or the scene is at fault (exit 2), rather than
    /// writing the result (exit 1).
    pub fn is_bad_input(&self) -> bool {
        match self {
            EditError::Io { .. } | EditError::Obj(_) | EditError::Skeleton(_) => false,
            EditError::Parse { .. }
            | EditError::Unknown { .. }
            | EditError::Taken { .. }
            | EditError::NotFinite { .. }
            | EditError::SceneObj(_)
            | EditError::SceneFile(_) => true,
        }
    }
}

/// An object of a scene being edited.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// Name.
    pub name: String,
    /// Its OBJ groups.
    pub groups: Vec<String>,
    /// Its material.
    pub material: String,
}

/// A scene's meshes and objects, editable.
#[derive(Debug, Clone, PartialEq)]
pub struct EditableScene {
    /// The scene's name.
    pub name: String,
    /// Meshes by OBJ group.
    pub meshes: Vec<NamedMesh>,
    /// Objects.
    pub objects: Vec<SceneObject>,
    /// Material groups.
    pub materials: Vec<SkeletonMaterial>,
    /// The scene's camera poses, kept.
    pub poses: Vec<SkeletonPose>,
    /// The scene's targets file, as a path from where the scene was read.
    pub targets: Option<PathBuf>,
}

fn listed<'a>(names: impl Iterator<Item = &'a str>) -> String {
    names.collect::<Vec<_>>().join(", ")
}

impl EditableScene {
    /// Reads the scene file at `path` (a skeleton or a full scene file) and
    /// its OBJ; OBJ groups no surface lists become objects of their own.
    pub fn read(path: &Path) -> Result<EditableScene, EditError> {
        let skeleton = SceneSkeleton::read(path).map_err(EditError::SceneFile)?;
        let scene_dir = path.parent().unwrap_or(Path::new("."));
        let obj = scene_dir.join(&skeleton.geometry);
        let meshes = read_obj(&obj).map_err(EditError::SceneObj)?;
        let mut objects: Vec<SceneObject> = skeleton
            .surfaces
            .iter()
            .map(|s| SceneObject {
                name: s.name.clone(),
                groups: s.groups.clone(),
                material: s.material.clone(),
            })
            .collect();
        let mut materials = skeleton.materials.clone();
        for m in &meshes {
            if !objects.iter().any(|o| o.groups.contains(&m.group)) {
                objects.push(SceneObject {
                    name: m.group.clone(),
                    groups: vec![m.group.clone()],
                    material: m.group.clone(),
                });
                materials.push(SkeletonMaterial::named(&m.group));
            }
        }
        Ok(EditableScene {
            name: skeleton.name,
            meshes,
            objects,
            materials,
            poses: skeleton.poses,
            targets: skeleton.targets.map(|t| scene_dir.join(t)),
        })
    }

    /// Writes `scene.obj` and `scene.ron` into `dir` (created if needed).
    pub fn write(&self, dir: &Path) -> Result<(), EditError> {
        std::fs::create_dir_all(dir).map_err(|source| EditError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        write_obj(&dir.join("scene.obj"), &self.meshes, "campanile-scan: an edited scene").map_err(EditError::Obj)?;
        let used: Vec<&String> = self.objects.iter().map(|o| &o.material).collect();
        // The targets file stays where it was: from the new directory, by
        // its absolute path.
        let targets = match &self.targets {
            Some(t) => Some(std::path::absolute(t).map_err(|source| EditError::Io {
                path: t.clone(),
                source,
            })?),
            None => None,
        };
        let skeleton = SceneSkeleton {
            name: self.name.clone(),
            geometry: PathBuf::from("scene.obj"),
            materials: self
                .materials
                .iter()
                .filter(|m| used.contains(&&m.name))
                .cloned()
                .collect(),
            surfaces: self
                .objects
                .iter()
                .map(|o| SkeletonSurface {
                    name: o.name.clone(),
                    groups: o.groups.clone(),
                    material: o.material.clone(),
                })
                .collect(),
            poses: self.poses.clone(),
            targets,
        };
        skeleton.write(&dir.join("scene.ron")).map_err(EditError::Skeleton)
    }

    fn object_index(&self, place: &str, name: &str) -> Result<usize, EditError> {
        self.objects
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| EditError::Unknown {
                place: place.to_string(),
                what: "object",
                name: name.to_string(),
                known: listed(self.objects.iter().map(|o| o.name.as_str())),
            })
    }

    fn check_new_name(&self, place: &str, name: &str) -> Result<(), EditError> {
        if name.trim().is_empty() || self.objects.iter().any(|o| o.name == name) {
            return Err(EditError::Taken {
                place: place.to_string(),
                name: name.to_string(),
            });
        }
        Ok(())
    }

    /// Merges `object`'s members into one object.
    fn merge(&mut self, place: &str, object: &Object) -> Result<(), EditError> {
        let mut groups = Vec::new();
        let mut materials = Vec::new();
        for member in &object.members {
            if let Some(o) = self.objects.iter().find(|o| &o.name == member) {
                groups.extend(o.groups.iter().cloned());
                materials.push(o.material.clone());
            } else if self.meshes.iter().any(|m| &m.group == member) {
                groups.push(member.clone());
                if let Some(o) = self.objects.iter().find(|o| o.groups.contains(member)) {
                    materials.push(o.material.clone());
                }
            } else {
                return Err(EditError::Unknown {
                    place: format!("{place} ({:?})", object.name),
                    what: "object or OBJ group",
                    name: member.clone(),
                    known: listed(
                        self.objects
                            .iter()
                            .map(|o| o.name.as_str())
                            .chain(self.meshes.iter().map(|m| m.group.as_str())),
                    ),
                });
            }
        }
        for o in &mut self.objects {
            o.groups.retain(|g| !groups.contains(g));
        }
        self.objects.retain(|o| !o.groups.is_empty());
        self.check_new_name(place, &object.name)?;
        let mut seen = std::collections::HashSet::new();
        groups.retain(|g| seen.insert(g.clone()));
        // One material among the members is kept; several give way to a
        // new one of the object's name, to be fitted.
        materials.dedup();
        let material = match &materials[..] {
            [one] => one.clone(),
            _ => {
                if !self.materials.iter().any(|m| m.name == object.name) {
                    self.materials.push(SkeletonMaterial::named(&object.name));
                }
                object.name.clone()
            }
        };
        self.objects.push(SceneObject {
            name: object.name.clone(),
            groups,
            material,
        });
        Ok(())
    }

    /// Applies `edit`; the scene is unchanged if an error is returned.
    pub fn apply(&mut self, edit: &SceneEdit) -> Result<(), EditError> {
        let mut scene = self.clone();
        for (i, object) in edit.objects.iter().enumerate() {
            scene.merge(&format!("objects[{i}]"), object)?;
        }
        for (i, operation) in edit.operations.iter().enumerate() {
            let place = format!("operations[{i}]");
            match operation {
                Operation::Move {
                    object,
                    translate_m,
                    rotate_z_deg,
                } => {
                    let k = scene.object_index(&place, object)?;
                    let t = finite(&place, "translate_m", translate_m)?;
                    finite(&place, "rotate_z_deg", &(*rotate_z_deg, 0.0, 0.0))?;
                    scene.transform(k, *rotate_z_deg, t);
                }
                Operation::Copy { object, name, offset_m } => {
                    let k = scene.object_index(&place, object)?;
                    scene.check_new_name(&place, name)?;
                    let t = finite(&place, "offset_m", offset_m)?;
                    let source = scene.objects[k].clone();
                    let mut groups = Vec::new();
                    for g in &source.groups {
                        let group = format!("{g}_{name}");
                        if scene.meshes.iter().any(|m| m.group == group) {
                            return Err(EditError::Taken { place, name: group });
                        }
                        if let Some(m) = scene.meshes.iter().find(|m| &m.group == g) {
                            let mut mesh = m.mesh.clone();
                            mesh.positions.iter_mut().for_each(|p| *p += t);
                            scene.meshes.push(NamedMesh {
                                group: group.clone(),
                                mesh,
                            });
                            groups.push(group);
                        }
                    }
                    scene.objects.push(SceneObject {
                        name: name.clone(),
                        groups,
                        material: source.material,
                    });
                }
                Operation::Delete { object } => {
                    let k = scene.object_index(&place, object)?;
                    let gone = scene.objects.remove(k);
                    scene.meshes.retain(|m| !gone.groups.contains(&m.group));
                }
            }
        }
        *self = scene;
        Ok(())
    }

    /// Turns object `k` by `rotate_z_deg` about the vertical through its
    /// bounding box's centre, then moves it by `t`.
    fn transform(&mut self, k: usize, rotate_z_deg: f64, t: Vector3<f64>) {
        let groups = &self.objects[k].groups;
        let mut all = crate::mesh::TriangleMesh::default();
        for m in self.meshes.iter().filter(|m| groups.contains(&m.group)) {
            all.append(&m.mesh);
        }
        let Some(centre) = all.bounding_box_centre() else {
            return;
        };
        let pivot = Vector3::new(centre.x, centre.y, 0.0);
        let turn = Rotation3::from_axis_angle(&Vector3::z_axis(), rotate_z_deg.to_radians());
        for m in self.meshes.iter_mut().filter(|m| groups.contains(&m.group)) {
            for p in &mut m.mesh.positions {
                *p = if rotate_z_deg == 0.0 {
                    *p + t
                } else {
                    pivot + turn * (*p - pivot) + t
                };
            }
        }
    }
}

fn finite(place: &str, field: &'static str, v: &(f64, f64, f64)) -> Result<Vector3<f64>, EditError> {
    match [v.0, v.1, v.2].into_iter().find(|x| !x.is_finite()) {
        Some(value) => Err(EditError::NotFinite {
            place: place.to_string(),
            field,
            value,
        }),
        None => Ok(Vector3::new(v.0, v.1, v.2)),
    }
}

/// Reads an edit file.
pub fn read_edit(path: &Path) -> Result<SceneEdit, EditError> {
    let text = std::fs::read_to_string(path).map_err(|e| EditError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    ron::from_str(&text).map_err(|e| EditError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Applies the edit file `edit` to the scene file `scene` (and its OBJ),
/// writing the edited `scene.obj` and `scene.ron` into `out`; returns the
/// edited scene.
pub fn edit_scene(scene: &Path, edit: &Path, out: &Path) -> Result<EditableScene, EditError> {
    let edit = read_edit(edit)?;
    let mut editable = EditableScene::read(scene)?;
    editable.apply(&edit)?;
    editable.write(out)?;
    Ok(editable)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshOptions;
    use crate::reconstruction::reconstruct;
    use crate::synthetic_scan::{cabinet, room, scan_of};

    /// The room with its cabinet, scanned from its centre and meshed into `dir`.
    fn scanned_room(dir: &Path) -> PathBuf {
        let rects: Vec<_> = room().into_iter().chain(cabinet()).collect();
        let (scan, seg) = scan_of(&rects, Vector3::new(2.0, 1.5, 1.25), 1.5, 87.0, 0.002);
        let out = dir.join("scanned");
        reconstruct(&[scan], &seg, &MeshOptions::default(), &out).unwrap();
        out.join("scene.ron")
    }

    fn vertices_of<'a>(scene: &'a EditableScene, object: &str) -> Vec<&'a Vector3<f64>> {
        let o = scene.objects.iter().find(|o| o.name == object).unwrap();
        scene
            .meshes
            .iter()
            .filter(|m| o.groups.contains(&m.group))
            .flat_map(|m| &m.mesh.positions)
            .collect()
    }

    #[test]
    fn an_edit_moves_and_copies_an_object_by_exactly_its_offset() {
        let dir = tempfile::tempdir().unwrap();
        let original = EditableScene::read(&scanned_room(dir.path())).unwrap();
        assert_eq!(original.objects.len(), 9);
        let edit: SceneEdit = ron::from_str(
            r#"SceneEdit(
                objects: [Object(name: "cabinet", members: ["cabinet_top", "cabinet_west", "surface_8"])],
                operations: [
                    Copy(object: "cabinet", name: "cabinet_2", offset_m: (-2.0, 1.25, 0.0)),
                    Move(object: "cabinet", translate_m: (0.1, -0.2, 0.05)),
                    Delete(object: "wall_east"),
                ],
            )"#,
        )
        .unwrap();
        let mut scene = original.clone();
        scene.apply(&edit).unwrap();
        // 9 objects, less 3 merged into one, plus a copy, less a wall.
        assert_eq!(scene.objects.len(), 9 - 3 + 1 + 1 - 1);
        let before = vertices_of(&original, "cabinet_top")
            .into_iter()
            .chain(vertices_of(&original, "cabinet_west"))
            .chain(vertices_of(&original, "cabinet_north"));
        let moved = vertices_of(&scene, "cabinet");
        let copied = vertices_of(&scene, "cabinet_2");
        let mut n = 0;
        for ((b, m), c) in before.zip(moved).zip(copied) {
            assert!((m - b - Vector3::new(0.1, -0.2, 0.05)).norm() < 1e-12);
            assert!((c - b - Vector3::new(-2.0, 1.25, 0.0)).norm() < 1e-12);
            n += 1;
        }
        assert!(n > 10);
        assert!(
            !scene.meshes.iter().any(|m| m.group == "surface_3"),
            "wall_east's mesh is gone"
        );
        let copy = scene.objects.iter().find(|o| o.name == "cabinet_2").unwrap();
        assert_eq!(
            copy.groups,
            ["surface_6_cabinet_2", "surface_7_cabinet_2", "surface_8_cabinet_2"]
        );
        assert_eq!(copy.material, "cabinet");

        // A turn of 90° about the cabinet's vertical centre line keeps that line.
        let mut turned = scene.clone();
        let turn = SceneEdit {
            objects: vec![],
            operations: vec![Operation::Move {
                object: "cabinet".into(),
                translate_m: (0.0, 0.0, 0.0),
                rotate_z_deg: 90.0,
            }],
        };
        turned.apply(&turn).unwrap();
        let centre = |s: &EditableScene| {
            let mut all = crate::mesh::TriangleMesh::default();
            let o = s.objects.iter().find(|o| o.name == "cabinet").unwrap();
            s.meshes
                .iter()
                .filter(|m| o.groups.contains(&m.group))
                .for_each(|m| all.append(&m.mesh));
            all.bounding_box_centre().unwrap()
        };
        let (c0, c1) = (centre(&scene), centre(&turned));
        assert!((c0.xy() - c1.xy()).norm() < 1e-12 && (c0.z - c1.z).abs() < 1e-12);
        let (p0, p1) = (vertices_of(&scene, "cabinet")[0], vertices_of(&turned, "cabinet")[0]);
        let (d0, d1) = (p0 - c0, p1 - c1);
        assert!((d1 - Vector3::new(-d0.y, d0.x, d0.z)).norm() < 1e-12);
    }

    #[test]
    fn edits_naming_what_does_not_exist_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let scene = EditableScene::read(&scanned_room(dir.path())).unwrap();
        let cases = [
            (
                r#"SceneEdit(operations: [Delete(object: "piano")])"#,
                "operations[0]: no object named \"piano\" (the scene has: floor, ceiling, wall_west, wall_east, \
                 wall_south, wall_north, cabinet_top, cabinet_west, cabinet_north)",
            ),
            (
                r#"SceneEdit(objects: [Object(name: "c", members: ["cabinet_top", "surface_42"])])"#,
                "objects[0] (\"c\"): no object or OBJ group named \"surface_42\"",
            ),
            (
                r#"SceneEdit(operations: [Copy(object: "floor", name: "ceiling", offset_m: (0.0, 0.0, 1.0))])"#,
                "operations[0]: the name \"ceiling\" is already taken (expected a new object name)",
            ),
        ];
        for (text, message) in cases {
            let edit: SceneEdit = ron::from_str(text).unwrap();
            let mut edited = scene.clone();
            let e = edited.apply(&edit).unwrap_err().to_string();
            assert!(e.starts_with(message), "{e}");
            assert_eq!(edited, scene, "a refused edit changes nothing");
        }
        let bad = dir.path().join("bad.ron");
        std::fs::write(&bad, "SceneEdit(operations: [Shrink(object: \"floor\")])").unwrap();
        let e = edit_scene(&dir.path().join("scanned/scene.ron"), &bad, dir.path()).unwrap_err();
        assert!(e.to_string().contains("bad.ron: 1:"), "{e}");
        assert!(e.is_bad_input());
        let nothing = dir.path().join("nothing.ron");
        std::fs::write(&nothing, "SceneEdit()").unwrap();
        let e = edit_scene(&dir.path().join("none.ron"), &nothing, dir.path()).unwrap_err();
        assert!(e.to_string().starts_with("reading the scene: "), "{e}");
        assert!(e.is_bad_input(), "{e}");
    }

    /// Thesis Fig. 2.6: the cabinet copied across the room and moved; the
    /// edited scene goes through the scene file and OBJ reader and the
    /// renderer that `campanile render` uses, and the copy stands where it
    /// was moved.
    #[test]
    fn an_edited_scene_renders_with_the_copy_where_it_was_moved() {
        use campanile_process::render::{CameraRig, Lighting, Material, PointLight, RenderSettings, Scene, render};
        let dir = tempfile::tempdir().unwrap();
        let scanned = scanned_room(dir.path());
        let edit = dir.path().join("edit.ron");
        std::fs::write(
            &edit,
            r#"SceneEdit(
                objects: [Object(name: "cabinet", members: ["cabinet_top", "cabinet_west", "cabinet_north"])],
                operations: [
                    Copy(object: "cabinet", name: "cabinet_2", offset_m: (-2.0, 1.2, 0.0)),
                    Move(object: "cabinet_2", translate_m: (0.0, 0.3, 0.0)),
                ],
            )"#,
        )
        .unwrap();
        let edited_dir = dir.path().join("edited");
        edit_scene(&scanned, &edit, &edited_dir).unwrap();

        // Where the copy's top should be: a point of the scanned top, moved
        // by the copy's offset and then the move.
        let original = EditableScene::read(&scanned).unwrap();
        let top = &original.meshes.iter().find(|m| m.group == "surface_6").unwrap().mesh;
        // The top's area-weighted centroid: well inside it.
        let on_top = (0..top.triangles.len())
            .map(|t| {
                let [a, b, c] = top.corners(t);
                (a + b + c) / 3.0 * top.area_normal(t).norm()
            })
            .sum::<Vector3<f64>>()
            / (2.0 * top.area());
        let expected = on_top + Vector3::new(-2.0, 1.5, 0.0);
        assert!((expected.z - 0.9).abs() < 0.01);

        let light = [PointLight {
            position: Vector3::new(2.0, 1.5, 2.3),
            intensity: [10.0; 3],
        }];
        // A camera under the ceiling, looking down past the copy's top to
        // the floor beyond it.
        let eye = expected + Vector3::new(0.3, -0.6, 1.5);
        let camera = CameraRig::look_at(eye, expected - eye, Vector3::z(), 60f64.to_radians(), 48, 36).unwrap();
        let (u, v) = camera.project(&expected).unwrap();
        let (px, py) = (u as usize, v as usize);
        let settings = RenderSettings {
            samples_per_pixel: 4,
            max_bounces: 1,
            seed: 1,
            split_rays: 0,
        };
        let mut seen = Vec::new();
        for scene_file in [scanned.clone(), edited_dir.join("scene.ron")] {
            let description = campanile_config::load_scene(&scene_file).unwrap().value;
            let obj = scene_file.parent().unwrap().join(&description.geometry);
            let geometry = campanile_process::scene_geometry::load_obj(&description, &obj).unwrap();
            let materials = geometry
                .material_names
                .iter()
                .map(|m| Material::diffuse(m, [0.5; 3]))
                .collect();
            let scene = Scene::new(geometry.triangles, materials, geometry.surface_names).unwrap();
            let ray = camera.ray(u, v).unwrap();
            let hit = scene.intersect(&ray, 100.0).unwrap();
            let surface = &scene.surfaces()[scene.triangles()[hit.triangle].surface as usize];
            let lighting = Lighting {
                sky: None,
                points: &light,
                spheres: &[],
            };
            let image = render(&scene, &camera, &lighting, &settings);
            seen.push((surface.clone(), hit.point, image.radiance(px, py, 1)));
        }
        let (before, after) = (&seen[0], &seen[1]);
        // Before the edit the camera sees the floor there; after, the copy's
        // top, at the very point it was moved to (to the OBJ's micrometre).
        assert_eq!(before.0, "floor");
        assert!(before.1.z.abs() < 0.01);
        assert_eq!(after.0, "cabinet_2");
        assert!((after.1 - expected).norm() < 1e-5, "{:?} against {expected:?}", after.1);
        // And the render changes there, to the copy's direct light: a
        // Lambertian face of albedo 0.5 under the lamp shows
        // L = (ρ/π) I cos θ / d² (the pixel's four samples average it
        // within a few per cent over its 3 cm).
        let direct = |p: Vector3<f64>| {
            let d = light[0].position - p;
            0.5 / std::f64::consts::PI * 10.0 * d.z / d.norm() / d.norm_squared()
        };
        for (surface, point, radiance) in [before, after] {
            let want = direct(*point);
            let got = f64::from(*radiance);
            assert!((got / want - 1.0).abs() < 0.03, "{surface}: {got} against {want}");
        }
        assert!(after.2 > 1.5 * before.2);
    }

    /// The repository's example room (a full scene file: material models,
    /// camera poses) edited as in Fig. 2.6: its table copied and turned, a
    /// sphere deleted. What it had is kept, and `campanile_config` accepts
    /// the result.
    #[test]
    fn the_example_room_edited_keeps_its_poses_and_materials() {
        let room = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/room-scene.ron");
        let dir = tempfile::tempdir().unwrap();
        let edit = dir.path().join("edit.ron");
        std::fs::write(
            &edit,
            r#"SceneEdit(operations: [
                Copy(object: "table", name: "table_2", offset_m: (0.0, 1.5, 0.0)),
                Move(object: "table_2", rotate_z_deg: 90.0),
                Delete(object: "sphere-metal"),
            ])"#,
        )
        .unwrap();
        let out = dir.path().join("edited");
        let edited = edit_scene(&room, &edit, &out).unwrap();
        let before = campanile_config::load_scene(&room).unwrap().value;
        let after = campanile_config::load_scene(&out.join("scene.ron")).unwrap().value;
        assert_eq!(after.poses, before.poses);
        let table_2 = after.surface("table_2").unwrap();
        assert_eq!(table_2.material, "wood");
        assert_eq!(table_2.groups.len(), 6);
        assert!(after.surface("sphere-metal").is_none());
        // The metal material went with its only sphere; wood keeps its model.
        assert!(!after.materials.iter().any(|m| m.name == "metal"));
        let wood = after.materials.iter().find(|m| m.name == "wood").unwrap();
        assert_eq!(wood.model, campanile_config::scene::MaterialModel::WardIsotropic);
        assert_eq!(edited.objects.len(), before.surfaces.len());
        // The copy's top is the table's, 1.5 m north, turned a quarter about
        // its own centre: same area, same height.
        let top = |s: &EditableScene, g: &str| s.meshes.iter().find(|m| m.group == g).unwrap().mesh.clone();
        let original = EditableScene::read(&room).unwrap();
        let (a, b) = (top(&original, "table-top"), top(&edited, "table-top_table_2"));
        assert!((a.area() - b.area()).abs() < 1e-9);
        let (ca, cb) = (a.bounding_box_centre().unwrap(), b.bounding_box_centre().unwrap());
        assert!((cb - ca - Vector3::new(0.0, 1.5, 0.0)).norm() < 1e-6, "{ca:?} {cb:?}");
    }
}
