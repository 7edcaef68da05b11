//! Pan-tilt head kinematics. Pan turns about the vertical, like azimuth
//! (from north toward east); tilt raises the optical axis. The mount
//! calibration gives the azimuth at pan 0, the tilt reading at the horizon,
//! and the small roll (about north) and pitch (about east) of a base that
//! is not quite level.

/// How the head sits in the world.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Mount {
    /// Azimuth the camera faces at pan 0, radians.
    pub pan_zero_azimuth_rad: f64,
    /// Tilt reading with the optical axis horizontal, radians.
    pub tilt_zero_rad: f64,
    /// Roll of the base about the north axis, radians.
    pub roll_rad: f64,
    /// Pitch of the base about the east axis, radians.
    pub pitch_rad: f64,
}

/// A head reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadPose {
    /// Pan, radians, in the head's own reading.
    pub pan_rad: f64,
    /// Tilt, radians, in the head's own reading.
    pub tilt_rad: f64,
}

fn rotate_x(v: [f64; 3], a: f64) -> [f64; 3] {
    rotate_x_sc(v, a.sin_cos())
}

fn rotate_y(v: [f64; 3], a: f64) -> [f64; 3] {
    rotate_y_sc(v, a.sin_cos())
}

/// [`rotate_x`] by an angle given as its (sine, cosine).
fn rotate_x_sc(v: [f64; 3], (s, c): (f64, f64)) -> [f64; 3] {
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

/// [`rotate_y`] by an angle given as its (sine, cosine).
fn rotate_y_sc(v: [f64; 3], (s, c): (f64, f64)) -> [f64; 3] {
    [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
}

/// A mount with the head at one pose, its rotations evaluated once: for
/// the many rays of a frame. [`OrientedMount::to_world`] gives exactly
/// (bit for bit) what [`Mount::to_world`] gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedMount {
    axes: [[f64; 3]; 3],
    roll: (f64, f64),
    pitch: (f64, f64),
}

impl OrientedMount {
    /// The world-frame direction of a camera-frame direction `d`.
    pub fn to_world(&self, d: [f64; 3]) -> [f64; 3] {
        let [right, down, forward] = self.axes;
        let level = [0, 1, 2].map(|i| d[0] * right[i] + d[1] * down[i] + d[2] * forward[i]);
        // The base's tilt: roll about north (y), then pitch about east (x).
        rotate_x_sc(rotate_y_sc(level, self.roll), self.pitch)
    }
}

impl Mount {
    /// A configured mount calibration, in radians.
    pub fn of_calibration(m: &campanile_config::head::MountCalibration) -> Mount {
        Mount {
            pan_zero_azimuth_rad: m.pan_zero_azimuth_deg.to_radians(),
            tilt_zero_rad: m.tilt_zero_deg.to_radians(),
            roll_rad: m.level_roll_deg.to_radians(),
            pitch_rad: m.level_pitch_deg.to_radians(),
        }
    }

    /// The camera's axes in the level frame for `pose`: right, down and
    /// forward (the optical axis), as unit vectors.
    fn axes(&self, pose: HeadPose) -> [[f64; 3]; 3] {
        let az = self.pan_zero_azimuth_rad + pose.pan_rad;
        let el = pose.tilt_rad - self.tilt_zero_rad;
        let (sa, ca) = az.sin_cos();
        let (se, ce) = el.sin_cos();
        let forward = [ce * sa, ce * ca, se];
        let right = [ca, -sa, 0.0];
        // down = forward × right
        let down = [
            forward[1] * right[2] - forward[2] * right[1],
            forward[2] * right[0] - forward[0] * right[2],
            forward[0] * right[1] - forward[1] * right[0],
        ];
        [right, down, forward]
    }

    /// The world-frame direction of a camera-frame direction `d` (x right,
    /// y down, z forward) with the head at `pose`.
    pub fn to_world(&self, pose: HeadPose, d: [f64; 3]) -> [f64; 3] {
        self.at(pose).to_world(d)
    }

    /// The mount with the head at `pose`, its rotations evaluated once.
    pub fn at(&self, pose: HeadPose) -> OrientedMount {
        OrientedMount {
            axes: self.axes(pose),
            roll: self.roll_rad.sin_cos(),
            pitch: self.pitch_rad.sin_cos(),
        }
    }

    /// A mount and head reading whose camera has world-frame axes `right`,
    /// `down` and `forward` (orthonormal, right-handed as a camera's are):
    /// how a hand-held photograph, turned any way about its optical axis,
    /// goes through the head's kinematics. The base's roll and pitch carry
    /// what pan and tilt cannot (an X–Y–X Euler decomposition of the
    /// orientation, with the pan at zero).
    pub fn holding(right: [f64; 3], down: [f64; 3], forward: [f64; 3]) -> (Mount, HeadPose) {
        // Level camera axes at pan 0, tilt 0 (columns of M0): right = x,
        // down = −z, forward = y; the orientation C = Rx(a) Ry(b) Rx(c) M0.
        let c_cols = [right, down, forward];
        let m0 = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]];
        // Q = C M0ᵀ: Q[i][j] = Σ_k C[i][k] M0[j][k], with C[i][k] = c_cols[k][i]
        // and M0[j][k] = m0[k][j] (both listed by columns).
        let q = |i: usize, j: usize| (0..3).map(|k| c_cols[k][i] * m0[k][j]).sum::<f64>();
        let b = q(0, 0).clamp(-1.0, 1.0).acos();
        let (a, c) = if b.sin().abs() > 1e-9 {
            (q(1, 0).atan2(-q(2, 0)), q(0, 1).atan2(q(0, 2)))
        } else if q(0, 0) > 0.0 {
            // Ry(0): Q = Rx(a + c).
            (0.0, q(2, 1).atan2(q(1, 1)))
        } else {
            // Ry(π) Rx(c): Q[1][2] = −sin c, Q[1][1] = cos c.
            (0.0, (-q(1, 2)).atan2(q(1, 1)))
        };
        (
            Mount {
                pan_zero_azimuth_rad: 0.0,
                tilt_zero_rad: 0.0,
                roll_rad: b,
                pitch_rad: a,
            },
            HeadPose {
                pan_rad: 0.0,
                tilt_rad: c,
            },
        )
    }

    /// The camera-frame direction of a world-frame direction (the inverse
    /// of [`Mount::to_world`]).
    pub fn to_camera(&self, pose: HeadPose, w: [f64; 3]) -> [f64; 3] {
        let level = rotate_y(rotate_x(w, -self.pitch_rad), -self.roll_rad);
        let dot = |a: [f64; 3]| a[0] * level[0] + a[1] * level[1] + a[2] * level[2];
        self.axes(pose).map(dot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mount holding a camera turned any way (the Euler decomposition's
    /// regular case, a level camera, one upside down and one looking
    /// straight up) maps each camera axis onto the world axis it was given,
    /// within 1e-12.
    #[test]
    fn a_held_camera_goes_through_the_mount_exactly() {
        let unit = |v: [f64; 3]| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / n)
        };
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let mut cases = Vec::new();
        for (az, el, roll) in [
            (35.0f64, 12.0f64, 30.0f64),
            (200.0, -40.0, -75.0),
            (300.0, 5.0, 0.0),
            (90.0, 0.0, 180.0),
            (10.0, 89.999, 20.0),
        ] {
            let (sa, ca) = az.to_radians().sin_cos();
            let (se, ce) = el.to_radians().sin_cos();
            let (sr, cr) = roll.to_radians().sin_cos();
            let forward = [ce * sa, ce * ca, se];
            let level_right = [ca, -sa, 0.0];
            let level_down = cross(forward, level_right);
            let right = unit([0, 1, 2].map(|i| level_right[i] * cr + level_down[i] * sr));
            cases.push((right, cross(forward, right), forward));
        }
        // A camera looking straight down with its right axis east.
        cases.push(([1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]));
        for (right, down, forward) in cases {
            let (m, head) = Mount::holding(right, down, forward);
            for (d, want) in [
                ([1.0, 0.0, 0.0], right),
                ([0.0, 1.0, 0.0], down),
                ([0.0, 0.0, 1.0], forward),
            ] {
                let got = m.to_world(head, d);
                for i in 0..3 {
                    assert!((got[i] - want[i]).abs() < 1e-12, "{d:?}: {got:?} against {want:?}");
                }
            }
        }
    }

    /// The rotations evaluated once give exactly the per-ray rotation by
    /// angles (so frames rendered through either are identical).
    #[test]
    fn an_oriented_mount_matches_the_per_ray_rotation_bit_for_bit() {
        let m = Mount {
            pan_zero_azimuth_rad: 0.3,
            tilt_zero_rad: -0.01,
            roll_rad: 0.0026,
            pitch_rad: -0.0017,
        };
        let pose = HeadPose {
            pan_rad: 1.1,
            tilt_rad: 0.4,
        };
        let o = m.at(pose);
        for i in 0..200 {
            let t = f64::from(i) * 0.37;
            let d = [t.sin() * 0.6, (1.7 * t).cos() * 0.4, 1.0];
            let [right, down, forward] = m.axes(pose);
            let level = [0, 1, 2].map(|k| d[0] * right[k] + d[1] * down[k] + d[2] * forward[k]);
            let by_angles = rotate_x(rotate_y(level, m.roll_rad), m.pitch_rad);
            assert_eq!(o.to_world(d), by_angles, "direction {i}");
            assert_eq!(m.to_world(pose, d), by_angles, "direction {i}");
        }
    }
    use std::f64::consts::FRAC_PI_2;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn pan_turns_like_azimuth_and_tilt_raises_the_axis() {
        let m = Mount::default();
        let axis = [0.0, 0.0, 1.0];
        assert!(
            close(
                m.to_world(
                    HeadPose {
                        pan_rad: 0.0,
                        tilt_rad: 0.0
                    },
                    axis
                ),
                [0.0, 1.0, 0.0]
            ),
            "north"
        );
        assert!(
            close(
                m.to_world(
                    HeadPose {
                        pan_rad: FRAC_PI_2,
                        tilt_rad: 0.0
                    },
                    axis
                ),
                [1.0, 0.0, 0.0]
            ),
            "east"
        );
        assert!(
            close(
                m.to_world(
                    HeadPose {
                        pan_rad: 0.3,
                        tilt_rad: FRAC_PI_2
                    },
                    axis
                ),
                [0.0, 0.0, 1.0]
            ),
            "zenith"
        );
        // Image right is east when facing north; image down is down.
        assert!(close(
            m.to_world(
                HeadPose {
                    pan_rad: 0.0,
                    tilt_rad: 0.0
                },
                [1.0, 0.0, 0.0]
            ),
            [1.0, 0.0, 0.0]
        ));
        assert!(close(
            m.to_world(
                HeadPose {
                    pan_rad: 0.0,
                    tilt_rad: 0.0
                },
                [0.0, 1.0, 0.0]
            ),
            [0.0, 0.0, -1.0]
        ));
    }

    #[test]
    fn the_mount_offsets_shift_and_the_inverse_undoes_them() {
        let m = Mount {
            pan_zero_azimuth_rad: 0.2,
            tilt_zero_rad: 0.014,
            roll_rad: 0.003,
            pitch_rad: -0.002,
        };
        let pose = HeadPose {
            pan_rad: 1.1,
            tilt_rad: 0.4,
        };
        for d in [[0.0f64, 0.0, 1.0], [0.3, -0.2, 0.93], [-0.5, 0.4, 0.77]] {
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let d = d.map(|x| x / n);
            assert!(close(m.to_camera(pose, m.to_world(pose, d)), d));
        }
        // With a level base, the axis is at azimuth pan_zero + pan and elevation tilt − tilt_zero.
        let level = Mount {
            roll_rad: 0.0,
            pitch_rad: 0.0,
            ..m
        };
        let w = level.to_world(pose, [0.0, 0.0, 1.0]);
        assert!((w[0].atan2(w[1]) - 1.3).abs() < 1e-12 && (w[2].asin() - 0.386).abs() < 1e-12);
    }
}
