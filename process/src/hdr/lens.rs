//! The radial lens model of the thesis (§4.7.2): light falloff and radial
//! distortion, each a polynomial `1 + a r² + b r⁴` in the distance `r` from
//! the image centre, normalized so that `r = 1` at the corners.
//!
//! - **Falloff** (vignetting): the image of a uniform radiance field is
//!   `I(r) = I₀ (1 + a r² + b r⁴)`; the merge divides by it.
//! - **Distortion**: a point imaged at radius `r_d` belongs at the ideal radius
//!   `r_u = r_d (1 + a r_d² + b r_d⁴)`; [`undistort`] resamples to ideal radii.
//!
//! Both are fitted by linear least squares in f64 ([`fit_falloff`],
//! [`fit_distortion`]) from calibration data taken with the same lens settings.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::HdrError;
use super::merge::{MASK_UNDEREXPOSED, RadianceMap};
use crate::camera::image::RadianceImage;

/// `1 + a r² + b r⁴`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RadialPolynomial {
    /// Coefficient of `r²`.
    pub a: f64,
    /// Coefficient of `r⁴`.
    pub b: f64,
}

impl RadialPolynomial {
    /// The polynomial's value at squared normalized radius `r2`.
    pub fn at_r2(&self, r2: f64) -> f64 {
        1.0 + self.a * r2 + self.b * r2 * r2
    }
}

/// The lens model: falloff and distortion.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LensModel {
    /// Relative illumination `I(r)/I(0)`.
    pub falloff: RadialPolynomial,
    /// Radial distortion `r_u / r_d`.
    pub distortion: RadialPolynomial,
}

/// Squared normalized radius of pixel centre (`x`, `y`) in a `w × h` image.
pub fn normalized_r2(x: usize, y: usize, w: usize, h: usize) -> f64 {
    let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
    let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
    (dx * dx + dy * dy) / (cx * cx + cy * cy)
}

/// Fits the falloff to a flat-field frame (a uniformly lit, uniform target
/// filling the view), per channel averaged: least squares of
/// `I = c₀ + c₁ r² + c₂ r⁴` over all pixels with finite positive values,
/// then `a = c₁/c₀`, `b = c₂/c₀`. Returns the model and the RMS relative residual.
pub fn fit_falloff(flat: &RadianceImage) -> Result<(RadialPolynomial, f64), HdrError> {
    let (w, h) = (flat.width, flat.height);
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    let mut n = 0usize;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) * 3;
            let v = flat.data[i..i + 3].iter().map(|&s| f64::from(s)).sum::<f64>() / 3.0;
            if !(v.is_finite() && v > 0.0) {
                continue;
            }
            let r2 = normalized_r2(x, y, w, h);
            let row = Vector3::new(1.0, r2, r2 * r2);
            ata += row * row.transpose();
            atb += row * v;
            n += 1;
        }
    }
    if n < 3 {
        return Err(HdrError::BadImage {
            image: "flat field".into(),
            what: format!("{n} pixels with finite positive radiance: expected at least 3"),
        });
    }
    let c = ata.cholesky().ok_or_else(|| HdrError::Singular {
        channel: 0,
        what: "flat field covers too few distinct radii".into(),
    })?;
    let coef = c.solve(&atb);
    if coef[0] <= 0.0 {
        return Err(HdrError::BadImage {
            image: "flat field".into(),
            what: format!("fitted centre value {}: expected > 0", coef[0]),
        });
    }
    let model = RadialPolynomial {
        a: coef[1] / coef[0],
        b: coef[2] / coef[0],
    };
    let mut ss = 0.0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) * 3;
            let v = flat.data[i..i + 3].iter().map(|&s| f64::from(s)).sum::<f64>() / 3.0;
            if v.is_finite() && v > 0.0 {
                let pred = coef[0] * model.at_r2(normalized_r2(x, y, w, h));
                ss += ((v - pred) / pred).powi(2);
            }
        }
    }
    Ok((model, (ss / n as f64).sqrt()))
}

/// Fits the distortion from pairs (`r_distorted`, `r_ideal`) of normalized
/// radii (e.g. target corners found in the image and where the target's
/// geometry puts them): least squares of `r_u / r_d − 1 = a r_d² + b r_d⁴`.
pub fn fit_distortion(pairs: &[(f64, f64)]) -> Result<RadialPolynomial, HdrError> {
    let (mut s22, mut s24, mut s44, mut b2, mut b4) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut n = 0;
    for &(rd, ru) in pairs {
        if !(rd.is_finite() && ru.is_finite() && rd > 1e-6) {
            continue;
        }
        let (u2, u4) = (rd * rd, rd.powi(4));
        let y = ru / rd - 1.0;
        s22 += u2 * u2;
        s24 += u2 * u4;
        s44 += u4 * u4;
        b2 += u2 * y;
        b4 += u4 * y;
        n += 1;
    }
    let det = s22 * s44 - s24 * s24;
    if n < 2 || det.abs() < 1e-18 {
        return Err(HdrError::BadOption {
            name: "distortion pairs",
            value: format!("{n} usable pairs"),
            expected: "at least 2 pairs at distinct radii > 0",
        });
    }
    Ok(RadialPolynomial {
        a: (b2 * s44 - b4 * s24) / det,
        b: (s22 * b4 - s24 * b2) / det,
    })
}

