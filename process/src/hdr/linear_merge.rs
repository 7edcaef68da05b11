//! Merging linear RAW frames ([`LinearFrame`]) of one scene, with no
//! response curve: the sensor is linear up to its white level.
//!
//! Frame `j` has the relative exposure `k_j = t_j · ISO_j / N_j²` divided by
//! the first frame's, and its radiance estimate per channel is
//! `X_j = v_j / k_j` (`v` normalized: black 0, white level 1). The
//! photon-transfer model gives the variance of `v_j`:
//!
//! ```text
//! var v_j = v_j / FW_j + (σ_read / FW_j)²,   FW_j = FW · ISO_base / ISO_j
//! ```
//!
//! (shot noise and read noise, in electrons, with `FW_j` the electrons that
//! reach the white level at frame `j`'s ISO), and `var X_j = var v_j / k_j²`.
//! The merge is the inverse-variance weighted mean; the weights are
//! evaluated at the value predicted by a first estimate (`v_j = k_j X̂`), so
//! a sample's own noise does not bias its weight. Clipped samples (a
//! contributing photosite at the white level) get weight 0.
//!
//! Flags, in the mask bits of [`super::merge`]: a channel clipped in every
//! frame is [`MASK_SATURATED`] (value: the lower bound `1 / k_min`); a
//! channel whose merged signal is not above its own noise (SNR ≤ 1) is
//! [`MASK_UNDEREXPOSED`] (value: the read-noise floor of the most exposed
//! frame, an upper bound). Flagged channels have infinite variance; no
//! value is ever NaN.
//!
//! Colour, after merging: [`OutputColor::Camera`] (the default) keeps the
//! camera's raw channels, unbalanced — the project's radiance is per camera
//! channel (DESIGN.md, Units), and the radiometric calibration that turns
//! it into W·m⁻²·sr⁻¹ is per camera channel. [`OutputColor::LinearSrgb`]
//! applies the as-shot white balance and the file's colour matrix (dcraw's
//! method: `cam_rgb = ColorMatrix · sRGB→XYZ`, rows normalized to 1,
//! inverted); [`OutputColor::Xyz`] then maps linear sRGB to CIE XYZ (D65).

use rayon::prelude::*;

use super::HdrError;
use super::linear_frame::LinearFrame;
use super::merge::{MASK_SATURATED, MASK_UNDEREXPOSED, NoiseModel, RadianceMap};
use super::raw_error::RawError;

/// The colour space of the merged map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutputColor {
    /// The camera's own channels, no white balance (the default).
    #[default]
    Camera,
    /// White-balanced, through the file's colour matrix, linear sRGB (D65).
    LinearSrgb,
    /// White-balanced, CIE XYZ (D65).
    Xyz,
}

/// Options of [`merge_linear`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinearMergeOptions {
    /// Electrons at the white level at `base_iso`, and the read noise. The
    /// default (20 000 e⁻, 4 e⁻) is [`NoiseModel::default`].
    pub noise: NoiseModel,
    /// The ISO at which the white level is the full well (default 100).
    pub base_iso: f64,
    /// Exposure times in seconds, one per frame, instead of the metadata's.
    pub times_s: Option<Vec<f64>>,
    /// Output colour space.
    pub output: OutputColor,
    /// Radiance per unit of merged value, per output channel (default 1).
    pub radiometric_scale: [f64; 3],
}

impl Default for LinearMergeOptions {
    fn default() -> Self {
        Self {
            noise: NoiseModel::default(),
            base_iso: 100.0,
            times_s: None,
            output: OutputColor::Camera,
            radiometric_scale: [1.0; 3],
        }
    }
}

/// What the merge used per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameExposure {
    /// Exposure time, s.
    pub time_s: f64,
    /// F-number (1 for every frame when no frame states one).
    pub f_number: f64,
    /// ISO (the base ISO for every frame when no frame states one).
    pub iso: f64,
    /// Relative exposure `t · ISO / N²`, normalized to the first frame.
    pub relative_exposure: f64,
}

fn metadata_err(frame: &LinearFrame, field: &'static str, found: String, expected: &'static str) -> HdrError {
    RawError::Metadata {
        path: frame.label.clone().into(),
        field,
        found,
        expected,
    }
    .into()
}

