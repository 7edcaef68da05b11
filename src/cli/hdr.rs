//! `campanile hdr calibrate|merge|lens`: camera response recovery, HDR
//! merging and lens calibration on plain files. The science lives in
//! `campanile_process::hdr`; this module parses arguments, reads and writes
//! files, and maps errors to exit codes.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use campanile_process::camera::image::max_code;
use campanile_process::exr_io::{ExrPrecision, read_rgb_exr, write_radiance_exr, write_rgb_exr};
use campanile_process::hdr::HdrError;
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::bracket_files::BracketFiles;
use campanile_process::hdr::bracket_list::{
    FrameRecord, TimeSource, load_bracket_files, parse_time_s, read_bracket_list,
};
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::curve_plot::curve_plot_svg;
use campanile_process::hdr::debevec::{DEFAULT_LAMBDA, DebevecOptions, Smoothness, calibrate_debevec};
use campanile_process::hdr::deghost::{DeghostOptions, merge_deghosted};
use campanile_process::hdr::exposure_codes::ExposureCodes;
use campanile_process::hdr::lens::{LensModel, fit_distortion, fit_falloff, undistort_map};
use campanile_process::hdr::merge::{MergeOptions, NoiseModel, RadianceMap, merge};
use campanile_process::hdr::merge_stream::merge_files;
use campanile_process::hdr::robertson::{RobertsonOptions, calibrate_robertson};
use campanile_process::hdr::sampled_bracket::SampledBracket;
use campanile_process::hdr::sampling::SampleOptions;
use campanile_process::hdr::white_point::WhitePoint;
use campanile_process::rgbe_file::write_rgbe;
use clap::{Args, Subcommand, ValueEnum};

mod align;
mod raw;

use super::verdicts;
use super::{EXIT_FAILURE, EXIT_OK, EXIT_USAGE};
use campanile_process::quality::{ProductQuality, Quality, QualityReport, gates};

#[derive(Debug, Subcommand)]
pub enum HdrCommand {
    /// Recover the camera response curve from an exposure bracket.
    ///
    /// Input: PNG, TIFF or JPEG files, 8 or 16 bits per sample, grey or RGB
    /// (alpha ignored), turned upright by their EXIF orientation (RAW frames
    /// are linear and need no curve: merge them directly). Exposure
    /// times come from --times, from --list, or else from each file's EXIF
    /// (ExposureTime, with FNumber and ISO when every frame has them: the
    /// relative exposure is t·ISO/N², so brackets that vary aperture or ISO
    /// work). Codes where a frame's histogram piles up below the largest
    /// code (a JPEG clipping at 254) are treated as clipped.
    ///
    /// Writes the curve as CSV (g(z) = ln relative exposure per code and
    /// channel, with its 1σ uncertainty and support) and an SVG plot with the
    /// ±2σ band. Frames are decoded one at a time, keeping only the pixels
    /// the sampling can pick (about 4 bytes a pixel plus two frames).
    ///
    /// Example:
    ///   campanile hdr calibrate IMG_*.JPG -o curve.csv
    ///   campanile hdr calibrate a.png b.png c.png --times 1/250,1/60,1/15 -o curve.csv
    #[command(verbatim_doc_comment)]
    Calibrate(CalibrateArgs),
    /// Merge an exposure bracket into a radiance map (OpenEXR or Radiance RGBE).
    ///
    /// Input as for `calibrate`, or camera RAW (DNG, CR2, CR3, NEF, ARW, RAF,
    /// RW2, ORF, PEF, SRW; a DNG under any name), which merges linearly with
    /// no --curve: exposure time, f-number and ISO from the files (relative
    /// exposure t·ISO/N²), clipping from the white level.
    ///
    /// Output by OUT's extension or --format:
    /// - .exr (default): plain RGB (float, or half with --half), which every
    ///   viewer opens; with --with-variance also variance.R/G/B, valid (1/0)
    ///   and mask (bits: saturated 1<<c, underexposed 8<<c);
    /// - .hdr: Radiance RGBE (hdrgen's and RADIANCE's format; no variance).
    ///
    /// Pixels clipped in every exposure keep the darkest exposure's bound and
    /// are counted in the verdict (OUT's stem + .quality.json).
    ///
    /// Frames are decoded one at a time into per-pixel sums: memory is about
    /// 24 bytes a pixel plus two frames (0.8 GB for 21 MP), whatever the
    /// number of frames; --align and --deghost hold every frame.
    ///
    /// Example:
    ///   campanile hdr merge IMG_*.JPG --curve curve.csv -o scene.exr
    ///   campanile hdr merge IMG_*.JPG --curve curve.csv -o scene.hdr
    ///   campanile hdr merge DSC_*.NEF -o scene.exr
    #[command(verbatim_doc_comment)]
    Merge(MergeArgs),
    /// Fit the lens model 1 + a r² + b r⁴ (falloff and distortion).
    ///
    /// Falloff from a flat-field radiance map (EXR with R, G, B; a uniformly
    /// lit uniform target filling the view); distortion from a CSV of
    /// "r_distorted,r_ideal" normalized radii (r = 1 at the corners).
    ///
    /// Example:
    ///   campanile hdr lens --flat flat-field.exr --pairs grid-radii.csv -o lens.txt
    ///   campanile hdr merge IMG_*.JPG --curve curve.csv --lens lens.txt -o scene.exr
    #[command(verbatim_doc_comment)]
    Lens(LensArgs),
}

