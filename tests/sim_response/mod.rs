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

use std::path::{Path, PathBuf};

use campanile_config::{Station, load_station};
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

/// The example sky station's plan (`examples/sky-station.ron`: a sun
/// triplet and a sky scan) every 2 hours for 2 days, its scene path made
/// absolute, written to `dir/plan.ron`; the 64×48
/// `examples/sky-sim-station.ron`; and its true response in
/// `dir/response.csv` (the plan has no calibration bracket).
// Not every test crate that includes this module reads every field.
#[allow(dead_code)]
pub struct TwoDaySkyStation {
    pub plan: PathBuf,
    pub station_path: PathBuf,
    pub station: Station,
    pub response: PathBuf,
}

// Not every test crate that includes this module uses it.
#[allow(dead_code)]
pub fn two_day_sky_station(dir: &Path) -> TwoDaySkyStation {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let plan = dir.join("plan.ron");
    let plan_text = std::fs::read_to_string(root.join("examples/sky-station.ron"))
        .unwrap()
        .replace("interval_min: 10.0", "interval_min: 120.0")
        .replace("days: 3", "days: 2")
        .replace(
            "Some(\"sky-scene.ron\")",
            &format!("Some({:?})", root.join("examples/sky-scene.ron").display().to_string()),
        );
    assert!(plan_text.contains("interval_min: 120.0") && plan_text.contains("days: 2"));
    std::fs::write(&plan, plan_text).unwrap();
    let station_path = root.join("examples/sky-sim-station.ron");
    let station = load_station(&station_path).unwrap().value;
    let response = dir.join("response.csv");
    write_true_response(&response, station.camera.bit_depth);
    TwoDaySkyStation {
        plan,
        station_path,
        station,
        response,
    }
}
