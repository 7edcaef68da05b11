//! Sky samples from photographs (thesis §5.3.2): every pixel of an HDR
//! sky frame, through the head pose and the intrinsics, becomes a direction
//! in the world and one radiance per channel.
//!
//! Masked automatically, before any fitting:
//! - pixels below the horizon (and within half a degree of it);
//! - the sun disc and a margin around it (where frames are clipped or
//!   flared; the aureole bands are separate frames at faster shutters);
//! - pixels the HDR merge marked invalid (clipped or black in every
//!   exposure);
//! - non-finite values.
//!
//! Non-sky pixels above the horizon (buildings, trees) are left to the
//! robust fit ([`super::fit_sky_robust`]).

use super::file::SampleTable;
use super::fit::SkySample;
use super::geometry::{angle_between, direction};
use crate::pose::{HeadPose, Mount, Pinhole};

/// One HDR sky frame and where it was taken.
#[derive(Debug, Clone, Copy)]
pub struct SkyFrame<'a> {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Interleaved RGB radiance, `3 × width × height`.
    pub rgb: &'a [f32],
    /// Per pixel: valid in every channel (from the merge), if known.
    pub valid: Option<&'a [bool]>,
    /// Intrinsics.
    pub camera: Pinhole,
    /// The head's mount.
    pub mount: Mount,
    /// The head's reading for this frame.
    pub pose: HeadPose,
}

/// Why samples could not be taken.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameSampleError {
    /// A frame's buffers do not match its size.
    #[error("frame {index}: {width}×{height} needs {needed} RGB values and {pixels} mask values; got {rgb} and {mask}")]
    Size {
        /// Frame index.
        index: usize,
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// RGB values needed.
        needed: usize,
        /// Pixels.
        pixels: usize,
        /// RGB values given.
        rgb: usize,
        /// Mask values given (or the pixel count when there is no mask).
        mask: usize,
    },
    /// `stride` was zero.
    #[error("the pixel stride must be at least 1")]
    Stride,
}

