//! `campanile hdr calibrate|merge` end to end: photograph a known HDR chart
//! through the camera model, write the bracket as PNGs, run the commands,
//! and compare the merged EXR with the chart's true radiance.

#[path = "cli_hdr/align.rs"]
mod align;
mod common;
#[path = "cli_hdr/raw.rs"]
mod raw;

use std::path::Path;

use campanile_process::camera::image::{CodeImage, RadianceImage};
use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::test_chart::hdr_chart;
use campanile_process::exr_io::{read_radiance_exr, read_rgb_exr};
use campanile_process::hdr::image_file::write_png;
use common::campanile;
use exif::experimental::Writer;
use exif::{Field, In, Rational, Tag, Value};

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
        "--with-variance",
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

/// EXIF settings of a test JPEG: exposure time, f-number, ISO, orientation.
struct Settings {
    time: (u32, u32),
    f_number: (u32, u32),
    iso: u16,
    orientation: u16,
}

/// Writes `img` as a quality-95 JPEG with an EXIF block (APP1) carrying `s`.
fn write_jpeg_with_exif(img: &CodeImage, path: &Path, s: &Settings) {
    let rgb: Vec<u8> = img.data.iter().map(|&z| z as u8).collect();
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 95)
        .encode(
            &rgb,
            img.width as u32,
            img.height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .expect("jpeg");
    let rational = |(num, denom): (u32, u32)| Value::Rational(vec![Rational { num, denom }]);
    let fields = [
        Field {
            tag: Tag::ExposureTime,
            ifd_num: In::PRIMARY,
            value: rational(s.time),
        },
        Field {
            tag: Tag::FNumber,
            ifd_num: In::PRIMARY,
            value: rational(s.f_number),
        },
        Field {
            tag: Tag::PhotographicSensitivity,
            ifd_num: In::PRIMARY,
            value: Value::Short(vec![s.iso]),
        },
        Field {
            tag: Tag::Orientation,
            ifd_num: In::PRIMARY,
            value: Value::Short(vec![s.orientation]),
        },
    ];
    let mut writer = Writer::new();
    for f in &fields {
        writer.push_field(f);
    }
    let mut tiff = std::io::Cursor::new(Vec::new());
    writer.write(&mut tiff, false).expect("exif");
    let tiff = tiff.into_inner();
    let mut out = jpeg[..2].to_vec();
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&((2 + 6 + tiff.len()) as u16).to_be_bytes());
    out.extend_from_slice(b"Exif\0\0");
    out.extend_from_slice(&tiff);
    out.extend_from_slice(&jpeg[2..]);
    std::fs::write(path, out).expect("write jpeg");
}

/// `img` as stored by a camera held on its side: the upright image turned
/// 90° counter-clockwise, to be turned back by EXIF orientation 6.
fn stored_on_its_side(img: &CodeImage) -> CodeImage {
    let (w, h) = (img.width, img.height);
    let mut data = Vec::with_capacity(img.data.len());
    for ys in 0..w {
        for xs in 0..h {
            let (x, y) = (w - 1 - ys, xs);
            data.extend_from_slice(&img.data[(y * w + x) * 3..(y * w + x) * 3 + 3]);
        }
    }
    CodeImage {
        width: h,
        height: w,
        data,
        ..img.clone()
    }
}

/// Median relative error of `map` against `truth` after the best scale per
/// channel (the curve's gauge is free), on pixels whose three channels lie
/// within the chart's well-exposed range.
fn median_error_after_scale(map: &RadianceImage, truth: &RadianceImage) -> [f64; 3] {
    std::array::from_fn(|c| {
        let mut ratios: Vec<f64> = (0..truth.width * truth.height)
            .map(|p| f64::from(map.data[3 * p + c]) / f64::from(truth.data[3 * p + c]))
            .filter(|r| r.is_finite() && *r > 0.0)
            .collect();
        ratios.sort_by(f64::total_cmp);
        let scale = ratios[ratios.len() / 2];
        let mut rel: Vec<f64> = ratios.iter().map(|r| (r / scale - 1.0).abs()).collect();
        rel.sort_by(f64::total_cmp);
        rel[rel.len() / 2]
    })
}

