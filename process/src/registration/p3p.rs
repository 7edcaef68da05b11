//! The minimal solver: three world points and their bearings give up to
//! four poses. Lambda Twist (Persson & Nordberg, ECCV 2018) through the
//! `lambda-twist` crate, whose types are `cv-core`'s (an older nalgebra);
//! this module converts at its border so nothing else sees them.

use cv_core::nalgebra as cvn;
use cv_core::sample_consensus::Estimator;
use cv_core::{Bearing, FeatureWorldMatch, WorldPoint};
use lambda_twist::LambdaTwist;
use nalgebra::{Matrix3, Rotation3, Vector3};

use super::camera_pose::CameraPose;

/// A unit bearing in the camera frame (x right, y down, z forward).
#[derive(Debug, Clone, Copy)]
struct UnitBearing([f64; 3]);

impl Bearing for UnitBearing {
    fn bearing_unnormalized(&self) -> cvn::Vector3<f64> {
        cvn::Vector3::new(self.0[0], self.0[1], self.0[2])
    }

    fn from_bearing_vector(bearing: cvn::Vector3<f64>) -> Self {
        UnitBearing([bearing.x, bearing.y, bearing.z])
    }
}

/// The poses (0 to 4) that image the world points `world` along the unit
/// camera-frame bearings `bearings`. Poses with a non-finite part, or
/// that put a point behind the camera, are dropped.
pub fn poses(world: [[f64; 3]; 3], bearings: [[f64; 3]; 3]) -> Vec<CameraPose> {
    let sample = |i: usize| {
        FeatureWorldMatch(
            UnitBearing(bearings[i]),
            WorldPoint(cvn::Vector4::new(world[i][0], world[i][1], world[i][2], 1.0)),
        )
    };
    let data = [sample(0), sample(1), sample(2)];
    LambdaTwist::new()
        .estimate(data.iter().cloned())
        .into_iter()
        .filter_map(|model| {
            let iso = model.0;
            let r = iso.rotation.matrix();
            let t = iso.translation.vector;
            let m = Matrix3::from_fn(|i, j| r[(i, j)]);
            let t = Vector3::new(t.x, t.y, t.z);
            if !m.iter().chain(t.iter()).all(|v| v.is_finite()) {
                return None;
            }
            // Camera point = R X + t, so the centre is −Rᵀ t.
            let rotation = Rotation3::from_matrix(&m);
            let centre = -(rotation.inverse() * t);
            let pose = CameraPose { rotation, centre };
            world
                .iter()
                .all(|x| pose.to_camera(&Vector3::from(*x)).z > 0.0)
                .then_some(pose)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_points_give_back_the_pose_they_were_seen_from() {
        let truth = CameraPose {
            rotation: Rotation3::from_euler_angles(0.3, -0.2, 1.1),
            centre: Vector3::new(1.0, -2.0, 0.5),
        };
        let world = [[4.0, 3.0, 2.0], [-1.0, 5.0, 1.0], [2.0, 6.0, -1.5]];
        // Place the points in front of the camera: move them along its axis.
        let world = world.map(|x| {
            let p = Vector3::from(x);
            let ahead = truth.centre + truth.forward() * 8.0;
            let w = ahead + (p - Vector3::new(2.0, 4.0, 0.5)) * 0.5;
            [w.x, w.y, w.z]
        });
        let bearings = world.map(|x| {
            let c = truth.to_camera(&Vector3::from(x)).normalize();
            [c.x, c.y, c.z]
        });
        let found = poses(world, bearings);
        assert!(!found.is_empty() && found.len() <= 4);
        let best = found
            .iter()
            .map(|p| (p.centre - truth.centre).norm() + p.angle_to_deg(&truth))
            .fold(f64::INFINITY, f64::min);
        assert!(best < 1e-8, "closest solution off by {best}");
    }
}
