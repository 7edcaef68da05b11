//! `campanile sky`: fit sky models to samples, and evaluate them.

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::quality::QualityReport;
use campanile_process::sky::{ChannelSelection, SkyFitOptions};
use campanile_session::site::SunGiven;
use campanile_session::sky_files;
use chrono::{DateTime, Utc};
use clap::{ArgGroup, Args, Subcommand};

#[derive(Debug, Subcommand)]
pub enum SkyCommand {
    /// Fit the sky model (thesis eq. 5.9) to sky samples, one model per channel.
    ///
    /// SAMPLES is a CSV with a header row and one row per sky element:
    ///   zenith_deg    the element's zenith angle, degrees, in [0, 90]
    ///   azimuth_deg   its azimuth, degrees from north through east
    ///                 (-360 to 360)
    ///   channels      its radiance, in any one unit, one column per channel:
    ///                 those --columns names, else r,g,b (or red,green,blue;
    ///                 any case) when all three are there, else the one
    ///                 column named y, luminance or radiance
    /// Other columns (ids, weights, times, notes) are ignored: their cells
    /// are not read. For example:
    ///   id,zenith_deg,azimuth_deg,r,g,b,note
    ///   17,35,190,0.0521,0.0803,0.1302,clear
    ///
    /// The sun: --sun-zenith-deg and --sun-azimuth-deg; or --time with
    /// --station (its site), or --time with --lat and --lon (and
    /// --elevation-m), through the ephemeris (NREL SPA; refraction for
    /// 1013.25 mbar and 12 °C with --lat/--lon, as `campanile sun`). Samples
    /// within 0.5° of the sun (the disc) are left out.
    ///
    /// Samples that are not sky (buildings, the mount, trees, glare) are
    /// found and left out: a graduated robust fit of the sky, then every
    /// sample more than max(3 robust deviations, 5%) off that fit in
    /// |ln(measured/model)| is masked, at most --max-masked of them (the
    /// worst first). --no-reject fits every sample.
    ///
    /// Each channel gets the smallest model the data supports, by the
    /// Bayesian information criterion: the best of the 15 CIE standard
    /// skies (scale only), eq. 5.9 with the aureole fixed (4 parameters),
    /// the Perez all-weather form (h = 1, 6) or the seven-parameter sky (7);
    /// the output says which and why. Bounded Levenberg–Marquardt, started
    /// from the best of the CIE and Perez-table skies; weights are relative
    /// errors, so the result does not depend on the radiance unit.
    ///
    /// OUTPUT (RON, to --out or standard output): sun_zenith_deg and
    /// sun_azimuth_deg (degrees), and per channel, in column order:
    ///   channel          its column's name
    ///   model            eq. (5.9)'s (lz, a, b, c, d, e, h); lz in the
    ///                    samples' unit
    ///   chosen, reason   the model chosen ("Cie(12)", "Perez",
    ///                    "SevenParameter", "SevenParameterFixedAureole")
    ///                    and why
    ///   rms_relative     RMS of measured / fitted − 1 over the sky samples
    ///   samples          samples used (outside the disc)
    ///   masked_fraction  the fraction of them left out as not sky
    ///   masked           how many, darker or brighter, and the threshold
    ///   convergence      the optimizer's ending: converged, termination
    ///                    (Gradient, Reduction, Step, Exact, ClosedForm, or
    ///                    Evaluations: not converged), iterations,
    ///                    evaluations, and any parameter that ended at a
    ///                    bound of its range (the sky's verdict is then poor)
    /// The log (standard error) gives one line per channel: the model, the
    /// residual, the masking and the convergence.
    ///
    /// Examples:
    ///   campanile sky fit scan.csv --lat 37.8719 --lon -122.2585 \
    ///       --time 2026-08-28T20:30:00Z --out sky.ron
    ///   campanile sky fit scan.csv --time 2026-08-28T20:30:00Z \
    ///       --station examples/sim-station.ron --columns r_mean,g_mean,b_mean --out sky.ron
    #[command(verbatim_doc_comment)]
    Fit {
        /// Sky samples (CSV).
        samples: PathBuf,
        /// The channel columns, in order (e.g. r,g,b); by default r,g,b,
        /// red,green,blue, or one of y, luminance, radiance.
        #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
        columns: Option<Vec<String>>,
        #[command(flatten)]
        sun: SunArgs,
        /// Where to write the fitted skies (RON); standard output when absent.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Also write a residual map (PNG): measured / fitted − 1 of the
        /// first channel's samples, binned on a fisheye (zenith at the
        /// centre, horizon on the circle, north up, east right, as seen from
        /// above), −10% blue to +10% red; masked samples count too.
        #[arg(long, value_name = "PNG")]
        residual_map: Option<PathBuf>,
        /// Quality thresholds (a `Quality(...)` RON file, any subset of the
        /// gates). The fit's verdict (residual, samples masked, convergence)
        /// goes to OUT's stem + .quality.json (with no --out, one line on
        /// standard error); a failed fit exits 3.
        #[arg(long, value_name = "FILE.ron")]
        thresholds: Option<PathBuf>,
        /// Fit every sample: no outlier rejection.
        #[arg(long)]
        no_reject: bool,
        /// The largest fraction of samples that may be masked as not sky
        /// (0 to 1); more outliers than that are kept, and said so.
        #[arg(long, default_value_t = campanile_process::sky::MAX_MASKED_FRACTION, value_name = "FRACTION",
              value_parser = fraction)]
        max_masked: f64,
    },
    /// Predict the sky at another sun position from skies fitted at others.
    ///
    /// Interpolates each channel as the thesis does (§5.5.1): the scale, the
    /// background and the aureole of the known skies are averaged separately
    /// with weights inversely proportional to the angle between their suns
    /// and the new sun, then a new model is fitted. Give at least one fitted
    /// sky (RON from `sky fit`), with the same channels, and the new sun:
    /// --sun-zenith-deg and --sun-azimuth-deg, or --time with --station or
    /// with --lat and --lon (as for `sky fit`).
    ///
    /// OUTPUT (RON, to --out or standard output): a sky file as `sky fit`
    /// writes (sun_zenith_deg, sun_azimuth_deg, and per channel: channel,
    /// model (lz, a, b, c, d, e, h), chosen, reason, rms_relative), with
    /// samples 0 and masked_fraction 0: nothing was measured. It inherits
    /// the verdicts of the skies it came from (their .quality.json).
    ///
    /// Example:
    ///   campanile sky predict morning.ron noon.ron evening.ron \
    ///       --time 2026-08-28T22:00:00Z --lat 37.8719 --lon -122.2585 --out sky.ron
    #[command(verbatim_doc_comment)]
    Predict {
        /// Fitted skies (RON), one per time.
        #[arg(required = true)]
        skies: Vec<PathBuf>,
        #[command(flatten)]
        sun: SunArgs,
        /// Where to write the predicted sky (RON); standard output when absent.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Render fitted skies (RON with r, g, b channels) as a lat-long OpenEXR map.
    ///
    /// The upper hemisphere: azimuth 0° (north) at the left edge, east at a
    /// quarter of the width; the zenith on the top row, the horizon at the
    /// bottom; WIDTH × WIDTH/4 pixels, radiance per channel, no sun disc.
    ///
    /// Example:
    ///   campanile sky map sky.ron --out sky.exr --width 1024
    #[command(verbatim_doc_comment)]
    Map {
        /// Fitted skies (RON).
        sky: PathBuf,
        /// Output map (OpenEXR).
        #[arg(long)]
        out: PathBuf,
        /// Map width in pixels (the height is a quarter of it).
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(4..=16384))]
        width: u32,
    },
    /// Evaluate fitted skies (RON from `sky fit` or `sky predict`) at directions.
    ///
    /// DIRECTIONS is a CSV with a header row and one row per direction:
    ///   zenith_deg    degrees, in [0, 90]
    ///   azimuth_deg   degrees from north through east (-360 to 360)
    /// Any other columns are ignored, so a sample file for `sky fit` will do.
    ///
    /// Prints a CSV: zenith_deg, azimuth_deg, then each sky channel's
    /// radiance, named as in the sky file.
    ///
    /// With --compare, DIRECTIONS must also hold the sky's channel columns
    /// (measured radiance, same names): each adds a column CHANNEL_residual,
    /// measured / fitted − 1, and one line on standard error gives per
    /// channel the median and 95th percentile of |measured / fitted − 1|.
    ///
    /// Examples:
    ///   campanile sky eval sky.ron directions.csv
    ///   campanile sky eval sky.ron scan.csv --compare > residuals.csv
    #[command(verbatim_doc_comment)]
    Eval {
        /// Fitted skies (RON).
        sky: PathBuf,
        /// Directions (CSV).
        directions: PathBuf,
        /// Compare with DIRECTIONS' measured channels: add measured /
        /// fitted − 1 columns and a summary on standard error.
        #[arg(long)]
        compare: bool,
    },
    /// Calibrate a fixed sky camera (a fisheye at the zenith) from one day's
    /// sun shots: its orientation and lens, by the sun's known track.
    ///
    /// SHOTS is a CSV with a header row and one row per sun shot:
    ///   time       the shot's instant, RFC 3339 (or a column time_utc)
    ///   u_px,v_px  the sun disc's centroid, pixels (pixel centres at
    ///              half-integers), at the camera's configured resolution
    /// Other columns are ignored. The station (--station) gives the site
    /// (for the ephemeris: NREL SPA, refraction at the site's pressure and
    /// temperature) and the nominal camera: its projection (Pinhole,
    /// Equidistant or Equisolid), focal length, principal point, radial
    /// terms and the head's mount calibration; the head is held at
    /// --pan-deg, --tilt-deg (the zenith by default).
    ///
    /// Fitted by Levenberg–Marquardt on the centroids' pixel residuals:
    /// the orientation as the mount's pan_zero_azimuth_deg, level_roll_deg
    /// and level_pitch_deg (tilt_zero_deg held), the focal length and k1;
    /// k2 and the principal point with --fit-k2 and --fit-principal-point
    /// (one day's track barely separates the principal point from a tilt:
    /// the report gives the correlation). Clouded shots far off the track
    /// are rejected and listed; shots with the sun down are left out.
    ///
    /// OUTPUT (RON, to --out or standard output): CameraCalibration(
    /// resolution, intrinsics, mount), the camera and mount the station
    /// file takes (copy them into `camera.intrinsics` and `head.mount`, or
    /// give the file to `campanile process --camera-calibration`). The
    /// report (residual in degrees, each parameter ± σ, the strongest
    /// correlation, rejected shots) goes to standard error; the verdict
    /// (ok, poor or failed: too few shots, a track too short, a residual
    /// over threshold, ill-conditioned) to OUT's stem + .quality.json; a
    /// failed calibration exits 3.
    ///
    /// Example:
    ///   campanile sky calibrate shots.csv --station examples/sky-fisheye-sim-station.ron \
    ///       --out camera.ron
    #[command(verbatim_doc_comment)]
    Calibrate {
        /// Sun centroids (CSV: time, u_px, v_px).
        shots: PathBuf,
        /// The station file: site, nominal camera and mount.
        #[arg(long)]
        station: PathBuf,
        /// The head's pan while the shots were taken, degrees.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        pan_deg: f64,
        /// The head's tilt while the shots were taken, degrees (90: the zenith).
        #[arg(long, default_value_t = 90.0, allow_negative_numbers = true)]
        tilt_deg: f64,
        /// Fit k2 too (else held at the station's).
        #[arg(long)]
        fit_k2: bool,
        /// Fit the principal point too (else held at the station's).
        #[arg(long)]
        fit_principal_point: bool,
        /// Where to write the calibration (RON); standard output when absent.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The sun: given, or from the ephemeris for a time and a site.
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("site").args(["station", "lat"])))]
pub struct SunArgs {
    /// The sun's zenith angle, degrees.
    #[arg(
        long,
        requires = "sun_azimuth_deg",
        conflicts_with_all = ["time", "station", "lat", "lon"],
        allow_negative_numbers = true
    )]
    sun_zenith_deg: Option<f64>,
    /// The sun's azimuth, degrees from north through east.
    #[arg(long, requires = "sun_zenith_deg", allow_negative_numbers = true)]
    sun_azimuth_deg: Option<f64>,
    /// The instant (RFC 3339, e.g. 2026-08-28T20:30:00Z), with --station or
    /// with --lat and --lon.
    #[arg(long, requires = "site", value_parser = rfc3339)]
    time: Option<DateTime<Utc>>,
    /// The station file whose site the ephemeris uses, with --time.
    #[arg(long, requires = "time")]
    station: Option<PathBuf>,
    /// The site's latitude, degrees, north positive (-90 to 90), with --lon
    /// and --time.
    #[arg(long, requires_all = ["lon", "time"], allow_negative_numbers = true)]
    lat: Option<f64>,
    /// The site's longitude, degrees, east positive (-180 up to 360), with
    /// --lat.
    #[arg(long, requires = "lat", allow_negative_numbers = true)]
    lon: Option<f64>,
    /// The site's height above sea level, metres, with --lat [default: 0].
    #[arg(long, requires = "lat", allow_negative_numbers = true)]
    elevation_m: Option<f64>,
}

