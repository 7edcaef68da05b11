//! `campanile hdr calibrate|merge|lens`: camera response recovery, HDR
//! merging and lens calibration on plain files. The work is
//! `campanile_session::hdr_files` (the science `campanile_process::hdr`);
//! this module parses arguments.

use std::path::PathBuf;

use anyhow::Result;
use campanile_process::hdr::debevec::DEFAULT_LAMBDA;
use campanile_process::hdr::merge::NoiseModel;
use campanile_session::hdr_files::{
    self, BracketSource, CalibrateOptions, LensRequest, MapFormat, MergeRequest, RawColor, ResponseMethod,
};
use clap::{Args, Subcommand, ValueEnum};

use super::verdicts;

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
    /// Frames are decoded one at a time into per-pixel sums, the next one
    /// on its own thread while the last is added: memory is about 24 bytes
    /// a pixel plus three frames (0.9 GB for 21 MP), whatever the number of
    /// frames; --align and --deghost hold every frame.
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
    #[arg(long, value_enum, default_value_t = RawColorArg::Camera)]
    raw_color: RawColorArg,
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

/// Colour space of a merged RAW bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RawColorArg {
    /// The camera's own channels, no white balance (radiance per camera channel).
    Camera,
    /// White-balanced linear sRGB through the file's colour matrix.
    Srgb,
    /// White-balanced CIE XYZ (D65).
    Xyz,
}

/// Runs an `hdr` subcommand.
pub fn run(cmd: HdrCommand) -> Result<()> {
    let out = &mut std::io::stdout();
    match cmd {
        HdrCommand::Calibrate(a) => {
            let o = CalibrateOptions {
                bracket: a.bracket.source(),
                out: a.out,
                plot: a.plot,
                method: match a.method {
                    Method::Debevec => ResponseMethod::Debevec,
                    Method::Robertson => ResponseMethod::Robertson,
                },
                lambda: a.lambda,
                samples: a.samples,
                seed: a.seed,
                fit_times: a.fit_times,
                align: a.align,
                thresholds: verdicts::thresholds(a.thresholds.as_deref(), None)?,
            };
            let report = hdr_files::calibrate(&o, out)?;
            verdicts::finish(&report, &verdicts::beside(&o.out))
        }
        HdrCommand::Merge(a) => {
            let o = MergeRequest {
                bracket: a.bracket.source(),
                curve: a.curve,
                raw_color: match a.raw_color {
                    RawColorArg::Camera => RawColor::Camera,
                    RawColorArg::Srgb => RawColor::Srgb,
                    RawColorArg::Xyz => RawColor::Xyz,
                },
                out: a.out,
                format: a.format.map(|f| match f {
                    OutputFormat::Exr => MapFormat::Exr,
                    OutputFormat::Hdr => MapFormat::Hdr,
                }),
                with_variance: a.with_variance,
                half: a.half,
                nd: a.nd,
                scale: a.scale,
                lens: a.lens,
                full_well: a.full_well,
                read_noise: a.read_noise,
                align: a.align,
                deghost: a.deghost,
                thresholds: verdicts::thresholds(a.thresholds.as_deref(), None)?,
            };
            let report = hdr_files::merge_bracket(&o, out)?;
            verdicts::finish(&report, &verdicts::beside(&o.out))
        }
        HdrCommand::Lens(a) => Ok(hdr_files::fit_lens(
            &LensRequest {
                flat: a.flat,
                pairs: a.pairs,
                out: a.out,
            },
            out,
        )?),
    }
}

impl BracketArgs {
    fn source(self) -> BracketSource {
        BracketSource {
            images: self.images,
            times: self.times,
            list: self.list,
        }
    }
}
