//! The simulated camera's true response, written as a response CSV (the
//! format of `campanile hdr calibrate` and `processed/response.csv`): what
//! `campanile station run --process --response CSV` is given in the
//! station tests, whose sky-only plans have no calibration bracket.
//!
//! The curve is the simulator's own inverse response `g(z) = ln f⁻¹(z)`
//! (its [`CameraModel::true_ln_exposure`]) at the curve's nodes; the
//! simulated camera's channel gains are 1, so radiance through this curve
//! is in W·m⁻²·sr⁻¹ with no gauge error (a real station's response comes
//! from a calibration bracket, with the full-well gauge; see
//! `campanile_process::pipeline`).

use std::path::Path;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::hdr::curve::{ChannelCurve, ResponseCurve, node_code, node_count};

/// Writes the true response of the simulator's camera at `bits` bits to
/// `path` and returns the curve.
pub fn write_true_response(path: &Path, bits: u8) -> ResponseCurve {
    let camera = CameraModel::typical(bits);
    assert_eq!(camera.sensor.gain, [1.0; 3], "the simulated camera's channel gains");
    let n = node_count(bits);
    let channel = |c: usize| ChannelCurve {
        // Code 0 is ln 0: the lowest node takes half a code's exposure.
        ln_exposure: (0..n)
            .map(|k| camera.true_ln_exposure(node_code(bits, k).max(0.5), c))
            .collect(),
        ln_exposure_std: vec![0.0; n],
        support: vec![0; n],
    };
    let curve = ResponseCurve {
        bits,
        channels: [channel(0), channel(1), channel(2)],
    };
    std::fs::write(path, curve.to_csv("simulator truth")).unwrap();
    curve
}