#[derive(Debug, Args)]
pub struct BracketArgs {
    /// Images of the bracket: PNG, TIFF or JPEG (8 or 16 bits), or camera
    /// RAW for `merge` (DNG, CR2, CR3, NEF, ARW, RAF, RW2, ORF, PEF, SRW; a
    /// DNG under any name).
    #[arg(value_name = "IMAGE")]
    images: Vec<PathBuf>,
    /// Exposure times in seconds, one per image, comma separated ("1/30"
    /// allowed); default: each file's EXIF.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    times: Vec<String>,
    /// A bracket list instead of IMAGE…: plain text, one "IMAGE TIME_S" per
    /// line, or CSV with a header naming "file" and "time" columns (and
    /// optionally "iso" and "f_number").
    #[arg(long, conflicts_with_all = ["images", "times"])]
    list: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Debevec–Malik (smoothness-regularized least squares).
    Debevec,
    /// Robertson et al. (iterative maximum likelihood), for comparison.
    Robertson,
}

#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    bracket: BracketArgs,
    /// Output curve (CSV).
    #[arg(long, short)]
    out: PathBuf,
    /// Output plot (SVG); default: the curve's path with .svg.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Recovery method.
    #[arg(long, value_enum, default_value_t = Method::Debevec)]
    method: Method,
    /// Smoothness weight λ (Debevec–Malik).
    #[arg(long, default_value_t = DEFAULT_LAMBDA)]
    lambda: f64,
    /// Pixels sampled per channel.
    #[arg(long, default_value_t = 4000)]
    samples: usize,
    /// Seed of the sample selection.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also fit the true exposure times (labelled times are often off by a few %).
    #[arg(long)]
    fit_times: bool,
    /// Accepted and ignored: resampled-looking input is no longer refused
    /// (camera JPEGs look resampled too; see validation/hdr/README.md).
    #[arg(long = "allow-resampled", hide = true)]
    _allow_resampled: bool,
    /// Quality thresholds (a `Quality(...)` RON file, any subset of the
    /// gates). The curve's verdict goes to OUT's stem + .quality.json; a
    /// failed curve exits 3.
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
    /// Align a hand-held bracket to its middle exposure first (translation
    /// and rotation up to 3°, to a fraction of a pixel), printing the
    /// transform found for each image.
    #[arg(long)]
    align: bool,
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    #[command(flatten)]
    bracket: BracketArgs,
    /// Response curve (CSV from `hdr calibrate`); required for PNG/TIFF/JPEG,
    /// not used for RAW (linear) frames.
    #[arg(long)]
    curve: Option<PathBuf>,
    /// Colour space of a merged RAW bracket (camera: the sensor's own
    /// channels, as everywhere in the project).
    #[arg(long, value_enum, default_value_t = raw::RawColor::Camera)]
    raw_color: raw::RawColor,
    /// Output radiance map: .exr (OpenEXR) or .hdr (Radiance RGBE).
    #[arg(long, short)]
    out: PathBuf,
    /// Output format; default: from OUT's extension (.hdr → hdr, else exr).
    #[arg(long, value_enum)]
    format: Option<OutputFormat>,
    /// OpenEXR: also write the variance and mask channels (variance.R/G/B, valid, mask).
    #[arg(long)]
    with_variance: bool,
    /// OpenEXR: half-float colour (16 bits; values above 65504 become +∞).
    #[arg(long, conflicts_with = "with_variance")]
    half: bool,
    /// ND filter transmittance: one value, or R,G,B.
    #[arg(long, value_delimiter = ',', default_value = "1")]
    nd: Vec<f64>,
    /// Radiometric scale (W·m⁻²·sr⁻¹ per unit of relative exposure per second): one value or R,G,B.
    #[arg(long, value_delimiter = ',', default_value = "1")]
    scale: Vec<f64>,
    /// Lens model file (from `hdr lens`): divides out falloff, then undistorts.
    #[arg(long)]
    lens: Option<PathBuf>,
    /// Sensor full well in electrons (noise-optimal weights).
    #[arg(long, default_value_t = NoiseModel::default().full_well_electrons)]
    full_well: f64,
    /// Sensor read noise in electrons.
    #[arg(long, default_value_t = NoiseModel::default().read_noise_electrons)]
    read_noise: f64,
    /// Quality thresholds (a `Quality(...)` RON file, any subset of the
    /// gates). The map's verdict (pixels valid, clipped or dark in every
    /// exposure) goes to OUT's stem + .quality.json; a failed map (an
    /// all-black or all-white bracket) exits 3.
    #[arg(long, value_name = "FILE.ron")]
    thresholds: Option<PathBuf>,
    /// Align a hand-held bracket to its middle exposure first (translation
    /// and rotation up to 3°, to a fraction of a pixel), printing the
    /// transform found for each image. Pixels that no exposure covers after
    /// alignment are masked.
    #[arg(long)]
    align: bool,
    /// Exclude samples inconsistent (beyond 4σ of the noise model, with a 5%
    /// floor) with the middle exposure's radiance, so a moving object comes
    /// from one exposure instead of a blend of its positions.
    #[arg(long)]
    deghost: bool,
}

