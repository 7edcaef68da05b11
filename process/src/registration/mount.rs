//! The head's mount calibration from registered photographs (thesis §3.3,
//! used as the issue asks: a station calibrating its mount from targets).
//!
//! A photograph taken from the head at reading (pan, tilt) and registered
//! from targets gives the camera's world orientation `R` and centre `C`.
//! The mount ([`Mount`]: the azimuth at pan 0, the tilt reading at the
//! horizon, the base's roll and pitch) predicts the orientation
//! `R̂(pan, tilt)` the same way every other part of Campanile does
//! ([`Mount::to_world`]). Here the four mount angles are fitted to all the
//! registered orientations at once, by Levenberg–Marquardt on the rotation
//! vectors of `R R̂ᵀ` (each view weighted by its registration's stated
//! angle uncertainty), and the head's place is the weighted mean of the
//! registered centres (the camera is taken to turn about its centre of
//! projection, as [`crate::pose`] does).
//!
//! One view fixes three angles of four, and views at a single pan cannot
//! tell the base's tilt from the tilt zero: the covariance says so and the
//! verdict is `failed` (singular) or `poor` (uncertain), never a silently
//! wrong mount.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DVector, Dyn, Matrix3, Matrix4, OMatrix, Owned, Rotation3, U4, Vector3, Vector4};

use super::camera_pose::CameraPose;
use super::verdict::Verdict;
use crate::pose::{HeadPose, Mount};

/// One registered photograph taken from the head.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadView {
    /// The head's reading when the photograph was taken.
    pub head: HeadPose,
    /// The registered world pose.
    pub pose: CameraPose,
    /// The registration's one-sigma orientation uncertainty, radians (its
    /// largest axis); views are weighted by its inverse square.
    pub sigma_angle_rad: f64,
    /// The registration's one-sigma position uncertainty, metres (its
    /// largest axis).
    pub sigma_position_m: f64,
}

/// What a fitted mount must meet to be `ok`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MountLimits {
    /// Largest one-sigma uncertainty of any of the four mount angles, degrees.
    pub max_sigma_angle_deg: f64,
    /// Largest orientation residual of any view, degrees: a view the mount
    /// does not explain (a wrong head reading, a registration gone wrong,
    /// a head that slipped).
    pub max_residual_deg: f64,
    /// Largest distance of a view's registered centre from the head's
    /// fitted place, metres (the camera's offset from the head's axes, or
    /// a tripod moved between photographs).
    pub max_centre_spread_m: f64,
}

impl Default for MountLimits {
    /// The registration's own goals: 0.05° on angles (so one sigma 0.025°),
    /// a residual of 0.1° (four times the registration's σ limit) and 2 cm
    /// of centre spread (a camera mounted off its head's axes by more
    /// moves the views more than that).
    fn default() -> Self {
        MountLimits {
            max_sigma_angle_deg: 0.025,
            max_residual_deg: 0.1,
            max_centre_spread_m: 0.02,
        }
    }
}

/// A fitted mount and how well it explains the views.
#[derive(Debug, Clone, PartialEq)]
pub struct MountFit {
    /// The mount.
    pub mount: Mount,
    /// The head's place, world frame, metres: the registered centres'
    /// weighted mean.
    pub position: Vector3<f64>,
    /// Each view's orientation residual (the angle of `R R̂ᵀ`), degrees, in input order.
    pub residuals_deg: Vec<f64>,
    /// Each view's centre's distance from [`MountFit::position`], metres.
    pub centre_offsets_m: Vec<f64>,
    /// One-sigma uncertainty of (pan zero azimuth, tilt zero, roll,
    /// pitch), degrees; `None` when the views do not fix all four.
    pub sigma_deg: Option<[f64; 4]>,
    /// The verdict.
    pub verdict: Verdict,
    /// Why the verdict is not `ok`.
    pub reasons: Vec<String>,
}