/// An instant as RFC 3339 gives it, for `--time`.
fn rfc3339(text: &str) -> Result<DateTime<Utc>, String> {
    DateTime::parse_from_rfc3339(text)
        .map(|t| t.with_timezone(&Utc))
        .map_err(|e| format!("expected an RFC 3339 instant such as 2026-08-28T20:30:00Z ({e})"))
}

impl SunArgs {
    /// The sun as given.
    pub fn given(&self) -> SunGiven {
        SunGiven {
            zenith_deg: self.sun_zenith_deg,
            azimuth_deg: self.sun_azimuth_deg,
            time: self.time,
            station: self.station.clone(),
            lat: self.lat,
            lon: self.lon,
            elevation_m: self.elevation_m,
        }
    }
}

/// Where a product's verdict goes: beside `out`, or one line on standard
/// error when the product went to standard output.
fn finish(quality: &QualityReport, out: Option<&std::path::Path>) -> Result<()> {
    match out {
        Some(path) => super::verdicts::finish(quality, &super::verdicts::beside(path)),
        None => super::verdicts::finish_on_stderr(quality),
    }
}

pub fn run(cmd: SkyCommand) -> Result<()> {
    match cmd {
        SkyCommand::Fit {
            samples,
            columns,
            sun,
            out,
            residual_map,
            thresholds,
            no_reject,
            max_masked,
        } => {
            let options = SkyFitOptions {
                reject_outliers: !no_reject,
                max_masked_fraction: max_masked,
            };
            let q = super::verdicts::thresholds(thresholds.as_deref(), None)?;
            let selection = columns.map_or(ChannelSelection::Auto, ChannelSelection::Named);
            let sun = sun.given().resolve()?;
            let (sky, quality) =
                sky_files::fit_checked(&samples, &selection, sun, &options, residual_map.as_deref(), &q)?;
            super::ron_output::write_ron(&sky, out.as_deref())?;
            finish(&quality, out.as_deref())
        }
        SkyCommand::Predict { skies, sun, out } => {
            let (sky, quality) = sky_files::predict_files(&skies, sun.given().resolve()?)?;
            super::ron_output::write_ron(&sky, out.as_deref())?;
            finish(&quality, out.as_deref())
        }
        SkyCommand::Calibrate {
            shots,
            station,
            pan_deg,
            tilt_deg,
            fit_k2,
            fit_principal_point,
            out,
        } => {
            let options = campanile_process::sky_camera_calibration::CalibrationOptions {
                fit_k2,
                fit_principal_point,
                ..Default::default()
            };
            let cal =
                campanile_session::sky_camera_files::calibrate_files(&shots, &station, (pan_deg, tilt_deg), &options)?;
            eprint!("{}", cal.report);
            let text = campanile_session::sky_camera_files::calibration_ron(&cal.file)?;
            match out.as_deref() {
                Some(path) => campanile_session::partial_file::write(path, text.as_bytes())?,
                None => print!("{text}"),
            }
            finish(&cal.quality, out.as_deref())
        }
        SkyCommand::Map { sky, out, width } => Ok(sky_files::map_file(&sky, width as usize, &out)?),
        SkyCommand::Eval {
            sky,
            directions,
            compare,
        } => Ok(sky_files::eval(
            &sky,
            &directions,
            compare,
            &mut std::io::stdout().lock(),
            &mut std::io::stderr(),
        )?),
    }
}

/// A fraction in [0, 1], for --max-masked.
fn fraction(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if (0.0..=1.0).contains(&x) => Ok(x),
        _ => Err(format!("found {text:?}; expected a fraction from 0 to 1")),
    }
}
