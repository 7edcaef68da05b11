//! Sky models on plain files, as `campanile sky` runs them: a fit to a
//! table of samples (with an optional residual map), a prediction at
//! another sun position from fitted skies, a sky as a lat-long map, and
//! a sky evaluated at directions (and compared with measurements there).

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use campanile_process::exr_io::write_radiance_exr;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::quality::{ProductQuality, Quality, QualityReport, gates};
use campanile_process::sky::{
    ChannelSelection, ChannelSky, KnownSky, SkyFile, SkyFitOptions, SkyModel, angle_between, compare_with_samples,
    direction, fit_sky_with, predict_sky, read_samples, render_latlong,
};

use crate::{Error, Result};

/// The sky per channel fitted to the samples in `samples` (their
/// channels as `selection` picks them) with the sun at `(zenith, azimuth)`
/// radians; with `residual_map`, a fisheye PNG of the first channel's
/// residuals written there.
pub fn fit(
    samples: &Path,
    selection: &ChannelSelection,
    (zs, az): (f64, f64),
    options: &SkyFitOptions,
    residual_map: Option<&Path>,
) -> Result<SkyFile> {
    let file = File::open(samples).with_context(|| format!("{}: cannot open", samples.display()))?;
    let table = read_samples(BufReader::new(file), selection).with_context(|| format!("{}", samples.display()))?;
    let sun_dir = direction(zs, az);
    let mut channels = Vec::new();
    for (c, name) in table.channels.iter().enumerate() {
        let pts = table.sky_samples(c, sun_dir);
        let robust =
            fit_sky_with(&pts, zs, options).with_context(|| format!("{}: channel {name}", samples.display()))?;
        let fit = &robust.fit;
        tracing::debug!(channel = %name, "{}", fit.reason);
        tracing::info!(
            "{name}: {}, RMS residual {:.3}%, {}; {}",
            fit.kind.label(),
            100.0 * fit.rms_relative,
            robust.masked_summary(),
            fit.convergence.summary()
        );
        channels.push(ChannelSky::of_robust(name, &robust));
    }
    let sky = SkyFile {
        sun_zenith_deg: zs.to_degrees(),
        sun_azimuth_deg: az.to_degrees(),
        channels,
    };
    if let Some(png) = residual_map {
        let model = &sky.channels[0].model;
        let pts: Vec<([f64; 3], f64)> = table
            .directions
            .iter()
            .zip(&table.values[0])
            .map(|(&(z, a), &v)| {
                let d = direction(z, a);
                (d, v / model.radiance(z, angle_between(d, sun_dir)) - 1.0)
            })
            .collect();
        let size = 256;
        let map = campanile_process::pipeline::fisheye_average(pts, size);
        let bytes = campanile_process::report::false_colour_png("sky residuals", size, size, &map, (-0.1, 0.1))?;
        std::fs::write(png, bytes).with_context(|| format!("{}: cannot write", png.display()))?;
    }
    Ok(sky)
}

/// The sky at the sun `(zenith, azimuth)` radians, predicted from `known`
/// skies (their channels alike).
pub fn predict(known: &[SkyFile], (zs, az): (f64, f64)) -> Result<SkyFile> {
    let names: Vec<&str> = known[0].channels.iter().map(|c| c.channel.as_str()).collect();
    let sun_dir = direction(zs, az);
    let mut channels = Vec::new();
    for (c, name) in names.iter().enumerate() {
        let skies_c: Vec<KnownSky> = known
            .iter()
            .map(|k| KnownSky {
                sun: direction(k.sun_zenith_deg.to_radians(), k.sun_azimuth_deg.to_radians()),
                model: k.channels[c].model,
            })
            .collect();
        let fit = predict_sky(&skies_c, sun_dir, 3.0).with_context(|| format!("channel {name}"))?;
        channels.push(ChannelSky::new(name, &fit, 0, 0.0));
    }
    Ok(SkyFile {
        sun_zenith_deg: zs.to_degrees(),
        sun_azimuth_deg: az.to_degrees(),
        channels,
    })
}

/// Writes the three channels' `models` of `sky_file` as a lat-long
/// OpenEXR radiance map `width` pixels wide to `out`.
pub fn write_map(models: &[SkyModel; 3], sky_file: &SkyFile, width: usize, out: &Path) -> Result<()> {
    let sun = direction(
        sky_file.sun_zenith_deg.to_radians(),
        sky_file.sun_azimuth_deg.to_radians(),
    );
    let (w, h, rgb) = render_latlong(models, sun, width);
    let map = RadianceMap {
        width: w,
        height: h,
        variance: vec![0.0; rgb.len()],
        mask: vec![0; w * h],
        rgb,
    };
    write_radiance_exr(&map, out).with_context(|| format!("{}: cannot write", out.display()))?;
    Ok(())
}

