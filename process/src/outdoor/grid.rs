//! The surface grid of thesis §5.4: "each polygon in the geometric model is
//! triangulated and a dense grid is set up on each triangle". Cells are
//! squares of a chosen spacing in the face's planar texture coordinates
//! (metres, [`Triangle::texture_coordinates`]), clipped to their triangle;
//! coplanar triangles of one named surface form a *face*, and share one
//! lattice, so a cell's neighbours on its face are found across triangle
//! edges.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::OutdoorError;
use crate::render::{Scene, Triangle};

/// Sub-samples per cell side used to clip a cell to its triangle and to
/// find its centroid.
pub const CELL_SUBSAMPLES: usize = 6;

/// One grid cell: the part of a lattice square inside one triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// The triangle the cell lies on.
    pub triangle: usize,
    /// The face (coplanar triangles of one surface) it belongs to.
    pub face: usize,
    /// The named surface.
    pub surface: usize,
    /// Lattice indices along the texture axes `s` and `t`.
    pub lattice: (i64, i64),
    /// Centroid of the part inside the triangle, world frame, metres.
    pub centre: Vector3<f64>,
    /// Unit normal on the side the cameras see.
    pub normal: Vector3<f64>,
    /// Area inside the triangle, m² (estimated from the sub-samples).
    pub area_m2: f64,
}

/// Coplanar triangles of one named surface, seen from one side.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The named surface.
    pub surface: usize,
    /// Unit normal on the side the cameras see.
    pub normal: Vector3<f64>,
    /// The triangles.
    pub triangles: Vec<usize>,
    /// The cells, as indices into [`Grid::cells`].
    pub cells: Vec<usize>,
}

/// The grid over the target surfaces of a scene.
#[derive(Debug, Clone)]
pub struct Grid {
    /// Cell size, metres.
    pub spacing_m: f64,
    /// The cells.
    pub cells: Vec<Cell>,
    /// The faces.
    pub faces: Vec<Face>,
    /// Which surfaces are solved for (the rest is environment).
    pub targets: Vec<usize>,
    /// The side sign of each triangle (+1 along its stored normal, −1
    /// against it); `None` for triangles that are not targets.
    side: Vec<Option<f64>>,
    /// (triangle, s index, t index) → cell.
    lookup: HashMap<(usize, i64, i64), usize>,
    /// (face, s index, t index) → cell (the first one, where a lattice
    /// square spans two triangles).
    by_face: HashMap<(usize, i64, i64), Vec<usize>>,
    /// Triangle → face.
    face_of: Vec<Option<usize>>,
}

fn inside(tri: &Triangle, p: &Vector3<f64>) -> bool {
    let [a, b, c] = tri.vertices;
    let n = tri.normal;
    let e = |x: Vector3<f64>, y: Vector3<f64>| (y - x).cross(&(p - x)).dot(&n) >= -1e-9;
    e(a, b) && e(b, c) && e(c, a)
}

impl Grid {
    /// The grid of `spacing_m` over the surfaces named in `targets` of
    /// `scene`. Each triangle's visible side is the one facing most of the
    /// `viewpoints` (the camera positions) that have a clear line of sight
    /// to its centroid; with none, the stored normal's side. (Counting
    /// viewpoints that cannot see the triangle would let cameras on the far
    /// side of a building outvote those that see it.)
    pub fn new(
        scene: &Scene,
        targets: &[usize],
        spacing_m: f64,
        viewpoints: &[Vector3<f64>],
    ) -> Result<Grid, OutdoorError> {
        Grid::with_sides(scene, targets, spacing_m, &|tri: &Triangle| {
            let centroid = (tri.vertices[0] + tri.vertices[1] + tri.vertices[2]) / 3.0;
            let facing: f64 = viewpoints
                .iter()
                .filter(|v| {
                    let d = centroid - *v;
                    let dist = d.norm();
                    if dist <= 0.0 {
                        return false;
                    }
                    let ray = crate::render::Ray {
                        origin: **v,
                        direction: d / dist,
                    };
                    // Clear when nothing is hit before the triangle's plane.
                    scene
                        .intersect(&ray, dist * (1.0 - 1e-6))
                        .is_none_or(|h| h.t >= dist * (1.0 - 1e-3))
                })
                .map(|v| (v - centroid).normalize().dot(&tri.normal).signum())
                .sum();
            if facing < 0.0 { -1.0 } else { 1.0 }
        })
    }

