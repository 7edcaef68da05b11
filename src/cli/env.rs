//! `campanile env`: fit environment region models, and predict regions
//! under new light.

use std::path::PathBuf;

use anyhow::{Context, Result};
use campanile_session::env_files;
use clap::Subcommand;

use super::sky::SunArgs;

#[derive(Debug, Subcommand)]
pub enum EnvCommand {
    /// Fit each environment region's radiance model (thesis eq. 5.15).
    ///
    /// OBSERVATIONS is a CSV with one row per region and time: region (a
    /// label), r,g,b (the region's mean radiance), sky_r,sky_g,sky_b (the
    /// sky's flux E_sky), sun_r,sun_g,sun_b (solar irradiance E_sun),
    /// sun_zenith_deg, sun_azimuth_deg. Each region gets ρ_sky, ρ_sun and a
    /// normal from at least three solar positions, or the sky term alone when
    /// it was never sunlit, the sun term does not pay for itself, or the sun
    /// track is too nearly planar to give a normal; the output says which
    /// and why, with the conditioning figures.
    ///
    /// Example:
    ///   campanile env fit observations.csv --out env.ron
    #[command(verbatim_doc_comment)]
    Fit {
        /// Region observations (CSV).
        observations: PathBuf,
        /// Where to write the models (RON); standard output when absent.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Quality thresholds (a `Quality(...)` RON file, any subset of the
        /// gates). Each region's verdict (its residual) goes to OUT's stem +
        /// .quality.json (with no --out, one line on standard error); a
        /// failed region exits 3.
        #[arg(long, value_name = "FILE.ron")]
        thresholds: Option<PathBuf>,
    },
    /// Predict every region's radiance under new light (eq. 5.13).
    ///
    /// Prints a CSV: region, r, g, b.
    ///
    /// Example:
    ///   campanile env predict env.ron --sky-irradiance 80,90,120 --sun-irradiance 900,850,780 \
    ///       --sun-zenith-deg 35 --sun-azimuth-deg 200
    #[command(verbatim_doc_comment)]
    Predict {
        /// Region models (RON from `env fit`).
        models: PathBuf,
        /// The sky's flux E_sky per channel, "r,g,b".
        #[arg(long, value_name = "R,G,B")]
        sky_irradiance: String,
        /// Solar irradiance E_sun per channel, "r,g,b".
        #[arg(long, value_name = "R,G,B")]
        sun_irradiance: String,
        #[command(flatten)]
        sun: SunArgs,
    },
}

fn rgb(flag: &str, text: &str) -> Result<[f64; 3]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--{flag} {text:?}: expected three numbers \"r,g,b\""))?;
    match v.as_slice() {
        &[r, g, b] if v.iter().all(|x| x.is_finite() && *x >= 0.0) => Ok([r, g, b]),
        _ => Err(super::exit::bad_input(format!(
            "--{flag} {text:?}: expected three non-negative numbers \"r,g,b\""
        ))),
    }
}

pub fn run(cmd: EnvCommand) -> Result<()> {
    match cmd {
        EnvCommand::Fit {
            observations,
            out,
            thresholds,
        } => {
            let q = super::verdicts::thresholds(thresholds.as_deref(), None)?;
            let (models, quality) = env_files::fit(&observations, &q)?;
            super::ron_output::write_ron(&models, out.as_deref())?;
            match &out {
                Some(path) => super::verdicts::finish(&quality, &super::verdicts::beside(path)),
                None => super::verdicts::finish_on_stderr(&quality),
            }
        }
        EnvCommand::Predict {
            models,
            sky_irradiance,
            sun_irradiance,
            sun,
        } => {
            let e_sky = rgb("sky-irradiance", &sky_irradiance)?;
            let e_sun = rgb("sun-irradiance", &sun_irradiance)?;
            let sun = sun.given().resolve_any()?;
            Ok(env_files::predict(
                &models,
                e_sky,
                e_sun,
                sun,
                &mut std::io::stdout().lock(),
            )?)
        }
    }
}
