//! The recovered pseudo-albedos on disk: two OpenEXR texture atlases (ρ^sun
//! and ρ^se, one texel per grid cell, every face's lattice packed in rows)
//! and a RON materials file that says where each face lies in the atlases.
//! Reading them back with the scene gives a [`Reflectance`] to re-render.
//!
//! In an atlas, a face's texel `(x0 + i − i_min, y0 + j_max − j)` holds
//! lattice square `(i, j)` (so `t`, up the face, is up in the image); where
//! a square spans two triangles, the texel holds their area-weighted mean.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::OutdoorError;
use super::estimate::{CellEstimate, CellStatus, Reflectance};
use super::grid::Grid;
use crate::camera::image::RadianceImage;
use crate::exr_io::{read_rgb_exr, write_radiance_exr};
use crate::hdr::merge::RadianceMap;
use crate::render::Scene;

/// Widest atlas row, texels.
pub const ATLAS_WIDTH: usize = 512;

/// Where one face lies in the atlases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AtlasFace {
    /// The named surface.
    pub surface: String,
    /// Unit normal on the visible side.
    pub normal: [f64; 3],
    /// `normal · p` for points `p` of the face's plane, metres.
    pub offset_m: f64,
    /// Lattice indices of the first texel: (i_min, j_max).
    pub lattice_origin: (i64, i64),
    /// Rectangle in the atlases: x, y, width, height (texels).
    pub rect: (usize, usize, usize, usize),
    /// Cells by status: solved, never sunlit, never shadowed, ill-conditioned, unseen.
    pub statuses: [usize; 5],
    /// Lattice squares `(i, j)` whose every cell no photograph saw: their
    /// texels hold the median of the nearest seen cells, not a measurement
    /// (absent in files written before this field: read as none).
    #[serde(default)]
    pub unseen: Vec<(i64, i64)>,
}

/// The materials file: the grid's spacing and each face's place in the atlases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialsFile {
    /// Grid spacing, metres.
    pub spacing_m: f64,
    /// ρ^sun atlas, relative to this file.
    pub rho_sun: String,
    /// ρ^se atlas, relative to this file.
    pub rho_se: String,
    /// Atlas size, texels.
    pub size: (usize, usize),
    /// The faces.
    pub faces: Vec<AtlasFace>,
    /// The recovery's findings, for the reader.
    pub diagnostics: Vec<String>,
}

fn status_index(s: CellStatus) -> usize {
    match s {
        CellStatus::Solved => 0,
        CellStatus::NeverSunlit => 1,
        CellStatus::NeverShadowed => 2,
        CellStatus::IllConditioned => 3,
        CellStatus::Unseen | CellStatus::FromFile => 4,
    }
}

