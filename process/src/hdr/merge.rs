//! HDR assembly: one parallel pass over the pixels, driven by lookup tables.
//!
//! For exposure `j` (time `t_j`) and code `z`, the curve gives the relative
//! exposure `e(z) = exp g(z)` and the radiance estimate `X_j = e(z) / t_j`.
//! With `x(z) = e(z)/e(z_max)` (≈ fraction of the full well), a Poisson
//! sensor with full well `FW` electrons and read noise `σ_r` gives the variance
//!
//! ```text
//! var x(z) = x(z)/FW + (σ_r/FW)² + x'(z)²/12,     var X_j = e(z_max)² var x(z) / t_j²
//! ```
//!
//! (shot noise, read noise, and quantization through the curve's derivative
//! `x'(z)`). The merge is the minimum-variance (inverse-variance weighted) mean
//!
//! ```text
//! X = Σ_j w_j X_j / Σ_j w_j,   w_j = 1 / var X_j,   var X = 1 / Σ_j w_j
//! ```
//!
//! Codes `0` and `z_max` (clipped) get weight 0 in their channel. The tables
//! `w_j(z)` and `w_j(z)·X_j(z)` are built once per exposure and channel, so the
//! pixel loop is two lookups and two additions per sample.
//!
//! A channel with no unclipped sample is flagged in the mask: saturated (its
//! value is the lower bound `e(z_max)/t_min` from the darkest exposure) or
//! underexposed (its value is the upper bound `e(1)/t_max`). Values are never NaN.
//!
//! Calibrations applied in the same pass: the radiometric scale per channel
//! (relative exposure to W·m⁻²·sr⁻¹), the ND filter transmittance per channel,
//! and the lens falloff `1 + a r² + b r⁴` (see [`super::lens`]).
//! Distortion is a resampling, done afterwards by [`super::lens::undistort`].

use rayon::prelude::*;

use super::HdrError;
use super::bracket::Bracket;
use super::curve::ResponseCurve;
use super::lens::{RadialPolynomial, normalized_r2};

/// Mask bit: channel `c` saturated in every exposure (`1 << c`).
pub const MASK_SATURATED: u8 = 0b000_001;
/// Mask bit: channel `c` underexposed in every exposure (`8 << c`).
pub const MASK_UNDEREXPOSED: u8 = 0b001_000;

/// The sensor noise the weights assume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseModel {
    /// Full-well capacity in electrons.
    pub full_well_electrons: f64,
    /// Read noise in electrons (1σ).
    pub read_noise_electrons: f64,
}

impl Default for NoiseModel {
    /// 20 000 e⁻ and 4 e⁻: a typical small-pixel CMOS sensor.
    fn default() -> Self {
        Self {
            full_well_electrons: 20_000.0,
            read_noise_electrons: 4.0,
        }
    }
}

/// Options of [`merge`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MergeOptions {
    /// Noise model of the weights.
    pub noise: NoiseModel,
    /// Transmittance of the ND filter per channel (1 = no filter).
    pub nd_transmittance: [f64; 3],
    /// Radiance (W·m⁻²·sr⁻¹) per unit of relative exposure per second, per channel.
    pub radiometric_scale: [f64; 3],
    /// Lens falloff to divide out, if known.
    pub falloff: Option<RadialPolynomial>,
}

impl Default for MergeOptions {
    fn default() -> Self {
        Self {
            noise: NoiseModel::default(),
            nd_transmittance: [1.0; 3],
            radiometric_scale: [1.0; 3],
            falloff: None,
        }
    }
}