/// A radiance map's file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// OpenEXR.
    Exr,
    /// Radiance RGBE (.hdr).
    Hdr,
}

#[derive(Debug, Args)]
pub struct LensArgs {
    /// Flat-field radiance map (EXR with R, G, B) for the falloff fit.
    #[arg(long)]
    flat: Option<PathBuf>,
    /// CSV of "r_distorted,r_ideal" pairs for the distortion fit.
    #[arg(long)]
    pairs: Option<PathBuf>,
    /// Output lens model (text, key = value).
    #[arg(long, short)]
    out: PathBuf,
}

/// Runs an `hdr` subcommand; returns the exit code (0 ok, 1 failure, 2 bad input or usage, 3 a failed product).
pub fn run(cmd: HdrCommand) -> u8 {
    let result = match cmd {
        HdrCommand::Calibrate(a) => calibrate(&a),
        HdrCommand::Merge(a) => merge_cmd(&a),
        HdrCommand::Lens(a) => lens(&a),
    };
    match result {
        Ok(()) => EXIT_OK,
        Err(e) if super::output::is_broken_pipe(&e) => EXIT_OK,
        Err(e) => {
            eprintln!("error: {e:#}");
            exit_code(&e)
        }
    }
}

/// 2 for problems with the input (files, values, options), 3 for a
/// product that failed its quality gate, 1 for failures while working.
fn exit_code(e: &anyhow::Error) -> u8 {
    let code = super::exit::code_of(e);
    if code != EXIT_FAILURE {
        return code;
    }
    match e.chain().find_map(|c| c.downcast_ref::<HdrError>()) {
        Some(HdrError::Singular { .. }) => EXIT_FAILURE,
        Some(HdrError::Io { .. } | HdrError::Exr { .. }) if is_output_error(e) => EXIT_FAILURE,
        Some(_) => EXIT_USAGE,
        None if is_output_error(e) => EXIT_FAILURE,
        None => EXIT_USAGE,
    }
}

fn is_output_error(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.to_string().starts_with("writing "))
}

/// The bracket's files and the times given for them (`None`: from EXIF).
fn paths_and_times(args: &BracketArgs) -> Result<(Vec<PathBuf>, Option<Vec<f64>>)> {
    match &args.list {
        Some(list) => {
            let (p, t) = read_bracket_list(list).with_context(|| format!("reading bracket list {}", list.display()))?;
            Ok((p, Some(t)))
        }
        None => {
            if args.images.is_empty() {
                return Err(anyhow!(
                    "no images: give IMAGE… (times from EXIF or --times T,…) or --list FILE"
                ));
            }
            let times = args
                .times
                .iter()
                .map(|t| {
                    parse_time_s(t)
                        .ok_or_else(|| anyhow!("--times: '{t}' is not a time in seconds > 0 (e.g. 0.033 or 1/30)"))
                })
                .collect::<Result<Vec<_>>>()?;
            Ok((args.images.clone(), (!times.is_empty()).then_some(times)))
        }
    }
}

