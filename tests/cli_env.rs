//! `campanile env fit|predict` end to end: observations of known regions at
//! four times of a late-August day in Berkeley, a fit, and a prediction at a
//! fifth time checked against the truth.

mod common;

use std::fmt::Write as _;

use campanile_process::sun::{Ephemeris, Observer};
use chrono::{TimeZone, Utc};
use common::campanile;

/// (E_sky, E_sun) per channel for a sun at elevation `el` (radians): a
/// plausible clear day whose sky flux has a constant part.
fn light(el: f64) -> ([f64; 3], [f64; 3]) {
    let s = el.sin().max(0.0);
    (
        [60.0 + 40.0 * s, 70.0 + 45.0 * s, 95.0 + 60.0 * s],
        [900.0 * s.powf(0.1), 850.0 * s.powf(0.12), 780.0 * s.powf(0.15)],
    )
}

fn truth(region: &str) -> ([f64; 3], [f64; 3], [f64; 3]) {
    match region {
        // A slope facing south-east, and a face toward north that the sun never reaches.
        "slope" => ([0.05, 0.07, 0.06], [0.12, 0.15, 0.10], [0.3 / 1.0, -0.6, 0.75]),
        _ => ([0.04, 0.05, 0.06], [0.0; 3], [0.0, 1.0, 0.0]),
    }
}

fn radiance(region: &str, sun: [f64; 3]) -> [f64; 3] {
    let (sky, sun_rho, n) = truth(region);
    let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let cos = ((n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]) / norm).max(0.0);
    let (e_sky, e_sun) = light(sun[2].asin());
    [0, 1, 2].map(|c| sky[c] * e_sky[c] + sun_rho[c] * e_sun[c] * cos)
}

fn sun_at(hour: u32, day: u32) -> ([f64; 3], f64, f64) {
    let obs = Observer::from_degrees(37.8721, -122.2578, 90.0, 1010.0, 18.0);
    let t = Utc.with_ymd_and_hms(2026, 8, day, hour, 0, 0).single().expect("t");
    let p = Ephemeris::at(t, Some(69.0)).and_then(|e| e.position(&obs)).expect("ok");
    (p.direction(), p.zenith_rad.to_degrees(), p.azimuth_rad.to_degrees())
}

#[test]
fn fit_then_predict_a_fifth_time_of_day() {
    let mut csv = String::from("region,r,g,b,sky_r,sky_g,sky_b,sun_r,sun_g,sun_b,sun_zenith_deg,sun_azimuth_deg\n");
    for (hour, day) in [(16, 28), (19, 28), (22, 28), (0, 29)] {
        let (sun, z, a) = sun_at(hour, day);
        let (e_sky, e_sun) = light(sun[2].asin());
        for region in ["north-wall", "slope"] {
            let r = radiance(region, sun);
            let _ = writeln!(
                csv,
                "{region},{},{},{},{},{},{},{},{},{},{z},{a}",
                r[0], r[1], r[2], e_sky[0], e_sky[1], e_sky[2], e_sun[0], e_sun[1], e_sun[2]
            );
        }
    }
    let dir = tempfile::tempdir().expect("temp");
    let obs = dir.path().join("obs.csv");
    let models = dir.path().join("env.ron");
    std::fs::write(&obs, csv).expect("write");
    let out = campanile(&[
        "env",
        "fit",
        obs.to_str().expect("utf-8"),
        "--out",
        models.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&models).expect("written");
    assert!(
        text.contains("kind: SkyOnly") && text.contains("kind: SkyAndSun"),
        "{text}"
    );

    // Held out: 14:00 PDT (21:00 UTC).
    let (sun, z, a) = sun_at(21, 28);
    let (e_sky, e_sun) = light(sun[2].asin());
    let fmt = |v: [f64; 3]| format!("{},{},{}", v[0], v[1], v[2]);
    let out = campanile(&[
        "env",
        "predict",
        models.to_str().expect("utf-8"),
        "--sky-irradiance",
        &fmt(e_sky),
        "--sun-irradiance",
        &fmt(e_sun),
        "--sun-zenith-deg",
        &z.to_string(),
        "--sun-azimuth-deg",
        &a.to_string(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    for line in stdout.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let want = radiance(f[0], sun);
        for c in 0..3 {
            let got: f64 = f[1 + c].parse().expect("number");
            assert!((got / want[c] - 1.0).abs() < 1e-3, "{line}: want {want:?}");
        }
    }
}
