//! The station's camera model: a projection (the pinhole's central one, or
//! an equidistant or equisolid fisheye) with radial distortion. A ray θ
//! off the optical axis has the ideal normalized radius `r = ρ(θ)` of the
//! projection (`tan θ`, `θ`, `2 sin(θ/2)`; thesis §3.2 for the pinhole) and
//! is imaged at `r (1 + k1 r² + k2 r⁴)` focal lengths from the principal
//! point, the model of the station's configuration.

pub use campanile_config::camera::Projection;

/// Intrinsics of one camera (named for the default projection; a fisheye
/// is the same model with another [`Projection`]).
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
    /// How a ray's angle off the axis maps to its ideal radius.
    pub projection: Projection,
}

impl Pinhole {
    /// The camera model of a configured camera at its configured resolution.
    pub fn of_camera(camera: &campanile_config::Camera) -> Pinhole {
        let (w, h) = (camera.resolution.width, camera.resolution.height);
        let i = &camera.intrinsics;
        Pinhole {
            focal_px: i.focal.pixels_for(i.projection, w),
            principal_px: i.principal_point_px.unwrap_or((f64::from(w) / 2.0, f64::from(h) / 2.0)),
            k1: i.distortion.0,
            k2: i.distortion.1,
            projection: i.projection,
        }
    }

    /// An undistorted rectilinear camera of focal length `focal_px`, its
    /// principal point at the centre of a `width` × `height` frame: a
    /// photograph whose lens is known only by its focal length (a zoom
    /// photograph's EXIF).
    pub fn centred(focal_px: f64, width: usize, height: usize) -> Pinhole {
        Pinhole {
            focal_px,
            principal_px: (width as f64 / 2.0, height as f64 / 2.0),
            k1: 0.0,
            k2: 0.0,
            projection: Projection::Pinhole,
        }
    }

    /// This camera, given for `from` = (width, height), rescaled to a frame
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

