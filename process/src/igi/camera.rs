//! The pinhole camera of an inverse-global-illumination view: position,
//! look direction, up, vertical field of view and resolution, as the scene
//! file gives them (no distortion: the images are assumed rectified).
//!
//! Pixel `(x, y)` covers `[x, x+1) × [y, y+1)`, rows downward; its centre
//! is at `(x + 0.5, y + 0.5)`.

use nalgebra::Vector3;

use super::error::IgiError;

/// A rectified pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewCamera {
    /// Centre of projection, world frame, metres.
    pub position: Vector3<f64>,
    /// Viewing direction (any length).
    pub look: Vector3<f64>,
    /// Up hint (any length, not parallel to `look`).
    pub up: Vector3<f64>,
    /// Vertical field of view, radians, in (0, π).
    pub vfov_rad: f64,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
}

impl ViewCamera {
    /// Checks every field; `view` names the view in the error.
    pub fn validate(&self, view: &str) -> Result<(), IgiError> {
        let err = |field: &'static str, value: String, expected: &'static str| IgiError::Camera {
            view: view.to_string(),
            field,
            value,
            expected,
        };
        let finite = |v: &Vector3<f64>| v.iter().all(|c| c.is_finite());
        if !finite(&self.position) {
            return Err(err("position", format!("{:?}", self.position), "finite coordinates"));
        }
        if !finite(&self.look) || self.look.norm() == 0.0 {
            return Err(err("look", format!("{:?}", self.look), "a finite non-zero direction"));
        }
        if !finite(&self.up) || self.look.normalize().cross(&self.up).norm() < 1e-9 * self.up.norm().max(1e-300) {
            return Err(err(
                "up",
                format!("{:?}", self.up),
                "a finite direction not parallel to look",
            ));
        }
        if !(self.vfov_rad > 0.0 && self.vfov_rad < std::f64::consts::PI) {
            return Err(err("vfov", format!("{} rad", self.vfov_rad), "an angle in (0, 180°)"));
        }
        if self.width == 0 || self.height == 0 {
            return Err(err(
                "resolution",
                format!("{}x{}", self.width, self.height),
                "at least 1x1 pixels",
            ));
        }
        Ok(())
    }

    /// Forward, right and up unit vectors.
    fn basis(&self) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let f = self.look.normalize();
        let r = f.cross(&self.up).normalize();
        (f, r, r.cross(&f))
    }

    /// Half-height of the image plane at unit distance, and the aspect ratio.
    fn plane(&self) -> (f64, f64) {
        ((0.5 * self.vfov_rad).tan(), self.width as f64 / self.height as f64)
    }

    /// The unit world direction through image point `(px, py)` (pixel units).
    pub fn direction(&self, px: f64, py: f64) -> Vector3<f64> {
        let (f, r, u) = self.basis();
        let (t, aspect) = self.plane();
        let x = (2.0 * px / self.width as f64 - 1.0) * t * aspect;
        let y = (1.0 - 2.0 * py / self.height as f64) * t;
        (f + r * x + u * y).normalize()
    }

    /// The image point a world point projects to, if in front of the camera
    /// (it may fall outside the image).
    pub fn project(&self, p: &Vector3<f64>) -> Option<(f64, f64)> {
        let (f, r, u) = self.basis();
        let (t, aspect) = self.plane();
        let d = p - self.position;
        let z = d.dot(&f);
        if z <= 0.0 {
            return None;
        }
        let x = d.dot(&r) / z / (t * aspect);
        let y = d.dot(&u) / z / t;
        Some((
            (x + 1.0) * 0.5 * self.width as f64,
            (1.0 - y) * 0.5 * self.height as f64,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_and_project_are_inverse() {
        let cam = ViewCamera {
            position: Vector3::new(0.5, 0.5, 0.5),
            look: Vector3::new(1.0, 0.2, -0.1),
            up: Vector3::z(),
            vfov_rad: 1.2,
            width: 80,
            height: 60,
        };
        cam.validate("t").unwrap();
        for (px, py) in [(0.5, 0.5), (40.0, 30.0), (79.5, 12.25)] {
            let p = cam.position + cam.direction(px, py) * 2.5;
            let (x, y) = cam.project(&p).unwrap();
            assert!((x - px).abs() < 1e-9 && (y - py).abs() < 1e-9, "{x} {y}");
        }
        // The image centre looks along `look`.
        assert!((cam.direction(40.0, 30.0) - cam.look.normalize()).norm() < 1e-12);
        let bad = ViewCamera { up: cam.look, ..cam };
        assert!(matches!(bad.validate("t"), Err(IgiError::Camera { field: "up", .. })));
    }
}
