//! An undistorted pinhole photograph's geometry: where a world point lands
//! in the image and the ray through an image point.
//!
//! Camera axes: x right, y down (rows), z forward. Pixel `(x, y)` covers
//! `[x, x+1) × [y, y+1)`; its centre is `(x + 0.5, y + 0.5)`.

use nalgebra::{Matrix3, Vector3};

use super::VisibilityError;
use crate::render::Ray;

/// Points nearer than this to the camera plane (metres) are not projected.
pub const NEAR_M: f64 = 1e-3;

/// A pinhole view.
#[derive(Debug, Clone, PartialEq)]
pub struct PinholeView {
    /// A name for diagnostics.
    pub name: String,
    /// Centre of projection, world frame, metres.
    pub position: Vector3<f64>,
    /// World → camera rotation (rows: right, down, forward).
    pub rotation: Matrix3<f64>,
    /// Focal length, pixels.
    pub focal_px: f64,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
}

impl PinholeView {
    /// A view at `position` looking along `look` with `up` upward in the
    /// image, vertical field of view `vfov_rad`, `width × height` pixels.
    pub fn look_at(
        name: &str,
        position: Vector3<f64>,
        look: Vector3<f64>,
        up: Vector3<f64>,
        vfov_rad: f64,
        width: usize,
        height: usize,
    ) -> Result<PinholeView, VisibilityError> {
        let bad = |field: &'static str, value: String, expected: &'static str| VisibilityError::BadView {
            view: name.to_string(),
            field,
            value,
            expected,
        };
        if !position.iter().all(|c| c.is_finite()) {
            return Err(bad("position", format!("{position:?}"), "finite coordinates"));
        }
        let f = look.try_normalize(1e-12).filter(|v| v.iter().all(|c| c.is_finite()));
        let f = f.ok_or_else(|| bad("look", format!("{look:?}"), "a finite non-zero direction"))?;
        let r = f
            .cross(&up)
            .try_normalize(1e-9)
            .ok_or_else(|| bad("up", format!("{up:?}"), "a direction not parallel to look"))?;
        if !(vfov_rad.is_finite() && vfov_rad > 0.0 && vfov_rad < std::f64::consts::PI) {
            return Err(bad("vfov", format!("{vfov_rad} rad"), "an angle in (0, π)"));
        }
        if width == 0 || height == 0 {
            return Err(bad("resolution", format!("{width}×{height}"), "at least 1×1 pixels"));
        }
        let d = f.cross(&r); // down = forward × right
        let rotation = Matrix3::from_rows(&[r.transpose(), d.transpose(), f.transpose()]);
        let focal_px = height as f64 / 2.0 / (vfov_rad / 2.0).tan();
        Ok(PinholeView {
            name: name.to_string(),
            position,
            rotation,
            focal_px,
            width,
            height,
        })
    }

    /// Camera coordinates of world point `p`.
    pub fn camera(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * (p - self.position)
    }

    /// The image point of world point `p`, if it is in front of the near plane.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let c = self.camera(p);
        (c.z >= NEAR_M).then(|| {
            [
                self.focal_px * c.x / c.z + self.width as f64 / 2.0,
                self.focal_px * c.y / c.z + self.height as f64 / 2.0,
            ]
        })
    }

    /// The unit ray from the centre of projection through image point `(x, y)`.
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        let c = Vector3::new(
            (x - self.width as f64 / 2.0) / self.focal_px,
            (y - self.height as f64 / 2.0) / self.focal_px,
            1.0,
        );
        Ray {
            origin: self.position,
            direction: (self.rotation.transpose() * c).normalize(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projects_and_casts_back() {
        let v = PinholeView::look_at(
            "t",
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::z(),
            60f64.to_radians(),
            64,
            48,
        )
        .unwrap();
        let p = Vector3::new(2.0, 12.0, 4.0);
        let [x, y] = v.project(&p).unwrap();
        // 1 m right and 1 m up at 10 m: focal 24/tan 30° = 41.57 px.
        assert!((x - (32.0 + 4.1569219)).abs() < 1e-6 && (y - (24.0 - 4.1569219)).abs() < 1e-6);
        let r = v.ray(x, y);
        let back = r.origin + r.direction * (p - r.origin).norm();
        assert!((back - p).norm() < 1e-9);
        assert!(v.project(&Vector3::new(1.0, 1.0, 3.0)).is_none());
        let err = PinholeView::look_at("w", p, Vector3::z(), Vector3::z(), 1.0, 4, 4).unwrap_err();
        assert!(err.to_string().contains("up"), "{err}");
    }
}