/// The bracket's files with their times, sorted, to be read one frame at a time.
fn open_files(args: &BracketArgs) -> Result<BracketFiles> {
    let (paths, times) = paths_and_times(args)?;
    let files = BracketFiles::open(&paths, times.as_deref()).context("reading the bracket")?;
    report_exif(files.records())?;
    Ok(files)
}

/// The whole bracket in memory (for alignment and deghosting, which look
/// at every frame at once).
fn load(args: &BracketArgs) -> Result<Bracket> {
    let (paths, times) = paths_and_times(args)?;
    let (bracket, frames) = load_bracket_files(&paths, times.as_deref()).context("reading the bracket")?;
    report_exif(&frames)?;
    let labels: Vec<&str> = bracket.images().iter().map(|im| im.label.as_str()).collect();
    report_white_points(&labels, bracket.white_points(), bracket.images()[0].max_code())?;
    Ok(bracket)
}

/// Reads `files` one frame at a time into `visit`, with a progress bar.
fn scan<T>(files: &BracketFiles, what: &str, visit: impl FnOnce(&dyn Fn(usize)) -> Result<T, HdrError>) -> Result<T> {
    let bar = campanile_session::progress::bar(files.len() as u64, what);
    let out = visit(&|k| bar.set_position(k as u64));
    bar.finish_and_clear();
    Ok(out?)
}

/// One line per frame whose time came from EXIF: its time and where from.
fn report_exif(frames: &[FrameRecord]) -> Result<()> {
    for f in frames.iter().filter(|f| f.source == TimeSource::Exif) {
        let m = &f.metadata;
        let mut what = vec![format!("{} s", m.exposure_time_s.map_or_else(String::new, shutter))];
        if let Some(n) = m.f_number {
            what.push(format!("f/{n}"));
        }
        if let Some(iso) = m.iso {
            what.push(format!("ISO {iso}"));
        }
        outln!(
            "{}: EXIF {}{} → exposure {:.6} s",
            f.path.display(),
            what.join(", "),
            m.camera.as_deref().map_or_else(String::new, |c| format!(" ({c})")),
            f.time_s
        )?;
    }
    Ok(())
}

/// One line per white point found below the largest code (frames by
/// ascending exposure, labelled).
fn report_white_points(labels: &[&str], white: &[[Option<WhitePoint>; 3]], max_code: u16) -> Result<()> {
    for (label, wp) in labels.iter().zip(white) {
        for (c, p) in wp.iter().enumerate() {
            if let Some(p) = p {
                outln!(
                    "{label}: {} piles up at code {} (below the largest, {max_code}): codes ≥ {} treated as clipped ({} pixels)",
                    ["red", "green", "blue"][c],
                    p.code,
                    p.clipped_from,
                    p.pixels
                )?;
            }
        }
    }
    Ok(())
}

/// The labels of a bracket's files, shortest exposure first.
fn labels(files: &BracketFiles) -> Vec<String> {
    files.records().iter().map(|r| r.path.display().to_string()).collect()
}