/// Resamples `img` (distorted) to ideal radii by bilinear interpolation:
/// output pixel at `r_u` reads the input at `r_d` with `r_u = r_d · D(r_d²)`
/// (Newton's method). Pixels that map outside the input get 0.
pub fn undistort(img: &RadianceImage, d: &RadialPolynomial) -> RadianceImage {
    let (w, h) = (img.width, img.height);
    let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
    let norm = (cx * cx + cy * cy).sqrt();
    let mut out = vec![0.0f32; img.data.len()];
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = ((x as f64 + 0.5 - cx) / norm, (y as f64 + 0.5 - cy) / norm);
            let ru = (dx * dx + dy * dy).sqrt();
            let rd = distorted_radius(ru, d);
            let s = if ru > 1e-12 { rd / ru } else { 1.0 };
            let (sx, sy) = (cx + dx * s * norm - 0.5, cy + dy * s * norm - 0.5);
            if sx < 0.0 || sy < 0.0 || sx > (w - 1) as f64 || sy > (h - 1) as f64 {
                continue;
            }
            let (x0, y0) = (sx.floor() as usize, sy.floor() as usize);
            let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
            let (fx, fy) = ((sx - x0 as f64) as f32, (sy - y0 as f64) as f32);
            for c in 0..3 {
                let p = |xx: usize, yy: usize| img.data[(yy * w + xx) * 3 + c];
                let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
                let bot = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
                out[(y * w + x) * 3 + c] = top * (1.0 - fy) + bot * fy;
            }
        }
    }
    RadianceImage {
        width: w,
        height: h,
        data: out,
    }
}

/// [`undistort`] applied to a merged map: radiance and variance resampled
/// bilinearly, the mask by nearest neighbour (pixels from outside the input
/// get radiance 0, infinite variance and all underexposed bits).
pub fn undistort_map(map: &RadianceMap, d: &RadialPolynomial) -> RadianceMap {
    let (w, h) = (map.width, map.height);
    let as_image = |data: &[f32]| RadianceImage {
        width: w,
        height: h,
        data: data.to_vec(),
    };
    let rgb = undistort(&as_image(&map.rgb), d).data;
    let mut variance = undistort(&as_image(&map.variance), d).data;
    let mask_img: Vec<f32> = map.mask.iter().flat_map(|&m| [f32::from(m), 0.0, 0.0]).collect();
    // Nearest neighbour for the mask: resample an index image with a zero-size kernel.
    let (cx, cy) = (0.5 * w as f64, 0.5 * h as f64);
    let norm = (cx * cx + cy * cy).sqrt();
    let mut mask = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = ((x as f64 + 0.5 - cx) / norm, (y as f64 + 0.5 - cy) / norm);
            let ru = (dx * dx + dy * dy).sqrt();
            let rd = distorted_radius(ru, d);
            let s = if ru > 1e-12 { rd / ru } else { 1.0 };
            let (sx, sy) = ((cx + dx * s * norm).floor(), (cy + dy * s * norm).floor());
            let p = y * w + x;
            if sx < 0.0 || sy < 0.0 || sx >= w as f64 || sy >= h as f64 {
                mask[p] = MASK_UNDEREXPOSED * 0b111;
                for c in 0..3 {
                    variance[p * 3 + c] = f32::INFINITY;
                }
            } else {
                mask[p] = mask_img[(sy as usize * w + sx as usize) * 3] as u8;
            }
        }
    }
    RadianceMap {
        width: w,
        height: h,
        rgb,
        variance,
        mask,
    }
}

/// The distorted radius `r_d` imaged at ideal radius `r_u`: solves
/// `r_u = r_d (1 + a r_d² + b r_d⁴)` by Newton's method.
pub fn distorted_radius(ru: f64, d: &RadialPolynomial) -> f64 {
    let mut rd = ru;
    for _ in 0..20 {
        let f = rd * d.at_r2(rd * rd) - ru;
        let df = 1.0 + 3.0 * d.a * rd * rd + 5.0 * d.b * rd.powi(4);
        if df.abs() < 1e-12 {
            break;
        }
        rd -= f / df;
    }
    rd
}