/// Why no mount could be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MountFitError {
    /// No views.
    #[error("no registered views: a mount needs at least two, at different pans")]
    NoViews,
    /// A view's figures are not finite or its uncertainty not positive.
    #[error("view {index}: {what}")]
    BadView {
        /// The view's index.
        index: usize,
        /// What is wrong.
        what: String,
    },
}

/// The rotation `R̂` (world to camera, rows the camera's axes) that `mount`
/// predicts at `head`.
fn predicted(mount: &Mount, head: HeadPose) -> Rotation3<f64> {
    let at = mount.at(head);
    let axis = |d: [f64; 3]| Vector3::from(at.to_world(d));
    let m = Matrix3::from_rows(&[
        axis([1.0, 0.0, 0.0]).transpose(),
        axis([0.0, 1.0, 0.0]).transpose(),
        axis([0.0, 0.0, 1.0]).transpose(),
    ]);
    // Orthonormal by construction (rotations of the unit axes).
    Rotation3::from_matrix_unchecked(m)
}

/// The rotation vector of `R R̂ᵀ`, radians (world axes), from its skew and
/// trace parts through atan2: exact near the identity, where an angle
/// from the trace alone (acos) loses precision or leaves its domain.
fn rotation_error(view: &HeadView, mount: &Mount) -> Vector3<f64> {
    let m = (view.pose.rotation.inverse() * predicted(mount, view.head)).into_inner();
    let v = 0.5 * Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]);
    let sin = v.norm();
    let angle = sin.atan2(0.5 * (m.trace() - 1.0));
    if sin < 1e-300 {
        return Vector3::zeros();
    }
    v * (angle / sin)
}

fn mount_of(p: &Vector4<f64>) -> Mount {
    Mount {
        pan_zero_azimuth_rad: p[0],
        tilt_zero_rad: p[1],
        roll_rad: p[2],
        pitch_rad: p[3],
    }
}

struct Problem<'a> {
    views: &'a [HeadView],
    params: Vector4<f64>,
}

impl Problem<'_> {
    fn residual_at(&self, p: &Vector4<f64>) -> DVector<f64> {
        let mount = mount_of(p);
        let mut r = DVector::zeros(3 * self.views.len());
        for (i, v) in self.views.iter().enumerate() {
            let e = rotation_error(v, &mount) / v.sigma_angle_rad;
            r.fixed_rows_mut::<3>(3 * i).copy_from(&e);
        }
        r
    }
}