/// Issue 23: camera JPEGs with EXIF calibrate and merge with no --times and
/// no override; the orientation tag is applied; a bracket that varies
/// aperture and ISO instead of time merges to the same radiance.
#[test]
fn exif_jpegs_calibrate_and_merge_without_times() {
    let dir = tempfile::tempdir().expect("temp");
    let (w, h) = (128, 96);
    let chart = hdr_chart(w, h);
    let camera = CameraModel::typical(8);
    // A time bracket, 2 stops apart, stored on its side (orientation 6).
    let mut side = Vec::new();
    for k in 0..7u32 {
        let t = (1u32 << (2 * k), 64u32);
        let p = dir.path().join(format!("IMG_{k}.JPG"));
        let shot = camera.photograph(&chart, f64::from(t.0) / f64::from(t.1), 11 + u64::from(k));
        let settings = Settings {
            time: t,
            f_number: (8, 1),
            iso: 100,
            orientation: 6,
        };
        write_jpeg_with_exif(&stored_on_its_side(&shot), &p, &settings);
        side.push(p.to_str().expect("utf-8").to_owned());
    }
    let curve = dir.path().join("curve.csv");
    let mut args = vec!["hdr", "calibrate", "-o", curve.to_str().expect("utf-8")];
    args.extend(side.iter().map(String::as_str));
    let out = campanile(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("IMG_0.JPG: EXIF 1/64 s, f/8, ISO 100 → exposure 0.015625 s"),
        "{stdout}"
    );

    let exr = dir.path().join("side.exr");
    let mut args = vec![
        "hdr",
        "merge",
        "--curve",
        curve.to_str().expect("utf-8"),
        "-o",
        exr.to_str().expect("utf-8"),
    ];
    args.extend(side.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map = read_rgb_exr(&exr).expect("plain RGB EXR");
    assert_eq!((map.width, map.height), (w, h), "turned upright");
    let err = median_error_after_scale(&map, &chart);
    assert!(
        err.iter().all(|&e| e < 0.03),
        "orientation-6 bracket: median errors {err:?}"
    );

    // Same relative exposures from aperture and ISO: t·ISO/N² = 1, 4, 16, 64, 256 × (1/64 s at f/8, ISO 100).
    let plan = [
        ((1, 64), (8, 1), 100),
        ((1, 64), (4, 1), 100),
        ((1, 64), (4, 1), 400),
        ((1, 16), (4, 1), 400),
        ((1, 4), (4, 1), 400),
    ];
    let mut mixed = Vec::new();
    for (k, &(time, f_number, iso)) in plan.iter().enumerate() {
        let t_eff = 4f64.powi(k as i32) / 64.0;
        let p = dir.path().join(format!("mixed_{k}.jpg"));
        let settings = Settings {
            time,
            f_number,
            iso,
            orientation: 1,
        };
        write_jpeg_with_exif(&camera.photograph(&chart, t_eff, 40 + k as u64), &p, &settings);
        mixed.push(p.to_str().expect("utf-8").to_owned());
    }
    let exr2 = dir.path().join("mixed.exr");
    let mut args = vec![
        "hdr",
        "merge",
        "--curve",
        curve.to_str().expect("utf-8"),
        "-o",
        exr2.to_str().expect("utf-8"),
    ];
    args.extend(mixed.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map2 = read_rgb_exr(&exr2).expect("plain RGB EXR");
    // Against the time bracket's map: same scale (same curve, same gauge).
    for c in 0..3 {
        let mut rel: Vec<f64> = (0..w * h)
            .map(|p| (f64::from(map2.data[3 * p + c]) / f64::from(map.data[3 * p + c]) - 1.0).abs())
            .filter(|r| r.is_finite())
            .collect();
        rel.sort_by(f64::total_cmp);
        let median = rel[rel.len() / 2];
        assert!(
            median < 0.03,
            "channel {c}: aperture/ISO bracket vs time bracket median {median}"
        );
    }

    // A PNG without EXIF and no --times: a usage error naming the file and the way out.
    let png = dir.path().join("plain.png");
    write_png(&camera.photograph(&chart, 0.1, 1), &png).expect("png");
    let out = campanile(&["hdr", "calibrate", "-o", curve.to_str().unwrap(), png.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("plain.png") && stderr.contains("ExposureTime") && stderr.contains("--times"),
        "{stderr}"
    );
}

/// Issue 23: a green channel that a camera clips at 254 in every exposure
/// (the phone's moon) is marked clipped, not merged into a magenta pixel;
/// the radiance map is also written as Radiance RGBE.
#[test]
fn channel_clipped_below_the_largest_code_is_masked() {
    let dir = tempfile::tempdir().expect("temp");
    let (w, h) = (96, 64);
    let chart = hdr_chart(w, h);
    let camera = CameraModel::typical(8);
    let times = [1.0 / 16.0, 0.25, 1.0, 4.0, 16.0];
    let times_arg = "1/16,1/4,1,4,16";
    // The moon: a 12×12 square, red and blue well exposed in the short
    // frames, green written as 254 in every frame.
    let in_moon = |p: usize| (40..52).contains(&(p % w)) && (20..32).contains(&(p / w));
    let mut paths = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let mut shot = camera.photograph(&chart, t, 3 + k as u64);
        for p in (0..w * h).filter(|&p| in_moon(p)) {
            let rb = ((40.0 * t * 16.0) as u16).min(255);
            shot.data[3 * p..3 * p + 3].copy_from_slice(&[rb, 254, rb]);
        }
        let path = dir.path().join(format!("m{k}.png"));
        write_png(&shot, &path).expect("png");
        paths.push(path.to_str().expect("utf-8").to_owned());
    }
    let curve = dir.path().join("c.csv");
    let mut args = vec!["hdr", "calibrate", "--times", times_arg, "-o", curve.to_str().unwrap()];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("m0.png: green piles up at code 254 (below the largest, 255): codes ≥ 253 treated as clipped"),
        "{stdout}"
    );
    let exr = dir.path().join("moon.exr");
    let mut args = vec![
        "hdr",
        "merge",
        "--with-variance",
        "--times",
        times_arg,
        "--curve",
        curve.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map = read_radiance_exr(&exr).expect("EXR with mask");
    let moon: Vec<usize> = (0..w * h).filter(|&p| in_moon(p)).collect();
    let flagged = moon.iter().filter(|&&p| map.mask[p] & 0b010 != 0).count();
    assert_eq!(flagged, moon.len(), "every moon pixel's green flagged saturated");
    assert!(moon.iter().all(|&p| !map.is_valid(p)), "no moon pixel valid");
    // The green bound (the darkest exposure's clipped value) is not below red: not magenta.
    let p = moon[moon.len() / 2];
    assert!(
        map.rgb[3 * p + 1] >= 0.5 * map.rgb[3 * p],
        "green {} red {}",
        map.rgb[3 * p + 1],
        map.rgb[3 * p]
    );

    // Radiance RGBE by extension; the OpenEXR-only options are refused for it.
    let hdr = dir.path().join("moon.hdr");
    let mut args = vec![
        "hdr",
        "merge",
        "--times",
        times_arg,
        "--curve",
        curve.to_str().unwrap(),
        "-o",
        hdr.to_str().unwrap(),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let rgbe = image::open(&hdr).expect("readable .hdr").into_rgb32f();
    assert_eq!((rgbe.width() as usize, rgbe.height() as usize), (w, h));
    let q = 5 * w + 5;
    let (got, want) = (rgbe.as_raw()[3 * q], map.rgb[3 * q]);
    assert!((got / want - 1.0).abs() < 0.01, "RGBE {got} vs EXR {want}");
    args.push("--with-variance");
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}

/// ln exposure per code and channel from a curve CSV: Campanile's own
/// (`ResponseCurve`) or a peer's `code,ln_exposure_r,ln_exposure_g,ln_exposure_b`.
fn peer_curve(path: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(path).expect("curve csv");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("code"))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().expect("number")).collect();
            [v[1], v[2], v[3]]
        })
        .collect()
}