/// A merged radiance map with per-pixel variance and validity mask.
#[derive(Debug, Clone, PartialEq)]
pub struct RadianceMap {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Interleaved RGB radiance, W·m⁻²·sr⁻¹ (times the radiometric scale's unit).
    pub rgb: Vec<f32>,
    /// Interleaved RGB variance of `rgb`.
    pub variance: Vec<f32>,
    /// Per pixel: 0 = valid; otherwise [`MASK_SATURATED`]` << c` and/or [`MASK_UNDEREXPOSED`]` << c`.
    pub mask: Vec<u8>,
}

impl RadianceMap {
    /// Whether pixel `p` (`y · width + x`) is valid in every channel.
    pub fn is_valid(&self, p: usize) -> bool {
        self.mask[p] == 0
    }
}

/// Per (exposure, channel) tables of weight and weighted radiance, plus the
/// bounds used for clipped pixels.
pub(super) struct Tables {
    pub(super) codes: usize,
    /// `[j][c][z]` → (w, w·X), flattened.
    pub(super) lut: Vec<[f32; 2]>,
    /// Per channel: lower bound for saturated pixels, upper bound for underexposed ones.
    sat_bound: [f32; 3],
    dark_bound: [f32; 3],
    /// Variance scale (the tables' weights are normalized by it).
    pub(super) var_scale: [f64; 3],
}

pub(super) fn build_tables(bits: u8, times: &[f64], curve: &ResponseCurve, noise: &NoiseModel) -> Tables {
    let codes = usize::from(crate::camera::image::max_code(bits)) + 1;
    let zmax = codes - 1;
    let p = times.len();
    let mut raw = vec![[0.0f64; 2]; p * 3 * codes];
    let mut sat_bound = [0.0f32; 3];
    let mut dark_bound = [0.0f32; 3];
    let mut var_scale = [1.0f64; 3];
    let fw = noise.full_well_electrons;
    let read = noise.read_noise_electrons / fw;
    for c in 0..3 {
        let e = curve.exposure_lut(c);
        let emax = e[zmax];
        let x: Vec<f64> = e.iter().map(|v| v / emax).collect();
        let var_x: Vec<f64> = (0..codes)
            .map(|z| {
                let lo = x[z.saturating_sub(1)];
                let hi = x[(z + 1).min(zmax)];
                let dx = (hi - lo) / ((z + 1).min(zmax) - z.saturating_sub(1)) as f64;
                x[z] / fw + read * read + dx * dx / 12.0
            })
            .collect();
        let mut wmax = 0.0f64;
        for (j, &t) in times.iter().enumerate() {
            for z in 1..zmax {
                let var_xj = emax * emax * var_x[z] / (t * t);
                let w = 1.0 / var_xj;
                wmax = wmax.max(w);
                raw[(j * 3 + c) * codes + z] = [w, w * e[z] / t];
            }
        }
        let k = if wmax > 0.0 && wmax.is_finite() { wmax } else { 1.0 };
        for j in 0..p {
            for v in &mut raw[(j * 3 + c) * codes..(j * 3 + c + 1) * codes] {
                v[0] /= k;
                v[1] /= k;
            }
        }
        var_scale[c] = 1.0 / k;
        sat_bound[c] = (e[zmax] / times[0]) as f32;
        dark_bound[c] = (e[1.min(zmax)] / times[p - 1]) as f32;
    }
    let lut = raw.into_iter().map(|[a, b]| [a as f32, b as f32]).collect();
    Tables {
        codes,
        lut,
        sat_bound,
        dark_bound,
        var_scale,
    }
}

/// Merges `bracket` into a radiance map through `curve`.
pub fn merge(bracket: &Bracket, curve: &ResponseCurve, opts: &MergeOptions) -> Result<RadianceMap, HdrError> {
    let mut out = RadianceMap {
        width: 0,
        height: 0,
        rgb: Vec::new(),
        variance: Vec::new(),
        mask: Vec::new(),
    };
    merge_into(bracket, curve, opts, &mut out)?;
    Ok(out)
}

/// [`merge`] into an existing map, reusing its buffers (for streams of brackets).
pub fn merge_into(
    bracket: &Bracket,
    curve: &ResponseCurve,
    opts: &MergeOptions,
    out: &mut RadianceMap,
) -> Result<(), HdrError> {
    check_inputs(bracket.bits(), curve, opts)?;
    let t = build_tables(bracket.bits(), bracket.times_s(), curve, &opts.noise);
    let (w, h) = (bracket.width(), bracket.height());
    let zmax = (t.codes - 1) as u16;
    let (gain, var_gain) = gains(&t, opts);
    out.width = w;
    out.height = h;
    out.rgb.resize(w * h * 3, 0.0);
    out.variance.resize(w * h * 3, 0.0);
    out.mask.resize(w * h, 0);
    let ctx = PassContext {
        images: bracket.images().iter().map(|im| im.data.as_slice()).collect(),
        tables: &t,
        falloff: opts.falloff,
        gain,
        var_gain,
        zmax,
        width: w,
        height: h,
    };
    // One monomorphized pass per bit depth: the tables are fixed-size arrays
    // indexed by masked codes, so the inner loop has no bounds checks.
    match bracket.bits() {
        8 => pass::<256>(&ctx, out),
        9 => pass::<512>(&ctx, out),
        10 => pass::<1024>(&ctx, out),
        11 => pass::<2048>(&ctx, out),
        12 => pass::<4096>(&ctx, out),
        13 => pass::<8192>(&ctx, out),
        14 => pass::<16384>(&ctx, out),
        15 => pass::<32768>(&ctx, out),
        _ => pass::<65536>(&ctx, out),
    }
    Ok(())
}

/// The checks of [`merge`]: curve depth, positive calibrations, a sane noise model.
pub(super) fn check_inputs(bits: u8, curve: &ResponseCurve, opts: &MergeOptions) -> Result<(), HdrError> {
    if curve.bits != bits {
        return Err(HdrError::CurveBitsMismatch {
            curve_bits: curve.bits,
            image_bits: bits,
        });
    }
    for (name, v) in [
        ("nd_transmittance", opts.nd_transmittance),
        ("radiometric_scale", opts.radiometric_scale),
    ] {
        if let Some(bad) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
            return Err(HdrError::BadOption {
                name,
                value: bad.to_string(),
                expected: "finite values > 0",
            });
        }
    }
    let n = opts.noise;
    if !(n.full_well_electrons.is_finite()
        && n.full_well_electrons > 0.0
        && n.read_noise_electrons.is_finite()
        && n.read_noise_electrons >= 0.0)
    {
        return Err(HdrError::BadOption {
            name: "noise",
            value: format!(
                "full well {} e-, read noise {} e-",
                n.full_well_electrons, n.read_noise_electrons
            ),
            expected: "full well > 0 and read noise ≥ 0",
        });
    }
    Ok(())
}