/// A time as photographers write it: "1/250" below a second, else decimal.
fn shutter(t: f64) -> String {
    if t < 1.0 && (1.0 / t - (1.0 / t).round()).abs() < 1e-3 * (1.0 / t) {
        format!("1/{}", (1.0 / t).round())
    } else {
        format!("{t}")
    }
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

fn calibrate(a: &CalibrateArgs) -> Result<()> {
    let q = verdicts::thresholds(a.thresholds.as_deref(), None)?;
    raw::refuse_raw_calibration(&a.bracket)?;
    let sampling = SampleOptions {
        samples: a.samples,
        seed: a.seed,
        ..Default::default()
    };
    let (curve, method, quality) = if a.align {
        let bracket = align::aligned(&load(&a.bracket)?)?;
        recover(&bracket, a, sampling, &q)?
    } else {
        // One frame at a time, keeping the pixels sampling looks at.
        let files = open_files(&a.bracket)?;
        let (sampled, white) = scan(&files, "reading frames", |p| SampledBracket::read(&files, &sampling, p))
            .context("reading the bracket")?;
        let labels = labels(&files);
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        report_white_points(&labels, &white, sampled.max_code())?;
        recover(&sampled, a, sampling, &q)?
    };
    write(&a.out, &curve.to_csv(&method))?;
    let plot = a.plot.clone().unwrap_or_else(|| a.out.with_extension("svg"));
    let svg = curve_plot_svg(&curve, &format!("Response curve ({method})")).context("plotting the curve")?;
    write(&plot, &svg)?;
    outln!("wrote {} and {}", a.out.display(), plot.display())?;
    verdicts::finish(&QualityReport::new(vec![quality], &q), &verdicts::beside(&a.out))
}

/// The response by `a.method` from `bracket`, its method line and verdict.
fn recover<B: ExposureCodes>(
    bracket: &B,
    a: &CalibrateArgs,
    sampling: SampleOptions,
    q: &Quality,
) -> Result<(ResponseCurve, String, ProductQuality)> {
    Ok(match a.method {
        Method::Debevec => {
            let opts = DebevecOptions {
                lambda: a.lambda,
                smoothness: Smoothness::Code,
                sampling,
                fit_exposure_times: a.fit_times,
                ..Default::default()
            };
            let cal = calibrate_debevec(bracket, &opts).context("recovering the response (Debevec–Malik)")?;
            for (c, d) in cal.channels.iter().enumerate() {
                outln!(
                    "channel {}: {} samples, {} observations, residual RMS {:.4}, {} nodes made monotone, \
                     condition ≈ {:.1e}, dark-end bias correction up to {:.3}",
                    ["R", "G", "B"][c],
                    d.samples,
                    d.observations,
                    d.residual_rms,
                    d.monotone_adjustments,
                    d.condition_estimate,
                    d.noise_bias.max_correction
                )?;
            }
            if a.fit_times {
                for (label, fitted) in bracket.times_s().iter().zip(&cal.times_s) {
                    outln!(
                        "exposure labelled {label} s: fitted {fitted:.6} s ({:+.2} %)",
                        100.0 * (fitted / label - 1.0)
                    )?;
                }
            }
            let quality = gates::response(&cal, bracket.exposures(), bracket.exposures(), q);
            (cal.curve, cal.method, quality)
        }
        Method::Robertson => {
            let opts = RobertsonOptions {
                sampling,
                ..Default::default()
            };
            let (curve, iters) = calibrate_robertson(bracket, &opts).context("recovering the response (Robertson)")?;
            outln!("Robertson: {iters:?} iterations (R, G, B)")?;
            let quality = gates::response_curve(&curve, bracket.exposures(), bracket.exposures(), q);
            (
                curve,
                format!("robertson samples={} seed={}", a.samples, a.seed),
                quality,
            )
        }
    })
}

fn per_channel(name: &str, v: &[f64]) -> Result<[f64; 3]> {
    match v {
        [x] => Ok([*x; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(anyhow!(
            "--{name}: {} values given: expected one value or three (R,G,B)",
            v.len()
        )),
    }
}

/// The output format: `--format`, else by OUT's extension; the
/// OpenEXR-only options refused for Radiance RGBE.
fn output_format(a: &MergeArgs) -> Result<OutputFormat> {
    let format = a.format.unwrap_or_else(|| {
        let hdr = a.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("hdr"));
        if hdr { OutputFormat::Hdr } else { OutputFormat::Exr }
    });
    if format == OutputFormat::Hdr && (a.with_variance || a.half) {
        return Err(super::exit::bad_input(
            "--with-variance and --half are OpenEXR options: Radiance RGBE (.hdr) holds colour only",
        ));
    }
    Ok(format)
}

/// Writes a merged map as `hdr merge`'s options ask.
fn write_map(a: &MergeArgs, format: OutputFormat, map: &RadianceMap) -> Result<()> {
    match format {
        OutputFormat::Hdr => write_rgbe(map, &a.out),
        OutputFormat::Exr if a.with_variance => write_radiance_exr(map, &a.out),
        OutputFormat::Exr if a.half => write_rgb_exr(map, &a.out, ExrPrecision::Half),
        OutputFormat::Exr => write_rgb_exr(map, &a.out, ExrPrecision::Float),
    }
    .context("writing the radiance map")
}

fn merge_cmd(a: &MergeArgs) -> Result<()> {
    let format = output_format(a)?;
    if raw::is_raw_bracket(&a.bracket)? {
        return raw::merge_raw(a, format);
    }
    let q = verdicts::thresholds(a.thresholds.as_deref(), None)?;
    let curve_path = a.curve.as_deref().ok_or_else(|| {
        super::exit::bad_input(
            "--curve is required for PNG/TIFF/JPEG brackets (run `campanile hdr calibrate` first); only RAW frames merge without one",
        )
    })?;
    let text =
        std::fs::read_to_string(curve_path).with_context(|| format!("reading curve {}", curve_path.display()))?;
    let curve = ResponseCurve::from_csv(&text, curve_path).context("reading the curve")?;
    let lens = match &a.lens {
        Some(p) => {
            let t = std::fs::read_to_string(p).with_context(|| format!("reading lens model {}", p.display()))?;
            Some(LensModel::from_text(&t, p)?)
        }
        None => None,
    };
    let opts = MergeOptions {
        noise: NoiseModel {
            full_well_electrons: a.full_well,
            read_noise_electrons: a.read_noise,
        },
        nd_transmittance: per_channel("nd", &a.nd)?,
        radiometric_scale: per_channel("scale", &a.scale)?,
        falloff: lens.map(|l| l.falloff),
    };
    let (mut map, exposures) = if a.align || a.deghost {
        let mut bracket = load(&a.bracket)?;
        if a.align {
            bracket = align::aligned(&bracket)?;
        }
        let map = if a.deghost {
            let (map, stats) =
                merge_deghosted(&bracket, &curve, &opts, &DeghostOptions::default()).context("merging")?;
            align::report_deghost(&stats)?;
            map
        } else {
            merge(&bracket, &curve, &opts).context("merging")?
        };
        (map, bracket.len())
    } else {
        // One frame at a time into per-pixel sums (bounded memory).
        let files = open_files(&a.bracket)?;
        let (map, white) =
            scan(&files, "merging frames", |p| merge_files(&files, &curve, &opts, p)).context("merging")?;
        let labels = labels(&files);
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        report_white_points(&labels, &white, max_code(curve.bits))?;
        (map, files.len())
    };
    if !(a.with_variance || a.align || a.deghost) {
        // Only the OpenEXR with variance writes it: free it before writing.
        map.variance = Vec::new();
    }
    if let Some(l) = lens
        && (l.distortion.a != 0.0 || l.distortion.b != 0.0)
    {
        map = undistort_map(&map, &l.distortion);
    }
    write_map(a, format, &map)?;
    let invalid = map.mask.iter().filter(|&&m| m != 0).count();
    outln!(
        "wrote {} ({}×{}, {} exposures; {invalid} pixels clipped in some channel in every exposure)",
        a.out.display(),
        map.width,
        map.height,
        exposures
    )?;
    let name = a
        .out
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let mut quality = gates::radiance(&name, &map, false, &q);
    if let Some(curve) = verdicts::of_input(curve_path)? {
        quality.inherit(&curve);
    }
    verdicts::finish(&QualityReport::new(vec![quality], &q), &verdicts::beside(&a.out))
}

fn lens(a: &LensArgs) -> Result<()> {
    if a.flat.is_none() && a.pairs.is_none() {
        return Err(anyhow!("nothing to fit: give --flat FLAT.exr and/or --pairs PAIRS.csv"));
    }
    let mut model = LensModel::default();
    if let Some(flat) = &a.flat {
        let img = read_rgb_exr(flat).with_context(|| format!("reading flat field {}", flat.display()))?;
        let (falloff, rms) = fit_falloff(&img).context("fitting the falloff")?;
        outln!(
            "falloff: a = {:.6}, b = {:.6} (RMS relative residual {:.4})",
            falloff.a,
            falloff.b,
            rms
        )?;
        model.falloff = falloff;
    }
    if let Some(pairs) = &a.pairs {
        let text = std::fs::read_to_string(pairs).with_context(|| format!("reading {}", pairs.display()))?;
        let mut v = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with('r') {
                continue;
            }
            let (d, u) = line.split_once(',').ok_or_else(|| {
                anyhow!(
                    "{}:{}: '{line}': expected 'r_distorted,r_ideal'",
                    pairs.display(),
                    i + 1
                )
            })?;
            let num = |s: &str| {
                s.trim()
                    .parse::<f64>()
                    .map_err(|_| anyhow!("{}:{}: '{}': expected a number", pairs.display(), i + 1, s.trim()))
            };
            v.push((num(d)?, num(u)?));
        }
        model.distortion = fit_distortion(&v).context("fitting the distortion")?;
        outln!(
            "distortion: a = {:.6}, b = {:.6} ({} pairs)",
            model.distortion.a,
            model.distortion.b,
            v.len()
        )?;
    }
    write(&a.out, &model.to_text())?;
    outln!("wrote {}", a.out.display())?;
    Ok(())
}
