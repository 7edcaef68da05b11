//! A simulated Bayer sensor: photographs a [`RadianceImage`] into a linear
//! colour-filter-array mosaic, as a camera's RAW file stores it.
//!
//! Per photosite of colour `c` (from the 2×2 pattern): collected electrons
//! `e = x_c · FW` with `x_c = L_c · t · k_c · (N_ref / N)²` (radiance `L`, time
//! `t`, per-channel gain `k_c` as in [`super::sensor::SensorModel`], f-number
//! `N`); noise `e + √e·n₁ + σ_read·n₂` (the Gaussian approximation of Poisson
//! shot noise, as [`super::sensor::CameraModel::photograph`]); analog gain
//! `ISO / ISO_base`; then `v = noisy · ISO / (ISO_base · FW)`, clipped to `v ≤ 1`
//! (the white level) and written as the raw code
//! `round(black + v · (white − black))`, at least 0. At base ISO the white
//! level is the full well; at higher ISO it is reached with fewer electrons.
//! Each row draws from its own ChaCha8 stream of the seed.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::image::RadianceImage;
use super::sensor::standard_normal_pair;

/// A 2×2 Bayer colour filter pattern, named by its top-left, top-right,
/// bottom-left and bottom-right colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CfaPattern {
    /// Red at (0, 0).
    Rggb,
    /// Blue at (0, 0).
    Bggr,
    /// Green, red on the first row.
    Grbg,
    /// Green, blue on the first row.
    Gbrg,
}

impl CfaPattern {
    /// All four patterns.
    pub const ALL: [CfaPattern; 4] = [Self::Rggb, Self::Bggr, Self::Grbg, Self::Gbrg];

    /// Colours (0 = R, 1 = G, 2 = B) of the 2×2 cell, row-major — the DNG
    /// CFAPattern tag's bytes.
    pub fn colors(self) -> [u8; 4] {
        match self {
            Self::Rggb => [0, 1, 1, 2],
            Self::Bggr => [2, 1, 1, 0],
            Self::Grbg => [1, 0, 2, 1],
            Self::Gbrg => [1, 2, 0, 1],
        }
    }

    /// The pattern with these colours, if it is one of the four.
    pub fn from_colors(colors: [u8; 4]) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.colors() == colors)
    }

    /// Colour of the photosite at column `x`, row `y`.
    pub fn color_at(self, x: usize, y: usize) -> usize {
        usize::from(self.colors()[(y % 2) * 2 + x % 2])
    }

    /// The pattern's name, e.g. "RGGB".
    pub fn name(self) -> &'static str {
        match self {
            Self::Rggb => "RGGB",
            Self::Bggr => "BGGR",
            Self::Grbg => "GRBG",
            Self::Gbrg => "GBRG",
        }
    }
}

/// How one frame was exposed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exposure {
    /// Exposure time in seconds.
    pub time_s: f64,
    /// Aperture f-number.
    pub f_number: f64,
    /// ISO speed.
    pub iso: f64,
}

/// A Bayer sensor and its analog-to-digital conversion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BayerSensor {
    /// Electrons at the white level at base ISO (the full well).
    pub full_well_electrons: f64,
    /// Read noise, 1σ, in electrons.
    pub read_noise_electrons: f64,
    /// Per-channel gain at the reference f-number: fraction of the full well
    /// per unit radiant exposure (W·m⁻²·sr⁻¹ · s).
    pub gain: [f64; 3],
    /// Bits per raw sample (12 or 14).
    pub bits: u8,
    /// Black level per position of the 2×2 pattern, row-major.
    pub black_levels: [u16; 4],
    /// White level: the code of a saturated photosite.
    pub white_level: u16,
    /// The colour filter pattern.
    pub pattern: CfaPattern,
    /// ISO at which the white level is the full well.
    pub base_iso: f64,
    /// F-number at which `gain` holds.
    pub reference_f_number: f64,
}

impl BayerSensor {
    /// A 14-bit RGGB sensor: 20 000 e⁻ full well, 4 e⁻ read noise, black 256,
    /// white 16383, gains R 0.5, G 1, B 0.7 (green the most sensitive, as in
    /// real cameras), base ISO 100 at f/4.
    pub fn typical_14bit() -> Self {
        Self {
            full_well_electrons: 20_000.0,
            read_noise_electrons: 4.0,
            gain: [0.5, 1.0, 0.7],
            bits: 14,
            black_levels: [256; 4],
            white_level: 16_383,
            pattern: CfaPattern::Rggb,
            base_iso: 100.0,
            reference_f_number: 4.0,
        }
    }

    /// The noiseless normalized raw value (0 = black, 1 = white level,
    /// unclipped) of channel `c` for radiance `radiance`.
    pub fn normalized_value(&self, radiance: f64, e: &Exposure, c: usize) -> f64 {
        let aperture = (self.reference_f_number / e.f_number).powi(2);
        radiance * e.time_s * self.gain[c] * aperture * e.iso / self.base_iso
    }

    /// The white-balance neutral of this sensor: each channel's response to
    /// a white (equal-radiance) object, relative to green — the DNG
    /// AsShotNeutral of a daylight shot.
    pub fn neutral(&self) -> [f64; 3] {
        let g = self.gain[1];
        [self.gain[0] / g, 1.0, self.gain[2] / g]
    }

