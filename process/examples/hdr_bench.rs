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
    // The memory roofline, measured in this run: the copy bandwidth of
    // large buffers (read + written bytes per second) on the merge's
    // threads, and a kernel that moves exactly the merge's bytes (every
    // frame's codes read, radiance, variance and mask written through the
    // same row-parallel loop) with next to no arithmetic.
    let merge_best_ms = merge_ms.iter().copied().fold(f64::INFINITY, f64::min);
    let copy_gb_s = copy_bandwidth_gb_s(rayon::current_num_threads());
    let copy1_gb_s = copy_bandwidth_gb_s(1);
    // (On a copy of the map's buffers: the merged map is scored below.)
    let traffic_ms = same_traffic_ms(&bracket, &mut map.clone(), repeats.max(10));
    let bytes_per_px_exp = merge_bytes_per_px_exp(bracket.len());
    let merge_gb_s = (w * h * bracket.len()) as f64 * bytes_per_px_exp / (merge_best_ms / 1e3) / 1e9;
    println!("memory_copy_gb_s={copy_gb_s:.2}");
    println!("memory_copy_one_thread_gb_s={copy1_gb_s:.2}");
    println!("merge_bytes_per_px_exp={bytes_per_px_exp:.3}");
    println!("merge_best_gb_s={merge_gb_s:.2}");
    println!("merge_share_of_copy_roofline={:.3}", merge_gb_s / copy_gb_s);
    println!("same_traffic_kernel_best_ms={traffic_ms:.3}");
    println!("merge_share_of_same_traffic_kernel={:.3}", traffic_ms / merge_best_ms);
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

/// Bytes the merge must move per pixel and exposure: three u16 codes read,
/// and its share of the 25 bytes a pixel written (radiance and variance, 3
/// f32 each, and the mask byte).
fn merge_bytes_per_px_exp(exposures: usize) -> f64 {
    6.0 + 25.0 / exposures as f64
}

/// Best of five copies of a 256 MiB buffer on `threads` threads, in GB/s of
/// bytes read plus bytes written.
fn copy_bandwidth_gb_s(threads: usize) -> f64 {
    let n = 256 << 20;
    let src = vec![1u8; n];
    let mut dst = vec![0u8; n];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let chunk = n / threads;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        pool.install(|| {
            use rayon::prelude::*;
            dst.par_chunks_mut(chunk)
                .zip(src.par_chunks(chunk))
                .for_each(|(d, s)| d.copy_from_slice(s));
        });
        best = best.min(t0.elapsed().as_secs_f64());
    }
    std::hint::black_box(&dst);
    2.0 * n as f64 / best / 1e9
}

/// Best time (ms) of a pass that reads every frame's codes and writes the
/// map's radiance, variance and mask row by row like the merge, with one
/// addition per sample instead of the merge's tables.
fn same_traffic_ms(bracket: &Bracket, map: &mut campanile_process::hdr::merge::RadianceMap, repeats: usize) -> f64 {
    use rayon::prelude::*;
    let w = bracket.width();
    let images: Vec<&[u16]> = bracket.images().iter().map(|im| im.data.as_slice()).collect();
    let mut best = f64::INFINITY;
    for _ in 0..repeats {
        let t0 = Instant::now();
        map.rgb
            .par_chunks_mut(w * 3)
            .zip(map.variance.par_chunks_mut(w * 3))
            .zip(map.mask.par_chunks_mut(w))
            .enumerate()
            .for_each_init(Vec::new, |acc: &mut Vec<u32>, (y, ((rgb, var), mask))| {
                // Vectorized sums of the frames' rows, then the writes.
                let base = y * w * 3;
                acc.clear();
                acc.resize(w * 3, 0);
                for im in &images {
                    for (a, &z) in acc.iter_mut().zip(&im[base..base + w * 3]) {
                        *a += u32::from(z);
                    }
                }
                for ((r, v), &a) in rgb.iter_mut().zip(var.iter_mut()).zip(acc.iter()) {
                    *r = a as f32;
                    *v = (a + 1) as f32;
                }
                for (m, a) in mask.iter_mut().zip(acc.chunks_exact(3)) {
                    *m = (a[0] & 1) as u8;
                }
            });
        best = best.min(t0.elapsed().as_secs_f64());
    }
    std::hint::black_box(&map.rgb);
    best * 1e3
}
