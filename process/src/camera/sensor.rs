//! The sensor: exposure, shot and read noise, saturation and quantization,
//! followed by the camera's response curve.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::code_table::code_tables;
use super::image::{CodeImage, RadianceImage, max_code};
use super::response::ParametricResponse;

/// The electrical side of a sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorModel {
    /// Electrons at saturation (the full well). Shot noise is Poisson in electrons.
    pub full_well_electrons: f64,
    /// Read noise, standard deviation in electrons.
    pub read_noise_electrons: f64,
    /// Bits per output sample: 8, 12 or 16.
    pub bits: u8,
    /// Per-channel gain: normalized exposure (1 = full well) per unit radiant
    /// exposure, i.e. per (W·m⁻²·sr⁻¹ · s).
    pub gain: [f64; 3],
}

/// A camera: sensor plus per-channel response curves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraModel {
    /// The sensor.
    pub sensor: SensorModel,
    /// Response curve of each channel.
    pub response: [ParametricResponse; 3],
}

impl CameraModel {
    /// A typical consumer camera: γ ≈ 2.2 with a film-like S-curve (slightly
    /// different per channel), 20 000 e⁻ full well, 4 e⁻ read noise.
    pub fn typical(bits: u8) -> Self {
        let r = |g, c| ParametricResponse::new(g, c).expect("constant parameters are valid");
        Self {
            sensor: SensorModel {
                full_well_electrons: 20_000.0,
                read_noise_electrons: 4.0,
                bits,
                gain: [1.0, 1.0, 1.0],
            },
            response: [r(2.3, 0.55), r(2.2, 0.5), r(2.1, 0.45)],
        }
    }

    /// Normalized sensor exposure (1 = full well) of channel `c` for radiance
    /// `radiance` (W·m⁻²·sr⁻¹) over `exposure_time_s`: `x = L · t · k_c`.
    pub fn normalized_exposure(&self, radiance: f64, exposure_time_s: f64, c: usize) -> f64 {
        radiance * exposure_time_s * self.sensor.gain[c]
    }

    /// The noiseless code (real-valued, before rounding) of channel `c`:
    /// `(2^bits − 1) · f_c(min(x, 1))`.
    pub fn ideal_code(&self, radiance: f64, exposure_time_s: f64, c: usize) -> f64 {
        let x = self.normalized_exposure(radiance, exposure_time_s, c);
        f64::from(max_code(self.sensor.bits)) * self.response[c].code_fraction(x)
    }

    /// The true inverse response in log form: `ln f_c⁻¹(z / (2^bits − 1))`,
    /// the natural log of the normalized exposure that produces code `z`.
    /// This is what Debevec–Malik's `g(z)` recovers, up to an additive constant.
    pub fn true_ln_exposure(&self, code: f64, c: usize) -> f64 {
        let y = code / f64::from(max_code(self.sensor.bits));
        self.response[c].exposure(y).ln()
    }

    /// Photographs `scene` for `exposure_time_s` seconds.
    ///
    /// Per sample: electrons `e = x · FW` with `x = L · t · k_c`; noise
    /// `e + √e·n₁ + σ_read·n₂` (Gaussian approximation of Poisson shot noise,
    /// `n₁, n₂ ~ N(0, 1)`); clipping to `[0, FW]` (saturation); the response
    /// `f_c`; rounding to the nearest code. Each row draws from its own ChaCha8
    /// stream of `seed`, so the result is the same for the same seed on any
    /// number of threads.
    pub fn photograph(&self, scene: &RadianceImage, exposure_time_s: f64, seed: u64) -> CodeImage {
        // The response's codes tabulated: the same codes as
        // `round(top · f(x))`, without a power and a sine per sample.
        let tables = code_tables(&self.response, self.sensor.bits);
        self.expose(scene, exposure_time_s, seed, |c, x| tables[c].code(x))
    }

    /// Photographs `scene` as [`CameraModel::photograph`] does, but read out
    /// linearly, as an astro or machine-vision sensor's FITS frame is: the
    /// code is `(2^bits − 1) · x` (the white level is the full well), no
    /// response curve.
    pub fn photograph_linear(&self, scene: &RadianceImage, exposure_time_s: f64, seed: u64) -> CodeImage {
        let top = f64::from(max_code(self.sensor.bits));
        self.expose(scene, exposure_time_s, seed, |_, x| (top * x).round() as u16)
    }

    /// Exposure, noise and clipping as [`CameraModel::photograph`]
    /// describes, then `quantize(channel, x)`: the code of the clipped
    /// normalized exposure `x`.
    fn expose(
        &self,
        scene: &RadianceImage,
        exposure_time_s: f64,
        seed: u64,
        quantize: impl Fn(usize, f64) -> u16 + Sync,
    ) -> CodeImage {
        let s = self.sensor;
        let width = scene.width;
        let mut data = vec![0u16; scene.data.len()];
        data.par_chunks_mut(width * 3).enumerate().for_each(|(y, row)| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(y as u64);
            let src = &scene.data[y * width * 3..(y + 1) * width * 3];
            for (i, (out, &l)) in row.iter_mut().zip(src).enumerate() {
                let c = i % 3;
                let x = self.normalized_exposure(f64::from(l.max(0.0)), exposure_time_s, c);
                let e = x * s.full_well_electrons;
                let (n1, n2) = standard_normal_pair(&mut rng);
                let noisy = e + e.max(0.0).sqrt() * n1 + s.read_noise_electrons * n2;
                let xn = (noisy / s.full_well_electrons).clamp(0.0, 1.0);
                *out = quantize(c, xn);
            }
        });
        CodeImage {
            width,
            height: scene.height,
            bits: s.bits,
            data,
            label: format!("simulated exposure {exposure_time_s} s (seed {seed})"),
        }
    }
}

/// Two independent standard normal variates (Box–Muller).
pub fn standard_normal_pair<R: Rng>(rng: &mut R) -> (f64, f64) {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    (r * c, r * s)
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

    #[test]
    fn same_seed_same_image_other_seed_differs() {
        let cam = CameraModel::typical(8);
        let scene = flat(0.3, 32);
        let a = cam.photograph(&scene, 1.0, 7);
        let b = cam.photograph(&scene, 1.0, 7);
        let c = cam.photograph(&scene, 1.0, 8);
        assert_eq!(a, b);
        assert_ne!(a.data, c.data);
    }

    #[test]
    fn noise_matches_poisson_plus_read_within_10_percent() {
        // 16-bit so that quantization is negligible; measure the spread in
        // normalized exposure by inverting the (known) response.
        let cam = CameraModel::typical(16);
        let scene = flat(0.25, 128);
        let img = cam.photograph(&scene, 1.0, 3);
        let c = 1;
        let xs: Vec<f64> = img
            .data
            .iter()
            .skip(c)
            .step_by(3)
            .map(|&z| cam.true_ln_exposure(f64::from(z), c).exp())
            .collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (xs.len() - 1) as f64;
        let fw = cam.sensor.full_well_electrons;
        let expected = (0.25 * fw + 16.0) / (fw * fw);
        assert!((mean - 0.25).abs() < 0.001, "mean {mean}");
        assert!((var / expected - 1.0).abs() < 0.1, "var {var} expected {expected}");
    }

    #[test]
    fn saturates_at_max_code() {
        let cam = CameraModel::typical(12);
        let img = cam.photograph(&flat(10.0, 8), 1.0, 1);
        assert!(img.data.iter().all(|&z| z == 4095));
        let black = cam.photograph(&flat(0.0, 8), 1.0, 1);
        assert!(black.data.iter().all(|&z| z < 400), "read noise only");
    }
}