    /// Photographs `scene` with shot and read noise (seeded).
    pub fn photograph(&self, scene: &RadianceImage, e: &Exposure, seed: u64) -> BayerMosaic {
        self.expose(scene, e, Some(seed))
    }

    /// Photographs `scene` without noise: every code is the rounded ideal value.
    pub fn photograph_noiseless(&self, scene: &RadianceImage, e: &Exposure) -> BayerMosaic {
        self.expose(scene, e, None)
    }

    fn expose(&self, scene: &RadianceImage, e: &Exposure, seed: Option<u64>) -> BayerMosaic {
        let (w, h) = (scene.width, scene.height);
        let fw = self.full_well_electrons;
        let amp = e.iso / self.base_iso;
        let white = f64::from(self.white_level);
        let mut data = vec![0u16; w * h];
        data.par_chunks_mut(w.max(1)).enumerate().for_each(|(y, row)| {
            let mut rng = seed.map(|s| {
                let mut r = ChaCha8Rng::seed_from_u64(s);
                r.set_stream(y as u64);
                r
            });
            for (x, out) in row.iter_mut().enumerate() {
                let c = self.pattern.color_at(x, y);
                let l = f64::from(scene.data[(y * w + x) * 3 + c].max(0.0));
                let electrons = self.normalized_value(l, e, c) / amp * fw;
                let noisy = match rng.as_mut() {
                    Some(r) => {
                        let (n1, n2) = standard_normal_pair(r);
                        electrons + electrons.max(0.0).sqrt() * n1 + self.read_noise_electrons * n2
                    }
                    None => electrons,
                };
                let v = (noisy * amp / fw).min(1.0);
                let black = f64::from(self.black_levels[(y % 2) * 2 + x % 2]);
                *out = (black + v * (white - black)).round().clamp(0.0, white) as u16;
            }
        });
        BayerMosaic {
            width: w,
            height: h,
            data,
            pattern: self.pattern,
            bits: self.bits,
            black_levels: self.black_levels,
            white_level: self.white_level,
        }
    }
}

/// A raw colour-filter-array image: one code per photosite.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BayerMosaic {
    /// Width in photosites.
    pub width: usize,
    /// Height in photosites.
    pub height: usize,
    /// Codes, row-major, `width · height` of them.
    pub data: Vec<u16>,
    /// The colour filter pattern.
    pub pattern: CfaPattern,
    /// Bits per sample.
    pub bits: u8,
    /// Black level per position of the 2×2 pattern, row-major.
    pub black_levels: [u16; 4],
    /// White level.
    pub white_level: u16,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(l: f32, n: usize) -> RadianceImage {
        RadianceImage {
            width: n,
            height: n,
            data: vec![l; n * n * 3],
        }
    }

    const BASE: Exposure = Exposure {
        time_s: 1.0,
        f_number: 4.0,
        iso: 100.0,
    };

    #[test]
    fn noiseless_codes_follow_the_pattern_gain_and_black() {
        let s = BayerSensor {
            black_levels: [256, 260, 252, 258],
            ..BayerSensor::typical_14bit()
        };
        let m = s.photograph_noiseless(&flat(0.5, 4), &BASE);
        // R at (0,0): 256 + 0.25·(16383−256) = 4287.75 → 4288; G at (1,0): 260 + 0.5·16123 = 8321.5 → 8322 (ties away from zero).
        assert_eq!(m.data[0], 4288);
        assert_eq!(m.data[1], 8322);
        // B at (1,1): 258 + 0.35·16125 = 5901.75 → 5902.
        assert_eq!(m.data[5], 5902);
    }

    #[test]
    fn clips_exactly_at_the_white_level_and_iso_reaches_it_sooner() {
        let s = BayerSensor::typical_14bit();
        let m = s.photograph(&flat(10.0, 8), &BASE, 1);
        assert!(m.data.iter().all(|&z| z == 16_383));
        // 0.3 of the full well at ISO 100 is 0.6 of the white level at ISO 200 (green).
        let e = Exposure { iso: 200.0, ..BASE };
        let g = s.photograph_noiseless(&flat(0.3, 2), &e).data[1];
        assert_eq!(g, (256.0f64 + 0.6 * 16_127.0).round() as u16);
    }

    #[test]
    fn noise_is_shot_plus_read_within_10_percent() {
        let s = BayerSensor::typical_14bit();
        let m = s.photograph(&flat(0.25, 128), &BASE, 3);
        // Green photosites: x = 0.25, e = 5000 e⁻.
        let v: Vec<f64> = (0..128 * 128)
            .filter(|i| s.pattern.color_at(i % 128, i / 128) == 1)
            .map(|i| (f64::from(m.data[i]) - 256.0) / 16_127.0)
            .collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        let expected = (5000.0 + 16.0) / 20_000f64.powi(2) + 1.0 / (12.0 * 16_127f64.powi(2));
        assert!((mean - 0.25).abs() < 5e-4, "mean {mean}");
        assert!((var / expected - 1.0).abs() < 0.1, "var {var} expected {expected}");
    }

    #[test]
    fn same_seed_same_mosaic() {
        let s = BayerSensor::typical_14bit();
        let a = s.photograph(&flat(0.2, 16), &BASE, 9);
        assert_eq!(a, s.photograph(&flat(0.2, 16), &BASE, 9));
        assert_ne!(a.data, s.photograph(&flat(0.2, 16), &BASE, 10).data);
    }
}
