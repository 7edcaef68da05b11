//! Triangles: intersection (Möller–Trumbore, in f64), the geometric frame
//! and the planar texture coordinates of each face.

use nalgebra::Vector3;

/// A ray: origin and unit direction, world frame (x east, y north, z up), metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vector3<f64>,
    /// Unit direction.
    pub direction: Vector3<f64>,
}

/// One triangle of a scene, with everything a hit needs precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Triangle {
    /// The three corners, counter-clockwise seen from the front.
    pub vertices: [Vector3<f64>; 3],
    /// Unit geometric normal (right-handed from the vertex order).
    pub normal: Vector3<f64>,
    /// Index of the triangle's material in the scene.
    pub material: u32,
    /// Index of the named surface (OBJ group) the triangle belongs to.
    pub surface: u32,
    /// Texture axes in the face's plane: `s` is horizontal where the face
    /// is not, `t` points up the face (or north on horizontal faces).
    pub texture_axes: [Vector3<f64>; 2],
}

impl Triangle {
    /// A triangle from its corners; `None` when degenerate (zero area or
    /// non-finite corners), which would give no normal.
    pub fn new(vertices: [Vector3<f64>; 3], material: u32, surface: u32) -> Option<Triangle> {
        if vertices.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return None;
        }
        let n = (vertices[1] - vertices[0]).cross(&(vertices[2] - vertices[0]));
        let len = n.norm();
        if len < 1e-12 {
            return None;
        }
        let normal = n / len;
        Some(Triangle {
            vertices,
            normal,
            material,
            surface,
            texture_axes: texture_axes(normal),
        })
    }

    /// Distance along `ray` to the triangle, if it is hit in `(t_min, t_max)`.
    /// Both sides of the triangle are hit.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        EdgeForm::new(self).intersect(ray, t_min, t_max)
    }

    /// Planar texture coordinates (metres) of a point on the face.
    pub fn texture_coordinates(&self, p: &Vector3<f64>) -> [f64; 2] {
        [p.dot(&self.texture_axes[0]), p.dot(&self.texture_axes[1])]
    }

    /// Area, m².
    pub fn area(&self) -> f64 {
        0.5 * (self.vertices[1] - self.vertices[0])
            .cross(&(self.vertices[2] - self.vertices[0]))
            .norm()
    }

    /// The point at barycentric coordinates `(u, v)` (weights of corners 1 and 2).
    pub fn point(&self, u: f64, v: f64) -> Vector3<f64> {
        self.vertices[0] + (self.vertices[1] - self.vertices[0]) * u + (self.vertices[2] - self.vertices[0]) * v
    }
}

/// A triangle's corner, edges and degeneracy tolerance, worked out once
/// for many ray tests ([`Triangle::intersect`] builds one per call; a
/// scene's hierarchy keeps one per triangle). Both give the same numbers
/// to the last bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EdgeForm {
    a: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    /// `|det|` below this is a ray in the triangle's plane.
    tolerance: f64,
}

impl EdgeForm {
    /// The form of `t`.
    pub(crate) fn new(t: &Triangle) -> EdgeForm {
        let [a, b, c] = t.vertices;
        let e1 = b - a;
        let e2 = c - a;
        EdgeForm {
            a,
            e1,
            e2,
            tolerance: 1e-14 * e1.norm() * e2.norm(),
        }
    }

    /// [`Triangle::intersect`] (Möller–Trumbore).
    pub(crate) fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        let (a, e1, e2) = (self.a, self.e1, self.e2);
        let p = ray.direction.cross(&e2);
        let det = e1.dot(&p);
        if det.abs() < self.tolerance {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - a;
        let u = s.dot(&p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(&e1);
        let v = ray.direction.dot(&q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(&q) * inv;
        (t > t_min && t < t_max).then_some(t)
    }
}

/// The texture axes of a face with unit normal `n`: `t` is the world "up"
/// projected into the face (north on horizontal faces), `s = t × n` runs
/// along the face, so coplanar faces share one continuous texture.
fn texture_axes(n: Vector3<f64>) -> [Vector3<f64>; 2] {
    let up = Vector3::z();
    let mut t = up - n * n.dot(&up);
    if t.norm() < 1e-6 {
        let north = Vector3::y();
        t = north - n * n.dot(&north);
    }
    let t = t.normalize();
    let s = t.cross(&n).normalize();
    [s, t]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Triangle {
        Triangle::new(
            [
                Vector3::zeros(),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            0,
            0,
        )
        .unwrap()
    }

    #[test]
    fn hits_inside_and_misses_outside() {
        let t = tri();
        let down = Vector3::new(0.0, 0.0, -1.0);
        let inside = Ray {
            origin: Vector3::new(0.25, 0.25, 2.0),
            direction: down,
        };
        assert!((t.intersect(&inside, 1e-9, f64::INFINITY).unwrap() - 2.0).abs() < 1e-12);
        let outside = Ray {
            origin: Vector3::new(0.75, 0.75, 2.0),
            direction: down,
        };
        assert_eq!(t.intersect(&outside, 1e-9, f64::INFINITY), None);
        let parallel = Ray {
            origin: Vector3::new(0.25, 0.25, 0.0),
            direction: Vector3::x(),
        };
        assert_eq!(t.intersect(&parallel, 1e-9, f64::INFINITY), None);
        assert!((t.normal - Vector3::z()).norm() < 1e-15);
        assert!((t.area() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn degenerate_triangles_are_refused() {
        let p = Vector3::new(1.0, 2.0, 3.0);
        assert!(Triangle::new([p, p, Vector3::zeros()], 0, 0).is_none());
        assert!(Triangle::new([Vector3::new(f64::NAN, 0.0, 0.0), p, Vector3::zeros()], 0, 0).is_none());
    }

    #[test]
    fn texture_axes_are_orthonormal_and_in_plane() {
        for n in [
            Vector3::z(),
            Vector3::x(),
            Vector3::new(1.0, 1.0, 1.0).normalize(),
            -Vector3::z(),
        ] {
            let [s, t] = texture_axes(n);
            assert!(s.dot(&n).abs() < 1e-12 && t.dot(&n).abs() < 1e-12 && s.dot(&t).abs() < 1e-12);
            assert!((s.norm() - 1.0).abs() < 1e-12 && (t.norm() - 1.0).abs() < 1e-12);
        }
    }
}