/// Per channel, the RMS in stops of the difference of two ln-exposure curves
/// over codes 10–245, after removing the mean (the curves' free offset):
/// the measure of validation/hdr/compare_curves.py.
fn stops_rms(a: &[[f64; 3]], b: &[[f64; 3]]) -> [f64; 3] {
    std::array::from_fn(|c| {
        let d: Vec<f64> = (10..=245).map(|z| a[z][c] - b[z][c]).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt() / std::f64::consts::LN_2
    })
}

/// Issue 23, on a real camera's files (Canon EOS 5D Mark II in-camera JPEGs,
/// 18 frames 13 s … 1/8000 s, 640² crops with their EXIF; GPL-3.0 data, see
/// validation/hdr/README.md): calibrate and merge with no --times and no
/// override; the times read agree with exiftool's; the curve agrees with
/// the peers', with hdrgen's own fit of these frames within the 0.10
/// stops in every channel (0.065 / 0.059 / 0.084), and in red and green
/// with the maker's shipped hdrgen curve within 0.10. Blue is 0.124 from the
/// shipped curve, as every peer is (0.136–0.141), and the pixels support
/// Campanile's curve there, not the shipped one (validation/hdr/README.md,
/// "Which curve the pixels support": 0.088 against 0.175 stops of pixel-pair
/// error): the bound there is the peers' level, not the issue's.
#[test]
fn real_camera_jpegs_calibrate_and_merge_from_exif() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/hdr/fixtures/radiantlab-eos");
    let mut jpegs: Vec<String> = std::fs::read_dir(&set)
        .expect("fixture set")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "JPG"))
        .map(|p| p.to_str().expect("utf-8").to_owned())
        .collect();
    jpegs.sort();
    assert_eq!(jpegs.len(), 18);
    let dir = tempfile::tempdir().expect("temp");
    let curve = dir.path().join("eos.csv");
    let mut args = vec!["hdr", "calibrate", "-o", curve.to_str().unwrap()];
    args.extend(jpegs.iter().map(String::as_str));
    let out = campanile(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // exiftool's ExposureTime per file against the effective time printed.
    let exiftool = std::fs::read_to_string(set.join("exposures.csv")).expect("exposures.csv");
    for line in exiftool.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let want = match cells[1].split_once('/') {
            Some((n, d)) => n.parse::<f64>().unwrap() / d.parse::<f64>().unwrap(),
            None => cells[1].parse::<f64>().unwrap(),
        };
        let printed = stdout
            .lines()
            .find(|l| l.contains(&format!("{}: EXIF", cells[0])))
            .unwrap_or_else(|| panic!("{}: no EXIF line in {stdout}", cells[0]));
        let got: f64 = printed
            .rsplit_once("→ exposure ")
            .and_then(|(_, t)| t.trim_end_matches(" s").parse().ok())
            .expect("a time");
        assert!(
            (got / want - 1.0).abs() < 1e-3,
            "{}: {got} vs exiftool {want}",
            cells[0]
        );
    }

    let ours = {
        let text = std::fs::read_to_string(&curve).unwrap();
        let c = campanile_process::hdr::curve::ResponseCurve::from_csv(&text, &curve).expect("curve");
        let luts: Vec<Vec<f64>> = (0..3).map(|ch| c.exposure_lut(ch)).collect();
        (0..256)
            .map(|z| std::array::from_fn(|ch| luts[ch][z].ln()))
            .collect::<Vec<[f64; 3]>>()
    };
    let peers = set.join("curves/crop");
    let maker = stops_rms(&ours, &peer_curve(&peers.join("hdrgen_rsp.csv")));
    assert!(
        maker[0] <= 0.10 && maker[1] <= 0.10 && maker[2] <= 0.14,
        "stops RMS against the maker's curve (R, G, B): {maker:?}"
    );
    let hdrgen = stops_rms(&ours, &peer_curve(&peers.join("hdrgen_rerun.csv")));
    assert!(
        hdrgen.iter().all(|&s| s <= 0.10),
        "stops RMS against hdrgen's own fit of the frames (R, G, B): {hdrgen:?}"
    );
    let opencv = stops_rms(&ours, &peer_curve(&peers.join("opencv_robertson.csv")));
    assert!(
        opencv.iter().all(|&s| s <= 0.05),
        "stops RMS against OpenCV Robertson: {opencv:?}"
    );

    let exr = dir.path().join("eos.exr");
    let mut args = vec![
        "hdr",
        "merge",
        "--curve",
        curve.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
    ];
    args.extend(jpegs.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map = read_rgb_exr(&exr).expect("plain RGB EXR");
    assert_eq!((map.width, map.height), (640, 640));
    assert!(
        map.data.iter().all(|v| v.is_finite() && *v >= 0.0),
        "finite, non-negative radiance"
    );
}