/// Gain and variance gain per channel (radiometric scale over ND transmittance).
pub(super) fn gains(t: &Tables, opts: &MergeOptions) -> ([f32; 3], [f32; 3]) {
    let gain: [f32; 3] = std::array::from_fn(|c| (opts.radiometric_scale[c] / opts.nd_transmittance[c]) as f32);
    let var_gain: [f32; 3] = std::array::from_fn(|c| (f64::from(gain[c]).powi(2) * t.var_scale[c]) as f32);
    (gain, var_gain)
}

/// Writes one pixel from its sums `Σw`, `Σw·X` per channel; returns its mask.
/// A channel with no weight gets the bound of its clipping, decided by
/// whether the shortest exposure's code is the largest (`saturated`).
#[inline(always)]
pub(super) fn finish_pixel(
    t: &Tables,
    (sw, swx): ([f32; 3], [f32; 3]),
    saturated: [bool; 3],
    (gain, var_gain): ([f32; 3], [f32; 3]),
    falloff: f32,
    rgb: &mut [f32],
    var: &mut [f32],
) -> u8 {
    let mut m = 0u8;
    for c in 0..3 {
        if sw[c] > 0.0 {
            rgb[c] = swx[c] / sw[c] * gain[c] / falloff;
            var[c] = var_gain[c] / (sw[c] * falloff * falloff);
        } else if saturated[c] {
            m |= MASK_SATURATED << c;
            rgb[c] = t.sat_bound[c] * gain[c] / falloff;
            var[c] = f32::INFINITY;
        } else {
            m |= MASK_UNDEREXPOSED << c;
            rgb[c] = t.dark_bound[c] * gain[c] / falloff;
            var[c] = f32::INFINITY;
        }
    }
    m
}