/// [`fit`], with the fit's verdict against `q`.
pub fn fit_checked(
    samples: &Path,
    selection: &ChannelSelection,
    sun: (f64, f64),
    options: &SkyFitOptions,
    residual_map: Option<&Path>,
    q: &Quality,
) -> Result<(SkyFile, QualityReport)> {
    let sky = fit(samples, selection, sun, options, residual_map)?;
    let name = samples
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let quality = QualityReport::new(vec![gates::sky(&name, &sky.channels, q)], q);
    Ok((sky, quality))
}

/// Reads a sky file (RON from `sky fit` or `sky predict`); a malformed one
/// is bad input, named by file and byte offset.
pub fn read_sky(path: &Path) -> Result<SkyFile> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    ron::from_str(&text).map_err(|e| Error::input(format!("{}:{}: {}", path.display(), e.span.start, e.code)))
}

/// The sky at the sun `(zenith, azimuth)` radians predicted from the sky
/// files `skies` (their channels alike), with the verdicts it inherits from
/// them (the `NAME.quality.json` beside each): a failed fit is not used in
/// silence.
pub fn predict_files(skies: &[PathBuf], sun: (f64, f64)) -> Result<(SkyFile, QualityReport)> {
    let known: Vec<SkyFile> = skies.iter().map(|p| read_sky(p)).collect::<Result<_>>()?;
    let names: Vec<&str> = known[0].channels.iter().map(|c| c.channel.as_str()).collect();
    for (path, k) in skies.iter().zip(&known) {
        let these: Vec<&str> = k.channels.iter().map(|c| c.channel.as_str()).collect();
        if these != names {
            return Err(Error::input(format!(
                "{}: channels {these:?} differ from {}'s {names:?}",
                path.display(),
                skies[0].display()
            )));
        }
    }
    let sky = predict(&known, sun)?;
    let mut predicted = ProductQuality::new("sky predicted", Vec::new());
    for path in skies {
        if let Some(input) = crate::verdicts::of_input(path)? {
            predicted.inherit(&input);
        }
    }
    Ok((sky, QualityReport::new(vec![predicted], &Quality::default())))
}

/// Writes the sky file `sky` (three channels) as a lat-long OpenEXR map
/// `width` pixels wide to `out`.
pub fn map_file(sky: &Path, width: usize, out: &Path) -> Result<()> {
    let sky_file = read_sky(sky)?;
    let [r, g, b] = sky_file.channels.as_slice() else {
        return Err(Error::input(format!(
            "{}: {} channels; a map needs exactly three (r, g, b)",
            sky.display(),
            sky_file.channels.len()
        )));
    };
    write_map(&[r.model, g.model, b.model], &sky_file, width, out)
}

/// Writes to `out` a CSV of the sky file `sky`'s radiance per channel at
/// each direction of the CSV `directions`; with `compare`, also measured /
/// fitted − 1 per channel from the file's own channel columns, and one
/// summary line (median and 95th percentile of its magnitude) to `err`.
pub fn eval(sky: &Path, directions: &Path, compare: bool, out: &mut dyn Write, err: &mut dyn Write) -> Result<()> {
    let sky_file = read_sky(sky)?;
    let names: Vec<&str> = sky_file.channels.iter().map(|c| c.channel.as_str()).collect();
    let selection = if compare {
        ChannelSelection::Named(names.iter().map(|&n| n.to_owned()).collect())
    } else {
        ChannelSelection::Directions
    };
    let file = File::open(directions).with_context(|| format!("{}: cannot open", directions.display()))?;
    let table = read_samples(BufReader::new(file), &selection).with_context(|| {
        if compare {
            format!("{}: --compare needs the sky's channels", directions.display())
        } else {
            format!("{}", directions.display())
        }
    })?;
    let compared = if compare {
        compare_with_samples(&sky_file, &table)
    } else {
        Vec::new()
    };
    let mut header = format!("zenith_deg,azimuth_deg,{}", names.join(","));
    for c in &compared {
        header += &format!(",{}_residual", c.channel);
    }
    writeln!(out, "{header}")?;
    for (row, &(z, a)) in table.directions.iter().enumerate() {
        let mut line = format!("{:.6},{:.6}", z.to_degrees(), a.to_degrees());
        for v in sky_file.radiance(z, a) {
            line += &format!(",{v:.9e}");
        }
        for c in &compared {
            line += &format!(",{:.6e}", c.ratio_minus_1[row]);
        }
        writeln!(out, "{line}")?;
    }
    if !compared.is_empty() {
        let parts: Vec<String> = compared
            .iter()
            .map(|c| format!("{} median {:.5}, p95 {:.5}", c.channel, c.median_abs, c.p95_abs))
            .collect();
        writeln!(
            err,
            "compared {} samples, |measured / fitted − 1|: {}",
            table.directions.len(),
            parts.join("; ")
        )?;
    }
    Ok(())
}
