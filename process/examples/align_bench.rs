//! Timing of hand-held bracket alignment (`hdr::align`): photographs the
//! textured scene through the camera model at 7 exposures, each moved by a
//! known shift (one also rotated), aligns them to the middle one and warps
//! them, and prints the time of each stage and the largest shift error.
//!
//! Usage: `align_bench [WIDTH HEIGHT]` (default 6000 4000). Run in release:
//! `cargo run --release -p campanile-process --example align_bench`.
//! Prints one `key=value` line per figure on stdout.

use std::time::Instant;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::test_chart::SEVEN_STOP_TIMES_S;
use campanile_process::camera::textured_scene::textured_scene;
use campanile_process::hdr::align::{AlignOptions, align_bracket, warp_bracket};
use campanile_process::hdr::bracket::Bracket;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize, d: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (w, h) = (num(1, 6000), num(2, 4000));
    // Times one stop apart around 1 s, so the textured scene (0.0007–3.7) is mid-grey in all.
    let times: Vec<f64> = SEVEN_STOP_TIMES_S.iter().map(|t| t.sqrt()).collect();
    let motion = [
        (3.25, -1.5, 0.0),
        (-7.75, 2.0, 0.0),
        (12.5, 6.25, 0.5),
        (0.0, 0.0, 0.0),
        (1.5, 4.25, 1.0),
        (-2.4, -5.6, 0.0),
        (20.75, -14.5, -0.8),
    ];
    let cam = CameraModel::typical(8);
    let t0 = Instant::now();
    let imgs = times
        .iter()
        .zip(motion)
        .enumerate()
        .map(|(k, (&t, (dx, dy, deg)))| {
            let deg: f64 = deg;
            cam.photograph(&textured_scene(w, h, dx, dy, deg.to_radians()), t, 90 + k as u64)
        })
        .collect();
    let bracket = Bracket::new(imgs, times.clone())?;
    println!("simulate_s={:.2}", t0.elapsed().as_secs_f64());
    let t1 = Instant::now();
    let al = align_bracket(&bracket, &AlignOptions::default())?;
    let align_s = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let warped = warp_bracket(&bracket, &al.transforms())?;
    let warp_s = t2.elapsed().as_secs_f64();
    let mut worst_px = 0.0f64;
    let mut worst_deg = 0.0f64;
    for (k, (a, (dx, dy, deg))) in al.images.iter().zip(motion).enumerate() {
        let t = a.transform;
        worst_px = worst_px.max((t.dx - dx).abs()).max((t.dy - dy).abs());
        worst_deg = worst_deg.max((t.angle_rad.to_degrees() - deg).abs());
        println!(
            "image{k}=dx {:+.3} dy {:+.3} rot {:+.3}° disagreement {:.3} iterations {} {:?}",
            t.dx,
            t.dy,
            t.angle_rad.to_degrees(),
            a.disagreement,
            a.iterations,
            a.verdict
        );
    }
    println!("size={w}x{h} frames={}", warped.len());
    println!("threads={}", rayon::current_num_threads());
    println!("align_s={align_s:.2}");
    println!("warp_s={warp_s:.2}");
    println!("max_shift_error_px={worst_px:.4}");
    println!("max_angle_error_deg={worst_deg:.4}");
    Ok(())
}