/// The exposure of each frame, from the options and the metadata.
pub fn frame_exposures(frames: &[LinearFrame], opts: &LinearMergeOptions) -> Result<Vec<FrameExposure>, HdrError> {
    if let Some(t) = &opts.times_s
        && t.len() != frames.len()
    {
        return Err(HdrError::TimeCountMismatch {
            images: frames.len(),
            times: t.len(),
        });
    }
    // F-number and ISO: all frames state them, or none does (then equal).
    let all_or_none = |field: &'static str, get: &dyn Fn(&LinearFrame) -> Option<f64>, default: f64| {
        let have: Vec<Option<f64>> = frames.iter().map(get).collect();
        if have.iter().all(Option::is_none) {
            return Ok(vec![default; frames.len()]);
        }
        frames
            .iter()
            .zip(&have)
            .map(|(f, v)| match v {
                Some(x) if x.is_finite() && *x > 0.0 => Ok(*x),
                Some(x) => Err(metadata_err(f, field, x.to_string(), "a finite value > 0")),
                None => Err(metadata_err(
                    f,
                    field,
                    "missing".into(),
                    "the same fields in every frame of a bracket (others state it)",
                )),
            })
            .collect::<Result<Vec<f64>, HdrError>>()
    };
    let n = all_or_none("FNumber", &|f| f.meta.f_number, 1.0)?;
    let iso = all_or_none("ISO", &|f| f.meta.iso, opts.base_iso)?;
    let mut out = Vec::with_capacity(frames.len());
    for (j, f) in frames.iter().enumerate() {
        let t = match &opts.times_s {
            Some(t) => t[j],
            None => f.meta.exposure_time_s.ok_or_else(|| {
                metadata_err(
                    f,
                    "ExposureTime",
                    "missing".into(),
                    "an EXIF exposure time, or give the times",
                )
            })?,
        };
        if !(t.is_finite() && t > 0.0) {
            return Err(HdrError::InvalidTime {
                image: f.label.clone(),
                time_s: t,
            });
        }
        out.push(FrameExposure {
            time_s: t,
            f_number: n[j],
            iso: iso[j],
            relative_exposure: t * iso[j] / (n[j] * n[j]),
        });
    }
    let k0 = out[0].relative_exposure;
    for e in &mut out {
        e.relative_exposure /= k0;
    }
    Ok(out)
}

fn check_frames(frames: &[LinearFrame]) -> Result<(), HdrError> {
    let first = frames.first().ok_or(HdrError::NoImages)?;
    for f in frames {
        if (f.width, f.height) != (first.width, first.height) {
            return Err(RawError::SizeMismatch {
                image: f.label.clone(),
                width: f.width,
                height: f.height,
                first: first.label.clone(),
                first_width: first.width,
                first_height: first.height,
            }
            .into());
        }
        let n = f.width * f.height;
        if n == 0 || f.rgb.len() != 3 * n || f.clipped.len() != n {
            return Err(RawError::BadFrame {
                image: f.label.clone(),
                what: format!(
                    "{}×{} with {} values and {} clipped flags: expected a non-empty image, {} and {}",
                    f.width,
                    f.height,
                    f.rgb.len(),
                    f.clipped.len(),
                    3 * n,
                    n
                ),
            }
            .into());
        }
        if let Some(i) = f.rgb.iter().position(|v| !v.is_finite()) {
            return Err(RawError::BadValue {
                image: f.label.clone(),
                x: (i / 3) % f.width,
                y: i / 3 / f.width,
                channel: i % 3,
                value: f.rgb[i],
            }
            .into());
        }
    }
    Ok(())
}

fn check_options(opts: &LinearMergeOptions) -> Result<(), HdrError> {
    let n = opts.noise;
    if !(n.full_well_electrons.is_finite()
        && n.full_well_electrons > 0.0
        && n.read_noise_electrons.is_finite()
        && n.read_noise_electrons > 0.0)
    {
        return Err(HdrError::BadOption {
            name: "noise",
            value: format!(
                "full well {} e-, read noise {} e-",
                n.full_well_electrons, n.read_noise_electrons
            ),
            expected: "full well > 0 and read noise > 0",
        });
    }
    if !(opts.base_iso.is_finite() && opts.base_iso > 0.0) {
        return Err(HdrError::BadOption {
            name: "base_iso",
            value: opts.base_iso.to_string(),
            expected: "a finite ISO > 0",
        });
    }
    if let Some(bad) = opts.radiometric_scale.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
        return Err(HdrError::BadOption {
            name: "radiometric_scale",
            value: bad.to_string(),
            expected: "finite values > 0",
        });
    }
    Ok(())
}

/// sRGB (D65) → XYZ.
pub const SRGB_TO_XYZ: [[f64; 3]; 3] = [
    [0.412_456_4, 0.357_576_1, 0.180_437_5],
    [0.212_672_9, 0.715_152_2, 0.072_175_0],
    [0.019_333_9, 0.119_192_0, 0.950_304_1],
];

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn invert(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if !det.is_finite() || det.abs() < 1e-12 {
        return None;
    }
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    Some(std::array::from_fn(|r| std::array::from_fn(|k| c(k, r) / det)))
}

