//! Aiming: head angles for a world direction through the mount's exact
//! kinematics (its level offsets included), and the world direction of a
//! pixel.

use campanile_config::Station;
use campanile_process::pose::{HeadPose, Mount, Pinhole};

/// The mount calibration of `station` in the processing crate's terms.
pub fn mount(station: &Station) -> Mount {
    let m = &station.head.mount;
    Mount {
        pan_zero_azimuth_rad: m.pan_zero_azimuth_deg.to_radians(),
        tilt_zero_rad: m.tilt_zero_deg.to_radians(),
        roll_rad: m.level_roll_deg.to_radians(),
        pitch_rad: m.level_pitch_deg.to_radians(),
    }
}

/// The camera model of `station`'s camera (its projection and radial
/// terms) at `width` × `height`.
pub fn pinhole(station: &Station, width: usize, height: usize) -> Pinhole {
    let c = &station.camera;
    let full = (c.resolution.width as usize, c.resolution.height as usize);
    Pinhole::of_camera(c).rescaled(full, width, height)
}

/// Unit world direction (x east, y north, z up) of azimuth and elevation in degrees.
pub fn direction_deg(azimuth_deg: f64, elevation_deg: f64) -> [f64; 3] {
    let (sa, ca) = azimuth_deg.to_radians().sin_cos();
    let (se, ce) = elevation_deg.to_radians().sin_cos();
    [ce * sa, ce * ca, se]
}

/// Azimuth and elevation in degrees of a world direction.
pub fn azimuth_elevation_deg(d: [f64; 3]) -> (f64, f64) {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(f64::MIN_POSITIVE);
    let az = d[0].atan2(d[1]).to_degrees().rem_euclid(360.0);
    let el = (d[2] / n).clamp(-1.0, 1.0).asin().to_degrees();
    (az, el)
}

/// Head angles `(pan, tilt)` in degrees that put the optical axis on the
/// world direction `(azimuth, elevation)` in degrees, with the base's
/// level offsets undone exactly (the inverse of [`Mount::to_world`] for
/// the forward axis), pan wrapped by whole turns into the head's limits;
/// `None` if unreachable.
pub fn head_angles(station: &Station, azimuth_deg: f64, elevation_deg: f64) -> Option<(f64, f64)> {
    let m = mount(station);
    let w = direction_deg(azimuth_deg, elevation_deg);
    // The level-frame direction: undo pitch (about east), then roll (about north).
    let level = rotate_y(rotate_x(w, -m.pitch_rad), -m.roll_rad);
    let (az, el) = azimuth_elevation_deg(level);
    let tilt = el + m.tilt_zero_rad.to_degrees();
    let pan0 = az - m.pan_zero_azimuth_rad.to_degrees();
    let limits = &station.head.limits;
    [0.0, -360.0, 360.0, -720.0, 720.0]
        .into_iter()
        .map(|turn| pan0 + turn)
        .find(|&pan| limits.contains(pan, tilt))
        .map(|pan| (pan, tilt))
}

/// World direction seen at pixel `(u, v)` with the head at `pose`.
pub fn pixel_direction(station: &Station, pinhole: &Pinhole, pose: HeadPose, u: f64, v: f64) -> Option<[f64; 3]> {
    let d = pinhole.unproject(u, v)?;
    Some(mount(station).to_world(pose, d))
}

/// Angle between two directions, degrees.
pub fn angle_between_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    (dot / (na * nb)).clamp(-1.0, 1.0).acos().to_degrees()
}

fn rotate_x(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

fn rotate_y(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Aiming at a direction through the exact kinematics puts the optical
    /// axis on it to 1e-9°, level offsets included.
    #[test]
    fn head_angles_invert_the_mount() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/sim-station.ron");
        let station = campanile_config::load_station(&path).unwrap().value;
        for (az, el) in [(10.0, 5.0), (97.5, 25.0), (200.0, 61.0), (300.0, -20.0)] {
            let (pan, tilt) = head_angles(&station, az, el).unwrap();
            let pose = HeadPose {
                pan_rad: pan.to_radians(),
                tilt_rad: tilt.to_radians(),
            };
            let axis = mount(&station).to_world(pose, [0.0, 0.0, 1.0]);
            assert!(angle_between_deg(axis, direction_deg(az, el)) < 1e-9, "{az} {el}");
        }
    }
}
