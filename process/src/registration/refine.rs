//! Levenberg–Marquardt refinement of all six pose parameters on the
//! reprojection error (thesis §3.3.3, there on the targets' centres; here
//! on every matched point), through the camera's radial distortion
//! ([`Pinhole`]: k1, k2), and the pose's covariance from the Jacobian.
//!
//! Parameters: a rotation vector ω applied on the left of the current
//! rotation, `R ← exp([ω]×) R`, and the centre of projection C, so the
//! covariance is directly that of the camera's orientation (radians about
//! the world axes) and position (metres).

use nalgebra::{Matrix6, Rotation3, SMatrix, Vector3, Vector6};

use super::camera_pose::CameraPose;
use super::correspondence::Correspondence;
use crate::pose::Pinhole;

/// A refined pose and how well it fits.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// The pose at the minimum.
    pub pose: CameraPose,
    /// Reprojection error of each point, pixels, in input order.
    pub errors_px: Vec<f64>,
    /// Root mean square reprojection error, pixels.
    pub rms_px: f64,
    /// The pixel noise the covariance assumes: the residuals' own
    /// estimate `√(SSR / (2n − 6))`, or the floor given, whichever is larger.
    pub sigma_px: f64,
    /// Covariance of (ωx, ωy, ωz, Cx, Cy, Cz): radians² about the world
    /// axes, metres², cross terms in radian·metres. `None` when the normal
    /// matrix is singular (the points do not fix the pose).
    pub covariance: Option<Matrix6<f64>>,
    /// Iterations taken.
    pub iterations: usize,
}

impl Refined {
    /// One-sigma uncertainty of the position along x, y, z, metres.
    pub fn sigma_position_m(&self) -> Option<[f64; 3]> {
        self.covariance.map(|c| [3, 4, 5].map(|i| c[(i, i)].max(0.0).sqrt()))
    }

    /// One-sigma uncertainty of the orientation about the world x, y and z
    /// axes, degrees.
    pub fn sigma_angle_deg(&self) -> Option<[f64; 3]> {
        self.covariance
            .map(|c| [0, 1, 2].map(|i| c[(i, i)].max(0.0).sqrt().to_degrees()))
    }
}

/// Why a refinement gave no pose.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefineError {
    /// Fewer than three points.
    #[error("{0} points cannot fix six pose parameters (at least 3 needed)")]
    TooFewPoints(usize),
    /// The starting pose puts a point behind the camera or outside the lens model.
    #[error("the starting pose does not image every point")]
    NotImaged,
}

/// The residual (u, v) of one point at `pose`, or `None` if not imaged.
fn residual(pinhole: &Pinhole, pose: &CameraPose, c: &Correspondence) -> Option<[f64; 2]> {
    let (u, v) = pose.project(pinhole, &Vector3::from(c.world))?;
    let r = [u - c.pixel.0, v - c.pixel.1];
    r.iter().all(|x| x.is_finite()).then_some(r)
}

/// The pose moved by parameters `d` = (ω, δC).
fn moved(pose: &CameraPose, d: &Vector6<f64>) -> CameraPose {
    CameraPose {
        rotation: Rotation3::new(Vector3::new(d[0], d[1], d[2])) * pose.rotation,
        centre: pose.centre + Vector3::new(d[3], d[4], d[5]),
    }
}

/// The 2 × 6 Jacobian of one point's residual, by central differences
/// (steps of 1e-7 rad and 1e-7 of the point's distance).
fn jacobian(pinhole: &Pinhole, pose: &CameraPose, c: &Correspondence) -> Option<SMatrix<f64, 2, 6>> {
    let range = (Vector3::from(c.world) - pose.centre).norm().max(1e-3);
    let mut j = SMatrix::<f64, 2, 6>::zeros();
    for k in 0..6 {
        let h = if k < 3 { 1e-7 } else { 1e-7 * range };
        let mut d = Vector6::zeros();
        d[k] = h;
        let plus = residual(pinhole, &moved(pose, &d), c)?;
        let minus = residual(pinhole, &moved(pose, &-d), c)?;
        j[(0, k)] = (plus[0] - minus[0]) / (2.0 * h);
        j[(1, k)] = (plus[1] - minus[1]) / (2.0 * h);
    }
    Some(j)
}

/// Sum of squared residuals at `pose`, or `None` if a point is not imaged.
fn cost(pinhole: &Pinhole, pose: &CameraPose, points: &[Correspondence]) -> Option<f64> {
    points
        .iter()
        .map(|c| residual(pinhole, pose, c).map(|r| r[0] * r[0] + r[1] * r[1]))
        .sum()
}

/// The normal equations `JᵀJ` and `Jᵀr` at `pose`.
fn normal_equations(
    pinhole: &Pinhole,
    pose: &CameraPose,
    points: &[Correspondence],
) -> Option<(Matrix6<f64>, Vector6<f64>)> {
    let mut jtj = Matrix6::zeros();
    let mut jtr = Vector6::zeros();
    for c in points {
        let r = residual(pinhole, pose, c)?;
        let j = jacobian(pinhole, pose, c)?;
        jtj += j.transpose() * j;
        jtr += j.transpose() * nalgebra::Vector2::new(r[0], r[1]);
    }
    Some((jtj, jtr))
}