    /// The distorted radius of ideal radius `r`: `r (1 + k1 r² + k2 r⁴)`.
    fn distorted(&self, r: f64) -> f64 {
        let r2 = r * r;
        r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2)
    }

    /// Whether the distorted radius still grows at every ideal radius up
    /// to `r` (the image does not fold over before it).
    fn grows_to(&self, r: f64) -> bool {
        campanile_config::camera::fold_radius((self.k1, self.k2), r).is_none()
    }

    /// The pixel `(u, v)` a camera-frame direction projects to, or `None`
    /// where no pixel sees it: behind a pinhole (z ≤ 0), past a fisheye's
    /// projection (equisolid at 180°) or where its radial terms fold over.
    pub fn project(&self, d: [f64; 3]) -> Option<(f64, f64)> {
        if self.projection.is_pinhole() {
            if d[2] <= 0.0 {
                return None;
            }
            let (x, y) = (d[0] / d[2], d[1] / d[2]);
            let r2 = x * x + y * y;
            let s = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
            return Some((
                self.principal_px.0 + self.focal_px * x * s,
                self.principal_px.1 + self.focal_px * y * s,
            ));
        }
        let lateral = d[0].hypot(d[1]);
        let theta = lateral.atan2(d[2]);
        if !theta.is_finite() || theta >= std::f64::consts::PI {
            return None;
        }
        let r = self.projection.radius(theta);
        if !self.grows_to(r) {
            return None;
        }
        let rd = self.distorted(r);
        let (cx, cy) = if lateral > 0.0 {
            (d[0] / lateral, d[1] / lateral)
        } else {
            (0.0, 0.0)
        };
        Some((
            self.principal_px.0 + self.focal_px * rd * cx,
            self.principal_px.1 + self.focal_px * rd * cy,
        ))
    }

    /// The unit camera-frame direction seen at pixel `(u, v)`, undoing the
    /// distortion by Newton's method on the radius (a handful of steps to
    /// machine precision for the moderate distortions of real lenses);
    /// `None` where the distortion folds over and no ray maps there, or
    /// past a fisheye's projection.
    pub fn unproject(&self, u: f64, v: f64) -> Option<[f64; 3]> {
        let (xd, yd) = (
            (u - self.principal_px.0) / self.focal_px,
            (v - self.principal_px.1) / self.focal_px,
        );
        let rd = (xd * xd + yd * yd).sqrt();
        let mut r = rd;
        for _ in 0..50 {
            let r2 = r * r;
            let f = self.distorted(r) - rd;
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
        if !r.is_finite() || r < 0.0 || (self.distorted(r) - rd).abs() > 1e-9 * (1.0 + rd) {
            return None;
        }
        let scale = if rd > 0.0 { r / rd } else { 1.0 };
        let (x, y) = (xd * scale, yd * scale);
        if self.projection.is_pinhole() {
            let n = (x * x + y * y + 1.0).sqrt();
            return Some([x / n, y / n, 1.0 / n]);
        }
        if !self.grows_to(r) {
            return None;
        }
        let theta = self.projection.angle(r)?;
        let (s, c) = theta.sin_cos();
        let (cx, cy) = if r > 0.0 { (x / r, y / r) } else { (0.0, 0.0) };
        Some([s * cx, s * cy, c])
    }

    /// The largest angle, radians, one pixel spans anywhere within
    /// `theta_max` of the axis (radially or around it), for margins
    /// around a point of the image: `1 / (f · min(dr/dθ, r/sin θ))`.
    pub fn max_pixel_angle_rad(&self, theta_max: f64) -> f64 {
        const STEPS: usize = 64;
        let top = theta_max.clamp(0.0, if self.projection.is_pinhole() { 1.5 } else { 3.1 });
        let mut smallest = f64::INFINITY;
        for k in 0..=STEPS {
            let t = top * k as f64 / STEPS as f64;
            let h = 1e-6;
            let (a, b) = (self.projection.radius(t), self.projection.radius(t + h));
            let radial = (self.distorted(b) - self.distorted(a)) / h;
            let tangential = if t > 1e-9 { self.distorted(a) / t.sin() } else { radial };
            smallest = smallest.min(radial).min(tangential);
        }
        if smallest > 0.0 && smallest.is_finite() {
            1.0 / (self.focal_px * smallest)
        } else {
            1.0 / self.focal_px
        }
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
            projection: Projection::Pinhole,
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
            projection: Projection::Pinhole,
        };
        assert_eq!(cam.unproject(50.0, 40.0), Some([0.0, 0.0, 1.0]));
        assert_eq!(cam.project([0.0, 0.0, -1.0]), None);
        // Without distortion, 45° off axis lands one focal length out.
        let plain = Pinhole { k1: 0.0, ..cam };
        let (u, _) = plain.project([1.0, 0.0, 1.0]).expect("in front");
        assert!((u - 150.0).abs() < 1e-12);
    }

    /// Fisheyes: every pixel of a 1024 × 1024 image out to 95° off the
    /// axis unprojects to a ray that projects back within 1e-9 px, and
    /// every direction out to 95° (90° exactly included) projects to a
    /// pixel that unprojects to it within 1e-9 rad; the ideal radius is
    /// θ (equidistant) or 2 sin(θ/2) (equisolid).
    #[test]
    fn fisheyes_round_trip_over_the_whole_field_including_90_degrees_off_axis() {
        for projection in [Projection::Equidistant, Projection::Equisolid] {
            for (k1, k2) in [(0.0, 0.0), (-0.02, 0.001), (0.03, -0.004)] {
                let cam = Pinhole {
                    focal_px: 300.0,
                    principal_px: (512.3, 509.8),
                    k1,
                    k2,
                    projection,
                };
                let edge = cam.project([1.0, 0.0, (95f64).to_radians().cos() / (95f64).to_radians().sin()]);
                let (edge_u, _) = edge.expect("95° is imaged");
                let reach = edge_u - cam.principal_px.0;
                for v in (0..1024).step_by(13) {
                    for u in (0..1024).step_by(11) {
                        let (u, v) = (f64::from(u) + 0.5, f64::from(v) + 0.5);
                        if (u - cam.principal_px.0).hypot(v - cam.principal_px.1) > reach {
                            continue;
                        }
                        let d = cam.unproject(u, v).expect("inside the image circle");
                        let (pu, pv) = cam.project(d).expect("imaged");
                        assert!(
                            (pu - u).abs() < 1e-9 && (pv - v).abs() < 1e-9,
                            "{projection:?} ({u}, {v}) → ({pu}, {pv})"
                        );
                        assert!(((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - 1.0).abs() < 1e-12);
                    }
                }
                for i in 0..=95 {
                    for j in 0..24 {
                        let theta = f64::from(i).to_radians();
                        let phi = f64::from(j) * std::f64::consts::TAU / 24.0;
                        let d = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
                        let (u, v) = cam.project(d).expect("imaged");
                        let back = cam.unproject(u, v).expect("a ray");
                        let err = (0..3).map(|k| (back[k] - d[k]).powi(2)).sum::<f64>().sqrt();
                        assert!(err < 1e-9, "{projection:?} θ {i}° φ {j}: {err:e}");
                    }
                }
                // The ideal radius at 90° off the axis, without radial terms.
                if k1 == 0.0 {
                    let (u, _) = cam.project([1.0, 0.0, 0.0]).expect("90° is imaged");
                    let want = match projection {
                        Projection::Equidistant => std::f64::consts::FRAC_PI_2,
                        _ => 2.0 * (std::f64::consts::FRAC_PI_4).sin(),
                    };
                    assert!(((u - cam.principal_px.0) / 300.0 - want).abs() < 1e-12);
                }
            }
        }
    }

    /// A fisheye whose radial terms fold the image over has no pixel for
    /// rays past the fold, and the ray straight behind has none.
    #[test]
    fn a_fisheye_refuses_rays_past_a_fold_and_behind_it() {
        let cam = Pinhole {
            focal_px: 100.0,
            principal_px: (100.0, 100.0),
            k1: -0.3,
            k2: 0.0,
            projection: Projection::Equidistant,
        };
        // 1 − 0.9 θ² = 0 at θ = 1.054 rad (60.4°).
        assert!(
            cam.project([(55f64).to_radians().sin(), 0.0, (55f64).to_radians().cos()])
                .is_some()
        );
        assert!(
            cam.project([(65f64).to_radians().sin(), 0.0, (65f64).to_radians().cos()])
                .is_none()
        );
        let equisolid = Pinhole {
            k1: 0.0,
            projection: Projection::Equisolid,
            ..cam
        };
        assert!(equisolid.project([0.0, 0.0, -1.0]).is_none());
        assert!(equisolid.unproject(100.0 + 250.0, 100.0).is_none(), "ρ = 2.5 > 2");
    }
}
