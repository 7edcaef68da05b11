//! Solar radiance from a filtered photograph of the sun (thesis §5.3.1):
//! find the disc, integrate it, undo the ND filter.
//!
//! The frame is one channel of an HDR radiance map (W·m⁻²·sr⁻¹, after the
//! response curve), taken through a filter of known transmittance. Each
//! pixel of a pinhole camera with focal length f (pixels) sees the solid
//! angle `cos³θ / f²`, θ its angle off the optical axis. The solar
//! irradiance on a plane facing the sun is the disc's radiance integrated
//! over its solid angle, above the sky background, divided by the filter's
//! transmittance.

/// A pinhole frame of one channel.
#[derive(Debug, Clone, Copy)]
pub struct SunFrame<'a> {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major radiance, `width × height`.
    pub radiance: &'a [f32],
    /// Pixels clipped in every exposure (from the HDR merge), if known.
    pub clipped: Option<&'a [bool]>,
    /// Focal length in pixels.
    pub focal_px: f64,
    /// Principal point in pixels.
    pub principal_px: (f64, f64),
    /// Transmittance of the ND filter in this channel, in (0, 1].
    pub transmittance: f64,
}

/// What was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunDisc {
    /// Radiance-weighted centroid of the disc, pixels.
    pub centroid_px: (f64, f64),
    /// Irradiance on a plane normal to the sun, W·m⁻², filter undone.
    pub irradiance: f64,
    /// Solid angle the disc pixels cover, sr.
    pub solid_angle_sr: f64,
    /// Mean disc radiance, filter undone.
    pub mean_radiance: f64,
    /// Sky background level subtracted (filtered frame units).
    pub background: f64,
    /// Pixels in the disc.
    pub pixels: usize,
}

/// Why the sun could not be measured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SunDiscError {
    /// Sizes disagree or parameters are out of range.
    #[error("invalid sun frame: {0}")]
    Invalid(String),
    /// Nothing stands out of the background.
    #[error("no sun disc: the brightest pixel ({peak}) is not above the background ({background})")]
    NoDisc {
        /// Brightest value.
        peak: f64,
        /// Background.
        background: f64,
    },
    /// The disc has clipped pixels: use a denser filter.
    #[error("{count} disc pixels are clipped in every exposure: retake with a denser ND filter")]
    Clipped {
        /// How many.
        count: usize,
    },
    /// The disc touches the frame edge: part of it is missing.
    #[error("the sun disc touches the frame edge at ({x}, {y}): aim closer to the sun")]
    AtEdge {
        /// Column.
        x: usize,
        /// Row.
        y: usize,
    },
    /// The bright region is much larger than the sun (clouds, haze, flare).
    #[error(
        "the bright region covers {found_sr:.3e} sr, {ratio:.1}× the sun's {expected_sr:.3e} sr: clouds or flare near the sun"
    )]
    TooLarge {
        /// Solid angle found.
        found_sr: f64,
        /// Expected.
        expected_sr: f64,
        /// Ratio.
        ratio: f64,
    },
}

