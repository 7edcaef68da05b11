//! Sky fit, speed against error (samples used → error and time), and the
//! data for the scipy comparison in `bench/sky/run.sh`.
//!
//!     cargo run --release -p campanile-process --example sky_fit_bench -- OUT_DIR
//!
//! For each sampling step it renders a seeded clear sky (eq. 5.9, 2% noise,
//! ξ ≤ 80°, a building hiding azimuths 200°–260°), fits it, and prints one
//! row: samples, fit time, visible-sky and whole-sky RMS relative error. It
//! It then fits 1000 random valid skies and reports how many converge. It
//! also writes the samples of the densest grid and the fitted parameters to
//! OUT_DIR for scipy to refit.

use std::f64::consts::PI;
use std::io::Write;
use std::time::Instant;

use campanile_process::sky::{SkyModel, SkySample, angle_between, direction, fit_sky};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).ok_or("usage: sky_fit_bench OUT_DIR")?;
    let truth = SkyModel {
        lz: 0.08,
        a: -1.0,
        b: -0.45,
        c: 14.0,
        d: -3.6,
        e: 0.6,
        h: 0.85,
    };
    let zs = 0.7_f64;
    let sun = [zs.sin(), 0.0, zs.cos()];
    let grid = |step_deg: f64, max_xi: f64, occlude: bool| {
        let mut v = Vec::new();
        let mut xi = 0.0_f64;
        while xi <= max_xi {
            let n = ((360.0 / step_deg) * xi.sin()).ceil().max(1.0) as usize;
            for k in 0..n {
                let az = 2.0 * PI * k as f64 / n as f64;
                if occlude && (200f64.to_radians()..260f64.to_radians()).contains(&az) {
                    continue;
                }
                let d = direction(xi, az);
                let g = angle_between(d, sun);
                if g > 0.5f64.to_radians() {
                    v.push((xi, g));
                }
            }
            xi += step_deg.to_radians();
        }
        v
    };
    let whole = grid(2.0, 89f64.to_radians(), false);
    let err = |m: &SkyModel, dirs: &[(f64, f64)]| {
        (dirs
            .iter()
            .map(|&(x, g)| (m.radiance(x, g) / truth.radiance(x, g) - 1.0).powi(2))
            .sum::<f64>()
            / dirs.len() as f64)
            .sqrt()
    };
    println!(
        "| grid step | samples | fit time | evaluations | visible RMS error | whole-sky RMS error | model chosen |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for step in [20.0, 12.0, 8.0, 5.0, 3.0, 2.0] {
        let dirs = grid(step, 80f64.to_radians(), true);
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let samples: Vec<SkySample> = dirs
            .iter()
            .map(|&(xi, gamma)| SkySample {
                xi,
                gamma,
                radiance: truth.radiance(xi, gamma) * (1.0 + 0.02 * 3f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0)),
            })
            .collect();
        let reps = 20;
        let t = Instant::now();
        let mut fit = fit_sky(&samples, zs)?;
        for _ in 1..reps {
            fit = fit_sky(&samples, zs)?;
        }
        let ms = t.elapsed().as_secs_f64() * 1e3 / reps as f64;
        println!(
            "| {step}° | {} | {ms:.2} ms | {} | {:.3}% | {:.3}% | {:?} |",
            samples.len(),
            fit.evaluations,
            100.0 * err(&fit.model, &dirs),
            100.0 * err(&fit.model, &whole),
            fit.kind
        );
        if step == 3.0 {
            let mut f = std::fs::File::create(format!("{out}/sky_samples.csv"))?;
            writeln!(f, "xi,gamma,radiance")?;
            for s in &samples {
                writeln!(f, "{:.17e},{:.17e},{:.17e}", s.xi, s.gamma, s.radiance)?;
            }
            let m = fit.model;
            std::fs::write(
                format!("{out}/sky_campanile.csv"),
                format!(
                    "lz,a,b,c,d,e,h,ms\n{},{},{},{},{},{},{},{ms}\n",
                    m.lz, m.a, m.b, m.c, m.d, m.e, m.h
                ),
            )?;
            let mut g = std::fs::File::create(format!("{out}/sky_whole.csv"))?;
            writeln!(g, "xi,gamma,truth")?;
            for &(x, gm) in &whole {
                writeln!(g, "{x:.17e},{gm:.17e},{:.17e}", truth.radiance(x, gm))?;
            }
        }
    }
    // Robustness: 1000 random valid skies (seeded), 2% noise, ξ ≤ 85°;
    // converged means whole-sky RMS error below 2%.
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let (mut ok, mut worst, mut nan) = (0, 0.0f64, 0);
    let trials = 1000;
    let t = Instant::now();
    for _ in 0..trials {
        let zs: f64 = rng.random_range(0.05..1.5);
        let sky = SkyModel {
            lz: 10f64.powf(rng.random_range(-3.0..3.0)),
            a: rng.random_range(-1.0..2.0),
            b: rng.random_range(-1.0..-0.1),
            c: rng.random_range(0.0..25.0),
            d: rng.random_range(-4.0..-1.0),
            e: rng.random_range(0.0..0.6),
            h: rng.random_range(0.7..1.3),
        };
        let sun = [zs.sin(), 0.0, zs.cos()];
        let mut samples = Vec::new();
        let mut dirs = Vec::new();
        let mut xi = 0.0_f64;
        while xi <= 85f64.to_radians() {
            let n = ((360.0 / 6.0) * xi.sin()).ceil().max(1.0) as usize;
            for k in 0..n {
                let az = 2.0 * PI * k as f64 / n as f64;
                let g = angle_between(direction(xi, az), sun);
                if g > 0.5f64.to_radians() {
                    let y = sky.radiance(xi, g) * (1.0 + 0.02 * 3f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0));
                    samples.push(SkySample {
                        xi,
                        gamma: g,
                        radiance: y,
                    });
                    dirs.push((xi, g));
                }
            }
            xi += 6f64.to_radians();
        }
        let fit = fit_sky(&samples, zs)?;
        let e = (dirs
            .iter()
            .map(|&(x, g)| (fit.model.radiance(x, g) / sky.radiance(x, g) - 1.0).powi(2))
            .sum::<f64>()
            / dirs.len() as f64)
            .sqrt();
        if !e.is_finite() {
            nan += 1;
        } else if e < 0.02 {
            ok += 1;
        }
        worst = worst.max(if e.is_finite() { e } else { f64::INFINITY });
    }
    println!();
    println!(
        "random skies: {ok} of {trials} converged (whole-sky RMS < 2%), {nan} NaN, worst {:.3}%, {:.1} ms per fit",
        100.0 * worst,
        t.elapsed().as_secs_f64() * 1e3 / trials as f64
    );
    Ok(())
}