/// What the pixel pass needs.
struct PassContext<'a> {
    images: Vec<&'a [u16]>,
    tables: &'a Tables,
    falloff: Option<RadialPolynomial>,
    gain: [f32; 3],
    var_gain: [f32; 3],
    zmax: u16,
    width: usize,
    height: usize,
}

/// Pixels merged together in the pass's inner loop.
const TILE: usize = 2;

/// The single parallel pass over the pixels, for `N = 2^bits` codes.
///
/// Row by row, in tiles of [`TILE`] pixels: each exposure's three tables
/// stay fixed while the tile's `3·TILE` codes are looked up, and the sums
/// `Σ w_j`, `Σ w_j X_j` stay in registers. Each sum adds the exposures in
/// order, as a loop per pixel would, so the numbers do not depend on the
/// tiling.
fn pass<const N: usize>(ctx: &PassContext, out: &mut RadianceMap) {
    let (w, h) = (ctx.width, ctx.height);
    let t = ctx.tables;
    debug_assert_eq!(t.codes, N);
    // Exposure j's tables: `[c · N + z]` in the j-th chunk.
    let luts = || t.lut.chunks_exact(3 * N);
    let shortest = ctx.images[0];
    let (gain, var_gain) = (ctx.gain, ctx.var_gain);
    out.rgb
        .par_chunks_mut(w * 3)
        .zip(out.variance.par_chunks_mut(w * 3))
        .zip(out.mask.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((rgb_row, var_row), mask_row))| {
            let base = y * w * 3;
            let rows: Vec<&[u16]> = ctx.images.iter().map(|im| &im[base..base + w * 3]).collect();
            let finish = |x: usize, sums: &[[f32; 2]], rgb: &mut [f32], var: &mut [f32]| {
                let falloff = ctx
                    .falloff
                    .map_or(1.0, |f| f.at_r2(normalized_r2(x, y, w, h)).max(1e-6) as f32);
                let k = x * 3;
                finish_pixel(
                    t,
                    (std::array::from_fn(|c| sums[c][0]), std::array::from_fn(|c| sums[c][1])),
                    std::array::from_fn(|c| shortest[base + k + c] >= ctx.zmax),
                    (gain, var_gain),
                    falloff,
                    rgb,
                    var,
                )
            };
            let tiled = w - w % TILE;
            for x0 in (0..tiled).step_by(TILE) {
                // (Σw, Σw·X) per sample of the tile.
                let mut acc = [[0.0f32; 2]; 3 * TILE];
                for (row, lut) in rows.iter().zip(luts()) {
                    let z: &[u16; 3 * TILE] = row[x0 * 3..(x0 + TILE) * 3].try_into().expect("a tile of codes");
                    for (s, a) in acc.iter_mut().enumerate() {
                        let [wj, wxj] = lut[(s % 3) * N + (usize::from(z[s]) & (N - 1))];
                        a[0] += wj;
                        a[1] += wxj;
                    }
                }
                if ctx.falloff.is_none() && acc.iter().all(|a| a[0] > 0.0) {
                    // Every sample has weight: the tile's radiance and
                    // variance in straight-line arithmetic (as finish_pixel
                    // computes them with falloff 1), mask clear.
                    let k = x0 * 3;
                    let rgb: &mut [f32; 3 * TILE] = (&mut rgb_row[k..k + 3 * TILE]).try_into().expect("a tile");
                    let var: &mut [f32; 3 * TILE] = (&mut var_row[k..k + 3 * TILE]).try_into().expect("a tile");
                    for (s, [sw, swx]) in acc.iter().enumerate() {
                        rgb[s] = swx / sw * gain[s % 3];
                        var[s] = var_gain[s % 3] / sw;
                    }
                    mask_row[x0..x0 + TILE].fill(0);
                } else {
                    for (i, sums) in acc.chunks_exact(3).enumerate() {
                        let (x, k) = (x0 + i, (x0 + i) * 3);
                        mask_row[x] = finish(x, sums, &mut rgb_row[k..k + 3], &mut var_row[k..k + 3]);
                    }
                }
            }
            for x in tiled..w {
                let mut acc = [[0.0f32; 2]; 3];
                for (row, lut) in rows.iter().zip(luts()) {
                    for (c, a) in acc.iter_mut().enumerate() {
                        let [wj, wxj] = lut[c * N + (usize::from(row[x * 3 + c]) & (N - 1))];
                        a[0] += wj;
                        a[1] += wxj;
                    }
                }
                let k = x * 3;
                mask_row[x] = finish(x, &acc, &mut rgb_row[k..k + 3], &mut var_row[k..k + 3]);
            }
        });
}

