//! The model (triangles, their plane frames, the shared ray-casting
//! hierarchy) and its fragments: planar pieces of a triangle stored in the
//! triangle's plane coordinates, each with a visibility label per view.

use geo::{Area, Coord, LineString, Polygon};
use nalgebra::Vector3;

use super::VisibilityError;
use super::image_clip::split_half_plane;
use super::view::{NEAR_M, PinholeView};
use crate::render::Triangle;
use crate::render::accel::Accel;

/// An orthonormal frame in a triangle's plane: `origin` is its first
/// vertex, `u` runs along its first edge, `v = normal × u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// First vertex.
    pub origin: Vector3<f64>,
    /// In-plane axis along the first edge.
    pub u: Vector3<f64>,
    /// In-plane axis, `normal × u`.
    pub v: Vector3<f64>,
    /// Unit normal (the triangle's front).
    pub normal: Vector3<f64>,
}

impl PlaneFrame {
    /// The frame of `t`.
    pub fn of(t: &Triangle) -> PlaneFrame {
        let u = (t.vertices[1] - t.vertices[0]).normalize();
        PlaneFrame {
            origin: t.vertices[0],
            u,
            v: t.normal.cross(&u),
            normal: t.normal,
        }
    }

    /// World point of plane coordinates `c`.
    pub fn world(&self, c: Coord<f64>) -> Vector3<f64> {
        self.origin + self.u * c.x + self.v * c.y
    }

    /// Plane coordinates of world point `p` (projected onto the plane).
    pub fn local(&self, p: &Vector3<f64>) -> Coord<f64> {
        let d = p - self.origin;
        Coord {
            x: d.dot(&self.u),
            y: d.dot(&self.v),
        }
    }

    /// Distance along `view`'s ray through image point `xy` to this plane,
    /// if the ray meets it in front of the camera.
    pub fn ray_distance(&self, view: &PinholeView, xy: [f64; 2]) -> Option<f64> {
        let ray = view.ray(xy[0], xy[1]);
        let den = self.normal.dot(&ray.direction);
        if den.abs() < 1e-15 {
            return None;
        }
        let t = self.normal.dot(&(self.origin - ray.origin)) / den;
        (t > 0.0 && t.is_finite()).then_some(t)
    }

    /// The image polygon of plane polygon `p` in `view` (every vertex must
    /// be in front of the near plane: see [`Model::near_part`]).
    pub fn to_image(&self, view: &PinholeView, p: &Polygon<f64>) -> Option<Polygon<f64>> {
        let ring = |ls: &LineString<f64>| -> Option<LineString<f64>> {
            ls.0.iter()
                .map(|c| view.project(&self.world(*c)).map(|[x, y]| Coord { x, y }))
                .collect::<Option<Vec<_>>>()
                .map(LineString::from)
        };
        Some(Polygon::new(
            ring(p.exterior())?,
            p.interiors().iter().map(ring).collect::<Option<Vec<_>>>()?,
        ))
    }

    /// The plane polygon seen at image polygon `p` in `view` (ray–plane
    /// intersection per vertex; exact, the projection being projective).
    pub fn from_image(&self, view: &PinholeView, p: &Polygon<f64>) -> Option<Polygon<f64>> {
        let ring = |ls: &LineString<f64>| -> Option<LineString<f64>> {
            ls.0.iter()
                .map(|c| {
                    let t = self.ray_distance(view, [c.x, c.y])?;
                    let r = view.ray(c.x, c.y);
                    Some(self.local(&(r.origin + r.direction * t)))
                })
                .collect::<Option<Vec<_>>>()
                .map(LineString::from)
        };
        Some(Polygon::new(
            ring(p.exterior())?,
            p.interiors().iter().map(ring).collect::<Option<Vec<_>>>()?,
        ))
    }
}

/// A piece of a triangle, wholly visible or wholly hidden in each view.
#[derive(Debug, Clone, PartialEq)]
pub struct Fragment {
    /// The original triangle (its id in the item buffer, §3.5 step 1).
    pub triangle: usize,
    /// The piece in the triangle's plane coordinates, metres.
    pub shape: Polygon<f64>,
    /// Per view: whether the piece is seen (front-facing, in the image and
    /// unoccluded).
    pub visible: Vec<bool>,
    /// Set when the piece was left whole below the size threshold although
    /// part of it differs from its label in some view.
    pub mixed: bool,
}

impl Fragment {
    /// Area in m².
    pub fn area(&self) -> f64 {
        self.shape.unsigned_area()
    }
}

