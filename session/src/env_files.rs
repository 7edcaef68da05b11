//! Environment regions on plain files, as `campanile env` runs them: each
//! region's radiance model fitted to its observations (thesis eq. 5.15),
//! and every region predicted under new light (eq. 5.13).

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::Path;

use anyhow::Context;
use campanile_process::environment::{EnvironmentFile, RegionRecord, fit_region, read_observations};
use campanile_process::quality::{Quality, QualityReport, gates};

use crate::{Error, Result};

/// The region models fitted to the observations in the CSV
/// `observations`, with each region's verdict against `q`.
pub fn fit(observations: &Path, q: &Quality) -> Result<(EnvironmentFile, QualityReport)> {
    let file = File::open(observations).with_context(|| format!("{}: cannot open", observations.display()))?;
    let groups = read_observations(BufReader::new(file)).with_context(|| format!("{}", observations.display()))?;
    let mut regions = Vec::new();
    for (label, obs) in &groups {
        let fit = fit_region(obs).with_context(|| format!("{}: region {label}", observations.display()))?;
        tracing::info!(region = %label, model = ?fit.kind, rms = fit.rms_relative, "{}", fit.reason);
        regions.push(RegionRecord {
            region: label.clone(),
            fit,
        });
    }
    let quality = QualityReport::new(
        regions
            .iter()
            .map(|r| gates::environment_region(&r.region, &r.fit, q))
            .collect(),
        q,
    );
    Ok((EnvironmentFile { regions }, quality))
}

/// Writes to `out` a CSV (region, r, g, b) of every region of the models
/// file `models` under the sky flux `e_sky` and solar irradiance `e_sun`
/// with the sun at `(zenith, azimuth)` radians.
pub fn predict(models: &Path, e_sky: [f64; 3], e_sun: [f64; 3], (z, a): (f64, f64), out: &mut dyn Write) -> Result<()> {
    let l = campanile_process::sky::direction(z, a);
    let text = std::fs::read_to_string(models).with_context(|| format!("{}: cannot read", models.display()))?;
    let env: EnvironmentFile = ron::from_str(&text)
        .map_err(|e| Error::Work(anyhow::anyhow!("{}:{}: {}", models.display(), e.span.start, e.code)))?;
    writeln!(out, "region,r,g,b")?;
    for r in &env.regions {
        let v = r.fit.radiance(e_sky, e_sun, l);
        writeln!(out, "{},{:.9e},{:.9e},{:.9e}", r.region, v[0], v[1], v[2])?;
    }
    Ok(())
}
