//! The RAW path end to end on simulated DNG brackets: the Bayer sensor
//! photographs the HDR chart (known radiance), the frames are written as
//! DNG, read back with `read_raw` and merged linearly.

#[path = "raw_bracket/references.rs"]
mod references;

use std::path::{Path, PathBuf};

use campanile_process::camera::bayer::{BayerSensor, Exposure};
use campanile_process::camera::image::RadianceImage;
use campanile_process::camera::test_chart::hdr_chart;
use campanile_process::hdr::dng_file::{DngLayout, DngMetadata, thumbnail_only_dng_bytes, write_dng};
use campanile_process::hdr::linear_merge::{LinearMergeOptions, merge_linear};
use campanile_process::hdr::merge::{MASK_SATURATED, NoiseModel, RadianceMap};
use campanile_process::hdr::raw_file::{is_raw, is_raw_input, read_raw, sniff_dng, sniff_dng_file};

const W: usize = 256;
const H: usize = 128;

/// A 14-bit DSLR-class sensor: 40 000 e⁻ at the white level at base ISO, 4 e⁻
/// read noise. The merge's own error (noiseless bracket) is a 0.10–0.20 %
/// median; the rest is photon noise, which this full well sets: with
/// 20 000 e⁻ the same bracket gives 0.92–1.10 % median, with 40 000 e⁻
/// 0.68–0.83 %.
fn sensor() -> BayerSensor {
    BayerSensor {
        full_well_electrons: 40_000.0,
        ..BayerSensor::typical_14bit()
    }
}

fn metadata(sensor: &BayerSensor, exposure: Exposure) -> DngMetadata {
    DngMetadata {
        make: "Campanile".into(),
        model: "Simulated Bayer".into(),
        exposure,
        xyz_to_camera: [[0.7, -0.1, -0.05], [-0.45, 1.3, 0.15], [-0.05, 0.2, 0.6]],
        as_shot_neutral: sensor.neutral(),
        calibration_illuminant: 21,
    }
}

/// Photographs `scene` at each exposure, writes DNGs into `dir`, returns their paths.
fn write_bracket(dir: &Path, scene: &RadianceImage, sensor: &BayerSensor, exposures: &[Exposure]) -> Vec<PathBuf> {
    exposures
        .iter()
        .enumerate()
        .map(|(j, e)| {
            let m = sensor.photograph(scene, e, 100 + j as u64);
            let p = dir.join(format!("frame{j}.dng"));
            let layout = if j % 2 == 0 {
                DngLayout::ThumbnailAndSubIfd
            } else {
                DngLayout::SingleIfd
            };
            write_dng(&p, &m, &metadata(sensor, *e), layout).expect("write DNG");
            p
        })
        .collect()
}

fn time_bracket() -> Vec<Exposure> {
    [1.0 / 64.0, 1.0 / 16.0, 0.25, 1.0, 4.0]
        .map(|t| Exposure {
            time_s: t,
            f_number: 4.0,
            iso: 100.0,
        })
        .to_vec()
}

/// Merges the DNGs; the map is in W·m⁻²·sr⁻¹ through the known sensor gain
/// (the merge is relative to the first frame: X = v / k = L · t₀ · gain).
fn merge_files(paths: &[PathBuf], sensor: &BayerSensor, first: &Exposure) -> RadianceMap {
    let frames: Vec<_> = paths.iter().map(|p| read_raw(p).expect("read DNG")).collect();
    let scale = std::array::from_fn(|c| 1.0 / sensor.normalized_value(1.0, first, c));
    let opts = LinearMergeOptions {
        radiometric_scale: scale,
        noise: NoiseModel {
            full_well_electrons: sensor.full_well_electrons,
            read_noise_electrons: sensor.read_noise_electrons,
        },
        ..Default::default()
    };
    merge_linear(&frames, &opts).expect("merge")
}

/// Median of map / truth − 1 of channel `c` over the valid pixels, signed
/// and absolute, and the number of valid pixels.
fn rel_errors(map: &RadianceMap, truth: &RadianceImage, c: usize) -> (f64, f64, usize) {
    let mut rel: Vec<f64> = (0..map.width * map.height)
        .filter(|&p| map.is_valid(p))
        .map(|p| f64::from(map.rgb[3 * p + c]) / f64::from(truth.data[3 * p + c]) - 1.0)
        .collect();
    rel.sort_by(f64::total_cmp);
    let signed = rel[rel.len() / 2];
    let mut abs: Vec<f64> = rel.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    (abs[abs.len() / 2], signed, abs.len())
}

