//! The orientation of a scene's named surfaces, read from its OBJ file, for
//! face triggers ("face F becomes sunlit") and for checking that every face
//! of an outdoor scene is sunlit at some session (thesis §5.2 needs each
//! surface seen under the sun).
//!
//! A surface's orientation is its area-weighted mean normal: the sum of its
//! triangles' `(v1 − v0) × (v2 − v0) / 2`, normalized. A surface whose
//! triangles mostly cancel (a closed box, a ring of facets, pillars facing
//! every way) has no net orientation; it is marked so and its face triggers
//! cannot fire. Self-shadowing by other geometry is not modelled: "sunlit"
//! means the sun is above the horizon and in front of the surface's plane.

use std::path::Path;

use campanile_config::Scene;
use serde::{Deserialize, Serialize};

use super::error::ScheduleError;

/// Below this ratio of net (vector) area to total area a surface has no net
/// orientation (1 for a plane; 0 for a closed surface).
pub const MIN_NET_ORIENTATION: f64 = 0.1;

/// The orientation of one named surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceOrientation {
    /// The surface's name in the scene.
    pub name: String,
    /// Total area of its triangles, m².
    pub area_m2: f64,
    /// Unit area-weighted mean normal in the world frame (x east, y north,
    /// z up); `None` when the surface has no net orientation.
    pub normal: Option<[f64; 3]>,
}

impl SurfaceOrientation {
    /// A surface from the sum of its triangles' area vectors and their total area.
    pub fn from_area_vectors(name: &str, net: [f64; 3], area_m2: f64) -> SurfaceOrientation {
        let len = (net[0] * net[0] + net[1] * net[1] + net[2] * net[2]).sqrt();
        let normal = (area_m2 > 0.0 && len >= MIN_NET_ORIENTATION * area_m2).then(|| net.map(|c| c / len));
        SurfaceOrientation {
            name: name.to_owned(),
            area_m2,
            normal,
        }
    }

    /// Whether direct sun from unit direction `sun` (world frame), at
    /// `elevation_rad` above the horizon, falls on the front of the surface.
    pub fn is_sunlit(&self, sun: [f64; 3], elevation_rad: f64) -> bool {
        self.sunlit_margin(sun, elevation_rad).is_some_and(|g| g > 0.0)
    }

    /// `min(n·s, sin elevation)`: positive exactly when the surface is
    /// sunlit, and continuous in time, so its zero crossings are the
    /// moments the face becomes sunlit or shadowed. `None` without a normal.
    pub fn sunlit_margin(&self, sun: [f64; 3], elevation_rad: f64) -> Option<f64> {
        let n = self.normal?;
        let cos_incidence = n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2];
        Some(cos_incidence.min(elevation_rad.sin()))
    }
}

/// A scene with the orientations of its named surfaces.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneGeometry {
    /// The scene description (poses, surfaces).
    pub scene: Scene,
    /// One entry per surface of `scene`, in its order.
    pub surfaces: Vec<SurfaceOrientation>,
}

impl SceneGeometry {
    /// Reads the scene's OBJ file (relative to `base_dir`, the scene file's
    /// directory) and computes each surface's orientation.
    pub fn load(scene: &Scene, base_dir: &Path) -> Result<SceneGeometry, ScheduleError> {
        let path = base_dir.join(&scene.geometry);
        let opts = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let (models, _materials) = tobj::load_obj(&path, &opts).map_err(|e| ScheduleError::Geometry {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        let surfaces = scene
            .surfaces
            .iter()
            .map(|s| {
                let mut net = [0.0; 3];
                let mut area = 0.0;
                for m in models.iter().filter(|m| s.groups.contains(&m.name)) {
                    let p = &m.mesh.positions;
                    let vertex = |i: u32| -> Option<[f64; 3]> {
                        let i = i as usize * 3;
                        Some([
                            f64::from(*p.get(i)?),
                            f64::from(*p.get(i + 1)?),
                            f64::from(*p.get(i + 2)?),
                        ])
                    };
                    for tri in m.mesh.indices.chunks_exact(3) {
                        let (Some(a), Some(b), Some(c)) = (vertex(tri[0]), vertex(tri[1]), vertex(tri[2])) else {
                            return Err(ScheduleError::Geometry {
                                path: path.clone(),
                                reason: format!("group {:?} has a face with a vertex index out of range", m.name),
                            });
                        };
                        let (u, v) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
                        let cross = [
                            u[1] * v[2] - u[2] * v[1],
                            u[2] * v[0] - u[0] * v[2],
                            u[0] * v[1] - u[1] * v[0],
                        ];
                        for k in 0..3 {
                            net[k] += 0.5 * cross[k];
                        }
                        area += 0.5 * (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
                    }
                }
                Ok(SurfaceOrientation::from_area_vectors(&s.name, net, area))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(SceneGeometry {
            scene: scene.clone(),
            surfaces,
        })
    }

    /// The orientation of the surface called `name`.
    pub fn surface(&self, name: &str) -> Option<&SurfaceOrientation> {
        self.surfaces.iter().find(|s| s.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> SceneGeometry {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
        let loaded = campanile_config::load_scene(&dir.join("campanile-scene.ron")).expect("valid example scene");
        SceneGeometry::load(&loaded.value, &loaded.source.base_dir()).expect("readable OBJ")
    }

    /// The tower's walls are axis-aligned: the south face's normal is −y
    /// (to 1e-9) and its area is shaft 11 × 70 plus belfry 8 × 15 = 890 m².
    #[test]
    fn the_tower_faces_point_where_their_names_say() {
        let g = example();
        let want = [
            ("south-face", [0.0, -1.0, 0.0]),
            ("east-face", [1.0, 0.0, 0.0]),
            ("north-face", [0.0, 1.0, 0.0]),
            ("west-face", [-1.0, 0.0, 0.0]),
            ("ground", [0.0, 0.0, 1.0]),
        ];
        for (name, n) in want {
            let s = g.surface(name).expect("surface");
            let got = s.normal.expect("oriented");
            assert!((0..3).all(|k| (got[k] - n[k]).abs() < 1e-9), "{name}: {got:?}");
        }
        let south = g.surface("south-face").expect("surface");
        assert!((south.area_m2 - 890.0).abs() < 1e-6, "{}", south.area_m2);
    }

    #[test]
    fn a_closed_box_has_no_net_orientation() {
        let s = SurfaceOrientation::from_area_vectors("box", [0.0, 0.0, 1e-12], 6.0);
        assert_eq!(s.normal, None);
        assert!(!s.is_sunlit([0.0, 0.0, 1.0], 1.0));
    }
}
