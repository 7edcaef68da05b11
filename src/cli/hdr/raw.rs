//! `campanile hdr merge` on camera RAW files (DNG, CR2, CR3, NEF, ARW, RAF,
//! RW2, ORF, PEF, SRW, or a DNG under another name): read each frame with
//! `campanile_process::hdr::raw_file`, merge linearly (no response curve),
//! write the EXR and its quality verdict. Also the checks that keep RAW
//! out of `hdr calibrate` and out of brackets mixed with PNG/TIFF/JPEG.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use campanile_process::hdr::bracket_list::{parse_time_s, read_bracket_list};
use campanile_process::hdr::linear_merge::{LinearMergeOptions, OutputColor, frame_exposures, merge_linear};
use campanile_process::hdr::merge::NoiseModel;
use campanile_process::hdr::raw_file::{is_raw_input, read_raw};
use campanile_process::quality::{QualityReport, gates};
use clap::ValueEnum;

use super::{BracketArgs, MergeArgs, OutputFormat, per_channel, write_map};
use crate::cli::exit::bad_input;
use crate::cli::verdicts;

/// Colour space of a merged RAW bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Default)]
pub enum RawColor {
    /// The camera's own channels, no white balance (radiance per camera channel).
    #[default]
    Camera,
    /// White-balanced linear sRGB through the file's colour matrix.
    Srgb,
    /// White-balanced CIE XYZ (D65).
    Xyz,
}

/// The bracket's files and the times given on the command line (or in the list).
fn paths_and_times(args: &BracketArgs) -> Result<(Vec<PathBuf>, Option<Vec<f64>>)> {
    if let Some(list) = &args.list {
        let (paths, times) =
            read_bracket_list(list).with_context(|| format!("reading bracket list {}", list.display()))?;
        return Ok((paths, Some(times)));
    }
    if args.times.is_empty() {
        return Ok((args.images.clone(), None));
    }
    let times = args
        .times
        .iter()
        .map(|t| {
            parse_time_s(t).ok_or_else(|| {
                bad_input(format!(
                    "--times: '{t}' is not a time in seconds > 0 (e.g. 0.033 or 1/30)"
                ))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((args.images.clone(), Some(times)))
}

/// Whether the bracket is RAW: `Some(true)` all RAW, `Some(false)` none,
/// and a usage error naming one of each when mixed. Lists are not read here
/// (their entries are classified when the list is loaded).
pub(super) fn is_raw_bracket(args: &BracketArgs) -> Result<bool> {
    let paths = match &args.list {
        Some(list) => match read_bracket_list(list) {
            Ok((paths, _)) => paths,
            // The ordinary loader reports a bad list.
            Err(_) => return Ok(false),
        },
        None => args.images.clone(),
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

/// `hdr calibrate` refuses RAW input: a linear sensor needs no curve.
pub(super) fn refuse_raw_calibration(args: &BracketArgs) -> Result<()> {
    if is_raw_bracket(args)? {
        return Err(bad_input(
            "RAW frames are linear: merge them directly with `campanile hdr merge` (no curve needed)",
        ));
    }
    Ok(())
}

fn output_color(c: RawColor) -> OutputColor {
    match c {
        RawColor::Camera => OutputColor::Camera,
        RawColor::Srgb => OutputColor::LinearSrgb,
        RawColor::Xyz => OutputColor::Xyz,
    }
}

/// Merges an all-RAW bracket linearly and writes the EXR and its verdict.
pub(super) fn merge_raw(a: &MergeArgs, format: OutputFormat) -> Result<()> {
    let q = verdicts::thresholds(a.thresholds.as_deref(), None)?;
    if a.curve.is_some() {
        return Err(bad_input(
            "--curve is for PNG/TIFF/JPEG brackets: RAW frames are linear and merged without a curve",
        ));
    }
    if a.lens.is_some() {
        return Err(bad_input("--lens is not applied to RAW brackets yet: merge without it"));
    }
    let (paths, times_s) = paths_and_times(&a.bracket)?;
    if paths.is_empty() {
        return Err(bad_input("no images: give IMAGE… or --list FILE"));
    }
    let frames = paths
        .iter()
        .map(|p| read_raw(p).with_context(|| format!("reading RAW frame {}", p.display())))
        .collect::<Result<Vec<_>>>()?;
    let nd = per_channel("nd", &a.nd)?;
    let scale = per_channel("scale", &a.scale)?;
    let opts = LinearMergeOptions {
        noise: NoiseModel {
            full_well_electrons: a.full_well,
            read_noise_electrons: a.read_noise,
        },
        times_s,
        output: output_color(a.raw_color),
        radiometric_scale: std::array::from_fn(|c| scale[c] / nd[c]),
        ..Default::default()
    };
    for (f, e) in frames
        .iter()
        .zip(frame_exposures(&frames, &opts).context("reading the exposures")?)
    {
        outln!(
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
    write_map(a, format, &map)?;
    let invalid = map.mask.iter().filter(|&&m| m != 0).count();
    outln!(
        "wrote {} ({}×{}, {} RAW exposures merged linearly, {:?} colour; {invalid} pixels clipped or dark in some channel in every exposure)",
        a.out.display(),
        map.width,
        map.height,
        frames.len(),
        a.raw_color
    )?;
    let name = file_name(&a.out);
    let quality = gates::radiance(&name, &map, false, &q);
    verdicts::finish(&QualityReport::new(vec![quality], &q), &verdicts::beside(&a.out))
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}
