//! OpenEXR output and input of merged radiance maps.
//!
//! Channels (all f32, one layer, sorted by name as OpenEXR requires):
//! `R`, `G`, `B` (radiance), `variance.R`, `variance.G`, `variance.B`,
//! `valid` (1 where every channel is valid, else 0) and `mask` (the merge's
//! bit field as a small integer: saturated `1 << c`, underexposed `8 << c`).
//! OpenImageIO and Blender read `R`, `G`, `B` as the colour and the rest as
//! extra channels.
//!
//! [`write_rgb_exr`] writes the plain colour image alone (`R`, `G`, `B`, half
//! or float, no layer name): what every viewer opens, and what `hdr merge`
//! writes unless asked for the variance.

use std::path::Path;

use exr::prelude::*;

use crate::camera::image::RadianceImage;
use crate::hdr::HdrError;
use crate::hdr::merge::RadianceMap;

/// Writes `map` to `path` as OpenEXR (PIZ-compressed scan lines).
pub fn write_radiance_exr(map: &RadianceMap, path: &Path) -> std::result::Result<(), HdrError> {
    let n = map.width * map.height;
    let plane = |src: &[f32], c: usize| -> Vec<f32> { (0..n).map(|p| src[p * 3 + c]).collect() };
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(8);
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        channels.push(AnyChannel::new(*name, FlatSamples::F32(plane(&map.rgb, c))));
        channels.push(AnyChannel::new(
            format!("variance.{name}").as_str(),
            FlatSamples::F32(plane(&map.variance, c)),
        ));
    }
    channels.push(AnyChannel::new(
        "valid",
        FlatSamples::F32(map.mask.iter().map(|&m| f32::from(u8::from(m == 0))).collect()),
    ));
    channels.push(AnyChannel::new(
        "mask",
        FlatSamples::F32(map.mask.iter().map(|&m| f32::from(m)).collect()),
    ));
    write_layer(map, LayerAttributes::named("radiance"), channels, path)
}

/// Writes one PIZ-compressed scan-line layer of `map`'s size.
fn write_layer(
    map: &RadianceMap,
    attributes: LayerAttributes,
    channels: Vec<AnyChannel<FlatSamples>>,
    path: &Path,
) -> std::result::Result<(), HdrError> {
    // PIZ (wavelet + Huffman, lossless) on scan lines: on a 21 MP float map
    // ZIP's deflate took 40 % of a whole 18-frame merge.
    let encoding = Encoding {
        compression: Compression::PIZ,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (map.width, map.height),
        attributes,
        encoding,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|cause| HdrError::Exr {
            path: path.to_path_buf(),
            cause,
        })
}

/// Sample precision of a plain RGB OpenEXR file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExrPrecision {
    /// 32-bit float.
    #[default]
    Float,
    /// 16-bit half float (max 65504; larger values become +∞).
    Half,
}

/// Writes the radiance of `map` alone as a plain RGB OpenEXR (PIZ-compressed
/// scan lines, channels `R`, `G`, `B`).
pub fn write_rgb_exr(map: &RadianceMap, path: &Path, precision: ExrPrecision) -> std::result::Result<(), HdrError> {
    let n = map.width * map.height;
    let plane = |c: usize| -> FlatSamples {
        let v = (0..n).map(|p| map.rgb[p * 3 + c]);
        match precision {
            ExrPrecision::Float => FlatSamples::F32(v.collect()),
            ExrPrecision::Half => FlatSamples::F16(v.map(f16::from_f32).collect()),
        }
    };
    let channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(c, name)| AnyChannel::new(*name, plane(c)))
        .collect();
    write_layer(map, LayerAttributes::default(), channels, path)
}

/// The first layer of the OpenEXR file at `path`, all channels as flat
/// samples; `expected` names what the caller wanted, for the error.
fn first_layer(path: &Path, expected: &str) -> std::result::Result<Layer<AnyChannels<FlatSamples>>, HdrError> {
    let image = read_all_flat_layers_from_file(path).map_err(|cause| HdrError::Exr {
        path: path.to_path_buf(),
        cause,
    })?;
    image.layer_data.into_iter().next().ok_or_else(|| HdrError::BadImage {
        image: path.display().to_string(),
        what: format!("no layer: expected {expected}"),
    })
}

/// Reads a file written by [`write_radiance_exr`].
pub fn read_radiance_exr(path: &Path) -> std::result::Result<RadianceMap, HdrError> {
    let layer = first_layer(path, "one radiance layer")?;
    let (w, h) = (layer.size.width(), layer.size.height());
    let get = |name: &str| -> std::result::Result<Vec<f32>, HdrError> {
        layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.to_string() == name)
            .map(|ch| ch.sample_data.values_as_f32().collect())
            .ok_or_else(|| HdrError::BadImage {
                image: path.display().to_string(),
                what: format!("no channel '{name}': expected R, G, B, variance.R/G/B, valid, mask"),
            })
    };
    let mut rgb = vec![0.0; w * h * 3];
    let mut variance = vec![0.0; w * h * 3];
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        for (p, v) in get(name)?.into_iter().enumerate() {
            rgb[p * 3 + c] = v;
        }
        for (p, v) in get(&format!("variance.{name}"))?.into_iter().enumerate() {
            variance[p * 3 + c] = v;
        }
    }
    let mask = get("mask")?.into_iter().map(|v| v as u8).collect();
    Ok(RadianceMap {
        width: w,
        height: h,
        rgb,
        variance,
        mask,
    })
}

