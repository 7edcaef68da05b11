//! The whole chain: correspondences to a judged pose. Consensus over the
//! three-point solver finds the targets that agree, Levenberg–Marquardt
//! refines on all their points, the agreeing set is checked again at the
//! refined pose (up to three rounds), and the figures are judged.

use nalgebra::{Matrix3, Matrix6, Vector3};
use serde::{Deserialize, Serialize};

use super::camera_pose::CameraPose;
use super::consensus::{ConsensusSettings, agreeing, consensus};
use super::correspondence::{Correspondence, target_count};
use super::refine::refine;
use super::verdict::{Quality, QualityLimits};
use crate::pose::Pinhole;

/// How to register.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RegistrationSettings {
    /// A target agrees with a pose when each of its points reprojects
    /// within this many pixels.
    pub inlier_threshold_px: f64,
    /// Most consensus samples.
    pub max_samples: usize,
    /// Seed of the consensus sampling.
    pub seed: u64,
    /// The least pixel noise the covariance assumes (the detector's precision).
    pub sigma_floor_px: f64,
    /// The limits of an `ok` pose.
    pub limits: QualityLimits,
}

impl Default for RegistrationSettings {
    fn default() -> Self {
        let c = ConsensusSettings::default();
        RegistrationSettings {
            inlier_threshold_px: c.threshold_px,
            max_samples: c.max_samples,
            seed: c.seed,
            sigma_floor_px: 0.05,
            limits: QualityLimits::default(),
        }
    }
}

/// A registered photograph: the pose (none when `failed`), its covariance
/// and the judged figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// The pose, unless the verdict is `failed`.
    pub pose: Option<CameraPose>,
    /// Covariance of (ωx, ωy, ωz, Cx, Cy, Cz) (see [`super::refine::Refined`]).
    pub covariance: Option<Matrix6<f64>>,
    /// Verdict and figures.
    pub quality: Quality,
}

/// The layout spread of target centres: √(λ₂/λ₁) of their scatter matrix.
pub fn layout_spread(centres: &[Vector3<f64>]) -> f64 {
    if centres.len() < 2 {
        return 0.0;
    }
    let mean = centres.iter().sum::<Vector3<f64>>() / centres.len() as f64;
    let scatter: Matrix3<f64> = centres.iter().map(|c| (c - mean) * (c - mean).transpose()).sum();
    let mut eig: Vec<f64> = scatter.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(|a, b| b.total_cmp(a));
    if eig[0] <= 0.0 {
        return 0.0;
    }
    (eig[1].max(0.0) / eig[0]).sqrt()
}

