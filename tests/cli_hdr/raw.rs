//! `campanile hdr merge` on RAW frames: a simulated DNG bracket of the HDR
//! chart (known radiance) merged linearly with no curve and no --times, and
//! the usage errors around RAW input.

use std::path::{Path, PathBuf};

use crate::common::campanile;
use campanile_process::camera::bayer::{BayerSensor, Exposure};
use campanile_process::camera::test_chart::hdr_chart;
use campanile_process::exr_io::read_radiance_exr;
use campanile_process::hdr::dng_file::{DngLayout, DngMetadata, write_dng};
use campanile_process::hdr::image_file::write_png;

// 256 px across the chart's 18 stops: 0.07 stop per pixel. At 128 px the
// bilinear demosaic's error on the steep ramp alone adds ~0.3 %.
const W: usize = 256;
const H: usize = 128;

/// A 14-bit DSLR-class sensor (40 000 e⁻ at the white level, 4 e⁻ read
/// noise): photon noise then leaves the merge 0.7–0.8 % median error
/// (process/tests/raw_bracket.rs has the breakdown).
fn sensor() -> BayerSensor {
    BayerSensor {
        full_well_electrons: 40_000.0,
        ..BayerSensor::typical_14bit()
    }
}

fn write_bracket(dir: &Path, sensor: &BayerSensor) -> (Vec<String>, Exposure) {
    let chart = hdr_chart(W, H);
    let exposures: Vec<Exposure> = [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0, 4.0]
        .iter()
        .map(|&time_s| Exposure {
            time_s,
            f_number: 4.0,
            iso: 100.0,
        })
        .collect();
    let paths = exposures
        .iter()
        .enumerate()
        .map(|(j, e)| {
            let p: PathBuf = dir.join(format!("IMG_{j:04}.DNG"));
            let meta = DngMetadata {
                make: "Campanile".into(),
                model: "Simulated Bayer".into(),
                exposure: *e,
                xyz_to_camera: [[0.7, -0.1, -0.05], [-0.45, 1.3, 0.15], [-0.05, 0.2, 0.6]],
                as_shot_neutral: sensor.neutral(),
                calibration_illuminant: 21,
            };
            write_dng(
                &p,
                &sensor.photograph(&chart, e, 40 + j as u64),
                &meta,
                DngLayout::ThumbnailAndSubIfd,
            )
            .expect("DNG");
            p.to_str().expect("utf-8").to_owned()
        })
        .collect();
    (paths, exposures[0])
}

#[test]
fn raw_bracket_merges_linearly_without_curve_or_times() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let (paths, first) = write_bracket(dir.path(), &sensor);
    let exr = dir.path().join("merged.exr");
    // The map is relative to the first frame: --scale turns it into radiance.
    let scale = (0..3)
        .map(|c| (1.0 / sensor.normalized_value(1.0, &first, c)).to_string())
        .collect::<Vec<_>>()
        .join(",");
    let mut args = vec![
        "hdr",
        "merge",
        "--with-variance",
        "--scale",
        &scale,
        "--full-well",
        "40000",
        "--out",
        exr.to_str().expect("utf-8"),
    ];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let map = read_radiance_exr(&exr).expect("readable EXR");
    assert_eq!((map.width, map.height), (W, H));
    let chart = hdr_chart(W, H);
    for c in 0..3 {
        let mut rel: Vec<f64> = (0..W * H)
            .filter(|&p| map.is_valid(p))
            .map(|p| (f64::from(map.rgb[3 * p + c]) / f64::from(chart.data[3 * p + c]) - 1.0).abs())
            .collect();
        assert!(rel.len() > W * H * 9 / 10, "channel {c}: {} valid", rel.len());
        rel.sort_by(f64::total_cmp);
        let median = rel[rel.len() / 2];
        assert!(median <= 0.01, "channel {c}: median relative error {median}");
    }
    let q: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("merged.quality.json")).expect("verdict"))
            .expect("json");
    assert_eq!(q["verdict"], "ok", "{q}");
}

#[test]
fn raw_usage_errors_exit_2_with_the_reason() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let (paths, _) = write_bracket(dir.path(), &sensor);
    let curve = dir.path().join("c.csv");
    let exr = dir.path().join("m.exr");

    let mut args = vec!["hdr", "calibrate", "--out", curve.to_str().expect("utf-8")];
    args.extend(paths.iter().map(String::as_str));
    let out = campanile(&args);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("RAW frames are linear: merge them directly with `campanile hdr merge` (no curve needed)"),
        "{err}"
    );

    // Mixed RAW and PNG.
    let png = dir.path().join("shot.png");
    let cam = campanile_process::camera::sensor::CameraModel::typical(8);
    write_png(&cam.photograph(&hdr_chart(W, H), 0.25, 1), &png).expect("png");
    let out = campanile(&[
        "hdr",
        "merge",
        "--times",
        "1,2",
        "--out",
        exr.to_str().expect("utf-8"),
        &paths[0],
        png.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!(
            "the bracket mixes RAW and non-RAW frames ({} is RAW, {} is not)",
            paths[0],
            png.display()
        )),
        "{err}"
    );

    // PNG without --curve.
    let out = campanile(&[
        "hdr",
        "merge",
        "--times",
        "1",
        "--out",
        exr.to_str().expect("utf-8"),
        png.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--curve is required for PNG/TIFF/JPEG brackets"), "{err}");
}