    /// The grid with each target triangle's visible side given by `side`
    /// (+1: along its stored normal, −1: against it).
    pub fn with_sides(
        scene: &Scene,
        targets: &[usize],
        spacing_m: f64,
        side_of: &dyn Fn(&Triangle) -> f64,
    ) -> Result<Grid, OutdoorError> {
        if !(spacing_m.is_finite() && spacing_m > 0.0) {
            return Err(OutdoorError::BadSpacing { spacing_m });
        }
        for &t in targets {
            if t >= scene.surfaces().len() {
                return Err(OutdoorError::UnknownSurface {
                    surface: t,
                    count: scene.surfaces().len(),
                });
            }
        }
        let tris = scene.triangles();
        let mut side = vec![None; tris.len()];
        let mut face_of = vec![None; tris.len()];
        let mut faces: Vec<Face> = Vec::new();
        let mut cells = Vec::new();
        let mut lookup = HashMap::new();
        let mut by_face: HashMap<(usize, i64, i64), Vec<usize>> = HashMap::new();
        for (ti, tri) in tris.iter().enumerate() {
            if !targets.contains(&(tri.surface as usize)) {
                continue;
            }
            let sgn = if side_of(tri) < 0.0 { -1.0 } else { 1.0 };
            side[ti] = Some(sgn);
            let normal = tri.normal * sgn;
            let offset = normal.dot(&tri.vertices[0]);
            let face = match faces.iter().position(|f| {
                f.surface == tri.surface as usize
                    && f.normal.dot(&normal) > 1.0 - 1e-9
                    && (f.normal.dot(&tris[f.triangles[0]].vertices[0]) - offset).abs() < 1e-6
            }) {
                Some(f) => f,
                None => {
                    faces.push(Face {
                        surface: tri.surface as usize,
                        normal,
                        triangles: Vec::new(),
                        cells: Vec::new(),
                    });
                    faces.len() - 1
                }
            };
            faces[face].triangles.push(ti);
            face_of[ti] = Some(face);
            // The lattice squares over the triangle's texture-coordinate box.
            let st: Vec<[f64; 2]> = tri.vertices.iter().map(|v| tri.texture_coordinates(v)).collect();
            let lo = |k: usize| st.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
            let hi = |k: usize| st.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
            let (i0, i1) = ((lo(0) / spacing_m).floor() as i64, (hi(0) / spacing_m).ceil() as i64);
            let (j0, j1) = ((lo(1) / spacing_m).floor() as i64, (hi(1) / spacing_m).ceil() as i64);
            // A point on the plane with texture coordinates (s, t).
            let [sa, ta] = tri.texture_axes;
            let base = tri.vertices[0] - sa * st[0][0] - ta * st[0][1];
            for i in i0..i1 {
                for j in j0..j1 {
                    let mut sum = Vector3::zeros();
                    let mut k = 0usize;
                    for a in 0..CELL_SUBSAMPLES {
                        for b in 0..CELL_SUBSAMPLES {
                            let s = (i as f64 + (a as f64 + 0.5) / CELL_SUBSAMPLES as f64) * spacing_m;
                            let t = (j as f64 + (b as f64 + 0.5) / CELL_SUBSAMPLES as f64) * spacing_m;
                            let p = base + sa * s + ta * t;
                            if inside(tri, &p) {
                                sum += p;
                                k += 1;
                            }
                        }
                    }
                    if k == 0 {
                        continue;
                    }
                    let id = cells.len();
                    cells.push(Cell {
                        triangle: ti,
                        face,
                        surface: tri.surface as usize,
                        lattice: (i, j),
                        centre: sum / k as f64,
                        normal,
                        area_m2: spacing_m * spacing_m * k as f64 / (CELL_SUBSAMPLES * CELL_SUBSAMPLES) as f64,
                    });
                    lookup.insert((ti, i, j), id);
                    by_face.entry((face, i, j)).or_default().push(id);
                    faces[face].cells.push(id);
                }
            }
        }
        Ok(Grid {
            spacing_m,
            cells,
            faces,
            targets: targets.to_vec(),
            side,
            lookup,
            by_face,
            face_of,
        })
    }

    /// The visible-side normal of target triangle `triangle`, or `None` for
    /// a triangle that is not solved for.
    pub fn visible_normal(&self, scene: &Scene, triangle: usize) -> Option<Vector3<f64>> {
        let s = (*self.side.get(triangle)?)?;
        Some(scene.triangles()[triangle].normal * s)
    }

    /// The cell containing `point` on `triangle`, if the triangle is a
    /// target and the point falls in one of its cells.
    pub fn cell_at(&self, scene: &Scene, triangle: usize, point: &Vector3<f64>) -> Option<usize> {
        self.side.get(triangle)?.as_ref()?;
        let [s, t] = scene.triangles()[triangle].texture_coordinates(point);
        let (i, j) = ((s / self.spacing_m).floor() as i64, (t / self.spacing_m).floor() as i64);
        self.lookup.get(&(triangle, i, j)).copied()
    }

