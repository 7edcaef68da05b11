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

    // The verdicts beside the products: both ok on the chart.
    for product in ["curve.quality.json", "merged.quality.json"] {
        let q: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join(product)).expect(product)).unwrap();
        assert_eq!(q["verdict"], "ok", "{product}: {q}");
    }

    // An all-black and an all-white bracket merge (every pixel is masked)
    // but fail their gate: exit 3, naming the figure (issue 21).
    for (name, code, figure) in [
        ("black", 0u16, "fraction of pixels dark in every exposure 1 > 0.5"),
        ("white", 255, "fraction of pixels clipped in every exposure 1 > 0.5"),
    ] {
        let mut shots = Vec::new();
        for k in 0..3 {
            let p = dir.path().join(format!("{name}{k}.png"));
            let img = campanile_process::camera::image::CodeImage {
                width: 16,
                height: 12,
                bits: 8,
                data: vec![code; 16 * 12 * 3],
                label: name.into(),
            };
            write_png(&img, &p).expect("png");
            shots.push(p.to_str().expect("utf-8").to_owned());
        }
        let exr = dir.path().join(format!("{name}.exr"));
        let mut args = vec![
            "hdr",
            "merge",
            "--times",
            "0.01,0.1,1",
            "--curve",
            curve.to_str().expect("utf-8"),
            "--out",
            exr.to_str().expect("utf-8"),
        ];
        args.extend(shots.iter().map(String::as_str));
        let out = campanile(&args);
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert_eq!(out.status.code(), Some(3), "{name}: {stdout}{stderr}");
        assert!(stdout.contains(figure), "{name}: {stdout}");
        let q: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join(format!("{name}.quality.json"))).unwrap()).unwrap();
        assert_eq!(q["products"][0]["verdict"], "failed", "{name}: {q}");

        // Thresholds are data: a file that accepts a blank frame passes it
        // (exit 0); one whose bounds are in the wrong order is refused
        // (exit 2), naming the field.
        let lenient = dir.path().join("lenient.ron");
        std::fs::write(
            &lenient,
            "Quality(merge: (valid: (poor: 0.0, failed: 0.0), clipped: (poor: 1.0, failed: 1.0), \
             dark: (poor: 1.0, failed: 1.0)))",
        )
        .unwrap();
        let bad = dir.path().join("bad.ron");
        std::fs::write(&bad, "Quality(merge: (valid: (poor: 0.5, failed: 0.9)))").unwrap();
        for (thresholds, code, expected) in [(&lenient, 0, "quality: 1 ok"), (&bad, 2, "merge.valid.failed")] {
            let mut with = args.clone();
            with.extend(["--thresholds", thresholds.to_str().unwrap()]);
            let out = campanile(&with);
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            assert_eq!(
                out.status.code(),
                Some(code),
                "{name}, {}: {text}",
                thresholds.display()
            );
            assert!(text.contains(expected), "{name}: {text}");
        }
    }

    // A merge through a curve whose verdict says failed inherits it: the
    // chart's good bracket merged through it exits 3 and says why.
    let verdict = dir.path().join("curve.quality.json");
    let mut q: serde_json::Value = serde_json::from_slice(&std::fs::read(&verdict).unwrap()).unwrap();
    q["verdict"] = "failed".into();
    std::fs::write(&verdict, q.to_string()).unwrap();
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
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(3), "{stdout}");
    assert!(
        stdout.contains("(inherited from ") && stdout.contains("curve.csv: failed"),
        "{stdout}"
    );
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
