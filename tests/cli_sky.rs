//! `campanile sky fit|eval` on plain files, against skies with known answers.

use std::fmt::Write as _;
mod common;

use common::campanile;

/// CIE standard clear sky (type 12), zenith value `lz`, sun at (zs, azs).
fn cie12(z: f64, g: f64, zs: f64, lz: f64) -> f64 {
    let f =
        |x: f64| 1.0 + 10.0 * ((-3.0 * x).exp() - (-3.0 * std::f64::consts::FRAC_PI_2).exp()) + 0.45 * x.cos().powi(2);
    let phi = |x: f64| 1.0 - (-0.32 / x.cos().max(0.01)).exp();
    lz * f(g) * phi(z) / (f(zs) * phi(0.0))
}

fn dir(z: f64, a: f64) -> [f64; 3] {
    [z.sin() * a.sin(), z.sin() * a.cos(), z.cos()]
}

#[test]
fn a_noisy_cie_clear_sky_is_fitted_as_cie_type_12_and_evaluates_back() {
    let (zs, azs) = (40f64.to_radians(), 190f64.to_radians());
    let sun = dir(zs, azs);
    let mut csv = String::from("zenith_deg,azimuth_deg,r,g,b\n");
    let mut k = 0u64;
    for zi in (0..86).step_by(5) {
        for ai in (0..360).step_by(10) {
            let (z, a) = (f64::from(zi).to_radians(), f64::from(ai).to_radians());
            let v = dir(z, a);
            let g = (v[0] * sun[0] + v[1] * sun[1] + v[2] * sun[2]).clamp(-1.0, 1.0).acos();
            // ±1% deterministic pseudo-noise.
            k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let n = 1.0 + 0.01 * ((k >> 33) as f64 / f64::from(1u32 << 31) * 2.0 - 1.0);
            let _ = writeln!(
                csv,
                "{zi},{ai},{},{},{}",
                cie12(z, g, zs, 0.05) * n,
                cie12(z, g, zs, 0.08) * n,
                cie12(z, g, zs, 0.13) * n
            );
        }
    }
    let dir_tmp = tempfile::tempdir().expect("temp");
    let samples = dir_tmp.path().join("scan.csv");
    let sky = dir_tmp.path().join("sky.ron");
    std::fs::write(&samples, csv).expect("write");
    let out = campanile(&[
        "sky",
        "fit",
        samples.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "40",
        "--sun-azimuth-deg",
        "190",
        "--out",
        sky.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&sky).expect("written");
    assert_eq!(text.matches("chosen: \"Cie(12)\"").count(), 3, "{text}");

    let dirs = dir_tmp.path().join("dirs.csv");
    std::fs::write(&dirs, "zenith_deg,azimuth_deg\n0,0\n60,300\n").expect("write");
    let out = campanile(&[
        "sky",
        "eval",
        sky.to_str().expect("utf-8"),
        dirs.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let zenith_g: f64 = stdout
        .lines()
        .nth(1)
        .and_then(|l| l.split(',').nth(3))
        .and_then(|v| v.parse().ok())
        .expect("value");
    assert!((zenith_g / 0.08 - 1.0).abs() < 0.01, "{stdout}");
}

#[test]
fn a_sun_below_the_horizon_is_refused_with_a_reason() {
    let dir_tmp = tempfile::tempdir().expect("temp");
    let samples = dir_tmp.path().join("scan.csv");
    std::fs::write(&samples, "zenith_deg,azimuth_deg,r\n10,0,1\n").expect("write");
    let out = campanile(&[
        "sky",
        "fit",
        samples.to_str().expect("utf-8"),
        "--time",
        "2026-08-28T08:00:00Z",
        "--station",
        "examples/sim-station.ron",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("below the horizon"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
