//! HDR on plain files: recovering a camera response from a bracket, merging
//! a bracket (through a curve, or linearly from camera RAW) into a radiance
//! map, and fitting a lens model. What `campanile hdr calibrate|merge|lens`
//! does; the science is in `campanile_process::hdr` (Debevec and Malik 1997,
//! the thesis's reference [11], which ch. 4 uses for its radiance images).
//!
//! Each function prints its progress lines to `out`, writes its products
//! and returns their verdicts ([`QualityReport`]), which the caller writes
//! beside the product ([`crate::verdicts::finish`]). Errors are classified
//! for the exit status: a singular system or an unwritable output is work
//! that failed; anything else the HDR library refuses is bad input.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use campanile_process::camera::image::max_code;
use campanile_process::exr_io::{ExrPrecision, read_rgb_exr, write_radiance_exr, write_rgb_exr};
use campanile_process::hdr::HdrError;
use campanile_process::hdr::align::{AlignOptions, align_bracket, warp_bracket};
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::bracket_files::BracketFiles;
use campanile_process::hdr::bracket_list::{
    FrameRecord, TimeSource, load_bracket_files, parse_time_s, read_bracket_list,
};
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::curve_plot::curve_plot_svg;
use campanile_process::hdr::debevec::{DebevecOptions, Smoothness, calibrate_debevec};
use campanile_process::hdr::deghost::{DeghostOptions, DeghostStats, merge_deghosted};
use campanile_process::hdr::exposure_codes::ExposureCodes;
use campanile_process::hdr::lens::{LensModel, fit_distortion, fit_falloff, undistort_map};
use campanile_process::hdr::linear_merge::{LinearMergeOptions, OutputColor, frame_exposures, merge_linear};
use campanile_process::hdr::merge::{MergeOptions, NoiseModel, RadianceMap, merge};
use campanile_process::hdr::merge_stream::merge_files;
use campanile_process::hdr::raw_file::{is_raw_input, read_raw};
use campanile_process::hdr::robertson::{RobertsonOptions, calibrate_robertson};
use campanile_process::hdr::sampled_bracket::SampledBracket;
use campanile_process::hdr::sampling::SampleOptions;
use campanile_process::hdr::white_point::WhitePoint;
use campanile_process::quality::{ProductQuality, Quality, QualityReport, gates};
use campanile_process::rgbe_file::write_rgbe;

use crate::error::{Error, Result, bad_input};
use crate::verdicts;

/// A bracket as the user names it: files with times (`times` empty: from
/// each file's EXIF), or a bracket list.
#[derive(Debug, Clone, Default)]
pub struct BracketSource {
    /// The bracket's images.
    pub images: Vec<PathBuf>,
    /// Exposure times as typed ("0.033", "1/30"), one per image, or none.
    pub times: Vec<String>,
    /// A bracket list (plain "IMAGE TIME_S" lines, or CSV) instead of images.
    pub list: Option<PathBuf>,
}

/// How the response is recovered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResponseMethod {
    /// Debevec–Malik (smoothness-regularized least squares).
    Debevec,
    /// Robertson et al. (iterative maximum likelihood).
    Robertson,
}

/// What `hdr calibrate` is asked.
#[derive(Debug, Clone)]
pub struct CalibrateOptions {
    /// The bracket.
    pub bracket: BracketSource,
    /// The curve (CSV).
    pub out: PathBuf,
    /// The plot (SVG); `None`: the curve's path with `.svg`.
    pub plot: Option<PathBuf>,
    /// The recovery method.
    pub method: ResponseMethod,
    /// Debevec–Malik's smoothness weight λ.
    pub lambda: f64,
    /// Pixels sampled per channel.
    pub samples: usize,
    /// Seed of the sample selection.
    pub seed: u64,
    /// Also fit the true exposure times.
    pub fit_times: bool,
    /// Align a hand-held bracket to its middle exposure first.
    pub align: bool,
    /// The gates the curve is held to.
    pub thresholds: Quality,
}

/// The colour space of a merged RAW bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RawColor {
    /// The camera's own channels, no white balance.
    #[default]
    Camera,
    /// White-balanced linear sRGB through the file's colour matrix.
    Srgb,
    /// White-balanced CIE XYZ (D65).
    Xyz,
}

/// A radiance map's file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapFormat {
    /// OpenEXR.
    Exr,
    /// Radiance RGBE (.hdr).
    Hdr,
}

