//! Times `read_raw` (rawler decode + normalization + bilinear demosaic) and
//! `merge_linear` on a 12 MP simulated DNG (4000×3000, 14-bit RGGB).
//!
//!     cargo run --release -p campanile-process --example raw_decode_time

use std::time::Instant;

use campanile_process::camera::bayer::{BayerSensor, Exposure};
use campanile_process::camera::test_chart::hdr_chart;
use campanile_process::hdr::dng_file::{DngLayout, DngMetadata, write_dng};
use campanile_process::hdr::linear_merge::{LinearMergeOptions, merge_linear};
use campanile_process::hdr::raw_file::read_raw;

fn main() {
    let (w, h) = (4000, 3000);
    let sensor = BayerSensor::typical_14bit();
    let chart = hdr_chart(w, h);
    let dir = std::env::temp_dir().join("campanile-raw-decode-time");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("error: {}: {e}", dir.display());
        std::process::exit(1);
    }
    let mut paths = Vec::new();
    for (j, t) in [1.0 / 64.0, 1.0 / 16.0, 0.25].into_iter().enumerate() {
        let e = Exposure {
            time_s: t,
            f_number: 4.0,
            iso: 100.0,
        };
        let meta = DngMetadata {
            make: "Campanile".into(),
            model: "Simulated Bayer".into(),
            exposure: e,
            xyz_to_camera: [[0.7, -0.1, -0.05], [-0.45, 1.3, 0.15], [-0.05, 0.2, 0.6]],
            as_shot_neutral: sensor.neutral(),
            calibration_illuminant: 21,
        };
        let p = dir.join(format!("frame{j}.dng"));
        if let Err(e) = write_dng(
            &p,
            &sensor.photograph(&chart, &e, j as u64),
            &meta,
            DngLayout::ThumbnailAndSubIfd,
        ) {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
        paths.push(p);
    }
    let mut frames = Vec::new();
    let mut times = Vec::new();
    for p in &paths {
        let t0 = Instant::now();
        match read_raw(p) {
            Ok(f) => frames.push(f),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
        times.push(t0.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    println!(
        "read_raw, {w}×{h} 14-bit DNG: median {:.3} s per frame (of {})",
        times[times.len() / 2],
        times.len()
    );
    let t0 = Instant::now();
    match merge_linear(&frames, &LinearMergeOptions::default()) {
        Ok(_) => println!(
            "merge_linear, {} frames: {:.3} s",
            frames.len(),
            t0.elapsed().as_secs_f64()
        ),
        Err(e) => eprintln!("error: {e}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}
