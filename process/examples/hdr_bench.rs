//! Benchmark driver for `bench/hdr/run.sh`: photographs the synthetic chart
//! through the camera model (7 exposures), writes the stack as PNG with the
//! exposure times and the true curve and radiance, reads the PNGs back, and
//! times Campanile's calibration and merge on them.
//!
//! Usage: `hdr_bench OUT_DIR [WIDTH HEIGHT REPEATS]` (default 1024 768 5).
//! Prints one `key=value` line per figure on stdout.

use std::io::Write as _;
use std::path::Path;
use std::time::Instant;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::debevec::{DebevecOptions, calibrate_debevec};
use campanile_process::hdr::image_file::{read_code_image, write_png};
use campanile_process::hdr::merge::{MergeOptions, median_relative_error, merge, merge_into};
use campanile_process::hdr::robertson::{RobertsonOptions, calibrate_robertson};
use campanile_process::hdr::sampling::SampleOptions;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let out = Path::new(args.get(1).map(String::as_str).unwrap_or("hdr-bench-out")).to_path_buf();
    let num = |i: usize, d: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (w, h, repeats) = (num(2, 1024), num(3, 768), num(4, 5).max(1));
    std::fs::create_dir_all(&out)?;
    let cam = CameraModel::typical(8);
    let scene = hdr_chart(w, h);
    let mut files = Vec::new();
    for (j, &t) in SEVEN_STOP_TIMES_S.iter().enumerate() {
        let img = cam.photograph(&scene, t, 1000 + j as u64);
        let p = out.join(format!("exposure_{j}.png"));
        write_png(&img, &p)?;
        files.push(p);
    }
    std::fs::write(
        out.join("times.txt"),
        SEVEN_STOP_TIMES_S.iter().map(|t| format!("{t}\n")).collect::<String>(),
    )?;
    let mut truth = String::from("code,ln_r,ln_g,ln_b\n");
    for z in 0..=255 {
        let v: Vec<String> = (0..3)
            .map(|c| format!("{:.9}", cam.true_ln_exposure(f64::from(z).max(0.5), c)))
            .collect();
        truth.push_str(&format!("{z},{}\n", v.join(",")));
    }
    std::fs::write(out.join("truth_curve.csv"), truth)?;
    let mut f = std::fs::File::create(out.join("truth_radiance.f32"))?;
    f.write_all(&scene.data.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>())?;

    let images = files
        .iter()
        .map(|p| read_code_image(p))
        .collect::<Result<Vec<_>, _>>()?;
    let bracket = Bracket::new(images, SEVEN_STOP_TIMES_S.to_vec())?;
    let opts = DebevecOptions::default();
    let mut cal_ms = Vec::new();
    let mut cal = None;
    for _ in 0..repeats {
        let t0 = Instant::now();
        cal = Some(calibrate_debevec(&bracket, &opts)?);
        cal_ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    let cal = cal.expect("repeats ≥ 1");
    std::fs::write(out.join("campanile_curve.csv"), cal.curve.to_csv(&cal.method))?;
    let mopts = MergeOptions::default();
    let mut merge_ms = Vec::new();
    let t0 = Instant::now();
    let mut map = merge(&bracket, &cal.curve, &mopts)?;
    let first_merge_ms = t0.elapsed().as_secs_f64() * 1e3;
    // Steady state: buffers reused, as when merging a stream of brackets.
    for _ in 0..repeats.max(10) {
        let t0 = Instant::now();
        merge_into(&bracket, &cal.curve, &mopts, &mut map)?;
        merge_ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    let (err, _) = median_relative_error(&map, &scene.data);
    let valid = map.mask.iter().filter(|&&m| m == 0).count() as f64 / map.mask.len() as f64;
    campanile_process::exr_io::write_radiance_exr(&map, &out.join("campanile_radiance.exr"))?;
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let merge_med = med(&mut merge_ms);
    let merge_best = merge_ms[0];
    println!("width={w}");
    println!("height={h}");
    println!("exposures={}", bracket.len());
    println!("threads={}", rayon::current_num_threads());
    println!("campanile_calibrate_ms={:.3}", med(&mut cal_ms));
    println!("campanile_merge_first_call_ms={first_merge_ms:.3}");
    println!("campanile_merge_ms={merge_med:.3}");
    println!("campanile_merge_best_ms={merge_best:.3}");
    println!(
        "campanile_merge_best_mpx_exp_per_s={:.1}",
        (w * h * bracket.len()) as f64 / 1e6 / (merge_best / 1e3)
    );
    println!(
        "campanile_merge_mpx_exp_per_s={:.1}",
        (w * h * bracket.len()) as f64 / 1e6 / (merge_med / 1e3)
    );
    println!("campanile_merge_median_rel_error={err:.5}");
    println!("campanile_merge_valid_fraction={valid:.4}");
    for c in 0..3 {
        let e = cal.curve.log_rms_error(c, |z| cam.true_ln_exposure(z, c), 5, 250);
        println!("campanile_curve_log_rms_{}={e:.5}", ["r", "g", "b"][c]);
    }
    let mean_err = |curve: &campanile_process::hdr::curve::ResponseCurve| {
        (0..3)
            .map(|c| curve.log_rms_error(c, |z| cam.true_ln_exposure(z, c), 5, 250))
            .sum::<f64>()
            / 3.0
    };
    // Robertson, for comparison (same samples).
    let t0 = Instant::now();
    let (rob, _) = calibrate_robertson(&bracket, &RobertsonOptions::default())?;
    println!(
        "campanile_robertson_calibrate_ms={:.3}",
        t0.elapsed().as_secs_f64() * 1e3
    );
    println!("campanile_robertson_curve_log_rms_mean={:.5}", mean_err(&rob));
    // Knob sweep: samples per channel and the dark-end correction, time against error.
    for samples in [250usize, 1000, 4000, 16000] {
        for correct_noise_bias in [false, true] {
            let o = DebevecOptions {
                sampling: SampleOptions {
                    samples,
                    ..Default::default()
                },
                correct_noise_bias,
                ..Default::default()
            };
            let t0 = Instant::now();
            let c = calibrate_debevec(&bracket, &o)?;
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            println!(
                "sweep_samples={samples} noise_bias_correction={correct_noise_bias} calibrate_ms={ms:.1} curve_log_rms_mean={:.5}",
                mean_err(&c.curve)
            );
        }
    }
    Ok(())
}
