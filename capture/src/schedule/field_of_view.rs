//! The camera's field of view as the tilings use it: the half-angles of the
//! largest rectangle in tangent space (`|x/z| ≤ tan h`, `|y/z| ≤ tan v`,
//! camera frame) whose every ray lands inside the image, radial distortion
//! included (thesis §3.2).

use campanile_config::camera::Camera;
use campanile_process::pose::Pinhole;

/// Points sampled along each image edge.
const EDGE_SAMPLES: usize = 33;

/// The largest half-angle a tiling takes, radians (80°): a fisheye whose
/// image reaches 90° off the axis and beyond covers a rectangle in tangent
/// space only this far.
pub const MAX_HALF_ANGLE_RAD: f64 = 80.0 * std::f64::consts::PI / 180.0;

/// Half-angles of the camera's usable field of view, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldOfView {
    /// Half the horizontal field of view.
    pub half_horizontal_rad: f64,
    /// Half the vertical field of view.
    pub half_vertical_rad: f64,
}

/// The configuration's camera model (projection and radial distortion).
pub fn pinhole(camera: &Camera) -> Pinhole {
    Pinhole::of_camera(camera)
}

impl FieldOfView {
    /// The field of view of `camera`: along each edge of the image, the
    /// smallest tangent of the undistorted ray, on either side of the
    /// principal point. When the distortion folds over inside the image the
    /// ideal pinhole's extent is used instead.
    pub fn of_camera(camera: &Camera) -> FieldOfView {
        let p = pinhole(camera);
        let (w, h) = (f64::from(camera.resolution.width), f64::from(camera.resolution.height));
        let along = |k: usize, len: f64| len * k as f64 / (EDGE_SAMPLES - 1) as f64;
        // The tangent of the ray's angle from the optical axis in the
        // plane of `axis` and the axis: infinite at or past 90° (a fisheye's
        // edge), where the rectangle is then capped below.
        let tangent = |u: f64, v: f64, axis: usize| {
            p.unproject(u, v).map(|d| {
                if d[2] > 0.0 {
                    (d[axis] / d[2]).abs()
                } else {
                    f64::INFINITY
                }
            })
        };
        let mut tx = Some(f64::INFINITY);
        let mut ty = Some(f64::INFINITY);
        for k in 0..EDGE_SAMPLES {
            for u in [0.0, w] {
                tx = tx.zip(tangent(u, along(k, h), 0)).map(|(a, b)| a.min(b));
            }
            for v in [0.0, h] {
                ty = ty.zip(tangent(along(k, w), v, 1)).map(|(a, b)| a.min(b));
            }
        }
        let (px, py) = p.principal_px;
        let ideal = |half: f64| {
            p.projection
                .angle(half / p.focal_px)
                .unwrap_or(MAX_HALF_ANGLE_RAD)
                .min(MAX_HALF_ANGLE_RAD)
                .tan()
        };
        let (ideal_x, ideal_y) = (ideal(px.min(w - px)), ideal(py.min(h - py)));
        let (tx, ty) = match (tx, ty) {
            (Some(x), Some(y)) if x.is_finite() || y.is_finite() => (x, y),
            _ => (ideal_x, ideal_y),
        };
        FieldOfView {
            half_horizontal_rad: tx.atan().min(MAX_HALF_ANGLE_RAD),
            half_vertical_rad: ty.atan().min(MAX_HALF_ANGLE_RAD),
        }
    }

    /// The field of view shrunk by a fractional `overlap` (in [0, 0.9]): tiles
    /// spaced to cover the region with this field of view overlap their
    /// neighbours by at least that fraction.
    pub fn shrunk(&self, overlap: f64) -> FieldOfView {
        let keep = 1.0 - overlap.clamp(0.0, 0.9);
        FieldOfView {
            half_horizontal_rad: self.half_horizontal_rad * keep,
            half_vertical_rad: self.half_vertical_rad * keep,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use campanile_config::camera::{CameraDriver, ExposureLimits, Focal, GainLimits, Intrinsics, Resolution};

    pub(crate) fn camera(hfov_deg: f64, width: u32, height: u32, distortion: (f64, f64)) -> Camera {
        Camera {
            driver: CameraDriver::Sim,
            device: None,
            resolution: Resolution { width, height },
            intrinsics: Intrinsics {
                focal: Focal::HorizontalFovDeg(hfov_deg),
                principal_point_px: None,
                projection: Default::default(),
                distortion,
                falloff: (0.0, 0.0),
            },
            bit_depth: 12,
            exposure: ExposureLimits {
                min_s: 1e-5,
                max_s: 30.0,
                steps: Default::default(),
            },
            gain: GainLimits {
                min_db: 0.0,
                max_db: 24.0,
            },
            response_curve: None,
            file_format: Default::default(),
        }
    }

    /// Without distortion, 60° across 256 × 192 px: half-angles 30° and
    /// atan(96 / 221.70) = 23.41°.
    #[test]
    fn an_ideal_pinhole_has_the_configured_field_of_view() {
        let fov = FieldOfView::of_camera(&camera(60.0, 256, 192, (0.0, 0.0)));
        assert!((fov.half_horizontal_rad.to_degrees() - 30.0).abs() < 1e-9);
        let want = (96.0 / (128.0 / 30f64.to_radians().tan())).atan().to_degrees();
        assert!((fov.half_vertical_rad.to_degrees() - want).abs() < 1e-9, "{want}");
    }

    /// Barrel distortion (k1 < 0) widens the view: the edge midpoint of a
    /// k1 = −0.05 lens at ideal tangent 0.577 sees a ray further out.
    #[test]
    fn barrel_distortion_widens_the_view() {
        let fov = FieldOfView::of_camera(&camera(60.0, 256, 192, (-0.05, 0.01)));
        assert!(fov.half_horizontal_rad.to_degrees() > 30.0);
        assert!(fov.half_horizontal_rad.to_degrees() < 31.5);
    }
}