#[test]
fn simulated_dng_bracket_merges_within_1_percent_median() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let chart = hdr_chart(W, H);
    let exposures = time_bracket();
    let paths = write_bracket(dir.path(), &chart, &sensor, &exposures);
    let map = merge_files(&paths, &sensor, &exposures[0]);
    assert_eq!((map.width, map.height), (W, H));
    assert!(map.rgb.iter().all(|v| v.is_finite()));
    for c in 0..3 {
        let (median, signed, valid) = rel_errors(&map, &chart, c);
        println!("channel {c}: median |relative error| {median:.5} (signed {signed:+.5}) over {valid} valid pixels");
        assert!(valid > W * H * 9 / 10, "channel {c}: only {valid} valid pixels");
        assert!(median <= 0.01, "channel {c}: median relative error {median}");
    }
}

#[test]
fn clipped_highlight_is_flagged_saturated_never_interpolated_into_valid() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let mut scene = hdr_chart(64, 32);
    // A 9×7 sun-like block at 1000 W·m⁻²·sr⁻¹: clipped even at 1/64 s.
    let block = |x: usize, y: usize| (20..29).contains(&x) && (10..17).contains(&y);
    for y in 0..32 {
        for x in 0..64 {
            if block(x, y) {
                scene.data[(y * 64 + x) * 3..(y * 64 + x) * 3 + 3].copy_from_slice(&[1000.0; 3]);
            }
        }
    }
    let exposures = time_bracket();
    let paths = write_bracket(dir.path(), &scene, &sensor, &exposures);
    let map = merge_files(&paths, &sensor, &exposures[0]);
    for y in 0..32 {
        for x in 0..64 {
            let p = y * 64 + x;
            if block(x, y) {
                assert_eq!(map.mask[p] & 0b111, 0b111, "pixel ({x}, {y}) mask {:#b}", map.mask[p]);
                assert!(!map.is_valid(p));
                // The value is the lower bound: the white level in the shortest exposure.
                let bound = 1.0 / sensor.normalized_value(1.0, &exposures[0], 1);
                assert!((f64::from(map.rgb[3 * p + 1]) - bound).abs() < 1e-3 * bound);
            } else if map.is_valid(p) && (17..31).contains(&x) && (7..20).contains(&y) {
                // Next to the block: valid channels never carry the clipped value.
                for c in 0..3 {
                    let r = f64::from(map.rgb[3 * p + c]) / f64::from(scene.data[3 * p + c]);
                    assert!(r < 2.0, "pixel ({x}, {y}) channel {c}: {r}× the truth, marked valid");
                }
            }
        }
    }
    // Outside the block, green is flagged exactly where it was interpolated
    // from a clipped photosite: the red and blue sites touching the block's
    // edges (RGGB: 3 left, 3 right, 4 above, 4 below), none elsewhere.
    let flagged_outside: Vec<(usize, usize)> = (0..64 * 32)
        .filter(|&p| !block(p % 64, p / 64) && map.mask[p] & (MASK_SATURATED << 1) != 0)
        .map(|p| (p % 64, p / 64))
        .collect();
    assert_eq!(flagged_outside.len(), 14, "{flagged_outside:?}");
    for &(x, y) in &flagged_outside {
        assert_eq!((x + y) % 2, 0, "({x}, {y}) is not a red or blue site");
        let touches = block(x + 1, y) || block(x.wrapping_sub(1), y) || block(x, y + 1) || block(x, y.wrapping_sub(1));
        assert!(touches, "({x}, {y}) does not touch the block");
    }
}

