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

    /// An undistorted pinhole camera at `position` looking along `look`
    /// with `up` upward in the image (a hint, made orthogonal to `look`),
    /// vertical field of view `vfov_rad` over `height` pixels, the
    /// principal point at the image centre: a calibrated photograph's
    /// camera, as plain files give it (IGI's and RADIANCE's views).
    ///
    /// The rig's mount carries the orientation: a level mount would only
    /// pan and tilt, so any roll of the camera about its axis is put in the
    /// mount's base roll and pitch (`world = R_x(pitch) R_y(roll) level`),
    /// the one of the two that is well conditioned for this camera's right
    /// vector, and the head's pan and tilt take the rest. `None` for a
    /// degenerate view (a zero `look`, `up` parallel to it, a field of view
    /// outside (0, π), an empty image).
    pub fn look_at(
        position: Vector3<f64>,
        look: Vector3<f64>,
        up: Vector3<f64>,
        vfov_rad: f64,
        width: usize,
        height: usize,
    ) -> Option<CameraRig> {
        if !(vfov_rad > 0.0 && vfov_rad < std::f64::consts::PI) || width == 0 || height == 0 {
            return None;
        }
        let forward = look.try_normalize(1e-300)?;
        let right = forward.cross(&up).try_normalize(1e-12)?;
        // Undo the base's tilt so that `right` becomes horizontal: roll
        // about north (y) when right has an east part, else pitch about east (x).
        let (roll, pitch) = if right.x.abs() >= right.y.abs() {
            ((-right.z).atan2(right.x), 0.0)
        } else {
            (0.0, right.z.atan2(right.y))
        };
        let level = |w: Vector3<f64>| {
            // R_y(-roll) R_x(-pitch) w
            let (sp, cp) = (-pitch).sin_cos();
            let x = Vector3::new(w.x, cp * w.y - sp * w.z, sp * w.y + cp * w.z);
            let (sr, cr) = (-roll).sin_cos();
            Vector3::new(cr * x.x + sr * x.z, x.y, -sr * x.x + cr * x.z)
        };
        let (r, f) = (level(right), level(forward));
        // A level right vector is (cos az, -sin az, 0); the forward vector
        // then lies in the plane of (sin az, cos az, 0) and z.
        let azimuth = (-r.y).atan2(r.x);
        let (sa, ca) = azimuth.sin_cos();
        let elevation = f.z.atan2(f.x * sa + f.y * ca);
        let focal_px = 0.5 * height as f64 / (0.5 * vfov_rad).tan();
        Some(CameraRig {
            pinhole: Pinhole {
                focal_px,
                principal_px: (0.5 * width as f64, 0.5 * height as f64),
                k1: 0.0,
                k2: 0.0,
                projection: crate::pose::Projection::Pinhole,
            },
            mount: Mount {
                pan_zero_azimuth_rad: 0.0,
                tilt_zero_rad: 0.0,
                roll_rad: roll,
                pitch_rad: pitch,
            },
            head: HeadPose {
                pan_rad: azimuth,
                tilt_rad: elevation,
            },
            position,
            width,
            height,
        })
    }

    /// The pixel a world point projects to, if in front of the camera.
    pub fn project(&self, p: &Vector3<f64>) -> Option<(f64, f64)> {
        let d = p - self.position;
        let c = self.mount.to_camera(self.head, [d.x, d.y, d.z]);
        self.pinhole.project(c)
    }
}

#[cfg(test)]
mod look_at_tests {
    use super::*;

    /// The rig's pixel rays are the pinhole's of the view: right = look ×
    /// up, image up = right × look, for level, rolled, upward, downward and
    /// portrait cameras, within 1e-12.
    #[test]
    fn look_at_rays_match_the_view_basis() {
        let cases = [
            (Vector3::new(0.0, 1.0, 0.2), Vector3::new(0.0, 0.0, 1.0)),
            (Vector3::new(-1.0, 0.3, -0.4), Vector3::new(0.0, 0.0, 1.0)),
            (Vector3::new(0.3, -1.0, 0.1), Vector3::new(0.4, 0.0, 1.0)),
            (Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 0.0, -1.0)),
            (Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 1.0, 0.0)),
            (Vector3::new(0.0, 0.0, -1.0), Vector3::new(1.0, 1.0, 0.0)),
            (Vector3::new(0.0, 1.0, 0.0), Vector3::new(1.0, 0.0, 0.0)),
            (Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 1.0, 0.0)),
            (Vector3::new(0.2, 0.7, 0.5), Vector3::new(-0.6, 0.5, 0.3)),
        ];
        let (w, h, vfov) = (96usize, 64usize, 40f64.to_radians());
        for (look, up) in cases {
            let rig = CameraRig::look_at(Vector3::new(1.0, 2.0, 3.0), look, up, vfov, w, h).unwrap();
            let f = look.normalize();
            let r = f.cross(&up).normalize();
            let u = r.cross(&f);
            let t = (0.5 * vfov).tan();
            for (px, py) in [(0.0, 0.0), (48.0, 32.0), (95.5, 10.25), (3.0, 63.0)] {
                let x = (2.0 * px / w as f64 - 1.0) * t * w as f64 / h as f64;
                let y = (1.0 - 2.0 * py / h as f64) * t;
                let want = (f + r * x + u * y).normalize();
                let got = rig.ray(px, py).unwrap().direction.normalize();
                assert!(
                    (got - want).norm() < 1e-12,
                    "look {look:?} up {up:?} pixel ({px}, {py}): {got:?} vs {want:?}"
                );
                let p = rig.position + want * 7.0;
                let (u2, v2) = rig.project(&p).unwrap();
                assert!((u2 - px).abs() < 1e-9 && (v2 - py).abs() < 1e-9);
            }
        }
        let flat = CameraRig::look_at(
            Vector3::zeros(),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 2.0, 0.0),
            vfov,
            w,
            h,
        );
        assert!(flat.is_none(), "up parallel to look");
        assert!(CameraRig::look_at(Vector3::zeros(), Vector3::zeros(), Vector3::z(), vfov, w, h).is_none());
    }
}
