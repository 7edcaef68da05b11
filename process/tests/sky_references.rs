//! The sky fit against skies Campanile did not make (issue 22): RADIANCE's
//! gendaylit rendered by rtrace, and the CIE standard general skies written
//! from the standard's text, committed as CSV under
//! `validation/sky/fixtures/` by `validation/sky/generate.sh --fixtures`
//! (no RADIANCE needed here). Samples as a calibrated sky camera gives
//! them: cos ξ ≥ 0.3 (perezlum.cal's blend toward the ground, up to 0.44%
//! there, is left in the data, not modelled) and 1° or more from the sun.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use campanile_process::error_figures::quantile;
use campanile_process::sky::{
    PARAMETER_RANGES, PerezSky, SkyModel, SkyModelKind, SkySample, angle_between, direction, fit_sky, fit_sky_robust,
    table_extremes,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../validation/sky/fixtures")
}

/// One reference sky: its manifest row and its samples per channel.
struct Reference {
    id: String,
    row: HashMap<String, String>,
    sun_zenith: f64,
    sun: [f64; 3],
    /// (zenith, azimuth) radians.
    directions: Vec<(f64, f64)>,
    channels: Vec<(String, Vec<f64>)>,
}

impl Reference {
    fn samples(&self, values: &[f64]) -> Vec<SkySample> {
        self.directions
            .iter()
            .zip(values)
            .map(|(&(z, a), &v)| SkySample {
                xi: z,
                gamma: angle_between(direction(z, a), self.sun),
                radiance: v,
            })
            .collect()
    }

    fn field(&self, key: &str) -> f64 {
        self.row[key]
            .parse()
            .unwrap_or_else(|e| panic!("{}: {key} = {:?}: {e}", self.id, self.row[key]))
    }
}

fn references() -> Vec<Reference> {
    let dir = fixtures();
    let mut manifest = csv::Reader::from_path(dir.join("manifest.csv")).expect("manifest.csv");
    let header = manifest.headers().expect("header").clone();
    let mut out = Vec::new();
    for rec in manifest.records() {
        let rec = rec.expect("row");
        let row: HashMap<String, String> = header
            .iter()
            .zip(rec.iter())
            .map(|(k, v)| (k.into(), v.into()))
            .collect();
        let id = row["id"].clone();
        let zs: f64 = row["sun_zenith_deg"].parse().expect("zenith");
        let az: f64 = row["sun_azimuth_deg"].parse().expect("azimuth");
        let mut rd = csv::Reader::from_path(dir.join("samples").join(format!("{id}.csv"))).expect("samples");
        let names: Vec<String> = rd.headers().expect("header").iter().skip(2).map(String::from).collect();
        let mut directions = Vec::new();
        let mut values = vec![Vec::new(); names.len()];
        for r in rd.records() {
            let r = r.expect("sample row");
            let x: Vec<f64> = r.iter().map(|c| c.parse().expect("number")).collect();
            directions.push((x[0].to_radians(), x[1].to_radians()));
            for (c, v) in values.iter_mut().enumerate() {
                v.push(x[2 + c]);
            }
        }
        out.push(Reference {
            sun_zenith: zs.to_radians(),
            sun: direction(zs.to_radians(), az.to_radians()),
            row,
            id,
            directions,
            channels: names.into_iter().zip(values).collect(),
        });
    }
    assert!(out.len() >= 30, "{} reference skies", out.len());
    out
}

