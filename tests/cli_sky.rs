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

use campanile_process::sky::direction as dir;

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
    let residuals = dir_tmp.path().join("residuals.png");
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
        "--residual-map",
        residuals.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&sky).expect("written");
    assert_eq!(text.matches("chosen: \"Cie(12)\"").count(), 3, "{text}");
    // Its verdict beside it: a 1%-noise clear sky fits within the gates.
    let q: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir_tmp.path().join("sky.quality.json")).expect("verdicts")).unwrap();
    assert_eq!(q["verdict"], "ok", "{q}");
    assert_eq!(q["products"][0]["checks"].as_array().unwrap().len(), 6, "{q}");

    // The residual map: a 256² fisheye, grey where no sample fell, and
    // within ±1.5% where one did (the noise is ±1%): the false colour's
    // channels stay above 255·(1 − 0.15) there.
    let map = image::open(&residuals).expect("a PNG").into_rgb8();
    assert_eq!(map.dimensions(), (256, 256));
    let (mut binned, mut off) = (0, 0);
    for p in map.pixels() {
        if p.0 == [128, 128, 128] {
            continue;
        }
        binned += 1;
        if p.0.iter().any(|&v| v < 216) {
            off += 1;
        }
    }
    assert!(binned >= 500, "{binned} fisheye pixels carry a residual");
    assert_eq!(off, 0, "{off} of {binned} pixels show a residual beyond 1.5%");

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
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("below the horizon"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A sky file with one channel `g` of the given eq. (5.9) parameters.
fn sky_ron(zenith_deg: f64, azimuth_deg: f64) -> String {
    format!(
        "(sun_zenith_deg: {zenith_deg:.1}, sun_azimuth_deg: {azimuth_deg:.1}, channels: [(channel: \"g\", \
         model: (lz: 0.07, a: -1.0, b: -0.4, c: 12.0, d: -3.2, e: 0.5, h: 0.9), chosen: \"SevenParameter\", \
         reason: \"test\", rms_relative: 0.0, samples: 100, masked_fraction: 0.0)])"
    )
}

#[test]
fn predict_interpolates_fitted_skies_to_a_new_sun() {
    let dir_tmp = tempfile::tempdir().expect("temp");
    let morning = dir_tmp.path().join("morning.ron");
    let evening = dir_tmp.path().join("evening.ron");
    let predicted = dir_tmp.path().join("predicted.ron");
    std::fs::write(&morning, sky_ron(60.0, 100.0)).expect("write");
    std::fs::write(&evening, sky_ron(55.0, 250.0)).expect("write");
    let out = campanile(&[
        "sky",
        "predict",
        morning.to_str().expect("utf-8"),
        evening.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "35",
        "--sun-azimuth-deg",
        "180",
        "--out",
        predicted.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    // Same shape, new sun: the predicted sky is the model's, seen from the new sun.
    let dirs = dir_tmp.path().join("dirs.csv");
    std::fs::write(&dirs, "zenith_deg,azimuth_deg\n35,180\n60,10\n").expect("write");
    let out = campanile(&[
        "sky",
        "eval",
        predicted.to_str().expect("utf-8"),
        dirs.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let model = |xi: f64, gamma: f64| {
        0.07 * (1.0 - (-0.4 / xi.cos()).exp())
            * (1.0 + 12.0 * (-3.2 * gamma.powf(0.9)).exp() + 0.5 * gamma.cos().powi(2))
    };
    let rows: Vec<f64> = stdout
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).and_then(|v| v.parse().ok()).expect("value"))
        .collect();
    // Row 2: ξ = 60°, azimuth 10°, γ from the new sun at (35°, 180°).
    let sun = dir(35f64.to_radians(), 180f64.to_radians());
    let v = dir(60f64.to_radians(), 10f64.to_radians());
    let gamma = (v[0] * sun[0] + v[1] * sun[1] + v[2] * sun[2]).clamp(-1.0, 1.0).acos();
    let want = model(60f64.to_radians(), gamma);
    assert!((rows[1] / want - 1.0).abs() < 2e-3, "{} vs {want}", rows[1]);

    // A sky whose fit failed its gate is not used in silence: the
    // prediction inherits its verdict and exits 3.
    std::fs::write(
        dir_tmp.path().join("morning.quality.json"),
        r#"{"verdict": "failed", "counts": {"ok": 0, "poor": 0, "failed": 1}, "thresholds": {}, "products": []}"#,
    )
    .expect("write");
    let out = campanile(&[
        "sky",
        "predict",
        morning.to_str().expect("utf-8"),
        evening.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "35",
        "--sun-azimuth-deg",
        "180",
        "--out",
        predicted.to_str().expect("utf-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(3), "{stdout}");
    assert!(
        stdout.contains("sky predicted (inherited from ") && stdout.contains("morning.ron: failed"),
        "{stdout}"
    );

    // Skies with different channels are refused.
    std::fs::write(&evening, sky_ron(55.0, 250.0).replace("\"g\"", "\"r\"")).expect("write");
    let out = campanile(&[
        "sky",
        "predict",
        morning.to_str().expect("utf-8"),
        evening.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "35",
        "--sun-azimuth-deg",
        "180",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("differ from"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn map_writes_a_lat_long_exr_of_the_fitted_sky() {
    let dir_tmp = tempfile::tempdir().expect("temp");
    let sky = dir_tmp.path().join("sky.ron");
    let exr = dir_tmp.path().join("sky.exr");
    let one = sky_ron(40.0, 180.0);
    let channel = &one[one.find("(channel").expect("channel")..one.rfind(']').expect("end")];
    let three = format!(
        "(sun_zenith_deg: 40.0, sun_azimuth_deg: 180.0, channels: [{}, {}, {}])",
        channel.replace("\"g\"", "\"r\""),
        channel,
        channel.replace("\"g\"", "\"b\"")
    );
    std::fs::write(&sky, three).expect("write");
    let out = campanile(&[
        "sky",
        "map",
        sky.to_str().expect("utf-8"),
        "--out",
        exr.to_str().expect("utf-8"),
        "--width",
        "64",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map = campanile_process::exr_io::read_radiance_exr(&exr).expect("readable EXR");
    assert_eq!((map.width, map.height), (64, 16));
    // The top row is within 3° of the zenith, where the model gives Lz Bg(0) Sa(40°).
    let zenith = 0.07
        * (1.0 - (-0.4f64).exp())
        * (1.0 + 12.0 * (-3.2 * 40f64.to_radians().powf(0.9)).exp() + 0.5 * 40f64.to_radians().cos().powi(2));
    let top: f64 = (0..64).map(|x| f64::from(map.rgb[3 * x + 1])).sum::<f64>() / 64.0;
    assert!((top / zenith - 1.0).abs() < 0.05, "{top} vs {zenith}");
    // Two channels are not a colour map.
    std::fs::write(&sky, sky_ron(40.0, 180.0)).expect("write");
    let out = campanile(&[
        "sky",
        "map",
        sky.to_str().expect("utf-8"),
        "--out",
        exr.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// A CIE clear sky (type 12) for a sun at (`zs_deg`, `azs_deg`), sampled
/// every 5° of zenith and 10° of azimuth with ±1% deterministic
/// pseudo-noise: `(zenith_deg, azimuth_deg, noise factor, [r, g, b])` per row.
fn clear_sky_rows(zs_deg: f64, azs_deg: f64) -> Vec<(u32, u32, f64, [f64; 3])> {
    let (zs, azs) = (zs_deg.to_radians(), azs_deg.to_radians());
    let sun = dir(zs, azs);
    let mut rows = Vec::new();
    let mut k = 0u64;
    for zi in (0..86).step_by(5) {
        for ai in (0..360).step_by(10) {
            let (z, a) = (f64::from(zi).to_radians(), f64::from(ai).to_radians());
            let v = dir(z, a);
            let g = (v[0] * sun[0] + v[1] * sun[1] + v[2] * sun[2]).clamp(-1.0, 1.0).acos();
            k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let n = 1.0 + 0.01 * ((k >> 33) as f64 / f64::from(1u32 << 31) * 2.0 - 1.0);
            rows.push((
                zi,
                ai,
                n,
                [
                    cie12(z, g, zs, 0.05) * n,
                    cie12(z, g, zs, 0.08) * n,
                    cie12(z, g, zs, 0.13) * n,
                ],
            ));
        }
    }
    rows
}

/// The sky file's fields `sun_zenith_deg`, `sun_azimuth_deg` and channel names.
fn sky_summary(path: &std::path::Path) -> (f64, f64, Vec<String>) {
    let sky: campanile_process::sky::SkyFile =
        ron::from_str(&std::fs::read_to_string(path).expect("written")).expect("a sky file");
    (
        sky.sun_zenith_deg,
        sky.sun_azimuth_deg,
        sky.channels.iter().map(|c| c.channel.clone()).collect(),
    )
}

#[test]
fn extra_columns_are_ignored_and_r_g_b_are_the_channels() {
    let tmp = tempfile::tempdir().expect("temp");
    let samples = tmp.path().join("scan.csv");
    let mut csv = String::from("id,zenith_deg,azimuth_deg,r,g,b,note\n");
    for (i, (zi, ai, _, [r, g, b])) in clear_sky_rows(40.0, 190.0).into_iter().enumerate() {
        let _ = writeln!(csv, "{i},{zi},{ai},{r},{g},{b},looks clear");
    }
    std::fs::write(&samples, csv).expect("write");
    let sky = tmp.path().join("sky.ron");
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
    assert_eq!(sky_summary(&sky).2, ["r", "g", "b"]);

    // --columns chooses the channels and their order.
    let out = campanile(&[
        "sky",
        "fit",
        samples.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "40",
        "--sun-azimuth-deg",
        "190",
        "--columns",
        "b,r",
        "--out",
        sky.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(sky_summary(&sky).2, ["b", "r"]);

    // A name that is not in the header is refused, listing the header.
    let out = campanile(&[
        "sky",
        "fit",
        samples.to_str().expect("utf-8"),
        "--sun-zenith-deg",
        "40",
        "--sun-azimuth-deg",
        "190",
        "--columns",
        "r,q",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("`q`") && stderr.contains("id,zenith_deg,azimuth_deg,r,g,b,note"),
        "{stderr}"
    );
}

#[test]
fn the_sun_from_lat_lon_and_time_is_the_ephemeris_sun() {
    use campanile_process::sun::{Ephemeris, Observer};
    // Berkeley, 2026-08-28 20:30 UTC; refraction for 1013.25 mbar, 12 °C.
    let (lat, lon, time) = (37.8719, -122.2585, "2026-08-28T20:30:00Z");
    let t: chrono::DateTime<chrono::Utc> = time.parse().expect("time");
    let p = Ephemeris::at(t, None)
        .and_then(|e| e.position(&Observer::from_degrees(lat, lon, 0.0, 1013.25, 12.0)))
        .expect("position");
    let (zs, azs) = (p.zenith_rad.to_degrees(), p.azimuth_rad.to_degrees());
    assert!((20.0..60.0).contains(&zs), "zenith {zs}");

    let tmp = tempfile::tempdir().expect("temp");
    let samples = tmp.path().join("scan.csv");
    let mut csv = String::from("zenith_deg,azimuth_deg,y\n");
    for (zi, ai, _, [_, y, _]) in clear_sky_rows(zs, azs) {
        let _ = writeln!(csv, "{zi},{ai},{y}");
    }
    std::fs::write(&samples, csv).expect("write");
    let fit = |name: &str, sun: &[&str]| {
        let sky = tmp.path().join(name);
        let mut args = vec![
            "sky",
            "fit",
            samples.to_str().expect("utf-8"),
            "--out",
            sky.to_str().expect("utf-8"),
        ];
        args.extend_from_slice(sun);
        let out = campanile(&args);
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        sky_summary(&sky)
    };
    let (z_text, a_text) = (format!("{zs:.17}"), format!("{azs:.17}"));
    let given = fit(
        "given.ron",
        &["--sun-zenith-deg", &z_text, "--sun-azimuth-deg", &a_text],
    );
    let lon_text = lon.to_string();
    let site = fit("site.ron", &["--lat", "37.8719", "--lon", &lon_text, "--time", time]);
    // The same longitude written east of 180°.
    let lon_east = (lon + 360.0).to_string();
    let east = fit("east.ron", &["--lat", "37.8719", "--lon", &lon_east, "--time", time]);
    for (name, s) in [("--lon -122.2585", &site), ("--lon 237.7415", &east)] {
        assert!((s.0 - given.0).abs() < 1e-9, "{name}: zenith {} vs {}", s.0, given.0);
        assert!((s.1 - given.1).abs() < 1e-9, "{name}: azimuth {} vs {}", s.1, given.1);
        assert_eq!(s.2, ["y"]);
    }
    // `campanile sun` prints the same sun (to its 5 decimals).
    let out = campanile(&["sun", "--lat", "37.8719", "--lon", &lon_text, "--time", time]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let field = |key: &str| -> f64 {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().parse().ok())
            .expect("a field")
    };
    assert!((field("zenith_deg") - site.0).abs() < 6e-6, "{stdout}");
    assert!((field("azimuth_deg") - site.1).abs() < 6e-6, "{stdout}");
}

#[test]
fn eval_reads_a_sample_file_and_compare_gives_the_noise_back() {
    let tmp = tempfile::tempdir().expect("temp");
    let samples = tmp.path().join("scan.csv");
    let rows = clear_sky_rows(40.0, 190.0);
    let mut csv = String::from("id,zenith_deg,azimuth_deg,r,g,b,note\n");
    for (i, (zi, ai, _, [r, g, b])) in rows.iter().enumerate() {
        let _ = writeln!(csv, "{i},{zi},{ai},{r},{g},{b},looks clear");
    }
    std::fs::write(&samples, csv).expect("write");
    let sky = tmp.path().join("sky.ron");
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

    // Plain eval of the sample file: directions and the sky's channels only.
    let out = campanile(&[
        "sky",
        "eval",
        sky.to_str().expect("utf-8"),
        samples.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().next(), Some("zenith_deg,azimuth_deg,r,g,b"));
    assert_eq!(stdout.lines().count(), rows.len() + 1);
    assert!(out.stderr.is_empty(), "{}", String::from_utf8_lossy(&out.stderr));

    // --compare: measured / fitted − 1 is the noise put in (±1%, uniform),
    // to within the fit's error in Lz.
    let out = campanile(&[
        "sky",
        "eval",
        sky.to_str().expect("utf-8"),
        samples.to_str().expect("utf-8"),
        "--compare",
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let mut lines = stdout.lines();
    assert_eq!(
        lines.next(),
        Some("zenith_deg,azimuth_deg,r,g,b,r_residual,g_residual,b_residual")
    );
    let mut worst = 0f64;
    for (line, (_, _, n, _)) in lines.zip(&rows) {
        let g: f64 = line.split(',').nth(6).and_then(|v| v.parse().ok()).expect("g_residual");
        worst = worst.max((g - (n - 1.0)).abs());
    }
    assert!(worst < 2e-3, "g_residual off the noise by up to {worst}");
    // The summary: the noise's own median and p95 of |n − 1|, nearest rank.
    let mut noise: Vec<f64> = rows.iter().map(|(_, _, n, _)| (n - 1.0).abs()).collect();
    noise.sort_by(f64::total_cmp);
    let rank = |q: f64| noise[((noise.len() - 1) as f64 * q).round() as usize];
    let summary = stderr
        .lines()
        .find(|l| l.starts_with("compared 648 samples, |measured / fitted − 1|: r median "))
        .expect(&stderr);
    let g_part = summary.split("; ").find(|p| p.starts_with("g median ")).expect(summary);
    let figures: Vec<f64> = g_part.split([' ', ',']).filter_map(|w| w.parse().ok()).collect();
    let [median, p95] = figures[..] else { panic!("{g_part}") };
    assert!((median - rank(0.5)).abs() < 1e-3, "{summary}: median vs {}", rank(0.5));
    assert!((p95 - rank(0.95)).abs() < 1e-3, "{summary}: p95 vs {}", rank(0.95));

    // --compare on a file without the sky's channels is bad input.
    let dirs = tmp.path().join("dirs.csv");
    std::fs::write(&dirs, "zenith_deg,azimuth_deg,r\n10,20,1\n").expect("write");
    let out = campanile(&[
        "sky",
        "eval",
        sky.to_str().expect("utf-8"),
        dirs.to_str().expect("utf-8"),
        "--compare",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--compare needs the sky's channels")
            && stderr.contains("channel column `g` is not in the header (it has: zenith_deg,azimuth_deg,r)"),
        "{stderr}"
    );
}

#[test]
fn the_help_documents_the_files_and_the_sun_options() {
    let out = campanile(&["sky", "fit", "--help"]);
    assert_eq!(out.status.code(), Some(0));
    let help = String::from_utf8_lossy(&out.stdout);
    for needed in [
        "--columns <NAME,...>",
        "--lat <LAT>",
        "--lon <LON>",
        "--elevation-m <ELEVATION_M>",
        "zenith_deg    the element's zenith angle, degrees, in [0, 90]",
        "azimuth_deg   its azimuth, degrees from north through east",
        "id,zenith_deg,azimuth_deg,r,g,b,note",
        "Other columns (ids, weights, times, notes) are ignored",
        "masked_fraction",
        "campanile sky fit scan.csv --lat 37.8719 --lon -122.2585",
    ] {
        assert!(help.contains(needed), "`sky fit --help` lacks {needed:?}:\n{help}");
    }
    let out = campanile(&["sky", "eval", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for needed in ["--compare", "CHANNEL_residual", "Any other columns are ignored"] {
        assert!(help.contains(needed), "`sky eval --help` lacks {needed:?}:\n{help}");
    }
    let out = campanile(&["sky", "predict", "--help"]);
    let help = String::from_utf8_lossy(&out.stdout);
    for needed in ["--lat <LAT>", "samples 0 and masked_fraction 0"] {
        assert!(help.contains(needed), "`sky predict --help` lacks {needed:?}:\n{help}");
    }
}

/// The sun of a validation fixture, from its manifest row.
fn fixture_sun(id: &str) -> (String, String) {
    let manifest = std::fs::read_to_string("validation/sky/fixtures/manifest.csv").expect("manifest");
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let row: Vec<&str> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|r| r[0] == id)
        .expect("the fixture's row");
    (row[col("sun_zenith_deg")].into(), row[col("sun_azimuth_deg")].into())
}

#[test]
fn a_gendaylit_sky_is_fitted_to_its_rendering_and_the_convergence_is_recorded() {
    // RADIANCE's clear "Denver noon" sky (validation/sky): the CLI's fit
    // within 0.1% median of rtrace's values, converged, nothing masked; with
    // --no-reject the same; a bad --max-masked is refused.
    let id = "gdl-bin8-denver-noon";
    let samples = format!("validation/sky/fixtures/samples/{id}.csv");
    let (zs, az) = fixture_sun(id);
    let tmp = tempfile::tempdir().expect("temp");
    for (name, extra) in [("robust", None), ("plain", Some("--no-reject"))] {
        let sky = tmp.path().join(format!("{name}.ron"));
        let mut args = vec![
            "sky",
            "fit",
            &samples,
            "--sun-zenith-deg",
            &zs,
            "--sun-azimuth-deg",
            &az,
            "--out",
            sky.to_str().expect("utf-8"),
        ];
        args.extend(extra);
        let out = campanile(&args);
        let log = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{log}");
        for c in ["r", "g", "b"] {
            assert!(log.contains(&format!("{c}: ")) && log.contains("converged ("), "{log}");
        }
        let text = std::fs::read_to_string(&sky).expect("sky file");
        assert_eq!(text.matches("converged: true").count(), 3, "{text}");
        assert_eq!(text.matches("at_bound: []").count(), 3, "{text}");
        assert_eq!(text.matches("masked_fraction: 0.0,").count(), 3, "{text}");
        let out = campanile(&["sky", "eval", sky.to_str().expect("utf-8"), &samples, "--compare"]);
        let summary = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{summary}");
        // "r median 0.000123, p95 …": every channel's median under 0.1%.
        let medians: Vec<f64> = summary
            .split("median ")
            .skip(1)
            .map(|s| {
                s.split(|c: char| c == ',' || c.is_whitespace())
                    .next()
                    .and_then(|x| x.trim_end_matches('%').parse().ok())
                    .expect("a median")
            })
            .collect();
        assert_eq!(medians.len(), 3, "{summary}");
        assert!(medians.iter().all(|m| *m < 1e-3), "{name}: {summary}");
    }
    let out = campanile(&[
        "sky",
        "fit",
        &samples,
        "--sun-zenith-deg",
        &zs,
        "--sun-azimuth-deg",
        &az,
        "--max-masked",
        "1.5",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("expected a fraction from 0 to 1"));
}