impl LensModel {
    /// Text form: `key = value` lines (`falloff_a`, `falloff_b`, `distortion_a`, `distortion_b`).
    pub fn to_text(&self) -> String {
        let mut s = String::from("# campanile lens model: 1 + a r^2 + b r^4, r = 1 at the image corners\n");
        let _ = writeln!(s, "falloff_a = {:.9}", self.falloff.a);
        let _ = writeln!(s, "falloff_b = {:.9}", self.falloff.b);
        let _ = writeln!(s, "distortion_a = {:.9}", self.distortion.a);
        let _ = writeln!(s, "distortion_b = {:.9}", self.distortion.b);
        s
    }

    /// Parses [`Self::to_text`]; missing keys are 0. `path` is for error messages.
    pub fn from_text(text: &str, path: &Path) -> Result<Self, HdrError> {
        let mut m = Self::default();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let perr = |what: String| HdrError::Parse {
                path: path.to_path_buf(),
                line: i + 1,
                what,
            };
            let (k, v) = line
                .split_once('=')
                .ok_or_else(|| perr(format!("'{line}': expected 'key = value'")))?;
            let v: f64 = v
                .trim()
                .parse()
                .map_err(|_| perr(format!("'{}': expected a number", v.trim())))?;
            if !v.is_finite() {
                return Err(perr(format!("{v}: expected a finite number")));
            }
            match k.trim() {
                "falloff_a" => m.falloff.a = v,
                "falloff_b" => m.falloff.b = v,
                "distortion_a" => m.distortion.a = v,
                "distortion_b" => m.distortion.b = v,
                other => {
                    return Err(perr(format!(
                        "unknown key '{other}': expected falloff_a, falloff_b, distortion_a or distortion_b"
                    )));
                }
            }
        }
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloff_fit_recovers_known_coefficients_to_1e_6() {
        let (w, h) = (96, 64);
        let truth = RadialPolynomial { a: -0.3, b: 0.05 };
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let v = 2.5 * truth.at_r2(normalized_r2(x, y, w, h));
                data.extend([v as f32; 3]);
            }
        }
        let (m, rms) = fit_falloff(&RadianceImage {
            width: w,
            height: h,
            data,
        })
        .unwrap();
        assert!((m.a - truth.a).abs() < 1e-6 && (m.b - truth.b).abs() < 1e-6, "{m:?}");
        assert!(rms < 1e-6);
    }

    #[test]
    fn distortion_fit_and_text_round_trip() {
        let truth = RadialPolynomial { a: 0.08, b: -0.02 };
        let pairs: Vec<(f64, f64)> = (1..20)
            .map(|i| i as f64 / 20.0)
            .map(|r| (r, r * truth.at_r2(r * r)))
            .collect();
        let d = fit_distortion(&pairs).unwrap();
        assert!((d.a - truth.a).abs() < 1e-9 && (d.b - truth.b).abs() < 1e-9, "{d:?}");
        let m = LensModel {
            falloff: RadialPolynomial { a: -0.2, b: 0.01 },
            distortion: d,
        };
        let back = LensModel::from_text(&m.to_text(), Path::new("l.txt")).unwrap();
        assert!((back.distortion.a - m.distortion.a).abs() < 1e-8);
        let e = LensModel::from_text("foo = 1", Path::new("l.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("l.txt:1") && e.contains("unknown key 'foo'"), "{e}");
        assert!(fit_distortion(&[(0.5, 0.5)]).is_err());
    }

    #[test]
    fn distorted_radius_inverts_the_model() {
        let d = RadialPolynomial { a: 0.1, b: -0.03 };
        for i in 1..10 {
            let rd = i as f64 / 10.0;
            assert!((distorted_radius(rd * d.at_r2(rd * rd), &d) - rd).abs() < 1e-12);
        }
    }

    #[test]
    fn undistort_map_keeps_mask_and_variance_consistent() {
        let (w, h) = (16, 12);
        let mut mask = vec![0u8; w * h];
        mask[5 * w + 8] = 0b010;
        let map = RadianceMap {
            width: w,
            height: h,
            rgb: vec![1.0; w * h * 3],
            variance: vec![0.5; w * h * 3],
            mask,
        };
        let same = undistort_map(&map, &RadialPolynomial::default());
        assert_eq!(same.mask, map.mask);
        let pinched = undistort_map(&map, &RadialPolynomial { a: -0.3, b: 0.0 });
        // Barrel correction pulls in from outside at the corners: flagged, never NaN.
        assert_eq!(pinched.mask[0], 0b111_000);
        assert!(pinched.variance[0].is_infinite() && pinched.rgb.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn undistort_with_zero_model_is_identity() {
        let data: Vec<f32> = (0..16 * 12 * 3).map(|i| i as f32).collect();
        let img = RadianceImage {
            width: 16,
            height: 12,
            data,
        };
        let out = undistort(&img, &RadialPolynomial::default());
        for (a, b) in img.data.iter().zip(&out.data) {
            assert!((a - b).abs() < 1e-3);
        }
    }
}
