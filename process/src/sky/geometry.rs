//! The angles a sky model takes, from directions in the world frame.

/// The angle between two unit vectors, accurate at 0 and π alike:
/// `atan2(|u × v|, u · v)` (an arccos of the dot product loses half the
/// digits near 0, where the aureole is brightest).
pub fn angle_between(u: [f64; 3], v: [f64; 3]) -> f64 {
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let sin = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    let cos = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    sin.atan2(cos)
}

/// The unit vector (world frame: x east, y north, z up) at zenith angle
/// `zenith` and azimuth `azimuth` (from north through east), radians.
pub fn direction(zenith: f64, azimuth: f64) -> [f64; 3] {
    let (sz, cz) = zenith.sin_cos();
    let (sa, ca) = azimuth.sin_cos();
    [sz * sa, sz * ca, cz]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiny_and_near_antipodal_angles_keep_their_digits() {
        let t = 1e-9_f64;
        let u = [0.0, 0.0, 1.0];
        let v = [t.sin(), 0.0, t.cos()];
        assert!((angle_between(u, v) - t).abs() < 1e-20, "{}", angle_between(u, v));
        let w = [t.sin(), 0.0, -t.cos()];
        assert!((angle_between(u, w) - (std::f64::consts::PI - t)).abs() < 1e-15);
    }
}
