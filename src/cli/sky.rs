//! `campanile sky`: fit sky models to samples, and evaluate them.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use campanile_process::sky::{ChannelSky, SkyFile, angle_between, fit_sky_robust, read_directions, read_samples};
use campanile_process::sun::{Ephemeris, Observer};
use chrono::{DateTime, Utc};
use clap::{Args, Subcommand};

#[derive(Debug, Subcommand)]
pub enum SkyCommand {
    /// Fit the sky model (thesis eq. 5.9) to sky samples, one model per channel.
    ///
    /// SAMPLES is a CSV with zenith_deg, azimuth_deg (from north through
    /// east) and one column per channel (e.g. r,g,b) of radiance. The sun's
    /// position comes from --sun-zenith-deg/--sun-azimuth-deg, or from --time
    /// and --station through the ephemeris. Samples within 0.5° of the sun
    /// (the disc) are left out.
    ///
    /// Samples that are not sky (buildings, trees, glare) are found and left
    /// out by robust fitting; the output gives the masked fraction.
    ///
    /// Each channel gets the smallest model the data supports: one of the 15
    /// CIE standard skies, or the seven-parameter sky (with the aureole fixed
    /// when no sample is within 10° of the sun); the output says which and
    /// why. Weights are relative errors, so the result does not depend on
    /// the radiance unit.
    ///
    /// Example: campanile sky fit scan.csv --time 2026-08-28T20:30:00Z \
    ///            --station examples/sim-station.ron --out sky.ron
    #[command(verbatim_doc_comment)]
    Fit {
        /// Sky samples (CSV).
        samples: PathBuf,
        #[command(flatten)]
        sun: SunArgs,
        /// Where to write the fitted skies (RON); standard output when absent.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Evaluate fitted skies (RON from `sky fit`) at directions.
    ///
    /// DIRECTIONS is a CSV with zenith_deg and azimuth_deg; the output adds
    /// one radiance column per channel.
    #[command(verbatim_doc_comment)]
    Eval {
        /// Fitted skies (RON).
        sky: PathBuf,
        /// Directions (CSV).
        directions: PathBuf,
    },
}

#[derive(Debug, Args)]
pub struct SunArgs {
    /// The sun's zenith angle, degrees.
    #[arg(long, requires = "sun_azimuth_deg", conflicts_with = "time")]
    sun_zenith_deg: Option<f64>,
    /// The sun's azimuth, degrees from north through east.
    #[arg(long, requires = "sun_zenith_deg")]
    sun_azimuth_deg: Option<f64>,
    /// The instant the samples were taken (RFC 3339), with --station.
    #[arg(long, requires = "station")]
    time: Option<DateTime<Utc>>,
    /// The station file whose site the ephemeris uses, with --time.
    #[arg(long, requires = "time")]
    station: Option<PathBuf>,
}

impl SunArgs {
    /// (zenith, azimuth) in radians.
    fn resolve(&self) -> Result<(f64, f64)> {
        match (self.sun_zenith_deg, self.sun_azimuth_deg, self.time, &self.station) {
            (Some(z), Some(a), _, _) => {
                if !(0.0..=90.0).contains(&z) {
                    bail!(
                        "--sun-zenith-deg {z}: expected a zenith angle in [0, 90] degrees (the sky model needs the sun up)"
                    );
                }
                Ok((z.to_radians(), a.to_radians()))
            }
            (_, _, Some(t), Some(path)) => {
                let s = campanile_config::load_station(path)
                    .map_err(|e| anyhow::anyhow!("{e}"))?
                    .value
                    .site;
                let obs = Observer::from_degrees(
                    s.latitude_deg,
                    s.longitude_deg,
                    s.elevation_m,
                    s.pressure_mbar,
                    s.temperature_c,
                );
                let p = Ephemeris::at(t, s.delta_t_s)?.position(&obs)?;
                if p.zenith_rad > std::f64::consts::FRAC_PI_2 {
                    bail!(
                        "at {t} the sun is {:.2}° below the horizon at {}: no daylight sky to fit",
                        -p.elevation_rad().to_degrees(),
                        s.name
                    );
                }
                Ok((p.zenith_rad, p.azimuth_rad))
            }
            _ => bail!("give the sun: --sun-zenith-deg and --sun-azimuth-deg, or --time and --station"),
        }
    }
}

fn direction(zenith: f64, azimuth: f64) -> [f64; 3] {
    [zenith.sin() * azimuth.sin(), zenith.sin() * azimuth.cos(), zenith.cos()]
}

pub fn run(cmd: SkyCommand) -> Result<()> {
    match cmd {
        SkyCommand::Fit { samples, sun, out } => {
            let (zs, az) = sun.resolve()?;
            let file = File::open(&samples).with_context(|| format!("{}: cannot open", samples.display()))?;
            let table = read_samples(BufReader::new(file)).with_context(|| format!("{}", samples.display()))?;
            let sun_dir = direction(zs, az);
            let mut channels = Vec::new();
            for (c, name) in table.channels.iter().enumerate() {
                let pts = table.sky_samples(c, sun_dir);
                let robust =
                    fit_sky_robust(&pts, zs).with_context(|| format!("{}: channel {name}", samples.display()))?;
                let fit = &robust.fit;
                tracing::info!(
                    channel = %name,
                    model = ?fit.kind,
                    rms = fit.rms_relative,
                    masked = robust.masked_fraction,
                    "{}",
                    fit.reason
                );
                channels.push(ChannelSky::new(name, fit, pts.len(), robust.masked_fraction));
            }
            let sky = SkyFile {
                sun_zenith_deg: zs.to_degrees(),
                sun_azimuth_deg: az.to_degrees(),
                channels,
            };
            let text = ron::ser::to_string_pretty(&sky, ron::ser::PrettyConfig::default())?;
            match out {
                Some(path) => {
                    let tmp = path.with_extension("ron.partial");
                    std::fs::write(&tmp, text + "\n").with_context(|| format!("{}: cannot write", tmp.display()))?;
                    std::fs::rename(&tmp, &path).with_context(|| format!("{}: cannot write", path.display()))?;
                }
                None => println!("{text}"),
            }
            Ok(())
        }
        SkyCommand::Eval { sky, directions } => {
            let text = std::fs::read_to_string(&sky).with_context(|| format!("{}: cannot read", sky.display()))?;
            let sky_file: SkyFile =
                ron::from_str(&text).map_err(|e| anyhow::anyhow!("{}:{}: {}", sky.display(), e.span.start, e.code))?;
            let file = File::open(&directions).with_context(|| format!("{}: cannot open", directions.display()))?;
            let table = read_directions(BufReader::new(file)).with_context(|| format!("{}", directions.display()))?;
            let sun_dir = direction(
                sky_file.sun_zenith_deg.to_radians(),
                sky_file.sun_azimuth_deg.to_radians(),
            );
            let mut out = std::io::stdout().lock();
            let names: Vec<&str> = sky_file.channels.iter().map(|c| c.channel.as_str()).collect();
            writeln!(out, "zenith_deg,azimuth_deg,{}", names.join(","))?;
            for &(z, a) in &table.directions {
                let g = angle_between(direction(z, a), sun_dir);
                let vals: Vec<String> = sky_file
                    .channels
                    .iter()
                    .map(|c| format!("{:.9e}", c.model.radiance(z, g)))
                    .collect();
                writeln!(out, "{:.6},{:.6},{}", z.to_degrees(), a.to_degrees(), vals.join(","))?;
            }
            Ok(())
        }
    }
}