/// White-balanced camera RGB → linear sRGB from a DNG ColorMatrix (XYZ →
/// camera), as dcraw and LibRaw compute it: `cam_rgb = ColorMatrix ·
/// sRGB→XYZ`, each row divided by its sum (so white stays white), inverted.
/// `None` if a row sums to 0 or the result is singular.
pub fn camera_to_srgb(xyz_to_cam: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let mut norm = mul(xyz_to_cam, &SRGB_TO_XYZ);
    for row in &mut norm {
        let s: f64 = row.iter().sum();
        if !(s.is_finite() && s.abs() > 1e-12) {
            return None;
        }
        for v in row.iter_mut() {
            *v /= s;
        }
    }
    invert(&norm)
}

/// The 3×3 matrix from merged camera RGB to the output space (white
/// balance included), for the first frame's metadata.
pub fn output_matrix(frame: &LinearFrame, output: OutputColor) -> Result<[[f64; 3]; 3], HdrError> {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if output == OutputColor::Camera {
        return Ok(identity);
    }
    let (xyz_to_cam, _) = frame.meta.xyz_to_camera.ok_or_else(|| {
        metadata_err(
            frame,
            "ColorMatrix",
            "missing".into(),
            "a colour matrix for sRGB or XYZ output (or use camera RGB)",
        )
    })?;
    let rgb_cam = camera_to_srgb(&xyz_to_cam).ok_or_else(|| {
        metadata_err(
            frame,
            "ColorMatrix",
            format!("{xyz_to_cam:?}"),
            "an invertible matrix whose rows map white to a non-zero response",
        )
    })?;
    let cam_rgb = mul(&xyz_to_cam, &SRGB_TO_XYZ);
    // White balance: the file's as-shot multipliers, else the matrix's D65 white.
    let wb = match frame.meta.wb_multipliers {
        Some(w) => w,
        None => {
            let white = cam_rgb.map(|r| r.iter().sum::<f64>());
            [white[1] / white[0], 1.0, white[1] / white[2]]
        }
    };
    let balanced: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| rgb_cam[r][c] * wb[c]));
    Ok(match output {
        OutputColor::Xyz => mul(&SRGB_TO_XYZ, &balanced),
        _ => balanced,
    })
}

