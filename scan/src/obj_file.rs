//! Meshes as a Wavefront OBJ file with one group per mesh (`g surface_3`),
//! the form a scene file's `geometry` takes, and back (read with `tobj`, as
//! the solvers read it).

use std::io::Write;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::mesh::TriangleMesh;

/// A mesh with its OBJ group name.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedMesh {
    /// The OBJ group (`g` line); no white space.
    pub group: String,
    /// The mesh.
    pub mesh: TriangleMesh,
}

/// Why an OBJ file could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// The file could not be written or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The file is not an OBJ `tobj` reads.
    #[error("{}: {message} (expected a Wavefront OBJ file)", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A group name an OBJ `g` line cannot hold.
    #[error("OBJ group {group:?}: expected a name without white space")]
    GroupName {
        /// The name.
        group: String,
    },
}

/// Writes `meshes` to `path`, one `g` group each, vertices to the
/// micrometre, faces wound as the meshes are (counter-clockwise seen from
/// the side the normal faces).
pub fn write_obj(path: &Path, meshes: &[NamedMesh], comment: &str) -> Result<(), ObjError> {
    let io = |source| ObjError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut text = String::new();
    for line in comment.lines() {
        text.push_str(&format!("# {line}\n"));
    }
    let mut base = 1usize;
    for m in meshes {
        if m.group.is_empty() || m.group.chars().any(char::is_whitespace) {
            return Err(ObjError::GroupName { group: m.group.clone() });
        }
        text.push_str(&format!("g {}\n", m.group));
        for p in &m.mesh.positions {
            text.push_str(&format!("v {:.6} {:.6} {:.6}\n", p.x, p.y, p.z));
        }
        for t in &m.mesh.triangles {
            let [a, b, c] = t.map(|i| i as usize + base);
            text.push_str(&format!("f {a} {b} {c}\n"));
        }
        base += m.mesh.positions.len();
    }
    let mut file = std::fs::File::create(path).map_err(io)?;
    file.write_all(text.as_bytes()).map_err(io)?;
    // (One string: an OBJ of a million triangles is some 40 MB.)
    file.sync_all().map_err(io)
}

/// Reads the groups of the OBJ file at `path` (polygons fanned into
/// triangles).
pub fn read_obj(path: &Path) -> Result<Vec<NamedMesh>, ObjError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &opts).map_err(|e| ObjError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(models
        .into_iter()
        .map(|m| NamedMesh {
            group: m.name,
            mesh: TriangleMesh {
                positions: m
                    .mesh
                    .positions
                    .chunks_exact(3)
                    .map(|p| Vector3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
                    .collect(),
                triangles: m.mesh.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            },
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_survive_a_round_trip_through_tobj() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.obj");
        let square = crate::mesh::simplification::fine_square(1);
        let mut lifted = square.clone();
        lifted.positions.iter_mut().for_each(|p| p.z = 2.5);
        let meshes = vec![
            NamedMesh {
                group: "surface_0".into(),
                mesh: square,
            },
            NamedMesh {
                group: "surface_1".into(),
                mesh: lifted,
            },
        ];
        write_obj(&path, &meshes, "two squares").unwrap();
        let back = read_obj(&path).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].group, "surface_1");
        assert_eq!(back[1].mesh.triangles.len(), 2);
        assert!(back[1].mesh.positions.iter().all(|p| p.z == 2.5));
        assert!((back[0].mesh.area() - 1.0).abs() < 1e-12);
        let bad = [NamedMesh {
            group: "a wall".into(),
            mesh: TriangleMesh::default(),
        }];
        let e = write_obj(&path, &bad, "").unwrap_err();
        assert_eq!(
            e.to_string(),
            "OBJ group \"a wall\": expected a name without white space"
        );
    }
}