fn file_error(path: &Path, message: impl ToString) -> OutdoorError {
    OutdoorError::File {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// Writes `materials.ron`, `rho_sun.exr` and `rho_se.exr` into `dir` (made
/// if missing); returns the materials file's path.
pub fn write_materials(scene: &Scene, refl: &Reflectance, dir: &Path) -> Result<PathBuf, OutdoorError> {
    std::fs::create_dir_all(dir).map_err(|e| file_error(dir, e))?;
    let g = &refl.grid;
    // Shelf packing of the faces' lattice boxes.
    let (mut x, mut y, mut row_h, mut width) = (0usize, 0usize, 0usize, 0usize);
    let mut faces = Vec::new();
    for f in &g.faces {
        let is: Vec<i64> = f.cells.iter().map(|&c| g.cells[c].lattice.0).collect();
        let js: Vec<i64> = f.cells.iter().map(|&c| g.cells[c].lattice.1).collect();
        let (i0, i1) = (*is.iter().min().unwrap_or(&0), *is.iter().max().unwrap_or(&0));
        let (j0, j1) = (*js.iter().min().unwrap_or(&0), *js.iter().max().unwrap_or(&0));
        let (w, h) = ((i1 - i0 + 1) as usize, (j1 - j0 + 1) as usize);
        if x > 0 && x + w > ATLAS_WIDTH {
            x = 0;
            y += row_h;
            row_h = 0;
        }
        let tri = &scene.triangles()[f.triangles[0]];
        let mut statuses = [0; 5];
        for &c in &f.cells {
            statuses[status_index(refl.cells[c].status)] += 1;
        }
        // Squares where every cell is unseen (a square may span two triangles).
        let mut squares: BTreeMap<(i64, i64), bool> = BTreeMap::new();
        for &c in &f.cells {
            let unseen = refl.cells[c].status == CellStatus::Unseen;
            *squares.entry(g.cells[c].lattice).or_insert(true) &= unseen;
        }
        let unseen: Vec<(i64, i64)> = squares.into_iter().filter(|s| s.1).map(|s| s.0).collect();
        faces.push(AtlasFace {
            surface: scene.surfaces()[f.surface].clone(),
            normal: [f.normal.x, f.normal.y, f.normal.z],
            offset_m: f.normal.dot(&tri.vertices[0]),
            lattice_origin: (i0, j1),
            rect: (x, y, w, h),
            statuses,
            unseen,
        });
        x += w;
        width = width.max(x);
        row_h = row_h.max(h);
    }
    let height = y + row_h;
    let (width, height) = (width.max(1), height.max(1));
    let mut sun = vec![0f32; width * height * 3];
    let mut se = vec![0f32; width * height * 3];
    let mut area = vec![0f64; width * height];
    for (fi, f) in g.faces.iter().enumerate() {
        let a = &faces[fi];
        for &c in &f.cells {
            let (i, j) = g.cells[c].lattice;
            let px = a.rect.0 + (i - a.lattice_origin.0) as usize;
            let py = a.rect.1 + (a.lattice_origin.1 - j) as usize;
            let k = py * width + px;
            let wgt = g.cells[c].area_m2;
            let prev = area[k];
            for ch in 0..3 {
                let blend = |old: f32, new: f64| ((f64::from(old) * prev + new * wgt) / (prev + wgt)) as f32;
                sun[k * 3 + ch] = blend(sun[k * 3 + ch], refl.cells[c].rho_sun[ch]);
                se[k * 3 + ch] = blend(se[k * 3 + ch], refl.cells[c].rho_se[ch]);
            }
            area[k] = prev + wgt;
        }
    }
    let write = |data: Vec<f32>, name: &str| -> Result<(), OutdoorError> {
        let map = RadianceMap {
            width,
            height,
            variance: vec![0.0; data.len()],
            rgb: data,
            mask: vec![0; width * height],
        };
        let path = dir.join(name);
        write_radiance_exr(&map, &path).map_err(|e| file_error(&path, e))
    };
    write(sun, "rho_sun.exr")?;
    write(se, "rho_se.exr")?;
    let file = MaterialsFile {
        spacing_m: g.spacing_m,
        rho_sun: "rho_sun.exr".into(),
        rho_se: "rho_se.exr".into(),
        size: (width, height),
        faces,
        diagnostics: refl.diagnostics.clone(),
    };
    let text = ron::ser::to_string_pretty(&file, ron::ser::PrettyConfig::default()).map_err(|e| file_error(dir, e))?;
    let path = dir.join("materials.ron");
    std::fs::write(&path, text).map_err(|e| file_error(&path, e))?;
    Ok(path)
}

/// Reads a materials file written by [`write_materials`] for `scene`: the
/// grid is rebuilt on the surfaces it names, with the sides it records, and
/// each cell takes its texel (status [`CellStatus::FromFile`], or
/// [`CellStatus::Unseen`] where the file lists its square as unseen; its
/// stated uncertainty and conditioning are not stored, so read as infinite).
pub fn read_materials(scene: &Scene, path: &Path) -> Result<Reflectance, OutdoorError> {
    let text = std::fs::read_to_string(path).map_err(|e| file_error(path, e))?;
    let file: MaterialsFile =
        ron::from_str(&text).map_err(|e| file_error(path, format!("not a materials file: {e}")))?;
    if !(file.spacing_m.is_finite() && file.spacing_m > 0.0) {
        return Err(file_error(path, format!("spacing_m {} must be > 0", file.spacing_m)));
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let load = |name: &str| -> Result<RadianceImage, OutdoorError> {
        let p = dir.join(name);
        let img = read_rgb_exr(&p).map_err(|e| file_error(&p, e))?;
        if (img.width, img.height) != file.size {
            return Err(file_error(
                &p,
                format!(
                    "atlas is {}×{}, the materials file says {:?}",
                    img.width, img.height, file.size
                ),
            ));
        }
        Ok(img)
    };
    let (sun, se) = (load(&file.rho_sun)?, load(&file.rho_se)?);
    let mut targets = Vec::new();
    for f in &file.faces {
        let s = scene
            .surface_index(&f.surface)
            .ok_or_else(|| file_error(path, format!("surface {:?} is not in the scene", f.surface)))?;
        if !targets.contains(&s) {
            targets.push(s);
        }
    }
    let find = |surface: usize, normal: &nalgebra::Vector3<f64>, point: &nalgebra::Vector3<f64>| {
        file.faces.iter().position(|f| {
            let n = nalgebra::Vector3::from(f.normal);
            scene.surface_index(&f.surface) == Some(surface)
                && n.dot(normal).abs() > 1.0 - 1e-6
                && (n.dot(point) - f.offset_m).abs() < 1e-4
        })
    };
    let side = |tri: &crate::render::Triangle| {
        find(tri.surface as usize, &tri.normal, &tri.vertices[0]).map_or(1.0, |k| {
            nalgebra::Vector3::from(file.faces[k].normal).dot(&tri.normal).signum()
        })
    };
    let grid = Grid::with_sides(scene, &targets, file.spacing_m, &side)?;
    let unseen: Vec<HashSet<(i64, i64)>> = file.faces.iter().map(|f| f.unseen.iter().copied().collect()).collect();
    let mut cells = Vec::with_capacity(grid.cells.len());
    for c in &grid.cells {
        let tri = &scene.triangles()[c.triangle];
        let face = find(c.surface, &c.normal, &tri.vertices[0]);
        let texel = face.and_then(|k| {
            let f = &file.faces[k];
            let dx = c.lattice.0 - f.lattice_origin.0;
            let dy = f.lattice_origin.1 - c.lattice.1;
            (dx >= 0 && dy >= 0 && (dx as usize) < f.rect.2 && (dy as usize) < f.rect.3)
                .then(|| (f.rect.1 + dy as usize) * file.size.0 + f.rect.0 + dx as usize)
        });
        let listed_unseen = face.is_some_and(|k| unseen[k].contains(&c.lattice));
        let get = |img: &RadianceImage| texel.map_or([0.0; 3], |k| [0, 1, 2].map(|ch| f64::from(img.data[k * 3 + ch])));
        cells.push(CellEstimate {
            rho_sun: get(&sun),
            rho_se: get(&se),
            sigma_sun: [f64::INFINITY; 3],
            sigma_se: [f64::INFINITY; 3],
            status: if texel.is_some() && !listed_unseen {
                CellStatus::FromFile
            } else {
                CellStatus::Unseen
            },
            condition: f64::INFINITY,
            amplification: f64::INFINITY,
            observations: 0,
            rms_relative: 0.0,
        });
    }
    let n_faces = grid.faces.len();
    Ok(Reflectance {
        grid,
        cells,
        photos: Vec::new(),
        sampling: Default::default(),
        face_ratio: vec![[1.0; 3]; n_faces],
        diagnostics: file.diagnostics,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::outdoor::observation::SamplingReport;
    use crate::render::{Material, Triangle};

    /// Pseudo-albedos written as atlases and read back with the scene land
    /// on the same cells, to f32 precision; the cells no photograph saw
    /// (the lattice column i = 5, both triangles' cells there) come back
    /// unseen, the rest from the file.
    #[test]
    fn atlases_round_trip() {
        let v = |x: f64, z: f64| Vector3::new(x, 0.0, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0), v(6.0, 0.0), v(6.0, 4.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0), v(6.0, 4.0), v(0.0, 4.0)], 0, 0).unwrap(),
        ];
        let scene = Scene::new(tris, vec![Material::diffuse("m", [0.5; 3])], vec!["wall".into()]).unwrap();
        let grid = Grid::new(&scene, &[0], 1.0, &[Vector3::new(3.0, -20.0, 2.0)]).unwrap();
        let value = |c: &crate::outdoor::grid::Cell, k: f64| {
            [
                0.1 + 0.05 * c.lattice.0 as f64 * k,
                0.2 + 0.03 * c.lattice.1 as f64,
                0.3,
            ]
        };
        let cells = grid
            .cells
            .iter()
            .map(|c| CellEstimate {
                rho_sun: value(c, 1.0),
                rho_se: value(c, 0.5),
                sigma_sun: [0.01; 3],
                sigma_se: [0.01; 3],
                status: if c.lattice.0 == 5 {
                    CellStatus::Unseen
                } else {
                    CellStatus::Solved
                },
                condition: 2.0,
                amplification: 2.0,
                observations: 4,
                rms_relative: 0.01,
            })
            .collect();
        let refl = Reflectance {
            face_ratio: vec![[1.0; 3]; grid.faces.len()],
            grid,
            cells,
            photos: Vec::new(),
            sampling: SamplingReport::default(),
            diagnostics: vec!["a note".into()],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = write_materials(&scene, &refl, dir.path()).unwrap();
        let back = read_materials(&scene, &path).unwrap();
        assert_eq!(back.grid.cells.len(), refl.grid.cells.len());
        assert_eq!(back.diagnostics, refl.diagnostics);
        let unseen = refl.cells.iter().filter(|c| c.status == CellStatus::Unseen).count();
        // Column 5 of a 6 m × 4 m wall at 1 m: 4 squares, the diagonal's lower triangle in each.
        assert!(unseen >= 4, "{unseen}");
        for (a, b) in back.cells.iter().zip(&refl.cells) {
            let want = if b.status == CellStatus::Unseen {
                CellStatus::Unseen
            } else {
                CellStatus::FromFile
            };
            assert_eq!(a.status, want);
            for ch in 0..3 {
                assert!((a.rho_sun[ch] - b.rho_sun[ch]).abs() < 1e-6, "{a:?} {b:?}");
                assert!((a.rho_se[ch] - b.rho_se[ch]).abs() < 1e-6);
            }
        }
        // A materials file naming a surface the scene lacks is refused by name.
        let text = std::fs::read_to_string(&path).unwrap().replace("\"wall\"", "\"tower\"");
        std::fs::write(&path, text).unwrap();
        let err = read_materials(&scene, &path).unwrap_err().to_string();
        assert!(err.contains("tower"), "{err}");
    }
}