impl LeastSquaresProblem<f64, Dyn, U4> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U4>;
    type ParameterStorage = Owned<f64, U4>;

    fn set_params(&mut self, p: &Vector4<f64>) {
        self.params = *p;
    }

    fn params(&self) -> Vector4<f64> {
        self.params
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.residual_at(&self.params);
        r.iter().all(|x| x.is_finite()).then_some(r)
    }

    /// Central differences, steps of 1e-7 rad: the residuals are smooth
    /// rotations, and four parameters make this cheap.
    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U4>> {
        let h = 1e-7;
        let mut j = OMatrix::<f64, Dyn, U4>::zeros(3 * self.views.len());
        for k in 0..4 {
            let (mut a, mut b) = (self.params, self.params);
            a[k] += h;
            b[k] -= h;
            let d = (self.residual_at(&a) - self.residual_at(&b)) / (2.0 * h);
            j.set_column(k, &d);
        }
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

/// The starting mount from the first view: its pan and tilt zero, a level base.
fn start(view: &HeadView) -> Vector4<f64> {
    let az = view.pose.azimuth_deg().to_radians();
    let el = view.pose.elevation_deg().to_radians();
    Vector4::new(az - view.head.pan_rad, view.head.tilt_rad - el, 0.0, 0.0)
}

/// Fits the mount to registered views taken from the head, and judges it
/// against `limits`.
pub fn fit_mount(views: &[HeadView], limits: &MountLimits) -> Result<MountFit, MountFitError> {
    if views.is_empty() {
        return Err(MountFitError::NoViews);
    }
    for (index, v) in views.iter().enumerate() {
        let finite = v.head.pan_rad.is_finite()
            && v.head.tilt_rad.is_finite()
            && v.pose.centre.iter().all(|x| x.is_finite())
            && v.pose.rotation.matrix().iter().all(|x| x.is_finite());
        if !finite {
            return Err(MountFitError::BadView {
                index,
                what: "a head reading or registered pose that is not finite".into(),
            });
        }
        if !(v.sigma_angle_rad.is_finite() && v.sigma_angle_rad > 0.0) {
            return Err(MountFitError::BadView {
                index,
                what: format!(
                    "angle uncertainty {} rad: expected a positive number",
                    v.sigma_angle_rad
                ),
            });
        }
        if !(v.sigma_position_m.is_finite() && v.sigma_position_m > 0.0) {
            return Err(MountFitError::BadView {
                index,
                what: format!(
                    "position uncertainty {} m: expected a positive number",
                    v.sigma_position_m
                ),
            });
        }
    }

    let problem = Problem {
        views,
        params: start(&views[0]),
    };
    let (problem, _report) = LevenbergMarquardt::new().with_patience(200).minimize(problem);
    let mut p = problem.params;
    p[0] = p[0].rem_euclid(std::f64::consts::TAU);
    let mount = mount_of(&p);

    // Position: inverse-variance weighted mean of the centres.
    let weights: Vec<f64> = views.iter().map(|v| v.sigma_position_m.powi(-2)).collect();
    let total: f64 = weights.iter().sum();
    let position = views
        .iter()
        .zip(&weights)
        .fold(Vector3::zeros(), |acc, (v, w)| acc + v.pose.centre * *w)
        / total;
    let residuals_deg: Vec<f64> = views
        .iter()
        .map(|v| rotation_error(v, &mount).norm().to_degrees())
        .collect();
    let centre_offsets_m: Vec<f64> = views.iter().map(|v| (v.pose.centre - position).norm()).collect();

    // Covariance (JᵀJ)⁻¹ in the weighted residuals: the registrations'
    // stated uncertainties propagated, scaled up by the fit's own residual
    // when the views disagree by more than they say.
    let j = problem.jacobian();
    let normal = j.as_ref().map(|j| j.transpose() * j);
    let dof = (3 * views.len()).saturating_sub(4);
    let chi2 = problem.residual_at(&p).norm_squared();
    let scale = if dof > 0 { (chi2 / dof as f64).max(1.0) } else { 1.0 };
    let covariance: Option<Matrix4<f64>> = normal.and_then(|n| {
        // Singular when a direction of the four angles moves no residual:
        // judged on the smallest eigenvalue against the largest (a ratio
        // of 1e-6 makes that direction's σ a thousand times the best
        // one's; the central differences' own error is near 1e-10).
        let eig = n.symmetric_eigen().eigenvalues;
        let (lo, hi) = (eig.min(), eig.max());
        (hi > 0.0 && lo > 1e-6 * hi)
            .then(|| n.try_inverse())
            .flatten()
            .map(|c| c * scale)
    });
    let sigma_deg = covariance.map(|c| [0, 1, 2, 3].map(|i| c[(i, i)].max(0.0).sqrt().to_degrees()));

    let mut reasons = Vec::new();
    let mut verdict = Verdict::Ok;
    match sigma_deg {
        None => {
            verdict = Verdict::Failed;
            let pans = views
                .iter()
                .map(|v| v.head.pan_rad)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            reasons.push(format!(
                "{} view(s) spanning {:.1}° of pan do not fix the four mount angles (the base's tilt and the tilt zero need views at two or more pans)",
                views.len(),
                (pans.1 - pans.0).to_degrees()
            ));
        }
        Some(s) => {
            let worst = s.iter().copied().fold(0.0, f64::max);
            if worst > limits.max_sigma_angle_deg {
                verdict = Verdict::Poor;
                reasons.push(format!(
                    "a mount angle is uncertain to {worst:.4}° (one sigma; limit {}°): spread the views over more pan and tilt",
                    limits.max_sigma_angle_deg
                ));
            }
        }
    }
    let worst_residual = residuals_deg.iter().copied().fold(0.0, f64::max);
    if worst_residual > limits.max_residual_deg {
        if verdict == Verdict::Ok {
            verdict = Verdict::Poor;
        }
        let i = residuals_deg.iter().position(|&r| r == worst_residual).unwrap_or(0);
        reasons.push(format!(
            "view {i} is {worst_residual:.3}° from what the mount predicts (limit {}°): a wrong head reading, a slipped head or a wrong registration",
            limits.max_residual_deg
        ));
    }
    let worst_offset = centre_offsets_m.iter().copied().fold(0.0, f64::max);
    if worst_offset > limits.max_centre_spread_m {
        if verdict == Verdict::Ok {
            verdict = Verdict::Poor;
        }
        reasons.push(format!(
            "the registered centres spread {:.1} mm from the head's place (limit {:.1} mm): the tripod moved, or the camera sits off the head's axes",
            1e3 * worst_offset,
            1e3 * limits.max_centre_spread_m
        ));
    }
    Ok(MountFit {
        mount,
        position,
        residuals_deg,
        centre_offsets_m,
        sigma_deg,
        verdict,
        reasons,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registered pose a view from `mount` at `head` would have.
    fn view(mount: &Mount, head: HeadPose, centre: Vector3<f64>) -> HeadView {
        HeadView {
            head,
            pose: CameraPose {
                rotation: predicted(mount, head),
                centre,
            },
            sigma_angle_rad: 0.01f64.to_radians(),
            sigma_position_m: 0.002,
        }
    }

    fn truth() -> Mount {
        Mount {
            pan_zero_azimuth_rad: 217.3f64.to_radians(),
            tilt_zero_rad: (-1.7f64).to_radians(),
            roll_rad: 0.8f64.to_radians(),
            pitch_rad: (-0.45f64).to_radians(),
        }
    }

    fn heads(pairs: &[(f64, f64)]) -> Vec<HeadPose> {
        pairs
            .iter()
            .map(|&(p, t)| HeadPose {
                pan_rad: p.to_radians(),
                tilt_rad: t.to_radians(),
            })
            .collect()
    }

    #[test]
    fn views_at_three_pans_recover_the_mount_exactly() {
        let m = truth();
        let c = Vector3::new(3.0, -4.0, 1.5);
        let views: Vec<_> = heads(&[(0.0, 5.0), (60.0, 20.0), (-75.0, 10.0), (140.0, 0.0)])
            .into_iter()
            .map(|h| view(&m, h, c))
            .collect();
        let fit = fit_mount(&views, &MountLimits::default()).unwrap();
        let d = |a: f64, b: f64| (a - b).to_degrees().abs();
        assert!(d(fit.mount.pan_zero_azimuth_rad, m.pan_zero_azimuth_rad) < 1e-6);
        assert!(d(fit.mount.tilt_zero_rad, m.tilt_zero_rad) < 1e-6);
        assert!(d(fit.mount.roll_rad, m.roll_rad) < 1e-6);
        assert!(d(fit.mount.pitch_rad, m.pitch_rad) < 1e-6);
        assert!((fit.position - c).norm() < 1e-12);
        assert_eq!(fit.verdict, Verdict::Ok, "{:?}", fit.reasons);
    }

    /// Registration noise of 0.01° per view (its stated σ): the mount is
    /// within three of its own stated sigmas.
    #[test]
    fn noisy_views_land_within_their_stated_uncertainty() {
        let m = truth();
        let c = Vector3::new(0.0, 0.0, 1.2);
        let hs = heads(&[
            (-120.0, 0.0),
            (-60.0, 15.0),
            (0.0, 30.0),
            (60.0, 5.0),
            (120.0, 20.0),
            (180.0, 10.0),
        ]);
        // A fixed, irrational-step sequence of perturbations (no RNG needed).
        let views: Vec<_> = hs
            .into_iter()
            .enumerate()
            .map(|(i, h)| {
                let mut v = view(&m, h, c);
                let k = i as f64;
                let w =
                    Vector3::new((1.3 * k).sin(), (2.7 * k + 0.4).cos(), (0.9 * k + 1.1).sin()) * 0.01f64.to_radians();
                v.pose.rotation = Rotation3::new(w) * v.pose.rotation;
                v
            })
            .collect();
        let fit = fit_mount(&views, &MountLimits::default()).unwrap();
        let s = fit.sigma_deg.expect("six views at six pans fix the mount");
        let errors = [
            fit.mount.pan_zero_azimuth_rad - m.pan_zero_azimuth_rad,
            fit.mount.tilt_zero_rad - m.tilt_zero_rad,
            fit.mount.roll_rad - m.roll_rad,
            fit.mount.pitch_rad - m.pitch_rad,
        ]
        .map(|e| e.to_degrees().abs());
        for k in 0..4 {
            assert!(
                errors[k] < 3.0 * s[k],
                "angle {k}: error {}° against σ {}°",
                errors[k],
                s[k]
            );
            assert!(errors[k] < 0.02, "angle {k}: error {}°", errors[k]);
        }
        assert_eq!(fit.verdict, Verdict::Ok, "{:?}", fit.reasons);
    }

    #[test]
    fn one_pan_cannot_separate_the_base_from_the_tilt_zero() {
        let m = truth();
        let views = vec![view(&m, heads(&[(30.0, 10.0)])[0], Vector3::zeros())];
        let fit = fit_mount(&views, &MountLimits::default()).unwrap();
        assert_eq!(fit.verdict, Verdict::Failed);
        assert!(fit.sigma_deg.is_none());
        assert!(fit.reasons[0].contains("do not fix"), "{:?}", fit.reasons);
        assert!(fit.mount.roll_rad.is_finite() && fit.mount.tilt_zero_rad.is_finite());
    }

    #[test]
    fn a_view_with_a_wrong_head_reading_is_named() {
        let m = truth();
        let c = Vector3::zeros();
        let hs = heads(&[(0.0, 5.0), (90.0, 10.0), (180.0, 15.0), (270.0, 20.0)]);
        let mut views: Vec<_> = hs.iter().map(|&h| view(&m, h, c)).collect();
        // The journal says pan 90°, the head was at 90.5°.
        views[1] = view(
            &m,
            HeadPose {
                pan_rad: 90.5f64.to_radians(),
                tilt_rad: 10f64.to_radians(),
            },
            c,
        );
        views[1].head = hs[1];
        let fit = fit_mount(&views, &MountLimits::default()).unwrap();
        assert_eq!(fit.verdict, Verdict::Poor, "{:?}", fit.reasons);
        assert!(
            fit.reasons.iter().any(|r| r.starts_with("view 1 ")),
            "{:?}",
            fit.reasons
        );
    }

    #[test]
    fn a_moved_tripod_is_flagged_and_bad_input_refused() {
        let m = truth();
        let hs = heads(&[(0.0, 5.0), (90.0, 10.0), (180.0, 15.0)]);
        let mut views: Vec<_> = hs.iter().map(|&h| view(&m, h, Vector3::zeros())).collect();
        views[2].pose.centre = Vector3::new(0.05, 0.0, 0.0);
        let fit = fit_mount(&views, &MountLimits::default()).unwrap();
        assert_eq!(fit.verdict, Verdict::Poor);
        assert!(
            fit.reasons.iter().any(|r| r.contains("tripod moved")),
            "{:?}",
            fit.reasons
        );

        assert_eq!(fit_mount(&[], &MountLimits::default()), Err(MountFitError::NoViews));
        let mut bad = views.clone();
        bad[1].sigma_angle_rad = 0.0;
        assert!(matches!(
            fit_mount(&bad, &MountLimits::default()),
            Err(MountFitError::BadView { index: 1, .. })
        ));
    }
}
