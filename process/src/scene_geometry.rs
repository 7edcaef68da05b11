//! A scene's geometry from its description and OBJ file (thesis §5.4:
//! "each polygon in the geometric model is triangulated"): the OBJ read
//! with `tobj` (polygons fanned into triangles), each OBJ group becoming
//! part of the named surface that lists it, with that surface's material;
//! a group no surface lists becomes a surface of its own name, with a
//! material named "<group> (no material)". Degenerate triangles are
//! skipped and counted (the caller reports them).
//!
//! The simulator builds its scenes from this, adding true appearances; the
//! solvers, from this with recovered ones.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::render::Triangle;

/// Triangles with surface and material indices, and the names those index.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneGeometry {
    /// Triangles; `surface` indexes `surface_names`, `material` indexes `material_names`.
    pub triangles: Vec<Triangle>,
    /// The description's surfaces in order, then groups no surface lists.
    pub surface_names: Vec<String>,
    /// The description's materials in order, then any a surface names
    /// without describing, then one per unlisted group.
    pub material_names: Vec<String>,
    /// Zero-area triangles skipped.
    pub degenerate: usize,
}

/// Why the geometry could not be read.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GeometryError {
    /// The OBJ file could not be read or parsed.
    #[error("{}: {message}", path.display())]
    Obj {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A face refers to a vertex the file does not have.
    #[error("{}: group {group:?}: a face refers to missing vertex {vertex}", path.display())]
    MissingVertex {
        /// The file.
        path: PathBuf,
        /// The OBJ group.
        group: String,
        /// The 1-based vertex number.
        vertex: usize,
    },
    /// No non-degenerate triangle.
    #[error("{}: no triangles (expected at least one face of non-zero area)", path.display())]
    NoTriangles {
        /// The file.
        path: PathBuf,
    },
}

/// Reads `obj` as the geometry of `description`.
pub fn load_obj(description: &campanile_config::Scene, obj: &Path) -> Result<SceneGeometry, GeometryError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(obj, &opts).map_err(|e| GeometryError::Obj {
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
        let vertex = |i: u32| -> Result<Vector3<f64>, GeometryError> {
            let i = i as usize * 3;
            p.get(i..i + 3)
                .map(|v| Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
                .ok_or_else(|| GeometryError::MissingVertex {
                    path: obj.to_path_buf(),
                    group: model.name.clone(),
                    vertex: i / 3 + 1,
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
    if triangles.is_empty() {
        return Err(GeometryError::NoTriangles {
            path: obj.to_path_buf(),
        });
    }
    Ok(SceneGeometry {
        triangles,
        surface_names,
        material_names,
        degenerate,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn examples() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
    }

    /// Area per OBJ group from the raw polygons (shoelace in 3-D), read
    /// without `tobj`: the triangulation must keep every group's area.
    fn raw_areas(text: &str) -> Vec<(String, f64)> {
        let mut vs: Vec<Vector3<f64>> = Vec::new();
        let mut out: Vec<(String, f64)> = Vec::new();
        for line in text.lines() {
            let mut w = line.split_whitespace();
            match w.next() {
                Some("v") => {
                    let c: Vec<f64> = w.take(3).map(|x| x.parse().unwrap()).collect();
                    vs.push(Vector3::new(c[0], c[1], c[2]));
                }
                Some("g") => out.push((w.next().unwrap().to_string(), 0.0)),
                Some("f") => {
                    let idx: Vec<usize> = w
                        .map(|t| t.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                        .collect();
                    let mut sum = Vector3::zeros();
                    for k in 0..idx.len() {
                        sum += vs[idx[k]].cross(&vs[idx[(k + 1) % idx.len()]]);
                    }
                    out.last_mut().unwrap().1 += sum.norm() / 2.0;
                }
                _ => {}
            }
        }
        out
    }

    #[test]
    fn the_campanile_keeps_its_groups_and_their_areas() {
        let loaded = campanile_config::document::load_scene(&examples().join("campanile-scene.ron")).unwrap();
        let obj = examples().join("campanile.obj");
        let g = load_obj(&loaded.value, &obj).unwrap();
        assert_eq!(g.degenerate, 0);
        let raw = raw_areas(&std::fs::read_to_string(&obj).unwrap());
        for surface in &loaded.value.surfaces {
            let i = g.surface_names.iter().position(|n| n == &surface.name).unwrap();
            let area: f64 = g
                .triangles
                .iter()
                .filter(|t| t.surface as usize == i)
                .map(|t| t.area())
                .sum();
            let expected: f64 = raw
                .iter()
                .filter(|(n, _)| surface.groups.contains(n))
                .map(|(_, a)| a)
                .sum();
            // `tobj` keeps positions in f32: 1e-6 relative.
            assert!(
                expected > 0.0 && (area - expected).abs() < 1e-6 * expected,
                "{}: {area} against {expected}",
                surface.name
            );
            let m = &g.material_names[g.triangles.iter().find(|t| t.surface as usize == i).unwrap().material as usize];
            assert_eq!(m, &surface.material);
        }
        // The south face: the shaft's 11 m × 70 m plus the belfry's wall beside its openings.
        let south = g.surface_names.iter().position(|n| n == "south-face").unwrap();
        assert!(
            g.triangles
                .iter()
                .filter(|t| t.surface as usize == south)
                .map(|t| t.area())
                .sum::<f64>()
                > 770.0
        );
    }

    #[test]
    fn a_missing_file_and_a_missing_vertex_are_named() {
        let loaded = campanile_config::document::load_scene(&examples().join("campanile-scene.ron")).unwrap();
        let err = load_obj(&loaded.value, Path::new("/nonexistent/x.obj")).unwrap_err();
        assert!(err.to_string().contains("/nonexistent/x.obj"), "{err}");
        let dir = std::env::temp_dir().join(format!("campanile-geometry-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.obj");
        std::fs::write(&bad, "v 0 0 0\nv 1 0 0\ng roof\nf 1 2 3\n").unwrap();
        let err = load_obj(&loaded.value, &bad).unwrap_err().to_string();
        assert!(
            err.contains("bad.obj") && (err.contains("vertex") || err.contains("index")),
            "{err}"
        );
        std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 2 0 0\ng roof\nf 1 2 3\n").unwrap();
        let err = load_obj(&loaded.value, &bad).unwrap_err();
        assert_eq!(err, GeometryError::NoTriangles { path: bad.clone() });
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