/// Registers one photograph from its `points` (see the module doc).
pub fn register(pinhole: &Pinhole, points: &[Correspondence], settings: &RegistrationSettings) -> Registration {
    let seen = target_count(points);
    let failed = |reason: String| Registration {
        pose: None,
        covariance: None,
        quality: Quality::failed(reason, seen),
    };
    if seen < 3 {
        return failed(format!("too few targets: {seen} seen, at least 3 needed"));
    }
    let c_settings = ConsensusSettings {
        threshold_px: settings.inlier_threshold_px,
        max_samples: settings.max_samples,
        seed: settings.seed,
        ..ConsensusSettings::default()
    };
    let Some(found) = consensus(pinhole, points, &c_settings) else {
        return failed(format!(
            "no three of the {seen} targets agree on a pose within {} px",
            settings.inlier_threshold_px
        ));
    };
    let mut mask = found.inliers;
    let mut pose = found.pose;
    let mut refined = None;
    for round in 0..3 {
        let used: Vec<Correspondence> = points
            .iter()
            .zip(&mask)
            .filter(|(_, m)| **m)
            .map(|(c, _)| c.clone())
            .collect();
        let Ok(r) = refine(pinhole, &used, pose, settings.sigma_floor_px) else {
            break;
        };
        pose = r.pose;
        refined = Some(r);
        let again = agreeing(pinhole, points, &pose, settings.inlier_threshold_px);
        if again == mask || round == 2 {
            break;
        }
        mask = again;
    }
    let Some(r) = refined else {
        return failed("the refinement could not image the agreeing targets".into());
    };
    let used: Vec<&Correspondence> = points.iter().zip(&mask).filter(|(_, m)| **m).map(|(c, _)| c).collect();
    let mut ids: Vec<u32> = used.iter().map(|c| c.target).collect();
    ids.sort_unstable();
    ids.dedup();
    if ids.len() < 3 {
        return failed(format!(
            "only {} targets agree with the refined pose, at least 3 needed",
            ids.len()
        ));
    }
    let centres: Vec<Vector3<f64>> = ids
        .iter()
        .map(|id| {
            let pts: Vec<Vector3<f64>> = used
                .iter()
                .filter(|c| c.target == *id)
                .map(|c| Vector3::from(c.world))
                .collect();
            pts.iter().sum::<Vector3<f64>>() / pts.len() as f64
        })
        .collect();
    let mean_distance = centres.iter().map(|c| (c - pose.centre).norm()).sum::<f64>() / centres.len() as f64;
    let mut rejected: Vec<u32> = points.iter().map(|c| c.target).filter(|t| !ids.contains(t)).collect();
    rejected.sort_unstable();
    rejected.dedup();
    // The errors of the points used at the final pose.
    let used_owned: Vec<Correspondence> = used.iter().map(|c| (*c).clone()).collect();
    let errors: Vec<f64> = used_owned
        .iter()
        .map(|c| {
            pose.project(pinhole, &Vector3::from(c.world))
                .map_or(f64::INFINITY, |(u, v)| (u - c.pixel.0).hypot(v - c.pixel.1))
        })
        .collect();
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    let max = errors.iter().fold(0.0f64, |a, b| a.max(*b));
    let quality = Quality {
        verdict: super::verdict::Verdict::Ok,
        reasons: Vec::new(),
        targets_seen: seen,
        targets_used: ids.len(),
        points_used: used.len(),
        rejected_targets: rejected,
        rms_px: Some(rms),
        max_px: Some(max),
        sigma_position_m: r.sigma_position_m(),
        sigma_angle_deg: r.sigma_angle_deg(),
        mean_distance_m: Some(mean_distance),
        layout_spread: Some(layout_spread(&centres)),
    }
    .judged(&settings.limits);
    Registration {
        pose: Some(pose),
        covariance: r.covariance,
        quality,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registration::verdict::Verdict;
    use rand::SeedableRng;

    fn camera() -> Pinhole {
        Pinhole {
            focal_px: 1200.0,
            principal_px: (640.0, 480.0),
            k1: -0.06,
            k2: 0.01,
            projection: campanile_config::camera::Projection::Pinhole,
        }
    }

    /// Level, facing north from 10 m south of a wall at y = 0.
    fn truth() -> CameraPose {
        CameraPose::from_axes(Vector3::x(), -Vector3::z(), Vector3::y(), Vector3::new(0.3, -10.0, 1.6))
    }

    /// Four corners of a 0.4 m tag facing south (normal −y) per centre
    /// (x, y, z), seen from `pose` with Gaussian pixel noise `sigma`.
    fn tags(pose: &CameraPose, centres: &[(f64, f64, f64)], sigma: f64, seed: u64) -> Vec<Correspondence> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut out = Vec::new();
        for (k, (x, y, z)) in centres.iter().enumerate() {
            for (a, b) in [(-0.2, 0.2), (0.2, 0.2), (0.2, -0.2), (-0.2, -0.2)] {
                let w = [x + a, *y, z + b];
                let (u, v) = pose.project(&camera(), &Vector3::from(w)).expect("in view");
                let (n1, n2) = crate::camera::sensor::standard_normal_pair(&mut rng);
                out.push(Correspondence {
                    target: k as u32,
                    pixel: (u + sigma * n1, v + sigma * n2),
                    world: w,
                });
            }
        }
        out
    }

    /// Eight targets, on the wall and on posts up to 4 m in front of it:
    /// a layout with depth, as on a building's corner or a courtyard.
    const SPREAD: [(f64, f64, f64); 8] = [
        (-3.0, 0.0, 0.5),
        (3.0, 0.0, 0.8),
        (-2.0, 0.0, 4.0),
        (2.5, 0.0, 3.0),
        (0.0, 0.0, 6.0),
        (-4.0, -3.0, 2.0),
        (3.5, -4.0, 1.0),
        (0.5, -2.0, 0.3),
    ];

    #[test]
    fn eight_targets_with_a_tenth_of_a_pixel_of_noise_give_an_ok_pose_within_the_goals() {
        let t = truth();
        let r = register(&camera(), &tags(&t, &SPREAD, 0.1, 1), &RegistrationSettings::default());
        let pose = r.pose.expect("a pose");
        assert_eq!(r.quality.verdict, Verdict::Ok, "{:?}", r.quality.reasons);
        assert!((pose.centre - t.centre).norm() < 0.005, "{:?}", pose.centre - t.centre);
        assert!(pose.angle_to_deg(&t) < 0.05);
        assert!(r.quality.rejected_targets.is_empty());
    }

    #[test]
    fn a_moved_target_is_rejected_and_the_pose_stays_right() {
        let t = truth();
        let mut points = tags(&t, &SPREAD, 0.1, 2);
        // Target 3 was surveyed 30 cm east of where it hangs.
        for c in points.iter_mut().filter(|c| c.target == 3) {
            c.world[0] += 0.3;
        }
        let r = register(&camera(), &points, &RegistrationSettings::default());
        assert_eq!(r.quality.rejected_targets, [3]);
        assert_eq!(r.quality.targets_used, 7);
        let pose = r.pose.expect("a pose");
        assert!((pose.centre - t.centre).norm() < 0.005);
    }

    #[test]
    fn two_targets_fail_and_targets_on_a_line_are_poor() {
        let t = truth();
        let r = register(
            &camera(),
            &tags(&t, &SPREAD[..2], 0.2, 3),
            &RegistrationSettings::default(),
        );
        assert_eq!(r.quality.verdict, Verdict::Failed);
        assert!(r.pose.is_none());
        assert!(
            r.quality.reasons[0].contains("too few targets: 2 seen"),
            "{:?}",
            r.quality.reasons
        );
        let line = [(-3.0, 0.0, 2.0), (-1.0, 0.0, 2.05), (1.0, 0.0, 2.0), (3.0, 0.0, 2.02)];
        let r = register(&camera(), &tags(&t, &line, 0.2, 4), &RegistrationSettings::default());
        assert_eq!(r.quality.verdict, Verdict::Poor);
        assert!(
            r.quality.reasons.iter().any(|s| s.contains("nearly on a line")),
            "{:?}",
            r.quality.reasons
        );
    }

    #[test]
    fn a_wrong_lens_model_shows_as_reprojection_error() {
        let t = truth();
        let points = tags(&t, &SPREAD, 0.2, 5);
        let wrong = Pinhole { k1: 0.1, ..camera() };
        let settings = RegistrationSettings {
            inlier_threshold_px: 40.0,
            ..RegistrationSettings::default()
        };
        let r = register(&wrong, &points, &settings);
        assert_eq!(r.quality.verdict, Verdict::Poor);
        assert!(
            r.quality.reasons.iter().any(|s| s.contains("reprojection error")),
            "{:?}",
            r.quality.reasons
        );
    }

    #[test]
    fn layout_spread_is_zero_on_a_line_and_one_on_a_square() {
        let line: Vec<Vector3<f64>> = (0..5)
            .map(|i| Vector3::new(f64::from(i), 2.0 * f64::from(i), 0.0))
            .collect();
        assert!(layout_spread(&line) < 1e-9);
        let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| Vector3::new(x, y, 3.0));
        assert!((layout_spread(&square) - 1.0).abs() < 1e-12);
    }
}
