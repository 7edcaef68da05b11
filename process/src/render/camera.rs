//! Camera rays: the station's pinhole-with-distortion intrinsics, mounted on
//! the head through the mount calibration ([`crate::pose`]), standing at a
//! world position.

use nalgebra::Vector3;

use super::mesh::Ray;
use crate::pose::{HeadPose, Mount, Pinhole};

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

impl CameraRig {
    /// The world ray through image point `(u, v)` (pixel units; pixel
    /// centres at half-integers), or `None` where the distortion model has
    /// no ray.
    pub fn ray(&self, u: f64, v: f64) -> Option<Ray> {
        let d = self.pinhole.unproject(u, v)?;
        let w = self.mount.to_world(self.head, d);
        let direction = Vector3::new(w[0], w[1], w[2]).normalize();
        Some(Ray {
            origin: self.position,
            direction,
        })
    }

    /// The pixel a world point projects to, if in front of the camera.
    pub fn project(&self, p: &Vector3<f64>) -> Option<(f64, f64)> {
        let d = p - self.position;
        let c = self.mount.to_camera(self.head, [d.x, d.y, d.z]);
        self.pinhole.project(c)
    }
}