    /// The cell containing `point` on `triangle`, or else the nearest cell
    /// of the same face within two lattice steps (slivers of a triangle too
    /// thin to hold a cell sub-sample have none of their own).
    pub fn nearest_cell(&self, scene: &Scene, triangle: usize, point: &Vector3<f64>) -> Option<usize> {
        if let Some(c) = self.cell_at(scene, triangle, point) {
            return Some(c);
        }
        let face = self.face_of(triangle)?;
        let [s, t] = scene.triangles()[triangle].texture_coordinates(point);
        let (i, j) = ((s / self.spacing_m).floor() as i64, (t / self.spacing_m).floor() as i64);
        let mut best: Option<(f64, usize)> = None;
        for di in -2..=2i64 {
            for dj in -2..=2i64 {
                for &c in self.by_face.get(&(face, i + di, j + dj)).into_iter().flatten() {
                    let d = (self.cells[c].centre - point).norm();
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, c));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// The cells of the same face within `ring` lattice steps of `cell`
    /// (itself excluded).
    pub fn neighbours(&self, cell: usize, ring: i64) -> Vec<usize> {
        let c = &self.cells[cell];
        let mut out = Vec::new();
        for di in -ring..=ring {
            for dj in -ring..=ring {
                if let Some(ids) = self.by_face.get(&(c.face, c.lattice.0 + di, c.lattice.1 + dj)) {
                    out.extend(ids.iter().copied().filter(|&k| k != cell));
                }
            }
        }
        out
    }

    /// The cell at lattice square `(i, j)` of face `face`, if any (the one
    /// on `prefer`'s triangle where the square spans two).
    pub fn face_cell(&self, face: usize, i: i64, j: i64, prefer: usize) -> Option<usize> {
        let ids = self.by_face.get(&(face, i, j))?;
        ids.iter()
            .copied()
            .find(|&c| self.cells[c].triangle == prefer)
            .or_else(|| ids.first().copied())
    }

    /// The face of target triangle `triangle`.
    pub fn face_of(&self, triangle: usize) -> Option<usize> {
        self.face_of.get(triangle).copied().flatten()
    }

    /// Points spread over `cell` (the sub-samples inside its triangle), for
    /// averaging a quantity over the cell.
    pub fn cell_points(&self, scene: &Scene, cell: usize, per_side: usize) -> Vec<Vector3<f64>> {
        let c = &self.cells[cell];
        let tri = &scene.triangles()[c.triangle];
        let [sa, ta] = tri.texture_axes;
        let st0 = tri.texture_coordinates(&tri.vertices[0]);
        let base = tri.vertices[0] - sa * st0[0] - ta * st0[1];
        let n = per_side.max(1);
        let mut out = Vec::new();
        for a in 0..n {
            for b in 0..n {
                let s = (c.lattice.0 as f64 + (a as f64 + 0.5) / n as f64) * self.spacing_m;
                let t = (c.lattice.1 as f64 + (b as f64 + 0.5) / n as f64) * self.spacing_m;
                let p = base + sa * s + ta * t;
                if inside(tri, &p) {
                    out.push(p);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Material;

    fn square() -> Scene {
        let v = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        let t1 = Triangle::new([v(0.0, 0.0), v(4.0, 0.0), v(4.0, 4.0)], 0, 0).unwrap();
        let t2 = Triangle::new([v(0.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)], 0, 0).unwrap();
        Scene::new(
            vec![t1, t2],
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["floor".into()],
        )
        .unwrap()
    }

    /// A 4 m square split in two triangles, 1 m cells: 16 lattice squares,
    /// 4 cut by the diagonal into two cells each; the areas sum to 16 m².
    #[test]
    fn cells_tile_the_face() {
        let scene = square();
        let g = Grid::new(&scene, &[0], 1.0, &[Vector3::new(2.0, 2.0, 10.0)]).unwrap();
        assert_eq!(g.faces.len(), 1);
        let area: f64 = g.cells.iter().map(|c| c.area_m2).sum();
        // Sub-samples on the shared diagonal count on both sides: within 5%.
        assert!((area - 16.0).abs() < 0.8, "area {area}");
        assert_eq!(g.cells.len(), 20);
        let c = g.cell_at(&scene, 0, &Vector3::new(3.5, 0.5, 0.0)).unwrap();
        assert_eq!(g.cells[c].lattice, (3, 0));
        // Its neighbours on the face: (2,0), (2,1), (3,1).
        assert_eq!(g.neighbours(c, 1).len(), 3);
    }

    #[test]
    fn a_bad_spacing_is_an_error() {
        let scene = square();
        assert!(matches!(
            Grid::new(&scene, &[0], 0.0, &[]),
            Err(OutdoorError::BadSpacing { .. })
        ));
        assert!(matches!(
            Grid::new(&scene, &[3], 1.0, &[]),
            Err(OutdoorError::UnknownSurface { .. })
        ));
    }
}
