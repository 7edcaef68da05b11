//! Sky models on plain files, as `campanile sky` runs them: a fit to a
//! table of samples (with an optional residual map), a prediction at
//! another sun position from fitted skies, and a sky as a lat-long map.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use anyhow::Context;
use campanile_process::exr_io::write_radiance_exr;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::sky::{
    ChannelSelection, ChannelSky, KnownSky, SkyFile, SkyFitOptions, SkyModel, angle_between, direction, fit_sky_with,
    predict_sky, read_samples, render_latlong,
};

use crate::Result;

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