/// Median relative error `|L − L_true| / L_true` over valid pixels and
/// channels, after the best per-channel scale (the curve's free gauge),
/// which is the median of `L_true / L` per channel. Returns (error, scales).
pub fn median_relative_error(map: &RadianceMap, truth: &[f32]) -> (f64, [f64; 3]) {
    let mut scales = [1.0; 3];
    for (c, s) in scales.iter_mut().enumerate() {
        let mut r: Vec<f64> = (0..map.width * map.height)
            .filter(|&p| map.is_valid(p) && map.rgb[p * 3 + c] > 0.0 && truth[p * 3 + c] > 0.0)
            .map(|p| f64::from(truth[p * 3 + c]) / f64::from(map.rgb[p * 3 + c]))
            .collect();
        if !r.is_empty() {
            *s = median(&mut r);
        }
    }
    let mut e: Vec<f64> = (0..map.width * map.height)
        .filter(|&p| map.is_valid(p))
        .flat_map(|p| (0..3).map(move |c| (p, c)))
        .filter(|&(p, c)| truth[p * 3 + c] > 0.0)
        .map(|(p, c)| {
            let t = f64::from(truth[p * 3 + c]);
            (f64::from(map.rgb[p * 3 + c]) * scales[c] - t).abs() / t
        })
        .collect();
    (if e.is_empty() { f64::NAN } else { median(&mut e) }, scales)
}