/// Lowest elevation sampled (0.5°): the horizon itself is where the
/// landscape starts.
pub const MIN_ELEVATION_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// Samples every `stride`-th pixel (in both directions) of each frame,
/// masking as the module describes, with the sun toward unit vector `sun`
/// and a disc margin of `sun_margin_rad` around it.
pub fn sky_samples(
    frames: &[SkyFrame<'_>],
    sun: [f64; 3],
    stride: usize,
    sun_margin_rad: f64,
) -> Result<SampleTable, FrameSampleError> {
    if stride == 0 {
        return Err(FrameSampleError::Stride);
    }
    let mut table = SampleTable {
        channels: vec!["r".into(), "g".into(), "b".into()],
        directions: Vec::new(),
        values: vec![Vec::new(), Vec::new(), Vec::new()],
    };
    for (index, f) in frames.iter().enumerate() {
        let pixels = f.width * f.height;
        let mask_len = f.valid.map_or(pixels, <[bool]>::len);
        if f.rgb.len() != 3 * pixels || mask_len != pixels {
            return Err(FrameSampleError::Size {
                index,
                width: f.width,
                height: f.height,
                needed: 3 * pixels,
                pixels,
                rgb: f.rgb.len(),
                mask: mask_len,
            });
        }
        for y in (0..f.height).step_by(stride) {
            for x in (0..f.width).step_by(stride) {
                let p = y * f.width + x;
                if f.valid.is_some_and(|v| !v[p]) {
                    continue;
                }
                let rgb = [f.rgb[3 * p], f.rgb[3 * p + 1], f.rgb[3 * p + 2]].map(f64::from);
                if !rgb.iter().all(|v| v.is_finite()) {
                    continue;
                }
                let Some(d) = f.camera.unproject(x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                let w = f.mount.to_world(f.pose, d);
                if w[2] < MIN_ELEVATION_RAD.sin() || angle_between(w, sun) < sun_margin_rad {
                    continue;
                }
                table.directions.push((
                    w[2].clamp(-1.0, 1.0).acos(),
                    w[0].atan2(w[1]).rem_euclid(std::f64::consts::TAU),
                ));
                for (c, v) in rgb.iter().enumerate() {
                    table.values[c].push(*v);
                }
            }
        }
    }
    Ok(table)
}

impl SampleTable {
    /// One channel's samples as (ξ, γ, radiance) for a sun toward unit
    /// vector `sun`, leaving out the 0.5° around the sun (the disc).
    pub fn sky_samples(&self, channel: usize, sun: [f64; 3]) -> Vec<SkySample> {
        self.directions
            .iter()
            .zip(&self.values[channel])
            .map(|(&(z, a), &v)| SkySample {
                xi: z,
                gamma: angle_between(direction(z, a), sun),
                radiance: v,
            })
            .filter(|s| s.gamma > 0.5f64.to_radians())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::{SkyModel, fit_sky_robust};

    /// Renders what the camera sees: the sky per channel, a dark textured
    /// building over azimuths 200°–240° up to 25° elevation, the ground
    /// below the horizon, and a clipped sun.
    fn render(
        cam: Pinhole,
        mount: Mount,
        pose: HeadPose,
        (w, h): (usize, usize),
        sky: &[SkyModel; 3],
        sun: [f64; 3],
    ) -> (Vec<f32>, Vec<bool>) {
        let mut rgb = vec![0f32; 3 * w * h];
        let mut valid = vec![true; w * h];
        for y in 0..h {
            for x in 0..w {
                let p = y * w + x;
                let d = mount.to_world(pose, cam.unproject(x as f64 + 0.5, y as f64 + 0.5).expect("ray"));
                let (xi, az) = (d[2].acos(), d[0].atan2(d[1]).rem_euclid(std::f64::consts::TAU));
                let gamma = angle_between(d, sun);
                for c in 0..3 {
                    let v = if d[2] < 0.0 {
                        0.02
                    } else if (200f64.to_radians()..240f64.to_radians()).contains(&az)
                        && d[2] < 25f64.to_radians().sin()
                    {
                        0.01 * (1.0 + 0.5 * ((x / 3 + y / 5) % 2) as f64)
                    } else if gamma < 0.3f64.to_radians() {
                        valid[p] = false;
                        1e6
                    } else {
                        sky[c].radiance(xi, gamma)
                    };
                    rgb[3 * p + c] = v as f32;
                }
            }
        }
        (rgb, valid)
    }

    #[test]
    fn frames_with_a_building_and_the_sun_give_a_sky_within_1_percent() {
        let sky = [
            SkyModel {
                lz: 0.05,
                a: -1.0,
                b: -0.4,
                c: 12.0,
                d: -3.2,
                e: 0.5,
                h: 0.9,
            },
            SkyModel {
                lz: 0.08,
                a: -1.0,
                b: -0.38,
                c: 11.0,
                d: -3.1,
                e: 0.5,
                h: 0.9,
            },
            SkyModel {
                lz: 0.13,
                a: -1.0,
                b: -0.33,
                c: 9.0,
                d: -3.0,
                e: 0.45,
                h: 0.95,
            },
        ];
        let sun = direction(40f64.to_radians(), 200f64.to_radians());
        let cam = Pinhole {
            focal_px: 60.0,
            principal_px: (64.0, 48.0),
            k1: -0.05,
            k2: 0.01,
            projection: crate::pose::Projection::Pinhole,
        };
        let mount = Mount {
            pan_zero_azimuth_rad: 0.05,
            tilt_zero_rad: 0.01,
            roll_rad: 0.002,
            pitch_rad: -0.001,
        };
        // Six frames around the horizon at 25° tilt, and one at the zenith.
        let mut poses: Vec<HeadPose> = (0..6)
            .map(|k| HeadPose {
                pan_rad: f64::from(k) * 1.047,
                tilt_rad: 0.45,
            })
            .collect();
        poses.push(HeadPose {
            pan_rad: 0.0,
            tilt_rad: 1.58,
        });
        let rendered: Vec<_> = poses
            .iter()
            .map(|&p| render(cam, mount, p, (128, 96), &sky, sun))
            .collect();
        let frames: Vec<SkyFrame> = rendered
            .iter()
            .zip(&poses)
            .map(|((rgb, valid), &pose)| SkyFrame {
                width: 128,
                height: 96,
                rgb,
                valid: Some(valid),
                camera: cam,
                mount,
                pose,
            })
            .collect();
        let table = sky_samples(&frames, sun, 2, 2f64.to_radians()).expect("samples");
        assert!(
            table.directions.iter().all(|&(z, _)| z < std::f64::consts::FRAC_PI_2),
            "nothing below the horizon"
        );
        for (c, truth) in sky.iter().enumerate() {
            let samples = table.sky_samples(c, sun);
            let fit = fit_sky_robust(&samples, 40f64.to_radians()).expect("fits");
            assert!(
                fit.masked_fraction > 0.03,
                "the building is masked: {}",
                fit.masked_fraction
            );
            let sky_only: Vec<_> = samples
                .iter()
                .zip(&fit.kept)
                .filter(|(_, k)| **k)
                .map(|(s, _)| *s)
                .collect();
            let err = (sky_only
                .iter()
                .map(|s| (fit.fit.model.radiance(s.xi, s.gamma) / truth.radiance(s.xi, s.gamma) - 1.0).powi(2))
                .sum::<f64>()
                / sky_only.len() as f64)
                .sqrt();
            assert!(err < 0.01, "channel {c}: {err}");
        }
    }

    #[test]
    fn mismatched_buffers_and_zero_stride_are_errors() {
        let cam = Pinhole {
            focal_px: 60.0,
            principal_px: (4.0, 4.0),
            k1: 0.0,
            k2: 0.0,
            projection: crate::pose::Projection::Pinhole,
        };
        let rgb = vec![0f32; 10];
        let f = SkyFrame {
            width: 8,
            height: 8,
            rgb: &rgb,
            valid: None,
            camera: cam,
            mount: Mount::default(),
            pose: HeadPose {
                pan_rad: 0.0,
                tilt_rad: 0.5,
            },
        };
        assert!(matches!(
            sky_samples(&[f], [0.0, 0.0, 1.0], 1, 0.0),
            Err(FrameSampleError::Size { index: 0, .. })
        ));
        assert_eq!(
            sky_samples(&[], [0.0, 0.0, 1.0], 0, 0.0).map(|t| t.directions.len()),
            Err(FrameSampleError::Stride)
        );
    }
}