/// Triangles with their plane frames and the renderer's ray-casting hierarchy.
#[derive(Debug, Clone)]
pub struct Model {
    /// The triangles.
    pub triangles: Vec<Triangle>,
    /// Their plane frames.
    pub frames: Vec<PlaneFrame>,
    /// The hierarchy over them (the renderer's).
    pub accel: Accel,
}

impl Model {
    /// The model of `triangles`.
    pub fn new(triangles: Vec<Triangle>) -> Result<Model, VisibilityError> {
        if triangles.is_empty() {
            return Err(VisibilityError::EmptyModel);
        }
        let frames = triangles.iter().map(PlaneFrame::of).collect();
        let accel = Accel::build(&triangles);
        Ok(Model {
            triangles,
            frames,
            accel,
        })
    }

    /// One whole fragment per triangle, not yet visible anywhere.
    pub fn whole_fragments(&self, views: usize) -> Vec<Fragment> {
        self.triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let f = &self.frames[i];
                let ring: Vec<Coord<f64>> = t.vertices.iter().map(|p| f.local(p)).collect();
                Fragment {
                    triangle: i,
                    shape: Polygon::new(LineString::from(ring), vec![]),
                    visible: vec![false; views],
                    mixed: false,
                }
            })
            .collect()
    }

    /// Whether triangle `t` faces the camera of `view`.
    pub fn front_facing(&self, t: usize, view: &PinholeView) -> bool {
        self.frames[t].normal.dot(&(view.position - self.frames[t].origin)) > 0.0
    }

    /// The view frustum in the plane coordinates of triangle `t`: five
    /// half-planes `a x + b y + c ≥ 0` (in front of the near plane; right
    /// of the image's left edge, left of its right edge, below its top edge,
    /// above its bottom edge). Clipping there, not in the image, keeps
    /// points near the camera plane from projecting to huge coordinates.
    pub fn frustum_half_planes(&self, t: usize, view: &PinholeView) -> [[f64; 3]; 5] {
        let fr = &self.frames[t];
        let (f, w, h) = (view.focal_px, view.width as f64 / 2.0, view.height as f64 / 2.0);
        let planes = [
            (Vector3::new(0.0, 0.0, 1.0), -NEAR_M),
            (Vector3::new(f, 0.0, w), 0.0),
            (Vector3::new(-f, 0.0, w), 0.0),
            (Vector3::new(0.0, f, h), 0.0),
            (Vector3::new(0.0, -f, h), 0.0),
        ];
        planes.map(|(k, k0)| {
            let n = view.rotation.transpose() * k;
            [n.dot(&fr.u), n.dot(&fr.v), n.dot(&(fr.origin - view.position)) + k0]
        })
    }

    /// The image polygon of the whole triangle `t` in `view` (its part in
    /// the frustum), as an occluder; `None` if none of it is in view.
    pub fn occluder_image(&self, t: usize, view: &PinholeView) -> Option<Polygon<f64>> {
        let mut shape = self.whole_fragments(0).swap_remove(t).shape;
        for plane in self.frustum_half_planes(t, view) {
            let (inside, _) = split_half_plane(&shape, plane);
            // A convex polygon cut by a half-plane stays one convex polygon.
            shape = inside.0.into_iter().next()?;
        }
        self.frames[t].to_image(view, &shape)
    }

    /// §3.5 step 3 for a view: `frag` split into the pieces inside the
    /// frustum (with their image polygons), and the pieces outside it or
    /// back-facing (not visible in this view: their labels are left false).
    pub fn split_by_frustum(
        &self,
        frag: Fragment,
        view: &PinholeView,
    ) -> (Vec<(Fragment, Polygon<f64>)>, Vec<Fragment>) {
        let t = frag.triangle;
        if !self.front_facing(t, view) {
            return (vec![], vec![frag]);
        }
        let piece = |shape: Polygon<f64>| Fragment {
            triangle: t,
            shape,
            visible: frag.visible.clone(),
            mixed: frag.mixed,
        };
        let mut out = Vec::new();
        let mut current = vec![frag.shape.clone()];
        for plane in self.frustum_half_planes(t, view) {
            let mut kept = Vec::new();
            for p in current {
                let (inside, outside) = split_half_plane(&p, plane);
                kept.extend(inside.0);
                out.extend(outside.0.into_iter().map(piece));
            }
            current = kept;
        }
        let frame = &self.frames[t];
        let mut inside = Vec::new();
        for p in current {
            match frame.to_image(view, &p) {
                Some(img) => inside.push((piece(p), img)),
                None => out.push(piece(p)),
            }
        }
        (inside, out)
    }
}
