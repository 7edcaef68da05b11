//! `campanile hdr calibrate|merge` end to end: photograph a known HDR chart
//! through the camera model, write the bracket as PNGs, run the commands,
//! and compare the merged EXR with the chart's true radiance.

mod common;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::test_chart::hdr_chart;
use campanile_process::exr_io::read_radiance_exr;
use campanile_process::hdr::image_file::write_png;
use common::campanile;

#[test]
fn calibrate_then_merge_recovers_the_chart_radiance() {
    let dir = tempfile::tempdir().expect("temp");
    let (w, h) = (128, 96);
    let chart = hdr_chart(w, h);
    let camera = CameraModel::typical(8);
    let times = [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0, 4.0, 16.0, 64.0];
    let mut paths = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let p = dir.path().join(format!("shot{k}.png"));
        write_png(&camera.photograph(&chart, t, 7 + k as u64), &p).expect("png");
        paths.push(p.to_str().expect("utf-8").to_owned());
    }
    let times_arg = times.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(",");
    let curve = dir.path().join("curve.csv");
    let exr = dir.path().join("merged.exr");

    let mut args = vec![
        "hdr",
        "calibrate",
        "--times",
        &times_arg,
        "--out",
        curve.to_str().expect("utf-8"),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(curve.is_file() && curve.with_extension("svg").is_file());

    let mut args = vec![
        "hdr",
        "merge",
        "--times",
        &times_arg,
        "--curve",
        curve.to_str().expect("utf-8"),
        "--out",
        exr.to_str().expect("utf-8"),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));

    // The curve's gauge is free: compare after the best single scale per channel.
    let map = read_radiance_exr(&exr).expect("readable EXR");
    assert_eq!((map.width, map.height), (w, h));
    for c in 0..3 {
        let mut ratios: Vec<f64> = (0..w * h)
            .filter(|&p| map.is_valid(p))
            .map(|p| f64::from(map.rgb[3 * p + c]) / f64::from(chart.radiance(p % w, p / w, c)))
            .collect();
        assert!(
            ratios.len() > w * h * 9 / 10,
            "channel {c}: only {} valid pixels",
            ratios.len()
        );
        ratios.sort_by(f64::total_cmp);
        let scale = ratios[ratios.len() / 2];
        let mut rel: Vec<f64> = ratios.iter().map(|r| (r / scale - 1.0).abs()).collect();
        rel.sort_by(f64::total_cmp);
        let median = rel[rel.len() / 2];
        assert!(median < 0.02, "channel {c}: median relative error {median}");
    }
}

#[test]
fn duplicate_exposure_times_are_a_usage_error() {
    let dir = tempfile::tempdir().expect("temp");
    let chart = hdr_chart(64, 48);
    let camera = CameraModel::typical(8);
    let mut paths = Vec::new();
    for k in 0..3 {
        let p = dir.path().join(format!("s{k}.png"));
        write_png(&camera.photograph(&chart, 0.5, k), &p).expect("png");
        paths.push(p.to_str().expect("utf-8").to_owned());
    }
    let curve = dir.path().join("c.csv");
    let mut args = vec![
        "hdr",
        "calibrate",
        "--times",
        "0.5,0.5,2",
        "--out",
        curve.to_str().expect("utf-8"),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!curve.exists(), "no partial output");
}