#[test]
fn iso_and_aperture_bracket_merges_to_the_same_radiance() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let chart = hdr_chart(W, H);
    // Relative exposures 1, 4, 16, 64, 256 through time, aperture and ISO.
    let e = |time_s: f64, f_number: f64, iso: f64| Exposure { time_s, f_number, iso };
    let exposures = vec![
        e(1.0 / 64.0, 4.0, 100.0),
        e(1.0 / 16.0, 4.0, 100.0),
        e(1.0 / 16.0, 2.0, 100.0),
        e(1.0 / 16.0, 2.0, 400.0),
        e(0.25, 2.0, 400.0),
    ];
    let paths = write_bracket(dir.path(), &chart, &sensor, &exposures);
    let mixed = merge_files(&paths, &sensor, &exposures[0]);
    let dir2 = tempfile::tempdir().expect("temp");
    let times = write_bracket(dir2.path(), &chart, &sensor, &time_bracket());
    let timed = merge_files(&times, &sensor, &exposures[0]);
    for c in 0..3 {
        // ISO 400 frames collect 4× fewer electrons, so the noise is larger
        // than the time bracket's (median |error| 0.9–1.1 %); what this test
        // checks is the scale k = t·ISO/N²: a wrong k would bias the median
        // by a factor (2× for N instead of N², 4× for a missed ISO).
        let (median, signed, valid) = rel_errors(&mixed, &chart, c);
        println!(
            "ISO/aperture bracket, channel {c}: median |relative error| {median:.5} (signed {signed:+.5}) over {valid} valid pixels"
        );
        assert!(
            signed.abs() <= 0.003,
            "channel {c}: median signed relative error {signed}"
        );
        // The same radiance as the time bracket: median ratio within 0.5 %.
        let mut ratio: Vec<f64> = (0..W * H)
            .filter(|&p| mixed.is_valid(p) && timed.is_valid(p))
            .map(|p| f64::from(mixed.rgb[3 * p + c]) / f64::from(timed.rgb[3 * p + c]))
            .collect();
        ratio.sort_by(f64::total_cmp);
        let m = ratio[ratio.len() / 2];
        assert!(
            (m - 1.0).abs() < 0.005,
            "channel {c}: median ratio to the time bracket {m}"
        );
    }
}

#[test]
fn thumbnail_only_dng_is_refused_naming_file_and_size() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let p = dir.path().join("stripped.dng");
    std::fs::write(
        &p,
        thumbnail_only_dng_bytes(8, 8, &metadata(&sensor, time_bracket()[0])),
    )
    .expect("write");
    let err = read_raw(&p).expect_err("a thumbnail must not be read").to_string();
    assert_eq!(
        err,
        format!(
            "{}: no pixel data: the only image is a 8×8 8-bit RGB preview (NewSubFileType 1); \
             expected a full-resolution CFA or LinearRaw image (NewSubFileType 0); a thumbnail is never merged",
            p.display()
        )
    );
    // Renamed .tif: still recognized as DNG, still refused.
    let tif = dir.path().join("stripped.tif");
    std::fs::copy(&p, &tif).expect("copy");
    assert!(is_raw_input(&tif));
    assert!(read_raw(&tif).is_err());
}

#[test]
fn dng_renamed_tif_is_recognized_by_its_dng_version_tag() {
    let dir = tempfile::tempdir().expect("temp");
    let sensor = sensor();
    let chart = hdr_chart(32, 16);
    let e = time_bracket()[2];
    let dng = dir.path().join("frame.tif");
    write_dng(
        &dng,
        &sensor.photograph(&chart, &e, 1),
        &metadata(&sensor, e),
        DngLayout::ThumbnailAndSubIfd,
    )
    .expect("write");
    assert!(!is_raw(&dng), "not by its extension");
    assert!(sniff_dng_file(&dng));
    assert!(is_raw_input(&dng));
    let frame = read_raw(&dng).expect("read as DNG");
    assert_eq!(
        (frame.width, frame.height),
        (32, 16),
        "the raw image, not the 4×2 thumbnail"
    );
    assert_eq!(frame.meta.exposure_time_s, Some(0.25));
    assert_eq!(frame.meta.iso, Some(100.0));
    assert_eq!(frame.meta.f_number, Some(4.0));
    // A plain TIFF is not a DNG.
    let plain = dir.path().join("plain.tif");
    image::RgbImage::from_pixel(4, 4, image::Rgb([1, 2, 3]))
        .save(&plain)
        .expect("tiff");
    assert!(!sniff_dng_file(&plain));
    assert!(!sniff_dng(b"II*\0"));
}