/// What `hdr merge` is asked.
#[derive(Debug, Clone)]
pub struct MergeRequest {
    /// The bracket.
    pub bracket: BracketSource,
    /// The response curve (CSV); required unless the frames are RAW.
    pub curve: Option<PathBuf>,
    /// The colour space of a RAW merge.
    pub raw_color: RawColor,
    /// The radiance map.
    pub out: PathBuf,
    /// The format; `None`: by `out`'s extension (.hdr, else OpenEXR).
    pub format: Option<MapFormat>,
    /// OpenEXR: also the variance and mask channels.
    pub with_variance: bool,
    /// OpenEXR: half-float colour.
    pub half: bool,
    /// ND filter transmittance: one value, or R, G, B.
    pub nd: Vec<f64>,
    /// Radiometric scale: one value, or R, G, B.
    pub scale: Vec<f64>,
    /// A lens model file (`hdr lens`).
    pub lens: Option<PathBuf>,
    /// The sensor's full well (electrons).
    pub full_well: f64,
    /// The sensor's read noise (electrons).
    pub read_noise: f64,
    /// Align a hand-held bracket first.
    pub align: bool,
    /// Exclude samples inconsistent with the middle exposure.
    pub deghost: bool,
    /// The gates the map is held to.
    pub thresholds: Quality,
}

/// What `hdr lens` is asked.
#[derive(Debug, Clone)]
pub struct LensRequest {
    /// A flat-field radiance map (EXR) for the falloff.
    pub flat: Option<PathBuf>,
    /// A CSV of "r_distorted,r_ideal" pairs for the distortion.
    pub pairs: Option<PathBuf>,
    /// The lens model (text).
    pub out: PathBuf,
}

/// Recovers the response of `o.bracket`, writes the curve and its plot, and
/// returns the curve's verdict.
pub fn calibrate(o: &CalibrateOptions, out: &mut dyn Write) -> Result<QualityReport> {
    classified(calibrate_inner(o, out))
}

/// Merges `o.bracket` into a radiance map (linearly when every frame is
/// RAW), writes it, and returns its verdict.
pub fn merge_bracket(o: &MergeRequest, out: &mut dyn Write) -> Result<QualityReport> {
    classified(merge_inner(o, out))
}

/// Fits the lens model 1 + a r² + b r⁴ to a flat field and/or radius pairs
/// and writes it.
pub fn fit_lens(o: &LensRequest, out: &mut dyn Write) -> Result<()> {
    classified(lens_inner(o, out))
}

/// The error kind for what went wrong: a singular system, or failing to
/// write an output, is work that failed; every other refusal of the HDR
/// library, and anything it could not read, is bad input.
fn classified<T>(r: anyhow::Result<T>) -> Result<T> {
    r.map_err(|e| {
        let chain = || e.chain();
        if chain().any(crate::error::is_quality_failure) {
            return Error::Work(e);
        }
        if chain().any(crate::error::is_bad_input) {
            return Error::input(format!("{e:#}"));
        }
        let output = chain().any(|c| c.to_string().starts_with("writing "));
        let work = match chain().find_map(|c| c.downcast_ref::<HdrError>()) {
            Some(HdrError::Singular { .. }) => true,
            Some(_) | None => output || chain().any(is_closed_pipe),
        };
        if work {
            Error::Work(e)
        } else {
            Error::input(format!("{e:#}"))
        }
    })
}

