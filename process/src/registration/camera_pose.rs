//! A camera's place and orientation in the world frame.

use nalgebra::{Matrix3, Rotation3, Vector3};

use crate::pose::{HeadPose, Mount, Pinhole};

/// Where a camera was and how it was turned: a world point `X` is seen in
/// the camera frame at `R (X − C)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// World-to-camera rotation `R`: its rows are the camera's right, down
    /// and forward axes in the world frame.
    pub rotation: Rotation3<f64>,
    /// The centre of projection `C`, world frame, metres.
    pub centre: Vector3<f64>,
}

impl CameraPose {
    /// The camera-frame position of world point `x`.
    pub fn to_camera(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * (x - self.centre)
    }

    /// The pixel where `x` is imaged through `pinhole`, or `None` behind the camera.
    pub fn project(&self, pinhole: &Pinhole, x: &Vector3<f64>) -> Option<(f64, f64)> {
        let p = self.to_camera(x);
        pinhole.project([p.x, p.y, p.z])
    }

    /// The optical axis (camera forward) in the world frame.
    pub fn forward(&self) -> Vector3<f64> {
        self.rotation.matrix().row(2).transpose()
    }

    /// A pose from the camera's axes in the world frame.
    pub fn from_axes(right: Vector3<f64>, down: Vector3<f64>, forward: Vector3<f64>, centre: Vector3<f64>) -> Self {
        let m = Matrix3::from_rows(&[right.transpose(), down.transpose(), forward.transpose()]);
        CameraPose {
            rotation: Rotation3::from_matrix(&m),
            centre,
        }
    }

    /// The pose with its optical axis at `azimuth_deg` (from north through
    /// east) and `elevation_deg`, turned `roll_deg` about it (as
    /// [`CameraPose::roll_deg`] measures), centred at `centre`: the inverse
    /// of those three angles, as a poses file writes them. At the zenith
    /// or nadir the azimuth still says which way the image's right points.
    pub fn from_angles(azimuth_deg: f64, elevation_deg: f64, roll_deg: f64, centre: Vector3<f64>) -> Self {
        let (sa, ca) = azimuth_deg.to_radians().sin_cos();
        let (se, ce) = elevation_deg.to_radians().sin_cos();
        let (sr, cr) = roll_deg.to_radians().sin_cos();
        let forward = Vector3::new(ce * sa, ce * ca, se);
        let level_right = Vector3::new(ca, -sa, 0.0);
        let level_down = forward.cross(&level_right);
        let right = level_right * cr + level_down * sr;
        let down = forward.cross(&right);
        CameraPose::from_axes(right, down, forward, centre)
    }

    /// The mount and head reading that turn a camera as this pose is
    /// turned ([`Mount::holding`]): how a photograph taken off the head,
    /// hand-held or rolled, goes through the head's kinematics (its
    /// position is [`CameraPose::centre`]).
    pub fn holding(&self) -> (Mount, HeadPose) {
        let m = self.rotation.matrix();
        let axis = |i: usize| [m[(i, 0)], m[(i, 1)], m[(i, 2)]];
        Mount::holding(axis(0), axis(1), axis(2))
    }

    /// Azimuth of the optical axis, degrees from north through east, in [0, 360).
    pub fn azimuth_deg(&self) -> f64 {
        let f = self.forward();
        f.x.atan2(f.y).to_degrees().rem_euclid(360.0)
    }

    /// Elevation of the optical axis above the horizon, degrees.
    pub fn elevation_deg(&self) -> f64 {
        let f = self.forward();
        f.z.clamp(-1.0, 1.0).asin().to_degrees()
    }

    /// Roll about the optical axis, degrees: the angle from the level
    /// right vector (horizontal, to the right of the axis) to the camera's
    /// right axis, positive when the image turns clockwise as seen by the
    /// photographer (the right axis dips). Zero for a head's pan–tilt view.
    pub fn roll_deg(&self) -> f64 {
        let m = self.rotation.matrix();
        let right = m.row(0).transpose();
        let f = self.forward();
        let level_right = f.cross(&Vector3::z());
        if level_right.norm() < 1e-12 {
            return 0.0;
        }
        let level_right = level_right.normalize();
        let level_down = f.cross(&level_right);
        (right.dot(&level_down)).atan2(right.dot(&level_right)).to_degrees()
    }

    /// The angle of the rotation that takes this pose's orientation to
    /// `other`'s, degrees.
    pub fn angle_to_deg(&self, other: &CameraPose) -> f64 {
        // atan2(sin θ, cos θ) from the skew and trace parts: precise for
        // small angles, where acos of the trace is not.
        let m = (self.rotation.inverse() * other.rotation).into_inner();
        let sin = 0.5 * Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]).norm();
        let cos = 0.5 * (m.trace() - 1.0);
        sin.atan2(cos).to_degrees()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_camera_facing_north_has_azimuth_zero_and_no_roll() {
        let pose = CameraPose::from_axes(Vector3::x(), -Vector3::z(), Vector3::y(), Vector3::new(1.0, 2.0, 3.0));
        assert!(pose.azimuth_deg().abs() < 1e-12);
        assert!(pose.elevation_deg().abs() < 1e-12);
        assert!(pose.roll_deg().abs() < 1e-12);
        // A point 10 m north, 1 m east and 1 m up is right of and above the axis.
        let p = pose.to_camera(&Vector3::new(2.0, 12.0, 4.0));
        assert!((p - Vector3::new(1.0, -1.0, 10.0)).norm() < 1e-12);
    }

    #[test]
    fn facing_east_raised_thirty_degrees_and_rolled_ten() {
        let (e, r) = (30f64.to_radians(), 10f64.to_radians());
        let forward = Vector3::new(e.cos(), 0.0, e.sin());
        let level_right = Vector3::new(0.0, -1.0, 0.0);
        let level_down = forward.cross(&level_right);
        let right = level_right * r.cos() + level_down * r.sin();
        let down = forward.cross(&right);
        let pose = CameraPose::from_axes(right, down, forward, Vector3::zeros());
        assert!((pose.azimuth_deg() - 90.0).abs() < 1e-9);
        assert!((pose.elevation_deg() - 30.0).abs() < 1e-9);
        assert!((pose.roll_deg() - 10.0).abs() < 1e-9);
        let back = CameraPose::from_angles(90.0, 30.0, 10.0, Vector3::zeros());
        assert!(pose.angle_to_deg(&back) < 1e-9, "{}", pose.angle_to_deg(&back));
    }

    /// Angles written to a poses file and read back give the same pose,
    /// rolled or not, looking down or up.
    #[test]
    fn angles_round_trip() {
        for &(az, el, roll) in &[
            (0.0, 0.0, 0.0),
            (217.3, -12.0, 4.5),
            (33.0, 71.0, -20.0),
            (300.0, 5.0, 170.0),
        ] {
            let p = CameraPose::from_angles(az, el, roll, Vector3::new(1.0, 2.0, 3.0));
            assert!((p.azimuth_deg() - az).abs() < 1e-9, "{az}: {}", p.azimuth_deg());
            assert!((p.elevation_deg() - el).abs() < 1e-9);
            assert!((p.roll_deg() - roll).abs() < 1e-9, "{roll}: {}", p.roll_deg());
        }
    }
}
