//! The scene's triangles indexed for ray casting, with each triangle's
//! radiosity cells: an `n × n` grid over its barycentric coordinates
//! `(u, v)` (cells wholly outside `u + v ≤ 1` stay empty). The cells carry
//! the diffuse radiance and the indirect irradiance of §4.3–4.5 at the
//! resolution the gathering needs; they are this solver's patches.

use nalgebra::Vector3;

use super::error::IgiError;
use crate::brdf::ShadingFrame;
use crate::render::{Material, Ray, Scene, SurfaceHit, Triangle};

/// Offset of a ray origin off the surface it leaves, metres.
pub(crate) const SURFACE_OFFSET: f64 = 1e-6;

/// A triangle's corner 0, its two edges, and the inverse of their Gram matrix.
type Corner = (Vector3<f64>, Vector3<f64>, Vector3<f64>, [f64; 3]);

/// Triangles, a ray-casting index and the cell grid.
#[derive(Debug, Clone)]
pub(crate) struct Geometry {
    scene: Scene,
    /// Per triangle: corner 0, the edges, and the inverse Gram matrix.
    corners: Vec<Corner>,
    /// Per triangle, the shading frames on the side of its normal and on the other side.
    frames: Vec<[ShadingFrame; 2]>,
    /// Cells per triangle edge.
    pub n: usize,
}

impl Geometry {
    /// Indexes `triangles` (materials are not needed: every triangle gets a
    /// placeholder so that the render scene's checks pass).
    pub fn new(triangles: &[Triangle], surfaces: &[String], n: usize) -> Result<Geometry, IgiError> {
        if triangles.is_empty() {
            return Err(IgiError::NoGeometry);
        }
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|t| Triangle {
                material: 0,
                ..t.clone()
            })
            .collect();
        let corners = tris
            .iter()
            .map(|t| {
                let e1 = t.vertices[1] - t.vertices[0];
                let e2 = t.vertices[2] - t.vertices[0];
                let (a, b, c) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
                let det = a * c - b * b;
                (t.vertices[0], e1, e2, [c / det, -b / det, a / det])
            })
            .collect();
        let frames = tris
            .iter()
            .map(|t| [t.normal, -t.normal].map(|n| shading_frame(n, t.texture_axes[0])))
            .collect();
        let scene = Scene::new(
            tris,
            vec![Material::diffuse("placeholder", [0.0; 3])],
            surfaces.to_vec(),
        )?;
        Ok(Geometry {
            scene,
            corners,
            frames,
            n,
        })
    }

    /// The triangles.
    pub fn triangles(&self) -> &[Triangle] {
        self.scene.triangles()
    }

    /// Number of cells in all.
    pub fn cell_count(&self) -> usize {
        self.triangles().len() * self.n * self.n
    }

    /// Nearest hit along a ray.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        self.scene.intersect(ray, t_max)
    }

    /// Whether a segment is blocked.
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.scene.occluded(ray, t_max)
    }

    /// Barycentric `(u, v)` of a point on triangle `tri`.
    fn barycentric(&self, tri: usize, p: &Vector3<f64>) -> (f64, f64) {
        let (o, e1, e2, g) = &self.corners[tri];
        let d = p - o;
        let (a, b) = (d.dot(e1), d.dot(e2));
        (g[0] * a + g[1] * b, g[1] * a + g[2] * b)
    }

    /// The cell holding point `p` of triangle `tri`.
    pub fn cell(&self, tri: usize, p: &Vector3<f64>) -> usize {
        self.cell_with_fraction(tri, p).0
    }

    /// The cell holding point `p` of triangle `tri`, and the point's
    /// fractional position in it (each in [0, 1]).
    pub fn cell_with_fraction(&self, tri: usize, p: &Vector3<f64>) -> (usize, [f64; 2]) {
        let (u, v) = self.barycentric(tri, p);
        let n = self.n;
        let (x, y) = (u * n as f64, v * n as f64);
        // `as` truncates toward zero and saturates (negative and NaN to 0):
        // the floor clamped at 0, without a call to `floor`.
        let i = (x as usize).min(n - 1);
        let j = (y as usize).min(n - 1);
        let f = [(x - i as f64).clamp(0.0, 1.0), (y - j as f64).clamp(0.0, 1.0)];
        (tri * n * n + i * n + j, f)
    }

    /// The triangle a cell belongs to.
    pub fn cell_triangle(&self, cell: usize) -> usize {
        cell / (self.n * self.n)
    }

    /// A point of cell `cell` at fractional position `f` in the cell, if it
    /// lies on the triangle.
    pub fn cell_point(&self, cell: usize, f: [f64; 2]) -> Option<Vector3<f64>> {
        let n = self.n;
        let tri = cell / (n * n);
        let (i, j) = ((cell % (n * n)) / n, cell % n);
        let u = (i as f64 + f[0]) / n as f64;
        let v = (j as f64 + f[1]) / n as f64;
        if u + v > 1.0 {
            return None;
        }
        let (o, e1, e2, _) = &self.corners[tri];
        Some(o + e1 * u + e2 * v)
    }

    /// A representative point of the cell on the triangle: its centre, or
    /// for a cell the diagonal cuts, the centre of the part inside; `None`
    /// for a cell wholly outside.
    pub fn cell_centre(&self, cell: usize) -> Option<Vector3<f64>> {
        self.cell_point(cell, [0.5, 0.5])
            .or_else(|| self.cell_point(cell, [1.0 / 3.0, 1.0 / 3.0]))
            .or_else(|| self.cell_point(cell, [0.0, 0.0]))
    }

    /// The shading frame of triangle `tri` on the side facing `toward`
    /// (tangent = the face's texture `s` axis, as the renderer uses).
    pub fn frame(&self, tri: usize, toward: &Vector3<f64>) -> ShadingFrame {
        let t = &self.triangles()[tri];
        self.frames[tri][usize::from(t.normal.dot(toward) < 0.0)]
    }
}

/// The shading frame with normal `n` and tangent `tangent` (the face's
/// texture `s` axis, as the renderer uses), or the world frame if `n` is
/// degenerate.
fn shading_frame(n: Vector3<f64>, tangent: Vector3<f64>) -> ShadingFrame {
    ShadingFrame::new(n, tangent).unwrap_or(ShadingFrame {
        normal: Vector3::z(),
        tangent: Vector3::x(),
        bitangent: Vector3::y(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_cover_the_triangle_and_find_their_points() {
        let t = Triangle::new(
            [
                Vector3::zeros(),
                Vector3::new(2.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            3,
            0,
        )
        .unwrap();
        let g = Geometry::new(&[t], &["s".into()], 8).unwrap();
        let mut inside = 0;
        for c in 0..g.cell_count() {
            if let Some(p) = g.cell_point(c, [0.5, 0.5]) {
                assert_eq!(g.cell(0, &p), c);
                inside += 1;
            }
        }
        // Cells (i, j) with i + j + 1 <= 8: centres inside.
        assert_eq!(inside, 36);
        assert!(g.cell_centre(8 * 8 - 1).is_none());
    }
}
