//! The sky fit on the independent references of `validation/sky` (RADIANCE
//! gendaylit skies rendered by rtrace, CIE standard skies): per sky and
//! channel, the fit's time and its error against the references, noise-free
//! and with 2% Gaussian noise; the time of Campanile's Levenberg–Marquardt
//! of the Perez form alone from the start the fit chose (`fit_perez_from`,
//! the like-for-like figure against scipy); and that start, so that
//! `validation/sky/scipy_fit.py --start` runs scipy's Levenberg–Marquardt
//! from the same start in the same run (`bench/sky/run.sh`).
//!
//!     cargo run --release -p campanile-process --example sky_references_bench -- DIR OUT_DIR
//!
//! DIR holds `manifest.csv` and `samples/` (the full set made by
//! `validation/sky/generate.sh`, or `validation/sky/fixtures`). Writes
//! OUT_DIR/campanile.csv and OUT_DIR/start.csv.

use std::collections::HashMap;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use campanile_process::error_figures::quantile;
use campanile_process::sky::{
    SkyModel, SkyModelKind, SkySample, angle_between, direction, fit_perez_from, fit_sky, fit_sky_robust,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

type Error = Box<dyn std::error::Error>;

/// The best of `reps` timings of `f`, milliseconds, and its last result.
fn best_ms<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..reps {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        last = Some(r);
    }
    (best, last.unwrap_or_else(|| unreachable!("reps ≥ 1")))
}

fn errors(m: &SkyModel, samples: &[SkySample], truth: &[f64]) -> (f64, f64, f64) {
    let mut e: Vec<f64> = samples
        .iter()
        .zip(truth)
        .map(|(s, &y)| (m.radiance(s.xi, s.gamma) / y - 1.0).abs())
        .collect();
    (quantile(&mut e, 0.5), quantile(&mut e, 0.95), quantile(&mut e, 1.0))
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().collect();
    let [_, dir, out] = args.as_slice() else {
        return Err("usage: sky_references_bench DIR OUT_DIR".into());
    };
    let dir = Path::new(dir);
    std::fs::create_dir_all(out)?;
    let mut results = std::fs::File::create(Path::new(out).join("campanile.csv"))?;
    let mut starts = std::fs::File::create(Path::new(out).join("start.csv"))?;
    writeln!(
        results,
        "id,channel,n,kind,converged,plain_ms,robust_ms,median_err,p95_err,max_err,robust_median_err,robust_p95_err,robust_max_err,masked,noisy_median_err,noisy_p95_err,evaluations,samples_evaluated,perez_evaluations,seven_evaluations,fixed_evaluations,lm_ms,lm_evaluations,lm_p95_err"
    )?;
    writeln!(starts, "id,channel,lz,a,b,c,d,e")?;
    let mut three = std::fs::File::create(Path::new(out).join("three.csv"))?;
    writeln!(three, "id,channels,n,serial_ms,parallel_ms")?;
    let mut manifest = csv::Reader::from_path(dir.join("manifest.csv"))?;
    let header = manifest.headers()?.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for rec in manifest.records() {
        let rec = rec?;
        let row: HashMap<&str, &str> = header.iter().zip(rec.iter()).collect();
        if row["n_nonpositive"] != "0" {
            continue;
        }
        let id = row["id"];
        let zs: f64 = row["sun_zenith_deg"].parse::<f64>()?.to_radians();
        let sun = direction(zs, row["sun_azimuth_deg"].parse::<f64>()?.to_radians());
        let mut rd = csv::Reader::from_path(dir.join("samples").join(format!("{id}.csv")))?;
        let names: Vec<String> = rd.headers()?.iter().skip(2).map(String::from).collect();
        let mut gammas = Vec::new();
        let mut xis = Vec::new();
        let mut values = vec![Vec::new(); names.len()];
        for r in rd.records() {
            let r = r?;
            let x: Vec<f64> = r.iter().map(str::parse).collect::<Result<_, _>>()?;
            let (z, a) = (x[0].to_radians(), x[1].to_radians());
            xis.push(z);
            gammas.push(angle_between(direction(z, a), sun));
            for (c, v) in values.iter_mut().enumerate() {
                v.push(x[2 + c]);
            }
        }
        let channels: Vec<Vec<SkySample>> = values
            .iter()
            .map(|v| {
                xis.iter()
                    .zip(&gammas)
                    .zip(v)
                    .map(|((&xi, &gamma), &radiance)| SkySample { xi, gamma, radiance })
                    .collect()
            })
            .collect();
        let (serial_ms, _) = best_ms(5, || channels.iter().map(|s| fit_sky(s, zs)).collect::<Vec<_>>());
        let (parallel_ms, _) = best_ms(5, || channels.par_iter().map(|s| fit_sky(s, zs)).collect::<Vec<_>>());
        writeln!(
            three,
            "{id},{},{},{serial_ms:.4},{parallel_ms:.4}",
            channels.len(),
            xis.len()
        )?;
        for (name, v) in names.iter().zip(&values) {
            let samples: Vec<SkySample> = xis
                .iter()
                .zip(&gammas)
                .zip(v)
                .map(|((&xi, &gamma), &radiance)| SkySample { xi, gamma, radiance })
                .collect();
            let (plain_ms, plain) = best_ms(5, || fit_sky(&samples, zs));
            let plain = plain?;
            let (robust_ms, robust) = best_ms(5, || fit_sky_robust(&samples, zs));
            let robust = robust?;
            let (lm_ms, lm) = best_ms(5, || fit_perez_from(&samples, &plain.start_model));
            let (lm_model, lm_convergence) = lm?;
            let (_, lm_p95, _) = errors(&lm_model, &samples, v);
            let candidate_evaluations = |kind: SkyModelKind| {
                plain
                    .candidates
                    .iter()
                    .find(|c| c.kind == kind)
                    .map_or(0, |c| c.evaluations)
            };
            let seven = candidate_evaluations(SkyModelKind::SevenParameter);
            let fixed = candidate_evaluations(SkyModelKind::SevenParameterFixedAureole);
            let (m, p, x) = errors(&plain.model, &samples, v);
            let (rm, rp, rx) = errors(&robust.fit.model, &samples, v);
            let noisy: Vec<SkySample> = samples
                .iter()
                .map(|s| {
                    let (u, w): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
                    let g = (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * w).cos();
                    SkySample {
                        radiance: s.radiance * (1.0 + 0.02 * g),
                        ..*s
                    }
                })
                .collect();
            let nf = fit_sky_robust(&noisy, zs)?;
            let (nm, np, _) = errors(&nf.fit.model, &samples, v);
            writeln!(
                results,
                "{id},{name},{},{},{},{plain_ms:.4},{robust_ms:.4},{m:.6e},{p:.6e},{x:.6e},{rm:.6e},{rp:.6e},{rx:.6e},{:.4},{nm:.6e},{np:.6e},{},{},{},{seven},{fixed},{lm_ms:.4},{},{lm_p95:.6e}",
                samples.len(),
                plain.kind.label(),
                plain.convergence.converged,
                robust.masked_fraction,
                plain.evaluations,
                plain.evaluations * samples.len(),
                plain.evaluations - seven - fixed,
                lm_convergence.evaluations
            )?;
            let s = plain.start_model;
            writeln!(starts, "{id},{name},{},{},{},{},{},{}", s.lz, s.a, s.b, s.c, s.d, s.e)?;
        }
    }
    Ok(())
}