/// Refines `start` to the least-squares pose over `points` (Levenberg–
/// Marquardt with Marquardt's diagonal scaling). `sigma_floor_px` is the
/// least pixel noise the covariance assumes (the detector's precision),
/// so that an exact fit of few points does not claim zero uncertainty.
pub fn refine(
    pinhole: &Pinhole,
    points: &[Correspondence],
    start: CameraPose,
    sigma_floor_px: f64,
) -> Result<Refined, RefineError> {
    if points.len() < 3 {
        return Err(RefineError::TooFewPoints(points.len()));
    }
    let mut pose = start;
    let mut current = cost(pinhole, &pose, points).ok_or(RefineError::NotImaged)?;
    let mut lambda = 1e-3;
    let mut iterations = 0;
    for _ in 0..100 {
        iterations += 1;
        let Some((jtj, jtr)) = normal_equations(pinhole, &pose, points) else {
            break;
        };
        let mut improved = false;
        while lambda < 1e12 {
            let mut a = jtj;
            for i in 0..6 {
                a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
            }
            let Some(step) = a.cholesky().map(|ch| ch.solve(&-jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let trial = moved(&pose, &step);
            match cost(pinhole, &trial, points) {
                Some(c) if c <= current => {
                    let converged = current - c <= 1e-12 * current.max(1e-30) || step.norm() < 1e-14;
                    pose = trial;
                    current = c;
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = !converged;
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved {
            break;
        }
    }
    let errors_px: Vec<f64> = points
        .iter()
        .map(|c| residual(pinhole, &pose, c).map_or(f64::INFINITY, |r| r[0].hypot(r[1])))
        .collect();
    let n = points.len();
    let rms_px = (current / n as f64).sqrt();
    let dof = 2 * n as i64 - 6;
    let estimate = if dof > 0 { (current / dof as f64).sqrt() } else { 0.0 };
    let sigma_px = estimate.max(sigma_floor_px);
    let covariance = normal_equations(pinhole, &pose, points)
        .and_then(|(jtj, _)| jtj.try_inverse())
        .map(|inv| inv * (sigma_px * sigma_px))
        .filter(|c| c.iter().all(|v| v.is_finite()) && (0..6).all(|i| c[(i, i)] >= 0.0));
    Ok(Refined {
        pose,
        errors_px,
        rms_px,
        sigma_px,
        covariance,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Pinhole {
        Pinhole {
            focal_px: 1000.0,
            principal_px: (640.0, 480.0),
            k1: -0.08,
            k2: 0.02,
            projection: campanile_config::camera::Projection::Pinhole,
        }
    }

    fn truth() -> CameraPose {
        CameraPose::from_axes(
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.2, -10.0, 1.5),
        )
    }

    fn grid(pose: &CameraPose) -> Vec<Correspondence> {
        let mut out = Vec::new();
        for (k, (x, z)) in [
            (-3.0, 0.5),
            (3.0, 0.5),
            (-2.0, 4.0),
            (2.5, 3.0),
            (0.0, 6.0),
            (-4.0, 2.0),
        ]
        .into_iter()
        .enumerate()
        {
            let w = [x, 0.3 * x, z];
            let (u, v) = pose.project(&camera(), &Vector3::from(w)).expect("in view");
            out.push(Correspondence {
                target: k as u32,
                pixel: (u, v),
                world: w,
            });
        }
        out
    }

    #[test]
    fn exact_points_bring_a_perturbed_start_back_to_the_truth() {
        let t = truth();
        let points = grid(&t);
        let start = moved(&t, &Vector6::new(0.02, -0.03, 0.01, 0.3, -0.4, 0.2));
        let r = refine(&camera(), &points, start, 0.1).expect("refines");
        assert!((r.pose.centre - t.centre).norm() < 1e-8, "{:?}", r.pose.centre);
        assert!(r.pose.angle_to_deg(&t) < 1e-8);
        assert!(r.rms_px < 1e-6);
        // The floor sets the noise an exact fit is given.
        assert_eq!(r.sigma_px, 0.1);
        let s = r.sigma_position_m().expect("covariance");
        assert!(s.iter().all(|v| *v > 0.0 && *v < 0.05), "{s:?}");
    }

    #[test]
    fn the_covariance_predicts_the_scatter_of_noisy_fits() {
        use rand::SeedableRng;
        let t = truth();
        let clean = grid(&t);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let sigma = 0.5;
        let trials = 300;
        let mut sq = [0.0; 6];
        let mut predicted = [0.0; 6];
        for _ in 0..trials {
            let noisy: Vec<Correspondence> = clean
                .iter()
                .map(|c| {
                    let (a, b) = crate::camera::sensor::standard_normal_pair(&mut rng);
                    Correspondence {
                        pixel: (c.pixel.0 + sigma * a, c.pixel.1 + sigma * b),
                        ..c.clone()
                    }
                })
                .collect();
            let r = refine(&camera(), &noisy, t, sigma).expect("refines");
            let dw = (r.pose.rotation * t.rotation.inverse()).scaled_axis();
            let dc = r.pose.centre - t.centre;
            let d = [dw.x, dw.y, dw.z, dc.x, dc.y, dc.z];
            // With the noise known, use it rather than the per-fit estimate.
            let cov = r.covariance.expect("covariance") * (sigma * sigma / (r.sigma_px * r.sigma_px));
            for i in 0..6 {
                sq[i] += d[i] * d[i];
                predicted[i] += cov[(i, i)];
            }
        }
        for i in 0..6 {
            let ratio = (sq[i] / predicted[i]).sqrt();
            // 300 trials: the sample standard deviation is within ±10% at 2σ.
            assert!((ratio - 1.0).abs() < 0.12, "parameter {i}: scatter/predicted {ratio}");
        }
    }

    #[test]
    fn too_few_points_is_an_error() {
        let t = truth();
        let points = grid(&t);
        assert_eq!(
            refine(&camera(), &points[..2], t, 0.1),
            Err(RefineError::TooFewPoints(2))
        );
    }
}
