//! Camera rays: the station's pinhole-with-distortion intrinsics, mounted on
//! the head through the mount calibration ([`crate::pose`]), standing at a
//! world position.

use nalgebra::Vector3;

use super::mesh::Ray;
use crate::pose::{HeadPose, Mount, OrientedMount, Pinhole};

/// A camera on its head, at a place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraRig {
    /// Intrinsics.
    pub pinhole: Pinhole,
    /// How the head sits in the world.
    pub mount: Mount,
    /// The head's (true) angles.
    pub head: HeadPose,
    /// Where the camera's centre of projection is, world frame, metres.
    pub position: Vector3<f64>,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
}

/// A [`CameraRig`] at its head pose, ready to cast rays.
#[derive(Debug, Clone, Copy)]
pub struct RayCaster<'a> {
    rig: &'a CameraRig,
    oriented: OrientedMount,
}

impl RayCaster<'_> {
    /// The world ray through image point `(u, v)` (see [`CameraRig::ray`]).
    pub fn ray(&self, u: f64, v: f64) -> Option<Ray> {
        let d = self.rig.pinhole.unproject(u, v)?;
        let w = self.oriented.to_world(d);
        let direction = Vector3::new(w[0], w[1], w[2]).normalize();
        Some(Ray {
            origin: self.rig.position,
            direction,
        })
    }
}

impl CameraRig {
    /// The world ray through image point `(u, v)` (pixel units; pixel
    /// centres at half-integers), or `None` where the distortion model has
    /// no ray.
    pub fn ray(&self, u: f64, v: f64) -> Option<Ray> {
        self.rays().ray(u, v)
    }

    /// The rig with its head rotations evaluated once, for casting a
    /// frame's rays (the same rays as [`CameraRig::ray`], bit for bit).
    pub fn rays(&self) -> RayCaster<'_> {
        RayCaster {
            rig: self,
            oriented: self.mount.at(self.head),
        }
    }

    /// The pixel a world point projects to, if in front of the camera.
    pub fn project(&self, p: &Vector3<f64>) -> Option<(f64, f64)> {
        let d = p - self.position;
        let c = self.mount.to_camera(self.head, [d.x, d.y, d.z]);
        self.pinhole.project(c)
    }
}
