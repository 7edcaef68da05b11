//! The pinhole camera with radial distortion: a ray at ideal normalized
//! radius r (distance from the axis over the focal length) is imaged at
//! `r (1 + k1 r² + k2 r⁴)`, the model of the station's configuration.

/// Intrinsics of one camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pinhole {
    /// Focal length, pixels.
    pub focal_px: f64,
    /// Principal point, pixels (pixel centres at half-integers).
    pub principal_px: (f64, f64),
    /// Radial distortion coefficients.
    pub k1: f64,
    /// Radial distortion coefficients.
    pub k2: f64,
}

impl Pinhole {
    /// The pinhole of a configured camera at its configured resolution.
    pub fn of_camera(camera: &campanile_config::Camera) -> Pinhole {
        let (w, h) = (camera.resolution.width, camera.resolution.height);
        let i = &camera.intrinsics;
        Pinhole {
            focal_px: i.focal.pixels(w),
            principal_px: i.principal_point_px.unwrap_or((f64::from(w) / 2.0, f64::from(h) / 2.0)),
            k1: i.distortion.0,
            k2: i.distortion.1,
        }
    }

    /// This pinhole, given for `from` = (width, height), rescaled to a frame
    /// of `width` × `height`: focal length and principal point scale.
    pub fn rescaled(&self, from: (usize, usize), width: usize, height: usize) -> Pinhole {
        let sx = width as f64 / from.0 as f64;
        let sy = height as f64 / from.1 as f64;
        Pinhole {
            focal_px: self.focal_px * sx,
            principal_px: (self.principal_px.0 * sx, self.principal_px.1 * sy),
            ..*self
        }
    }

    /// The pixel `(u, v)` a camera-frame direction projects to, or `None`
    /// behind the camera.
    pub fn project(&self, d: [f64; 3]) -> Option<(f64, f64)> {
        if d[2] <= 0.0 {
            return None;
        }
        let (x, y) = (d[0] / d[2], d[1] / d[2]);
        let r2 = x * x + y * y;
        let s = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        Some((
            self.principal_px.0 + self.focal_px * x * s,
            self.principal_px.1 + self.focal_px * y * s,
        ))
    }

    /// The unit camera-frame direction seen at pixel `(u, v)`, undoing the
    /// distortion by Newton's method on the radius (a handful of steps to
    /// machine precision for the moderate distortions of real lenses);
    /// `None` where the distortion folds over and no ray maps there.
    pub fn unproject(&self, u: f64, v: f64) -> Option<[f64; 3]> {
        let (xd, yd) = (
            (u - self.principal_px.0) / self.focal_px,
            (v - self.principal_px.1) / self.focal_px,
        );
        let rd = (xd * xd + yd * yd).sqrt();
        let mut r = rd;
        for _ in 0..30 {
            let r2 = r * r;
            let f = r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd;
            let df = 1.0 + 3.0 * self.k1 * r2 + 5.0 * self.k2 * r2 * r2;
            if df <= 0.0 {
                return None;
            }
            let step = f / df;
            r -= step;
            if step.abs() < 1e-15 * (1.0 + r.abs()) {
                break;
            }
        }
        let r2 = r * r;
        if !r.is_finite() || (r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd).abs() > 1e-9 {
            return None;
        }
        let scale = if rd > 0.0 { r / rd } else { 1.0 };
        let (x, y) = (xd * scale, yd * scale);
        let n = (x * x + y * y + 1.0).sqrt();
        Some([x / n, y / n, 1.0 / n])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project_and_unproject_round_trip_to_a_millionth_of_a_pixel() {
        let cam = Pinhole {
            focal_px: 221.7,
            principal_px: (128.0, 96.0),
            k1: -0.05,
            k2: 0.01,
        };
        for v in (0..192).step_by(7) {
            for u in (0..256).step_by(9) {
                let (u, v) = (f64::from(u) + 0.5, f64::from(v) + 0.5);
                let d = cam.unproject(u, v).expect("inside the lens");
                let (pu, pv) = cam.project(d).expect("in front");
                assert!(
                    (pu - u).abs() < 1e-6 && (pv - v).abs() < 1e-6,
                    "({u}, {v}) → ({pu}, {pv})"
                );
                assert!(((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_principal_point_looks_down_the_axis_and_behind_is_none() {
        let cam = Pinhole {
            focal_px: 100.0,
            principal_px: (50.0, 40.0),
            k1: 0.1,
            k2: 0.0,
        };
        assert_eq!(cam.unproject(50.0, 40.0), Some([0.0, 0.0, 1.0]));
        assert_eq!(cam.project([0.0, 0.0, -1.0]), None);
        // Without distortion, 45° off axis lands one focal length out.
        let plain = Pinhole { k1: 0.0, ..cam };
        let (u, _) = plain.project([1.0, 0.0, 1.0]).expect("in front");
        assert!((u - 150.0).abs() < 1e-12);
    }
}