/// |model / reference − 1| at every sample: (median, p95, max).
fn errors(m: &SkyModel, samples: &[SkySample], truth: &[f64]) -> (f64, f64, f64) {
    let mut e: Vec<f64> = samples
        .iter()
        .zip(truth)
        .map(|(s, &y)| (m.radiance(s.xi, s.gamma) / y - 1.0).abs())
        .collect();
    (quantile(&mut e, 0.5), quantile(&mut e, 0.95), quantile(&mut e, 1.0))
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

#[test]
fn the_perez_table_gives_the_coefficients_gendaylit_printed() {
    let mut worst = 0.0_f64;
    let mut n = 0;
    for r in references().iter().filter(|r| r.row["source"] == "gendaylit") {
        for (c, _) in &r.channels {
            let sky = PerezSky {
                clearness: r.field(&format!("eps_{c}")),
                brightness: r.field(&format!("delta_asked_{c}")),
                sun_zenith: r.sun_zenith,
            };
            let k = sky.coefficients();
            for (i, name) in ["a", "b", "c", "d", "e"].iter().enumerate() {
                let printed = r.field(&format!("{name}_{c}"));
                // gendaylit holds the table in float32 and prints 6 decimals.
                let d = (k[i] - printed).abs() / (1.0 + printed.abs());
                assert!(d < 1e-5, "{} {c} {name}: ours {} gendaylit {printed}", r.id, k[i]);
                worst = worst.max(d);
                n += 1;
            }
        }
    }
    assert!(n >= 300, "{n} coefficients compared");
    eprintln!("{n} coefficients, worst relative difference {worst:.1e}");
}

#[test]
fn every_perez_table_sky_lies_inside_the_fits_ranges_with_a_margin() {
    for (k, ((lo, hi), (min, max))) in PARAMETER_RANGES.iter().zip(table_extremes()).enumerate() {
        let margin = 0.15 * (max - min);
        assert!(
            *lo <= min - margin && *hi >= max + margin,
            "{}: range [{lo}, {hi}] against the table's [{min}, {max}] ± {margin}",
            ["a", "b", "c", "d", "e"][k]
        );
    }
}

#[test]
fn noise_free_references_within_half_a_percent_median_and_1_percent_p95() {
    let mut rows = Vec::new();
    for r in references() {
        for (c, values) in &r.channels {
            let samples = r.samples(values);
            // The path `campanile sky fit` takes: outliers rejected.
            let fit = fit_sky_robust(&samples, r.sun_zenith).unwrap_or_else(|e| panic!("{} {c}: {e}", r.id));
            let (median, p95, max) = errors(&fit.fit.model, &samples, values);
            assert!(
                fit.fit.convergence.converged,
                "{} {c}: {}",
                r.id,
                fit.fit.convergence.summary()
            );
            assert_eq!(fit.masked_fraction, 0.0, "{} {c}: {}", r.id, fit.masked_summary());
            rows.push((format!("{} {c}", r.id), median, p95, max, fit.fit.kind));
        }
    }
    for (name, median, p95, max, kind) in &rows {
        eprintln!(
            "{name}: median {:.3}% p95 {:.3}% max {:.3}% {kind:?}",
            100.0 * median,
            100.0 * p95,
            100.0 * max
        );
    }
    for (name, median, p95, _, _) in &rows {
        assert!(*median <= 0.005 && *p95 <= 0.01, "{name}: median {median} p95 {p95}");
    }
}

#[test]
fn with_2_percent_noise_within_1_2_times_scipys_error() {
    // scipy.optimize.least_squares(method="lm") on the same references with
    // its own 2% Gaussian noise (validation/sky/scipy_fit.py --noise 0.02
    // --seed 7 --cie-starts 12,1): the median over channels of each
    // channel's median and p95 error against the noise-free values.
    let mut rd = csv::Reader::from_path(fixtures().join("scipy_lm.csv")).expect("scipy_lm.csv");
    let mut scipy_median = Vec::new();
    let mut scipy_p95 = Vec::new();
    for rec in rd.records() {
        let rec = rec.expect("row");
        if rec[2].parse::<f64>().expect("noise") > 0.0 {
            scipy_median.push(rec[5].parse::<f64>().expect("median"));
            scipy_p95.push(rec[6].parse::<f64>().expect("p95"));
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let (mut ours_median, mut ours_p95) = (Vec::new(), Vec::new());
    for r in references() {
        for (c, values) in &r.channels {
            let noisy: Vec<f64> = values.iter().map(|v| v * (1.0 + 0.02 * gaussian(&mut rng))).collect();
            let fit = fit_sky_robust(&r.samples(&noisy), r.sun_zenith).unwrap_or_else(|e| panic!("{} {c}: {e}", r.id));
            let (median, p95, _) = errors(&fit.fit.model, &r.samples(values), values);
            ours_median.push(median);
            ours_p95.push(p95);
        }
    }
    let mid = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    assert_eq!(ours_median.len(), scipy_median.len(), "the same channels");
    let (om, sm, op, sp) = (mid(ours_median), mid(scipy_median), mid(ours_p95), mid(scipy_p95));
    eprintln!(
        "2% noise: median error {:.3}% (scipy {:.3}%), p95 {:.3}% (scipy {:.3}%)",
        100.0 * om,
        100.0 * sm,
        100.0 * op,
        100.0 * sp
    );
    assert!(om <= 1.2 * sm && op <= 1.2 * sp, "ours {om} / {op}, scipy {sm} / {sp}");
}

#[test]
fn a_mast_and_a_building_are_masked_and_the_robust_fit_beats_the_plain_one() {
    // 2% noise; a building over 60° of azimuth up to 25° elevation at 10–40%
    // of the sky, and a mast 3° wide from the horizon to the zenith at 5%.
    let mut rng = ChaCha8Rng::seed_from_u64(60);
    let mut worse = 0;
    let mut n = 0;
    for r in references().iter().filter(|r| r.row["source"] == "gendaylit") {
        let sun_az: f64 = r.field("sun_azimuth_deg");
        for (c, values) in &r.channels {
            let mut noisy = Vec::new();
            let mut sky = Vec::new();
            for (&(z, a), &v) in r.directions.iter().zip(values) {
                let az = a.to_degrees();
                // The building faces away from the sun; the mast stands beside it.
                let off = (az - sun_az - 180.0).rem_euclid(360.0);
                let building = !(30.0..=330.0).contains(&off) && z.to_degrees() > 65.0;
                let mast = (az - sun_az - 100.0).rem_euclid(360.0) < 3.0;
                let k = if building {
                    0.1 + 0.3 * rng.random::<f64>()
                } else if mast {
                    0.05
                } else {
                    1.0
                };
                noisy.push(v * k * (1.0 + 0.02 * gaussian(&mut rng)));
                sky.push(k == 1.0);
            }
            let samples = r.samples(&noisy);
            let plain = fit_sky(&samples, r.sun_zenith).expect("fits");
            let robust = fit_sky_robust(&samples, r.sun_zenith).expect("fits");
            let clean: Vec<SkySample> = r.samples(values);
            let keep = |v: &[SkySample]| -> Vec<SkySample> {
                v.iter().zip(&sky).filter(|(_, k)| **k).map(|(s, _)| *s).collect()
            };
            let truth: Vec<f64> = values.iter().zip(&sky).filter(|(_, k)| **k).map(|(v, _)| *v).collect();
            let (rm, rp, _) = errors(&robust.fit.model, &keep(&clean), &truth);
            let (pm, _, _) = errors(&plain.model, &keep(&clean), &truth);
            // Every occluded sample is masked.
            let missed = sky.iter().zip(&robust.kept).filter(|(s, k)| !**s && **k).count();
            assert_eq!(missed, 0, "{} {c}: {} occluded samples kept", r.id, missed);
            assert!(rm < 0.005 && rp < 0.02, "{} {c}: robust median {rm} p95 {rp}", r.id);
            if pm <= rm {
                worse += 1;
            }
            n += 1;
        }
    }
    assert_eq!(
        worse, 0,
        "the plain fit was as good as the robust one on {worse} of {n} channels"
    );
}

#[test]
fn the_plain_fit_chooses_as_before_within_its_evaluation_budget() {
    // The plain fit (every sample, `fit_sky`) of the 79 noise-free channels:
    // which model wins, counted, and the Levenberg–Marquardt evaluations
    // over all candidates. The choice was measured before the fit was made
    // cheaper (41 seven-parameter, 28 Perez form, 10 CIE; 1322 evaluations
    // at commit 639d777; 1181 with the reduction test that skips the
    // confirming evaluation; 996 with the seven-parameter candidate started
    // at λ = 10⁻⁶ from the Perez fit), and a cheaper fit must choose the same.
    let (mut seven, mut perez, mut cie, mut other, mut evaluations) = (0, 0, 0, 0, 0);
    for r in references() {
        for (c, values) in &r.channels {
            let fit = fit_sky(&r.samples(values), r.sun_zenith).unwrap_or_else(|e| panic!("{} {c}: {e}", r.id));
            match fit.kind {
                SkyModelKind::SevenParameter => seven += 1,
                SkyModelKind::Perez => perez += 1,
                SkyModelKind::Cie(_) => cie += 1,
                SkyModelKind::SevenParameterFixedAureole => other += 1,
            }
            evaluations += fit.evaluations;
        }
    }
    eprintln!("{seven} seven-parameter, {perez} Perez, {cie} CIE, {other} fixed aureole; {evaluations} evaluations");
    assert_eq!((seven, perez, cie, other), (41, 28, 10, 0));
    assert!(evaluations <= 1000, "{evaluations} evaluations");
}
