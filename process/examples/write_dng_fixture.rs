//! Writes the small DNG fixtures of `validation/raw/fixtures/` that a public
//! DNG reader (LibRaw, through rawpy) decodes in `validation/raw/check_dng.py`
//! and `process/tests/raw_references.rs` compares with `read_raw`.
//!
//! Each is 96×64 photosites: a grid of 6×4 flat patches, 16×16 each, with
//! distinct colours over three decades; patch (5, 0) saturates every
//! channel and patch (4, 0) only green. Noiseless, so a patch's interior is
//! exactly flat and any demosaic gives the same value there.
//!
//!     cargo run -p campanile-process --example write_dng_fixture -- validation/raw/fixtures

use std::path::PathBuf;

use campanile_process::camera::bayer::{BayerSensor, CfaPattern, Exposure};
use campanile_process::camera::image::RadianceImage;
use campanile_process::hdr::dng_file::{DngLayout, DngMetadata, write_dng};

fn scene() -> RadianceImage {
    let (w, h) = (96, 64);
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let (px, py) = (x / 16, y / 16);
            let rgb = match (px, py) {
                (5, 0) => [50.0, 50.0, 50.0],
                (4, 0) => [0.5, 8.0, 0.5],
                _ => {
                    let i = (py * 6 + px) as f64;
                    let base = 0.002 * 10f64.powf(i / 8.0);
                    [
                        base * (1.0 + 0.3 * (i * 0.7).sin()),
                        base,
                        base * (1.0 + 0.3 * (i * 1.3).cos()),
                    ]
                }
            };
            data.extend(rgb.map(|v| v as f32));
        }
    }
    RadianceImage {
        width: w,
        height: h,
        data,
    }
}

fn main() {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "validation/raw/fixtures".into()),
    );
    let scene = scene();
    let exposure = Exposure {
        time_s: 0.25,
        f_number: 4.0,
        iso: 100.0,
    };
    let fixtures = [
        (
            "sim_rggb_14bit",
            CfaPattern::Rggb,
            14u8,
            [256u16, 260, 252, 258],
            DngLayout::ThumbnailAndSubIfd,
        ),
        (
            "sim_bggr_14bit",
            CfaPattern::Bggr,
            14,
            [512, 512, 512, 512],
            DngLayout::SingleIfd,
        ),
        (
            "sim_grbg_12bit",
            CfaPattern::Grbg,
            12,
            [128, 130, 126, 128],
            DngLayout::SingleIfd,
        ),
        (
            "sim_gbrg_12bit",
            CfaPattern::Gbrg,
            12,
            [64, 64, 64, 64],
            DngLayout::ThumbnailAndSubIfd,
        ),
    ];
    for (name, pattern, bits, black_levels, layout) in fixtures {
        let sensor = BayerSensor {
            pattern,
            bits,
            black_levels,
            white_level: ((1u32 << bits) - 1) as u16,
            ..BayerSensor::typical_14bit()
        };
        let mosaic = sensor.photograph_noiseless(&scene, &exposure);
        let meta = DngMetadata {
            make: "Campanile".into(),
            model: "Simulated Bayer".into(),
            exposure,
            // A plausible daylight matrix (XYZ → camera), of the kind DNG files carry.
            xyz_to_camera: [[0.7, -0.1, -0.05], [-0.45, 1.3, 0.15], [-0.05, 0.2, 0.6]],
            as_shot_neutral: sensor.neutral(),
            calibration_illuminant: 21,
        };
        let path = dir.join(format!("{name}.dng"));
        if let Err(e) = write_dng(&path, &mosaic, &meta, layout) {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
        println!("wrote {}", path.display());
    }
}