/// Reads the `R`, `G`, `B` channels of the first layer of any OpenEXR file
/// (e.g. a flat-field radiance map for `hdr lens`), or, where there is no
/// `R`, the one `PREFIX.R`, `PREFIX.G`, `PREFIX.B` set (a renderer's layer,
/// e.g. Blender's `ViewLayer.Combined.R`).
pub fn read_rgb_exr(path: &Path) -> std::result::Result<RadianceImage, HdrError> {
    let layer = first_layer(path, "an RGB layer")?;
    let (w, h) = (layer.size.width(), layer.size.height());
    let names: Vec<String> = layer.channel_data.list.iter().map(|ch| ch.name.to_string()).collect();
    let prefix = if names.iter().any(|n| n == "R") {
        String::new()
    } else {
        let sets: Vec<&str> = names
            .iter()
            .filter_map(|n| n.strip_suffix(".R"))
            .filter(|p| names.contains(&format!("{p}.G")) && names.contains(&format!("{p}.B")))
            .collect();
        match sets.as_slice() {
            [p] => format!("{p}."),
            _ => String::new(),
        }
    };
    let mut data = vec![0.0f32; w * h * 3];
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let name = format!("{prefix}{name}");
        let ch = layer
            .channel_data
            .list
            .iter()
            .find(|ch| ch.name.to_string() == name)
            .ok_or_else(|| HdrError::BadImage {
                image: path.display().to_string(),
                what: format!(
                    "no channel '{name}': expected R, G and B, or one LAYER.R, LAYER.G, LAYER.B set (it has: {})",
                    names.join(", ")
                ),
            })?;
        if ch.sample_data.len() != w * h {
            return Err(HdrError::BadImage {
                image: path.display().to_string(),
                what: format!(
                    "channel '{name}' has {} samples: expected one per pixel ({w}x{h}, not subsampled)",
                    ch.sample_data.len()
                ),
            });
        }
        for (p, v) in ch.sample_data.values_as_f32().enumerate() {
            data[p * 3 + c] = v;
        }
    }
    Ok(RadianceImage {
        width: w,
        height: h,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_rgb_exr_has_only_r_g_b_in_float_or_half() {
        let (w, h) = (4, 2);
        let map = RadianceMap {
            width: w,
            height: h,
            rgb: (0..w * h * 3).map(|i| 0.5 + i as f32).collect(),
            variance: vec![1.0; w * h * 3],
            mask: vec![0; w * h],
        };
        let dir = tempfile::tempdir().unwrap();
        for (precision, kind) in [(ExrPrecision::Float, "F32"), (ExrPrecision::Half, "F16")] {
            let path = dir.path().join(format!("{kind}.exr"));
            write_rgb_exr(&map, &path, precision).unwrap();
            let image = read_all_flat_layers_from_file(&path).unwrap();
            let layer = &image.layer_data[0];
            let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
            assert_eq!(names, ["B", "G", "R"]);
            assert!(layer.attributes.layer_name.is_none());
            let r = &layer.channel_data.list[2].sample_data;
            let is_kind = match r {
                FlatSamples::F32(_) => kind == "F32",
                FlatSamples::F16(_) => kind == "F16",
                FlatSamples::U32(_) => false,
            };
            assert!(is_kind, "{kind}");
            let back = read_rgb_exr(&path).unwrap();
            assert_eq!(back.data, map.rgb, "{kind}: values 0.5..23.5 are exact in half too");
        }
    }

    #[test]
    fn exr_round_trip_checks_channels_and_values_with_the_exr_crate() {
        let (w, h) = (5, 3);
        let rgb: Vec<f32> = (0..w * h * 3).map(|i| 0.001 * (i as f32 + 1.0).powi(3)).collect();
        let variance: Vec<f32> = rgb.iter().map(|v| v * 1e-4).collect();
        let mut mask = vec![0u8; w * h];
        mask[4] = 0b101;
        let map = RadianceMap {
            width: w,
            height: h,
            rgb,
            variance,
            mask,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.exr");
        write_radiance_exr(&map, &path).unwrap();
        // Independent read with the exr crate's generic reader: channel names and exact values.
        let img = read_all_flat_layers_from_file(&path).unwrap();
        let layer = &img.layer_data[0];
        let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
        assert_eq!(
            names,
            ["B", "G", "R", "mask", "valid", "variance.B", "variance.G", "variance.R"]
        );
        let r: Vec<f32> = layer.channel_data.list[2].sample_data.values_as_f32().collect();
        assert_eq!(r[7], map.rgb[7 * 3]);
        let valid: Vec<f32> = layer.channel_data.list[4].sample_data.values_as_f32().collect();
        assert_eq!(valid[4], 0.0);
        assert_eq!(valid[3], 1.0);
        let back = read_radiance_exr(&path).unwrap();
        assert_eq!(back, map, "lossless round trip");
        let rgb = read_rgb_exr(&path).unwrap();
        assert_eq!(rgb.data, map.rgb);
    }

    #[test]
    fn rgb_of_a_renderer_layer_is_read_by_its_prefix() {
        let (w, h) = (3, 2);
        let plane = |c: usize| FlatSamples::F32((0..w * h).map(|p| (p * 3 + c) as f32).collect());
        let channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(c, n)| AnyChannel::new(format!("ViewLayer.Combined.{n}").as_str(), plane(c)))
            .chain(std::iter::once(AnyChannel::new("ViewLayer.Depth.Z", plane(0))))
            .collect();
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(channels)),
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blender.exr");
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let img = read_rgb_exr(&path).unwrap();
        assert_eq!(img.data, (0..w * h * 3).map(|i| i as f32).collect::<Vec<_>>());
    }
}