/// A closed standard output travels as work (the binary ends its output
/// silently on one).
fn is_closed_pipe(c: &(dyn std::error::Error + 'static)) -> bool {
    c.downcast_ref::<std::io::Error>()
        .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
}

/// The bracket's files and the times given for them (`None`: from EXIF).
fn paths_and_times(b: &BracketSource) -> anyhow::Result<(Vec<PathBuf>, Option<Vec<f64>>)> {
    if let Some(list) = &b.list {
        let (p, t) = read_bracket_list(list).with_context(|| format!("reading bracket list {}", list.display()))?;
        return Ok((p, Some(t)));
    }
    if b.images.is_empty() {
        return Err(bad_input(
            "no images: give IMAGE… (times from EXIF or --times T,…) or --list FILE",
        ));
    }
    let times = b
        .times
        .iter()
        .map(|t| {
            parse_time_s(t).ok_or_else(|| {
                bad_input(format!(
                    "--times: '{t}' is not a time in seconds > 0 (e.g. 0.033 or 1/30)"
                ))
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((b.images.clone(), (!times.is_empty()).then_some(times)))
}

/// The bracket's files with their times, sorted, to be read one frame at a time.
fn open_files(b: &BracketSource, out: &mut dyn Write) -> anyhow::Result<BracketFiles> {
    let (paths, times) = paths_and_times(b)?;
    let files = BracketFiles::open(&paths, times.as_deref()).context("reading the bracket")?;
    report_exif(files.records(), out)?;
    Ok(files)
}

/// The whole bracket in memory (for alignment and deghosting, which look
/// at every frame at once).
fn load(b: &BracketSource, out: &mut dyn Write) -> anyhow::Result<Bracket> {
    let (paths, times) = paths_and_times(b)?;
    let (bracket, frames) = load_bracket_files(&paths, times.as_deref()).context("reading the bracket")?;
    report_exif(&frames, out)?;
    let labels: Vec<String> = bracket.images().iter().map(|im| im.label.clone()).collect();
    report_white_points(&labels, bracket.white_points(), bracket.images()[0].max_code(), out)?;
    Ok(bracket)
}

/// Reads `files` one frame at a time into `visit`, with a progress bar.
fn scan<T>(
    files: &BracketFiles,
    what: &str,
    visit: impl FnOnce(&dyn Fn(usize)) -> Result<T, HdrError>,
) -> anyhow::Result<T> {
    let bar = crate::progress::bar(files.len() as u64, what);
    let result = visit(&|k| bar.set_position(k as u64));
    bar.finish_and_clear();
    Ok(result?)
}

/// One line per frame whose time came from EXIF: its time and where from.
fn report_exif(frames: &[FrameRecord], out: &mut dyn Write) -> anyhow::Result<()> {
    for f in frames.iter().filter(|f| f.source == TimeSource::Exif) {
        let m = &f.metadata;
        let mut what = vec![format!("{} s", m.exposure_time_s.map_or_else(String::new, shutter))];
        if let Some(n) = m.f_number {
            what.push(format!("f/{n}"));
        }
        if let Some(iso) = m.iso {
            what.push(format!("ISO {iso}"));
        }
        writeln!(
            out,
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
fn report_white_points(
    labels: &[String],
    white: &[[Option<WhitePoint>; 3]],
    max_code: u16,
    out: &mut dyn Write,
) -> anyhow::Result<()> {
    for (label, wp) in labels.iter().zip(white) {
        for (c, p) in wp.iter().enumerate() {
            if let Some(p) = p {
                writeln!(
                    out,
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

fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// Aligns `bracket` to its middle exposure, prints one line per image
/// (`image X: dx +3.25 px, dy -1.50 px, rotation +0.00°, disagreement 2.1%`)
/// and a warning for each doubtful one, and returns the warped bracket.
fn aligned(bracket: &Bracket, out: &mut dyn Write) -> anyhow::Result<Bracket> {
    let al = align_bracket(bracket, &AlignOptions::default()).context("aligning the bracket")?;
    for (img, a) in bracket.images().iter().zip(&al.images) {
        let t = a.transform;
        writeln!(
            out,
            "image {}: dx {:+.2} px, dy {:+.2} px, rotation {:+.2}°, disagreement {:.1}% ({})",
            img.label,
            t.dx,
            t.dy,
            t.angle_rad.to_degrees(),
            100.0 * a.disagreement,
            a.verdict.describe()
        )?;
        if !a.verdict.is_trusted() {
            tracing::warn!(
                "image {}: alignment {} ({:.1}% of pixels informative, shift uncertainty {:.3} px)",
                img.label,
                a.verdict.describe(),
                100.0 * a.informative_fraction,
                a.std_px
            );
        }
    }
    warp_bracket(bracket, &al.transforms()).context("resampling the aligned bracket")
}

fn report_deghost(s: &DeghostStats, out: &mut dyn Write) -> anyhow::Result<()> {
    writeln!(
        out,
        "deghost: {} samples excluded at {} of {} pixels ({:.2}%)",
        s.samples_excluded,
        s.pixels_affected,
        s.pixels,
        100.0 * s.pixels_affected as f64 / s.pixels.max(1) as f64
    )?;
    Ok(())
}

/// Whether the bracket is RAW: `false` when no frame is, and bad input
/// naming one of each when mixed. A list that cannot be read is left to the
/// ordinary loader, which reports it.
fn is_raw_bracket(b: &BracketSource) -> anyhow::Result<bool> {
    let paths = match &b.list {
        Some(list) => match read_bracket_list(list) {
            Ok((paths, _)) => paths,
            Err(_) => return Ok(false),
        },
        None => b.images.clone(),
    };
    let raw: Vec<&PathBuf> = paths.iter().filter(|p| is_raw_input(p)).collect();
    if raw.is_empty() {
        return Ok(false);
    }
    if let Some(other) = paths.iter().find(|p| !is_raw_input(p)) {
        return Err(bad_input(format!(
            "the bracket mixes RAW and non-RAW frames ({} is RAW, {} is not): \
             give only RAW files (merged linearly) or only PNG/TIFF/JPEG files (merged through a curve)",
            raw[0].display(),
            other.display()
        )));
    }
    Ok(true)
}

fn calibrate_inner(o: &CalibrateOptions, out: &mut dyn Write) -> anyhow::Result<QualityReport> {
    if is_raw_bracket(&o.bracket)? {
        return Err(bad_input(
            "RAW frames are linear: merge them directly with `campanile hdr merge` (no curve needed)",
        ));
    }
    let sampling = SampleOptions {
        samples: o.samples,
        seed: o.seed,
        ..Default::default()
    };
    let (curve, method, quality) = if o.align {
        let bracket = aligned(&load(&o.bracket, out)?, out)?;
        recover(&bracket, o, sampling, out)?
    } else {
        // One frame at a time, keeping the pixels sampling looks at.
        let files = open_files(&o.bracket, out)?;
        let (sampled, white) = scan(&files, "reading frames", |p| SampledBracket::read(&files, &sampling, p))
            .context("reading the bracket")?;
        report_white_points(&labels(&files), &white, sampled.max_code(), out)?;
        recover(&sampled, o, sampling, out)?
    };
    write_text(&o.out, &curve.to_csv(&method))?;
    let plot = o.plot.clone().unwrap_or_else(|| o.out.with_extension("svg"));
    let svg = curve_plot_svg(&curve, &format!("Response curve ({method})")).context("plotting the curve")?;
    write_text(&plot, &svg)?;
    writeln!(out, "wrote {} and {}", o.out.display(), plot.display())?;
    Ok(QualityReport::new(vec![quality], &o.thresholds))
}

/// The response by `o.method` from `bracket`, its method line and verdict.
fn recover<B: ExposureCodes>(
    bracket: &B,
    o: &CalibrateOptions,
    sampling: SampleOptions,
    out: &mut dyn Write,
) -> anyhow::Result<(ResponseCurve, String, ProductQuality)> {
    let q = &o.thresholds;
    Ok(match o.method {
        ResponseMethod::Debevec => {
            let opts = DebevecOptions {
                lambda: o.lambda,
                smoothness: Smoothness::Code,
                sampling,
                fit_exposure_times: o.fit_times,
                ..Default::default()
            };
            let cal = calibrate_debevec(bracket, &opts).context("recovering the response (Debevec–Malik)")?;
            for (c, d) in cal.channels.iter().enumerate() {
                writeln!(
                    out,
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
            if o.fit_times {
                for (label, fitted) in bracket.times_s().iter().zip(&cal.times_s) {
                    writeln!(
                        out,
                        "exposure labelled {label} s: fitted {fitted:.6} s ({:+.2} %)",
                        100.0 * (fitted / label - 1.0)
                    )?;
                }
            }
            let quality = gates::response(&cal, bracket.exposures(), bracket.exposures(), q);
            (cal.curve, cal.method, quality)
        }
        ResponseMethod::Robertson => {
            let opts = RobertsonOptions {
                sampling,
                ..Default::default()
            };
            let (curve, iters) = calibrate_robertson(bracket, &opts).context("recovering the response (Robertson)")?;
            writeln!(out, "Robertson: {iters:?} iterations (R, G, B)")?;
            let quality = gates::response_curve(&curve, bracket.exposures(), bracket.exposures(), q);
            (
                curve,
                format!("robertson samples={} seed={}", o.samples, o.seed),
                quality,
            )
        }
    })
}

fn per_channel(name: &str, v: &[f64]) -> anyhow::Result<[f64; 3]> {
    match v {
        [x] => Ok([*x; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(bad_input(format!(
            "--{name}: {} values given: expected one value or three (R,G,B)",
            v.len()
        ))),
    }
}

/// The output format: as asked, else by the output's extension; the
/// OpenEXR-only options refused for Radiance RGBE.
fn output_format(o: &MergeRequest) -> anyhow::Result<MapFormat> {
    let format = o.format.unwrap_or_else(|| {
        let hdr = o.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("hdr"));
        if hdr { MapFormat::Hdr } else { MapFormat::Exr }
    });
    if format == MapFormat::Hdr && (o.with_variance || o.half) {
        return Err(bad_input(
            "--with-variance and --half are OpenEXR options: Radiance RGBE (.hdr) holds colour only",
        ));
    }
    Ok(format)
}

/// Writes a merged map as asked.
fn write_map(o: &MergeRequest, format: MapFormat, map: &RadianceMap) -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    let written = match format {
        MapFormat::Hdr => write_rgbe(map, &o.out),
        MapFormat::Exr if o.with_variance => write_radiance_exr(map, &o.out),
        MapFormat::Exr if o.half => write_rgb_exr(map, &o.out, ExrPrecision::Half),
        MapFormat::Exr => write_rgb_exr(map, &o.out, ExrPrecision::Float),
    }
    .context("writing the radiance map");
    tracing::debug!(
        file = %o.out.display(),
        seconds = format!("{:.3}", started.elapsed().as_secs_f64()),
        "radiance map encoded and written"
    );
    written
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

fn merge_inner(o: &MergeRequest, out: &mut dyn Write) -> anyhow::Result<QualityReport> {
    let format = output_format(o)?;
    if is_raw_bracket(&o.bracket)? {
        return merge_raw(o, format, out);
    }
    let q = &o.thresholds;
    let curve_path = o.curve.as_deref().ok_or_else(|| {
        bad_input(
            "--curve is required for PNG/TIFF/JPEG brackets (run `campanile hdr calibrate` first); only RAW frames merge without one",
        )
    })?;
    let text =
        std::fs::read_to_string(curve_path).with_context(|| format!("reading curve {}", curve_path.display()))?;
    let curve = ResponseCurve::from_csv(&text, curve_path).context("reading the curve")?;
    let lens = match &o.lens {
        Some(p) => {
            let t = std::fs::read_to_string(p).with_context(|| format!("reading lens model {}", p.display()))?;
            Some(LensModel::from_text(&t, p)?)
        }
        None => None,
    };
    let opts = MergeOptions {
        noise: NoiseModel {
            full_well_electrons: o.full_well,
            read_noise_electrons: o.read_noise,
        },
        nd_transmittance: per_channel("nd", &o.nd)?,
        radiometric_scale: per_channel("scale", &o.scale)?,
        falloff: lens.map(|l| l.falloff),
    };
    let (mut map, exposures) = if o.align || o.deghost {
        let mut bracket = load(&o.bracket, out)?;
        if o.align {
            bracket = aligned(&bracket, out)?;
        }
        let map = if o.deghost {
            let (map, stats) =
                merge_deghosted(&bracket, &curve, &opts, &DeghostOptions::default()).context("merging")?;
            report_deghost(&stats, out)?;
            map
        } else {
            merge(&bracket, &curve, &opts).context("merging")?
        };
        (map, bracket.len())
    } else {
        // One frame at a time into per-pixel sums (bounded memory).
        let files = open_files(&o.bracket, out)?;
        let (map, white) =
            scan(&files, "merging frames", |p| merge_files(&files, &curve, &opts, p)).context("merging")?;
        report_white_points(&labels(&files), &white, max_code(curve.bits), out)?;
        (map, files.len())
    };
    if !(o.with_variance || o.align || o.deghost) {
        // Only the OpenEXR with variance writes it: free it before writing.
        map.variance = Vec::new();
    }
    if let Some(l) = lens
        && (l.distortion.a != 0.0 || l.distortion.b != 0.0)
    {
        map = undistort_map(&map, &l.distortion);
    }
    write_map(o, format, &map)?;
    let invalid = map.mask.iter().filter(|&&m| m != 0).count();
    writeln!(
        out,
        "wrote {} ({}×{}, {} exposures; {invalid} pixels clipped in some channel in every exposure)",
        o.out.display(),
        map.width,
        map.height,
        exposures
    )?;
    let mut quality = gates::radiance(&file_name(&o.out), &map, false, q);
    if let Some(curve) = verdicts::of_input(curve_path)? {
        quality.inherit(&curve);
    }
    Ok(QualityReport::new(vec![quality], q))
}

/// Merges an all-RAW bracket linearly and writes the map.
fn merge_raw(o: &MergeRequest, format: MapFormat, out: &mut dyn Write) -> anyhow::Result<QualityReport> {
    if o.curve.is_some() {
        return Err(bad_input(
            "--curve is for PNG/TIFF/JPEG brackets: RAW frames are linear and merged without a curve",
        ));
    }
    if o.lens.is_some() {
        return Err(bad_input("--lens is not applied to RAW brackets yet: merge without it"));
    }
    let (paths, times_s) = if o.bracket.list.is_none() && o.bracket.times.is_empty() {
        (o.bracket.images.clone(), None)
    } else {
        paths_and_times(&o.bracket)?
    };
    if paths.is_empty() {
        return Err(bad_input("no images: give IMAGE… or --list FILE"));
    }
    let frames = paths
        .iter()
        .map(|p| read_raw(p).with_context(|| format!("reading RAW frame {}", p.display())))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let nd = per_channel("nd", &o.nd)?;
    let scale = per_channel("scale", &o.scale)?;
    let opts = LinearMergeOptions {
        noise: NoiseModel {
            full_well_electrons: o.full_well,
            read_noise_electrons: o.read_noise,
        },
        times_s,
        output: match o.raw_color {
            RawColor::Camera => OutputColor::Camera,
            RawColor::Srgb => OutputColor::LinearSrgb,
            RawColor::Xyz => OutputColor::Xyz,
        },
        radiometric_scale: std::array::from_fn(|c| scale[c] / nd[c]),
        ..Default::default()
    };
    for (f, e) in frames
        .iter()
        .zip(frame_exposures(&frames, &opts).context("reading the exposures")?)
    {
        writeln!(
            out,
            "{}: {} s, f/{}, ISO {}: relative exposure {:.4} ({}, black {:?}, white {})",
            f.label,
            e.time_s,
            e.f_number,
            e.iso,
            e.relative_exposure,
            f.meta.cfa,
            f.meta.black_levels,
            f.meta.white_level
        )?;
    }
    let map = merge_linear(&frames, &opts).context("merging the RAW frames")?;
    write_map(o, format, &map)?;
    let invalid = map.mask.iter().filter(|&&m| m != 0).count();
    writeln!(
        out,
        "wrote {} ({}×{}, {} RAW exposures merged linearly, {:?} colour; {invalid} pixels clipped or dark in some channel in every exposure)",
        o.out.display(),
        map.width,
        map.height,
        frames.len(),
        o.raw_color
    )?;
    let quality = gates::radiance(&file_name(&o.out), &map, false, &o.thresholds);
    Ok(QualityReport::new(vec![quality], &o.thresholds))
}

fn lens_inner(o: &LensRequest, out: &mut dyn Write) -> anyhow::Result<()> {
    if o.flat.is_none() && o.pairs.is_none() {
        return Err(bad_input(
            "nothing to fit: give --flat FLAT.exr and/or --pairs PAIRS.csv",
        ));
    }
    let mut model = LensModel::default();
    if let Some(flat) = &o.flat {
        let img = read_rgb_exr(flat).with_context(|| format!("reading flat field {}", flat.display()))?;
        let (falloff, rms) = fit_falloff(&img).context("fitting the falloff")?;
        writeln!(
            out,
            "falloff: a = {:.6}, b = {:.6} (RMS relative residual {:.4})",
            falloff.a, falloff.b, rms
        )?;
        model.falloff = falloff;
    }
    if let Some(pairs) = &o.pairs {
        let text = std::fs::read_to_string(pairs).with_context(|| format!("reading {}", pairs.display()))?;
        let v = radius_pairs(&text, pairs)?;
        model.distortion = fit_distortion(&v).context("fitting the distortion")?;
        writeln!(
            out,
            "distortion: a = {:.6}, b = {:.6} ({} pairs)",
            model.distortion.a,
            model.distortion.b,
            v.len()
        )?;
    }
    write_text(&o.out, &model.to_text())?;
    writeln!(out, "wrote {}", o.out.display())?;
    Ok(())
}

/// The "r_distorted,r_ideal" pairs of `text` (blank, `#` and header lines
/// skipped), each bad line named by file and number.
fn radius_pairs(text: &str, path: &Path) -> anyhow::Result<Vec<(f64, f64)>> {
    let mut v = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with('r') {
            continue;
        }
        let at = || format!("{}:{}", path.display(), i + 1);
        let (d, u) = line
            .split_once(',')
            .ok_or_else(|| anyhow!("{}: '{line}': expected 'r_distorted,r_ideal'", at()))?;
        let num = |s: &str| {
            s.trim()
                .parse::<f64>()
                .map_err(|_| anyhow!("{}: '{}': expected a number", at(), s.trim()))
        };
        v.push((num(d)?, num(u)?));
    }
    Ok(v)
}