/// Merges `frames` (one scene, any exposure times, ISOs and apertures) into a
/// radiance map.
pub fn merge_linear(frames: &[LinearFrame], opts: &LinearMergeOptions) -> Result<RadianceMap, HdrError> {
    check_frames(frames)?;
    check_options(opts)?;
    let exposures = frame_exposures(frames, opts)?;
    let matrix = output_matrix(&frames[0], opts.output)?;
    let (w, h) = (frames[0].width, frames[0].height);
    let k: Vec<f64> = exposures.iter().map(|e| e.relative_exposure).collect();
    let fw: Vec<f64> = exposures
        .iter()
        .map(|e| opts.noise.full_well_electrons * opts.base_iso / e.iso)
        .collect();
    let read = opts.noise.read_noise_electrons;
    let k_min = k.iter().copied().fold(f64::INFINITY, f64::min);
    let j_max = (0..k.len()).max_by(|&a, &b| k[a].total_cmp(&k[b])).unwrap_or(0);
    let floor = read / fw[j_max] / k[j_max];
    let var_x = |j: usize, v: f64| (v.max(0.0) / fw[j] + (read / fw[j]).powi(2)) / (k[j] * k[j]);
    let mut out = RadianceMap {
        width: w,
        height: h,
        rgb: vec![0.0; w * h * 3],
        variance: vec![0.0; w * h * 3],
        mask: vec![0; w * h],
    };
    let scale = opts.radiometric_scale;
    out.rgb
        .par_chunks_mut(w * 3)
        .zip(out.variance.par_chunks_mut(w * 3))
        .zip(out.mask.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((rgb_row, var_row), mask_row))| {
            for x in 0..w {
                let p = y * w + x;
                let mut cam = [0.0f64; 3];
                let mut var = [0.0f64; 3];
                let mut m = 0u8;
                for c in 0..3 {
                    // First estimate with weights from each sample's own value,
                    // then weights from the predicted values.
                    let mut estimate = None;
                    for _ in 0..2 {
                        let (mut sw, mut swx) = (0.0f64, 0.0f64);
                        for (j, f) in frames.iter().enumerate() {
                            if f.clipped[p] & (1 << c) != 0 {
                                continue;
                            }
                            let v = f64::from(f.rgb[p * 3 + c]);
                            let wj = 1.0 / var_x(j, estimate.map_or(v, |e: f64| e * k[j]));
                            sw += wj;
                            swx += wj * v / k[j];
                        }
                        estimate = (sw > 0.0).then(|| swx / sw);
                        var[c] = if sw > 0.0 { 1.0 / sw } else { f64::INFINITY };
                    }
                    match estimate {
                        None => {
                            m |= MASK_SATURATED << c;
                            cam[c] = 1.0 / k_min;
                            var[c] = f64::INFINITY;
                        }
                        Some(e) if e <= var[c].sqrt() => {
                            m |= MASK_UNDEREXPOSED << c;
                            cam[c] = floor;
                            var[c] = f64::INFINITY;
                        }
                        Some(e) => cam[c] = e,
                    }
                }
                let mut mo = 0u8;
                for o in 0..3 {
                    let (mut v, mut s2) = (0.0f64, 0.0f64);
                    for i in 0..3 {
                        let a = matrix[o][i];
                        if a == 0.0 {
                            continue;
                        }
                        v += a * cam[i];
                        s2 += a * a * var[i];
                        if m & (MASK_SATURATED << i) != 0 {
                            mo |= MASK_SATURATED << o;
                        }
                        if m & (MASK_UNDEREXPOSED << i) != 0 {
                            mo |= MASK_UNDEREXPOSED << o;
                        }
                    }
                    rgb_row[x * 3 + o] = (v * scale[o]) as f32;
                    var_row[x * 3 + o] = (s2 * scale[o] * scale[o]) as f32;
                }
                mask_row[x] = mo;
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::linear_frame::FrameMetadata;

    fn frame(v: [f32; 3], clipped: u8, t: f64, n: f64, iso: f64) -> LinearFrame {
        LinearFrame {
            label: format!("t{t}"),
            width: 1,
            height: 1,
            rgb: v.to_vec(),
            clipped: vec![clipped],
            meta: FrameMetadata {
                exposure_time_s: Some(t),
                f_number: Some(n),
                iso: Some(iso),
                ..Default::default()
            },
        }
    }

    #[test]
    fn relative_exposure_is_t_iso_over_n_squared() {
        let f = [
            frame([0.1; 3], 0, 0.01, 4.0, 100.0),
            frame([0.1; 3], 0, 0.02, 2.0, 400.0),
        ];
        let e = frame_exposures(&f, &LinearMergeOptions::default()).unwrap();
        // (0.02 · 400 / 4) / (0.01 · 100 / 16) = 2 / 0.0625 = 32.
        assert!(
            (e[1].relative_exposure - 32.0).abs() < 1e-12,
            "{}",
            e[1].relative_exposure
        );
    }

    #[test]
    fn clipped_channels_get_no_weight_and_all_clipped_is_flagged_saturated() {
        // Exposure 2 (k = 4) clipped in R: R comes from exposure 1 only.
        let f = [
            frame([0.3, 0.2, 1.0], 0b100, 1.0, 4.0, 100.0),
            frame([1.0, 0.8, 1.0], 0b101, 4.0, 4.0, 100.0),
        ];
        let m = merge_linear(&f, &LinearMergeOptions::default()).unwrap();
        assert!((m.rgb[0] - 0.3).abs() < 1e-6, "{}", m.rgb[0]);
        assert_eq!(m.mask[0], MASK_SATURATED << 2);
        assert_eq!(m.rgb[2], 1.0, "lower bound 1 / k_min");
        assert!(m.variance[2].is_infinite());
        // G from both: (0.2 and 0.8/4 = 0.2).
        assert!((m.rgb[1] - 0.2).abs() < 1e-6);
    }

    #[test]
    fn missing_time_names_the_frame_and_field() {
        let mut f = frame([0.1; 3], 0, 1.0, 4.0, 100.0);
        f.meta.exposure_time_s = None;
        let e = merge_linear(&[f], &LinearMergeOptions::default())
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t1: ExposureTime is missing: expected an EXIF exposure time, or give the times"
        );
    }

    #[test]
    fn identity_colour_matrix_with_unit_wb_gives_srgb_equal_to_camera() {
        let mut f = frame([0.1, 0.2, 0.3], 0, 1.0, 4.0, 100.0);
        // XYZ→camera = XYZ→sRGB: then the camera is sRGB and the matrix is the identity.
        let xyz_to_srgb = invert(&SRGB_TO_XYZ).unwrap();
        f.meta.xyz_to_camera = Some((xyz_to_srgb, 21));
        f.meta.wb_multipliers = Some([1.0, 1.0, 1.0]);
        let m = output_matrix(&f, OutputColor::LinearSrgb).unwrap();
        for (r, row) in m.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                assert!((v - if r == c { 1.0 } else { 0.0 }).abs() < 1e-6, "{m:?}");
            }
        }
    }
}