fn median(v: &mut [f64]) -> f64 {
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::camera::image::CodeImage;
    use crate::camera::sensor::CameraModel;
    use crate::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
    use crate::hdr::curve::{ChannelCurve, node_code, node_count};
    use crate::hdr::debevec::{DebevecOptions, calibrate_debevec};

    /// The camera model's own curve, sampled at the curve nodes.
    pub(crate) fn true_curve(cam: &CameraModel) -> ResponseCurve {
        let bits = cam.sensor.bits;
        let n = node_count(bits);
        let ch = |c: usize| ChannelCurve {
            ln_exposure: (0..n)
                .map(|k| cam.true_ln_exposure(node_code(bits, k).max(0.5), c))
                .collect(),
            ln_exposure_std: vec![0.0; n],
            support: vec![0; n],
        };
        ResponseCurve {
            bits,
            channels: [ch(0), ch(1), ch(2)],
        }
    }

    fn bracket(cam: &CameraModel, w: usize, h: usize) -> (Bracket, Vec<f32>) {
        let scene = hdr_chart(w, h);
        let imgs = SEVEN_STOP_TIMES_S
            .iter()
            .enumerate()
            .map(|(j, &t)| cam.photograph(&scene, t, 40 + j as u64))
            .collect();
        (Bracket::new(imgs, SEVEN_STOP_TIMES_S.to_vec()).unwrap(), scene.data)
    }

    /// The tiled pass is the definition, pixel by pixel: on an odd width
    /// (a pixel left over after the tiles), with clipped and dark samples,
    /// with and without falloff, every radiance, variance and mask equals
    /// the per-pixel sum over exposures through the same tables and
    /// [`finish_pixel`], bit for bit.
    #[test]
    fn the_tiled_pass_is_the_per_pixel_definition() {
        let cam = CameraModel::typical(8);
        let (w, h) = (2 * TILE * 12 + 1, 9);
        let scene = hdr_chart(w, h);
        let images: Vec<CodeImage> = SEVEN_STOP_TIMES_S
            .iter()
            .enumerate()
            .map(|(j, &t)| {
                let mut im = cam.photograph(&scene, t, 40 + j as u64);
                // Two tiles and the last pixel clipped in every exposure,
                // one tile black in every exposure, one channel of a pixel each.
                for p in [0, 1, 2, 3, w - 1, 2 * w + 5] {
                    im.data[p * 3..p * 3 + 3].fill(255);
                }
                im.data[(3 * w + 7) * 3 + 1] = 255;
                for p in [4 * w, 4 * w + 1, w + 2] {
                    im.data[p * 3..p * 3 + 3].fill(0);
                }
                im.data[(5 * w + 3) * 3 + 2] = 0;
                im
            })
            .collect();
        let b = Bracket::new(images, SEVEN_STOP_TIMES_S.to_vec()).unwrap();
        let curve = true_curve(&cam);
        for falloff in [None, Some(RadialPolynomial { a: -0.3, b: 0.05 })] {
            let opts = MergeOptions {
                falloff,
                nd_transmittance: [0.5, 0.25, 0.125],
                ..Default::default()
            };
            let map = merge(&b, &curve, &opts).unwrap();
            let t = build_tables(8, b.times_s(), &curve, &opts.noise);
            let g = gains(&t, &opts);
            let (mut clipped, mut dark) = (0, 0);
            for p in 0..w * h {
                let (mut sw, mut swx) = ([0.0f32; 3], [0.0f32; 3]);
                for (j, im) in b.images().iter().enumerate() {
                    for c in 0..3 {
                        let [a, x] = t.lut[(j * 3 + c) * t.codes + usize::from(im.data[p * 3 + c])];
                        sw[c] += a;
                        swx[c] += x;
                    }
                }
                let f = falloff.map_or(1.0, |f| f.at_r2(normalized_r2(p % w, p / w, w, h)).max(1e-6) as f32);
                let (mut rgb, mut var) = ([0.0f32; 3], [0.0f32; 3]);
                let saturated = std::array::from_fn(|c| b.images()[0].data[p * 3 + c] >= 255);
                let m = finish_pixel(&t, (sw, swx), saturated, g, f, &mut rgb, &mut var);
                assert_eq!(map.mask[p], m, "pixel {p}");
                assert_eq!(&map.rgb[p * 3..p * 3 + 3], &rgb, "pixel {p}");
                assert_eq!(&map.variance[p * 3..p * 3 + 3], &var, "pixel {p}");
                clipped += usize::from(m & 0b111 != 0);
                dark += usize::from(m & 0b111_000 != 0);
            }
            assert_eq!((clipped, dark), (7, 4), "pixels clipped and dark in some channel");
        }
    }

    #[test]
    fn merged_radiance_median_error_below_1_percent_with_recovered_curve() {
        let cam = CameraModel::typical(8);
        let (b, truth) = bracket(&cam, 128, 96);
        let cal = calibrate_debevec(&b, &DebevecOptions::default()).unwrap();
        let map = merge(&b, &cal.curve, &MergeOptions::default()).unwrap();
        let (err, _) = median_relative_error(&map, &truth);
        eprintln!("median relative error {err:.5}");
        assert!(err < 0.01, "median relative error {err}");
        assert!(map.rgb.iter().all(|v| v.is_finite()));
        assert!(map.mask.iter().all(|&m| m == 0), "the chart is covered by the bracket");
    }

    #[test]
    fn variance_predicts_the_actual_error_within_a_factor_2() {
        let cam = CameraModel::typical(8);
        let (b, truth) = bracket(&cam, 96, 64);
        let map = merge(&b, &true_curve(&cam), &MergeOptions::default()).unwrap();
        // With the true curve, exposure/radiance = gain = 1 after scaling by e(z_max)… use the fitted scale.
        let (_, s) = median_relative_error(&map, &truth);
        let mut z2 = Vec::new();
        for p in 0..96 * 64 {
            for c in 0..3 {
                let d = f64::from(map.rgb[p * 3 + c]) * s[c] - f64::from(truth[p * 3 + c]);
                z2.push(d * d / (f64::from(map.variance[p * 3 + c]) * s[c] * s[c]));
            }
        }
        let mean_z2 = z2.iter().sum::<f64>() / z2.len() as f64;
        assert!(mean_z2 > 0.5 && mean_z2 < 2.0, "mean squared z-score {mean_z2}");
    }

    #[test]
    fn clipped_everywhere_is_masked_with_bounds_never_nan() {
        let cam = CameraModel::typical(8);
        let mk = |v: u16, t: f64| CodeImage {
            width: 8,
            height: 8,
            bits: 8,
            data: vec![v; 8 * 8 * 3],
            label: format!("t{t}"),
        };
        let mut short = mk(255, 0.01);
        let mut long = mk(255, 0.1);
        // Pixel 1: black in both exposures.
        for c in 0..3 {
            short.data[3 + c] = 0;
            long.data[3 + c] = 0;
        }
        // Pixel 2: only red saturated; green and blue fine.
        for (img, g) in [(&mut short, 40u16), (&mut long, 160)] {
            img.data[6] = 255;
            img.data[7] = g;
            img.data[8] = g;
        }
        let b = Bracket::new(vec![short, long], vec![0.01, 0.1]).unwrap();
        let curve = true_curve(&cam);
        let map = merge(&b, &curve, &MergeOptions::default()).unwrap();
        assert!(map.rgb.iter().all(|v| v.is_finite()) && map.variance.iter().all(|v| !v.is_nan()));
        assert_eq!(map.mask[0], 0b111, "saturated everywhere");
        let lower = curve.exposure_lut(0)[255] / 0.01;
        assert!(
            (f64::from(map.rgb[0]) / lower - 1.0).abs() < 1e-5,
            "darkest exposure's bound"
        );
        assert_eq!(map.mask[1], 0b111_000, "black everywhere");
        assert_eq!(map.mask[2], MASK_SATURATED, "red only");
        assert!(map.variance[7].is_finite() && map.variance[7] > 0.0);
    }

    #[test]
    fn single_exposure_merges_and_nd_and_falloff_scale_as_stated() {
        let cam = CameraModel::typical(8);
        let (b, _) = bracket(&cam, 32, 32);
        let one = Bracket::new(vec![b.images()[3].clone()], vec![b.times_s()[3]]).unwrap();
        let curve = true_curve(&cam);
        let plain = merge(&one, &curve, &MergeOptions::default()).unwrap();
        let nd = merge(
            &one,
            &curve,
            &MergeOptions {
                nd_transmittance: [0.5, 0.25, 0.125],
                ..Default::default()
            },
        )
        .unwrap();
        let fall = RadialPolynomial { a: -0.4, b: 0.0 };
        let lens = merge(
            &one,
            &curve,
            &MergeOptions {
                falloff: Some(fall),
                ..Default::default()
            },
        )
        .unwrap();
        for p in 0..32 * 32 {
            if !plain.is_valid(p) {
                continue;
            }
            for (c, f) in [2.0f32, 4.0, 8.0].iter().enumerate() {
                let i = p * 3 + c;
                assert!((nd.rgb[i] / plain.rgb[i] / f - 1.0).abs() < 1e-5);
                let v = fall.at_r2(normalized_r2(p % 32, p / 32, 32, 32)) as f32;
                assert!((lens.rgb[i] * v / plain.rgb[i] - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn sixteen_bit_merge_is_accurate() {
        let cam = CameraModel::typical(16);
        let (b, truth) = bracket(&cam, 64, 48);
        let map = merge(&b, &true_curve(&cam), &MergeOptions::default()).unwrap();
        let (err, _) = median_relative_error(&map, &truth);
        assert!(err < 0.01, "median relative error {err}");
    }

    #[test]
    fn curve_of_wrong_depth_is_refused() {
        let cam = CameraModel::typical(8);
        let (b, _) = bracket(&cam, 16, 16);
        let e = merge(&b, &true_curve(&CameraModel::typical(16)), &MergeOptions::default()).unwrap_err();
        assert!(e.to_string().contains("16-bit codes but the images have 8 bits"), "{e}");
    }
}
