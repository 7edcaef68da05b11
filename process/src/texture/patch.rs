//! The texture patches: one per *face* (the coplanar triangles of one named
//! surface), a lattice of square texels over the face's bounding box in its
//! planar texture coordinates `(s, t)` (metres). Texel `(i, j)` covers
//! `s ∈ [s0 + i·Δ, s0 + (i+1)·Δ)`, `t ∈ [t0 + j·Δ, …)`; it lies *on* the face
//! when its centre is inside one of the face's triangles (the others are
//! padding, filled from their neighbours so that filtering near an edge
//! reads plausible values).

use nalgebra::Vector3;

use super::TextureError;
use crate::render::{Scene, Triangle};

/// One face's texel lattice.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// The named surface (index into the scene's surfaces).
    pub surface: usize,
    /// The triangles of the face.
    pub triangles: Vec<usize>,
    /// Unit normal of the face (its first triangle's).
    pub normal: Vector3<f64>,
    /// `normal · p` for points `p` of the face's plane, metres.
    pub offset_m: f64,
    /// Texture axes `s`, `t` (the first triangle's).
    pub axes: [Vector3<f64>; 2],
    /// `(s0, t0)`: the lattice's lower corner, metres.
    pub origin: [f64; 2],
    /// Texel side, metres.
    pub texel_m: f64,
    /// Texels along `s`.
    pub cols: usize,
    /// Texels along `t`.
    pub rows: usize,
    /// The triangle each texel's centre lies in (`None`: padding), `j · cols + i`.
    pub texel_triangle: Vec<Option<u32>>,
}

impl Patch {
    /// The world point at texture coordinates `(s, t)` of the face.
    pub fn point_at(&self, s: f64, t: f64) -> Vector3<f64> {
        self.normal * self.offset_m + self.axes[0] * s + self.axes[1] * t
    }

    /// The centre of texel `(i, j)`, world frame.
    pub fn texel_centre(&self, i: usize, j: usize) -> Vector3<f64> {
        self.point_at(
            self.origin[0] + (i as f64 + 0.5) * self.texel_m,
            self.origin[1] + (j as f64 + 0.5) * self.texel_m,
        )
    }

    /// The face's texture coordinates of world point `p`.
    pub fn st(&self, p: &Vector3<f64>) -> [f64; 2] {
        [p.dot(&self.axes[0]), p.dot(&self.axes[1])]
    }

    /// Continuous lattice coordinates of `p`: texel `(i, j)` spans `[i, i+1) × [j, j+1)`.
    pub fn lattice(&self, p: &Vector3<f64>) -> [f64; 2] {
        let [s, t] = self.st(p);
        [(s - self.origin[0]) / self.texel_m, (t - self.origin[1]) / self.texel_m]
    }

    /// Texels on the face (centre inside a triangle).
    pub fn texels_on_face(&self) -> usize {
        self.texel_triangle.iter().filter(|t| t.is_some()).count()
    }
}

/// Whether `p` (on the triangle's plane) is inside `tri`, edges included.
pub(crate) fn inside(tri: &Triangle, p: &Vector3<f64>) -> bool {
    let [a, b, c] = tri.vertices;
    let n = tri.normal;
    let scale = (b - a).norm().max((c - a).norm());
    let e = |x: Vector3<f64>, y: Vector3<f64>| (y - x).cross(&(p - x)).dot(&n) >= -1e-9 * scale * scale;
    e(a, b) && e(b, c) && e(c, a)
}

/// The patches of the named surfaces `surfaces` of `scene` (all surfaces
/// when `None`) at `texel_m` metres per texel; refused when they would hold
/// more than `max_texels` texels in all.
pub fn patches(
    scene: &Scene,
    surfaces: Option<&[String]>,
    texel_m: f64,
    max_texels: usize,
) -> Result<Vec<Patch>, TextureError> {
    patches_with(scene, surfaces, texel_m, max_texels, false)
}

/// [`patches`] with each lattice's corner on a multiple of `texel_m` in
/// the face's texture coordinates, so that texel `(i, j)` is the square
/// `⌊s/Δ⌋ = i + i0`, `⌊t/Δ⌋ = j + j0` of the surface grid of the same
/// spacing ([`crate::outdoor::grid`]): an albedo texture at the grid's
/// spacing then copies each grid square into one texel, without resampling.
pub fn patches_on_lattice(
    scene: &Scene,
    surfaces: Option<&[String]>,
    texel_m: f64,
    max_texels: usize,
) -> Result<Vec<Patch>, TextureError> {
    patches_with(scene, surfaces, texel_m, max_texels, true)
}