/// Finds and integrates the sun disc. `expected_sr` is the disc's solid
/// angle for the date ([`super::sun_solid_angle_sr`]). A bright core (the
/// pixels above half the peak's excess) larger than three times the disc,
/// or than 2 × 2 pixels when that is more, is refused as clouds or flare.
///
/// The irradiance is the excess over the background integrated over the
/// core and one ring of pixels around it (§5.3.1), so it does not need the
/// disc resolved: a sun smaller than a pixel (a wide, small all-sky or
/// station camera) is integrated the same way, its flux spread over the
/// 1–4 pixels it falls on.
pub fn measure_sun(frame: &SunFrame<'_>, expected_sr: f64) -> Result<SunDisc, SunDiscError> {
    let (w, h) = (frame.width, frame.height);
    if w < 3 || h < 3 || frame.radiance.len() != w * h || frame.clipped.is_some_and(|c| c.len() != w * h) {
        return Err(SunDiscError::Invalid(format!(
            "{w}×{h} frame with {} radiance values{}",
            frame.radiance.len(),
            frame
                .clipped
                .map_or(String::new(), |c| format!(" and {} mask values", c.len()))
        )));
    }
    let transmittance_ok = frame.transmittance > 0.0 && frame.transmittance <= 1.0;
    let focal_ok = frame.focal_px.is_finite() && frame.focal_px > 0.0;
    if !(transmittance_ok && focal_ok) {
        return Err(SunDiscError::Invalid(format!(
            "transmittance {} and focal length {} px",
            frame.transmittance, frame.focal_px
        )));
    }
    let value = |i: usize| {
        let v = f64::from(frame.radiance[i]);
        if v.is_finite() { v } else { 0.0 }
    };
    // Background: the median of the frame (the disc covers a tiny part).
    let mut sorted: Vec<f64> = (0..w * h).map(value).collect();
    sorted.sort_by(f64::total_cmp);
    let background = sorted[sorted.len() / 2];
    let (peak_i, peak) = (0..w * h)
        .map(|i| (i, value(i)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0));
    if peak <= background * 1.5 || peak <= 0.0 {
        return Err(SunDiscError::NoDisc { peak, background });
    }
    // The disc: pixels connected to the peak above the half-way level.
    let level = background + 0.5 * (peak - background);
    let mut seen = vec![false; w * h];
    let mut stack = vec![peak_i];
    seen[peak_i] = true;
    let mut members = Vec::new();
    while let Some(i) = stack.pop() {
        members.push(i);
        let (x, y) = (i % w, i / w);
        if x == 0 || y == 0 || x == w - 1 || y == h - 1 {
            return Err(SunDiscError::AtEdge { x, y });
        }
        for j in [i - 1, i + 1, i - w, i + w] {
            if !seen[j] && value(j) > level {
                seen[j] = true;
                stack.push(j);
            }
        }
    }
    // Grow by one ring so that the limb's partial pixels are integrated too.
    let core = members.clone();
    for &i in &core {
        for j in [i - 1, i + 1, i - w, i + w, i - w - 1, i - w + 1, i + w - 1, i + w + 1] {
            if !seen[j] {
                seen[j] = true;
                members.push(j);
            }
        }
    }
    if let Some(mask) = frame.clipped {
        let count = members.iter().filter(|&&i| mask[i]).count();
        if count > 0 {
            return Err(SunDiscError::Clipped { count });
        }
    }
    let (cx, cy) = frame.principal_px;
    let f2 = frame.focal_px * frame.focal_px;
    let (mut flux, mut omega, mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for &i in &members {
        let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        let (dx, dy) = (x - cx, y - cy);
        let cos = frame.focal_px / (dx * dx + dy * dy + f2).sqrt();
        let pixel_sr = cos * cos * cos / f2;
        let excess = (value(i) - background).max(0.0);
        flux += excess * pixel_sr;
        omega += pixel_sr;
        sx += excess * x;
        sy += excess * y;
        sw += excess;
    }
    let core_sr: f64 = core
        .iter()
        .map(|&i| {
            let (dx, dy) = ((i % w) as f64 + 0.5 - cx, (i / w) as f64 + 0.5 - cy);
            let cos = frame.focal_px / (dx * dx + dy * dy + f2).sqrt();
            cos * cos * cos / f2
        })
        .sum();
    let peak_pixel_sr = {
        let (dx, dy) = ((peak_i % w) as f64 + 0.5 - cx, (peak_i / w) as f64 + 0.5 - cy);
        let cos = frame.focal_px / (dx * dx + dy * dy + f2).sqrt();
        cos * cos * cos / f2
    };
    if core_sr > core_limit_sr(expected_sr, peak_pixel_sr) {
        return Err(SunDiscError::TooLarge {
            found_sr: core_sr,
            expected_sr,
            ratio: core_sr / expected_sr,
        });
    }
    let irradiance = flux / frame.transmittance;
    Ok(SunDisc {
        centroid_px: (sx / sw, sy / sw),
        irradiance,
        solid_angle_sr: omega,
        mean_radiance: irradiance / expected_sr,
        background,
        pixels: members.len(),
    })
}

/// The largest bright core a clear sun may have, sr: three times the
/// disc's solid angle, or four pixels when that is more (pixels of at
/// least 3/4 of the disc's solid angle): a disc about a pixel wide or
/// smaller can straddle 2 × 2 pixels. At such pixel sizes clouds near the
/// sun are seen by the triplet's spread (a hazy aureole adds to the pixels
/// the sun is in), not by the core's size.
fn core_limit_sr(expected_sr: f64, pixel_sr: f64) -> f64 {
    (3.0 * expected_sr).max(4.0 * pixel_sr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sun::sun_solid_angle_sr;

    /// A disc of uniform radiance `l` at sub-pixel centre (x0, y0), radius
    /// `r_px`, over a background, 16×16 supersampled.
    fn render(w: usize, h: usize, x0: f64, y0: f64, r_px: f64, l: f64, bg: f64) -> Vec<f32> {
        let mut img = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut inside = 0;
                for sy in 0..16 {
                    for sx in 0..16 {
                        let px = x as f64 + (sx as f64 + 0.5) / 16.0;
                        let py = y as f64 + (sy as f64 + 0.5) / 16.0;
                        if (px - x0).powi(2) + (py - y0).powi(2) <= r_px * r_px {
                            inside += 1;
                        }
                    }
                }
                img[y * w + x] = (bg + l * inside as f64 / 256.0) as f32;
            }
        }
        img
    }

    #[test]
    fn a_filtered_sun_integrates_to_its_irradiance_and_centre() {
        // Narrow lens: f = 2000 px makes the 0.267° disc 9.3 px in radius.
        let f = 2000.0;
        let omega = sun_solid_angle_sr(1.0);
        let r_px = f * (omega / std::f64::consts::PI).sqrt();
        // Solar irradiance 1000 W/m² → radiance 1000/Ω; through ND 4 (T = 1e-4).
        let t = 1e-4;
        let l = 1000.0 / omega * t;
        let img = render(64, 64, 31.3, 30.7, r_px, l, 0.02 * l);
        let frame = SunFrame {
            width: 64,
            height: 64,
            radiance: &img,
            clipped: None,
            focal_px: f,
            principal_px: (32.0, 32.0),
            transmittance: t,
        };
        let d = measure_sun(&frame, omega).expect("measured");
        assert!((d.irradiance / 1000.0 - 1.0).abs() < 0.01, "{d:?}");
        assert!(
            (d.centroid_px.0 - 31.3).abs() < 0.02 && (d.centroid_px.1 - 30.7).abs() < 0.02,
            "{d:?}"
        );
    }

    /// A wide, small camera (80° over 64 px: a pixel is 10× the disc's
    /// solid angle): the disc, centred on a pixel corner so that it lights
    /// 2 × 2 pixels, still integrates to its irradiance within 1%; a
    /// bright region of 3 × 3 pixels is refused.
    #[test]
    fn a_sun_smaller_than_a_pixel_is_integrated_and_haze_refused() {
        let f = 32.0 / 40f64.to_radians().tan();
        let omega = sun_solid_angle_sr(1.0);
        let r_px = f * (omega / std::f64::consts::PI).sqrt();
        assert!(r_px < 0.2, "{r_px}");
        let t = 1e-3;
        let l = 900.0 / omega * t;
        // Centred on the corner of four pixels: a quarter of the disc in each.
        let mut img = vec![(0.01 * l) as f32; 64 * 48];
        let quarter = std::f64::consts::PI * r_px * r_px / 4.0;
        for i in [23 * 64 + 31, 23 * 64 + 32, 24 * 64 + 31, 24 * 64 + 32] {
            img[i] += (l * quarter) as f32;
        }
        let frame = SunFrame {
            width: 64,
            height: 48,
            radiance: &img,
            clipped: None,
            focal_px: f,
            principal_px: (32.0, 24.0),
            transmittance: t,
        };
        let d = measure_sun(&frame, omega).expect("measured");
        assert!((d.irradiance / 900.0 - 1.0).abs() < 0.01, "{d:?}");
        assert!((d.centroid_px.0 - 32.0).abs() < 0.05 && (d.centroid_px.1 - 24.0).abs() < 0.05);
        let haze = render(64, 48, 32.5, 24.5, 1.6, l, 0.01 * l);
        let hazy = SunFrame {
            radiance: &haze,
            ..frame
        };
        assert!(
            matches!(measure_sun(&hazy, omega), Err(SunDiscError::TooLarge { .. })),
            "{:?}",
            measure_sun(&hazy, omega)
        );
    }

    #[test]
    fn clipped_edge_cloudy_and_empty_frames_are_refused() {
        let f = 2000.0;
        let omega = sun_solid_angle_sr(1.0);
        let r_px = f * (omega / std::f64::consts::PI).sqrt();
        let img = render(64, 64, 32.0, 32.0, r_px, 100.0, 1.0);
        let mut clipped = vec![false; 64 * 64];
        clipped[32 * 64 + 32] = true;
        let mut frame = SunFrame {
            width: 64,
            height: 64,
            radiance: &img,
            clipped: Some(&clipped),
            focal_px: f,
            principal_px: (32.0, 32.0),
            transmittance: 1e-3,
        };
        assert_eq!(measure_sun(&frame, omega), Err(SunDiscError::Clipped { count: 1 }));
        frame.clipped = None;
        let edge = render(64, 64, 3.0, 32.0, r_px, 100.0, 1.0);
        frame.radiance = &edge;
        assert!(matches!(measure_sun(&frame, omega), Err(SunDiscError::AtEdge { .. })));
        // A bright region twice the sun's radius (four times its solid angle).
        let haze = render(96, 96, 48.0, 48.0, 2.0 * r_px, 100.0, 1.0);
        let hazy = SunFrame {
            width: 96,
            height: 96,
            radiance: &haze,
            principal_px: (48.0, 48.0),
            ..frame
        };
        assert!(
            matches!(measure_sun(&hazy, omega), Err(SunDiscError::TooLarge { .. })),
            "{:?}",
            measure_sun(&hazy, omega)
        );
        let flat = vec![1.0f32; 64 * 64];
        frame.radiance = &flat;
        assert!(matches!(measure_sun(&frame, omega), Err(SunDiscError::NoDisc { .. })));
        frame.transmittance = 0.0;
        assert!(matches!(measure_sun(&frame, omega), Err(SunDiscError::Invalid(_))));
    }
}