fn patches_with(
    scene: &Scene,
    surfaces: Option<&[String]>,
    texel_m: f64,
    max_texels: usize,
    on_lattice: bool,
) -> Result<Vec<Patch>, TextureError> {
    if !(texel_m.is_finite() && texel_m > 0.0) {
        return Err(TextureError::BadSetting {
            field: "texel_m",
            value: texel_m.to_string(),
            expected: "a finite length > 0 (metres per texel)".into(),
        });
    }
    let wanted: Option<Vec<usize>> = surfaces
        .map(|names| {
            names
                .iter()
                .map(|n| {
                    scene.surface_index(n).ok_or_else(|| TextureError::UnknownSurface {
                        name: n.clone(),
                        known: scene.surfaces().join(", "),
                    })
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    let tris = scene.triangles();
    let mut faces: Vec<(usize, Vector3<f64>, f64, Vec<usize>)> = Vec::new();
    for (ti, tri) in tris.iter().enumerate() {
        let surface = tri.surface as usize;
        if wanted.as_ref().is_some_and(|w| !w.contains(&surface)) {
            continue;
        }
        let offset = tri.normal.dot(&tri.vertices[0]);
        let scale = tri.vertices.iter().map(|v| v.norm()).fold(1.0, f64::max);
        match faces
            .iter_mut()
            .find(|(s, n, o, _)| *s == surface && n.dot(&tri.normal) > 1.0 - 1e-9 && (o - offset).abs() < 1e-9 * scale)
        {
            Some(face) => face.3.push(ti),
            None => faces.push((surface, tri.normal, offset, vec![ti])),
        }
    }
    let mut out = Vec::with_capacity(faces.len());
    let mut total = 0usize;
    for (surface, normal, offset_m, triangles) in faces {
        let axes = tris[triangles[0]].texture_axes;
        let st: Vec<[f64; 2]> = triangles
            .iter()
            .flat_map(|&t| tris[t].vertices.iter())
            .map(|v| [v.dot(&axes[0]), v.dot(&axes[1])])
            .collect();
        let lo = |k: usize| st.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = |k: usize| st.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        let origin = if on_lattice {
            [0, 1].map(|k| (lo(k) / texel_m + 1e-9).floor() * texel_m)
        } else {
            [lo(0), lo(1)]
        };
        let cols = (((hi(0) - origin[0]) / texel_m).ceil() as usize).max(1);
        let rows = (((hi(1) - origin[1]) / texel_m).ceil() as usize).max(1);
        total = total.saturating_add(cols.saturating_mul(rows));
        if total > max_texels {
            return Err(TextureError::TooManyTexels {
                texels: total,
                texel_m,
                limit: max_texels,
            });
        }
        let mut patch = Patch {
            surface,
            triangles,
            normal,
            offset_m,
            axes,
            origin,
            texel_m,
            cols,
            rows,
            texel_triangle: vec![None; cols * rows],
        };
        for j in 0..rows {
            for i in 0..cols {
                let p = patch.texel_centre(i, j);
                patch.texel_triangle[j * cols + i] = patch
                    .triangles
                    .iter()
                    .copied()
                    .find(|&t| inside(&tris[t], &p))
                    .map(|t| t as u32);
            }
        }
        out.push(patch);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Material;

    /// A 4 m × 2 m wall (two triangles) and a 1 m floor square of another
    /// surface: two patches; at 0.5 m the wall has 8 × 4 texels, every
    /// centre on the face, and each centre maps back to its lattice cell.
    #[test]
    fn a_wall_and_a_floor_make_two_patches() {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        let tris = vec![
            Triangle::new([v(0.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(4.0, 0.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 0.0, 0.0), v(4.0, 0.0, 2.0), v(0.0, 0.0, 2.0)], 0, 0).unwrap(),
            Triangle::new([v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0), v(1.0, 2.0, 0.0)], 0, 1).unwrap(),
        ];
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("m", [0.5; 3])],
            vec!["wall".into(), "floor".into()],
        )
        .unwrap();
        let ps = patches(&scene, None, 0.5, 1_000_000).unwrap();
        assert_eq!(ps.len(), 2);
        let wall = &ps[0];
        assert_eq!((wall.cols, wall.rows), (8, 4));
        assert_eq!(wall.texels_on_face(), 32);
        let c = wall.texel_centre(3, 2);
        let [x, y] = wall.lattice(&c);
        assert!((x - 3.5).abs() < 1e-12 && (y - 2.5).abs() < 1e-12);
        assert!(c.y.abs() < 1e-12, "{c:?}");
        // The floor's half-square triangle: of its 2 × 2 texels, the centres
        // (0.25, 0.25)… lie inside for 3 (on or below the diagonal).
        assert_eq!(ps[1].texels_on_face(), 3);
        // Only the floor; an unknown surface is named.
        assert_eq!(patches(&scene, Some(&["floor".into()]), 0.5, 100).unwrap().len(), 1);
        let err = patches(&scene, Some(&["roof".into()]), 0.5, 100)
            .unwrap_err()
            .to_string();
        assert!(err.contains("roof") && err.contains("wall"), "{err}");
        assert!(matches!(
            patches(&scene, None, 0.01, 1000),
            Err(TextureError::TooManyTexels { .. })
        ));
        assert!(patches(&scene, None, -1.0, 1000).is_err());
    }
}
