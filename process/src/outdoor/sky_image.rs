//! A sky fitted from an HDR fisheye image of it (thesis §5.3.2 on a plain
//! file): each pixel of a RADIANCE angular (`-vta`) or hemispherical
//! (`-vth`) fisheye picture becomes a direction and one radiance per
//! channel, and eq. (5.9) is fitted per channel by the robust sky fit
//! ([`crate::sky::fit_sky_with`]).
//!
//! The projections are RADIANCE's (`image.c`, `viewray`): with picture
//! coordinates `x, y ∈ [−½, ½]` from the centre (y up, pixel centres at
//! half-integers), an angular fisheye puts the ray at angle
//! `θ = √((x·vh)² + (y·vv)²)` from the view direction, towards `(x·vh,
//! y·vv)`; a hemispherical one at `sin θ`-radius, `(2x sin(vh/2), 2y
//! sin(vv/2))` on the unit disc.
//!
//! Left out before fitting: pixels outside the projection, less than
//! [`MIN_ELEVATION_DEG`] above the horizon (where a renderer blends the sky
//! into its ground glow and a camera sees the skyline), within
//! [`SUN_MARGIN_DEG`] of the sun (the disc and its glare), and non-finite or
//! non-positive values. The rest are thinned to at most [`MAX_SAMPLES`] on
//! a regular pixel stride.

use std::path::Path;

use nalgebra::Vector3;

use crate::igi::scene_file::SceneFileError;
use crate::radiance_file::read_radiance_image;
use crate::sky::{ChannelSky, SkyFitOptions, SkySample, angle_between, fit_sky_with};

/// Lowest elevation sampled, degrees.
pub const MIN_ELEVATION_DEG: f64 = 2.0;
/// Pixels nearer the sun than this are left out, degrees.
pub const SUN_MARGIN_DEG: f64 = 3.0;
/// At most this many samples are fitted per channel.
pub const MAX_SAMPLES: usize = 3000;

/// Why a sky image could not be fitted.
#[derive(Debug)]
pub enum SkyImageError {
    /// The image could not be read, or its fit failed.
    File(SceneFileError),
    /// The view is not a fisheye this module reads.
    Field {
        /// The view, printed.
        value: String,
        /// What was expected.
        expected: String,
    },
}

/// A RADIANCE fisheye view.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FisheyeView {
    angular: bool,
    vd: Vector3<f64>,
    vu: Vector3<f64>,
    vh_rad: f64,
    vv_rad: f64,
}

fn parse_view(text: &str) -> Result<FisheyeView, String> {
    let mut tokens = text.split_whitespace().peekable();
    if let Some(t) = tokens.peek()
        && (matches!(*t, "rpict" | "rvu" | "rview") || t.starts_with("VIEW="))
    {
        let t = tokens.next().unwrap_or_default();
        if let Some(rest) = t.strip_prefix("VIEW=")
            && !rest.is_empty()
        {
            return parse_view(&format!("{rest} {}", tokens.collect::<Vec<_>>().join(" ")));
        }
    }
    let mut v = FisheyeView {
        angular: true,
        vd: Vector3::new(0.0, 0.0, 1.0),
        vu: Vector3::new(0.0, 1.0, 0.0),
        vh_rad: 0.0,
        vv_rad: 0.0,
    };
    let mut typed = false;
    while let Some(opt) = tokens.next() {
        let mut number = |what: &str| -> Result<f64, String> {
            let t = tokens.next().ok_or_else(|| format!("{opt} needs {what}"))?;
            t.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{opt} {t}: expected {what}"))
        };
        match opt {
            "-vta" => (v.angular, typed) = (true, true),
            "-vth" => (v.angular, typed) = (false, true),
            _ if opt.starts_with("-vt") => {
                return Err(format!(
                    "view type {opt}: expected -vta (angular fisheye) or -vth (hemispherical fisheye)"
                ));
            }
            "-vp" => {
                for _ in 0..3 {
                    number("three numbers")?;
                }
            }
            "-vd" | "-vu" => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    *c = number("three numbers")?;
                }
                if opt == "-vd" {
                    v.vd = Vector3::from(p);
                } else {
                    v.vu = Vector3::from(p);
                }
            }
            "-vh" => v.vh_rad = number("an angle in degrees")?.to_radians(),
            "-vv" => v.vv_rad = number("an angle in degrees")?.to_radians(),
            "-vs" | "-vl" | "-vo" | "-va" => {
                let x = number("a number")?;
                if x != 0.0 {
                    return Err(format!(
                        "{opt} {x}: expected 0 (shifted views and clipping are not supported)"
                    ));
                }
            }
            _ => {
                return Err(format!(
                    "option {opt:?}: expected a RADIANCE view option (-vta|-vth -vp -vd -vu -vh -vv)"
                ));
            }
        }
    }
    if !typed {
        return Err("no view type: expected -vta (angular fisheye) or -vth (hemispherical fisheye)".into());
    }
    let limit = if v.angular {
        2.0 * std::f64::consts::PI
    } else {
        std::f64::consts::PI
    };
    for (opt, a) in [("-vh", v.vh_rad), ("-vv", v.vv_rad)] {
        if !(a > 0.0 && a <= limit + 1e-9) {
            return Err(format!(
                "{opt} {:.3}: expected an angle in (0, {:.0}] degrees",
                a.to_degrees(),
                limit.to_degrees()
            ));
        }
    }
    if v.vd.norm() == 0.0 || v.vd.normalize().cross(&v.vu).norm() < 1e-9 {
        return Err("-vd and -vu: expected a non-zero view direction and an up vector not parallel to it".into());
    }
    Ok(v)
}

impl FisheyeView {
    /// The world direction through picture point `(px, py)` (pixels from
    /// the top left), or `None` outside the projection.
    fn ray(&self, px: f64, py: f64, width: usize, height: usize) -> Option<Vector3<f64>> {
        let f = self.vd.normalize();
        let h = f.cross(&self.vu).normalize();
        let u = h.cross(&f);
        let x = px / width as f64 - 0.5;
        let y = 0.5 - py / height as f64;
        let (a, b, z) = if self.angular {
            let (ax, ay) = (x * self.vh_rad, y * self.vv_rad);
            let theta = (ax * ax + ay * ay).sqrt();
            if theta > std::f64::consts::PI {
                return None;
            }
            let s = if theta == 0.0 { 1.0 } else { theta.sin() / theta };
            (ax * s, ay * s, theta.cos())
        } else {
            let (ax, ay) = (2.0 * x * (0.5 * self.vh_rad).sin(), 2.0 * y * (0.5 * self.vv_rad).sin());
            let z2 = 1.0 - ax * ax - ay * ay;
            if z2 < 0.0 {
                return None;
            }
            (ax, ay, z2.sqrt())
        };
        Some((h * a + u * b + f * z).normalize())
    }
}

/// Fits eq. (5.9) per channel (r, g, b) to the fisheye sky image `path`
/// with RADIANCE view `view` (or `"from-image"`), the sun at unit
/// direction `sun`.
pub fn fit_fisheye_sky(path: &Path, view: &str, sun: [f64; 3]) -> Result<Vec<ChannelSky>, SkyImageError> {
    let file_err = |message: String| {
        SkyImageError::File(SceneFileError::File {
            path: path.to_path_buf(),
            message,
        })
    };
    let picture = read_radiance_image(path).map_err(|e| file_err(e.message))?;
    let text = if view.trim() == "from-image" {
        picture.view.clone().ok_or_else(|| SkyImageError::Field {
            value: "\"from-image\"".into(),
            expected: format!(
                "a VIEW= line in the header of {} (none: give the view string)",
                path.display()
            ),
        })?
    } else {
        view.to_string()
    };
    let v = parse_view(&text).map_err(|e| SkyImageError::Field {
        value: format!("{text:?}"),
        expected: e,
    })?;
    let img = &picture.image;
    let min_z = MIN_ELEVATION_DEG.to_radians().sin();
    let margin = SUN_MARGIN_DEG.to_radians();
    let mut kept: Vec<(f64, f64, [f64; 3])> = Vec::new();
    for y in 0..img.height {
        for x in 0..img.width {
            let Some(d) = v.ray(x as f64 + 0.5, y as f64 + 0.5, img.width, img.height) else {
                continue;
            };
            if d.z < min_z {
                continue;
            }
            let d = [d.x, d.y, d.z];
            let gamma = angle_between(d, sun);
            if gamma < margin {
                continue;
            }
            let i = 3 * (y * img.width + x);
            let rgb = [0, 1, 2].map(|c| f64::from(img.data[i + c]));
            if rgb.iter().all(|r| r.is_finite() && *r > 0.0) {
                kept.push((d[2].clamp(-1.0, 1.0).acos(), gamma, rgb));
            }
        }
    }
    let stride = kept.len().div_ceil(MAX_SAMPLES).max(1);
    let kept: Vec<_> = kept.into_iter().step_by(stride).collect();
    let sun_zenith = sun[2].clamp(-1.0, 1.0).acos();
    let mut channels = Vec::new();
    for (c, name) in ["r", "g", "b"].into_iter().enumerate() {
        let samples: Vec<SkySample> = kept
            .iter()
            .map(|&(xi, gamma, rgb)| SkySample {
                xi,
                gamma,
                radiance: rgb[c],
            })
            .collect();
        let robust = fit_sky_with(&samples, sun_zenith, &SkyFitOptions::default()).map_err(|e| {
            file_err(format!(
                "channel {name}: the sky fit failed on {} samples above {MIN_ELEVATION_DEG}° elevation and \
                 {SUN_MARGIN_DEG}° from the sun: {e}",
                samples.len()
            ))
        })?;
        channels.push(ChannelSky::of_robust(name, &robust));
    }
    Ok(channels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RADIANCE's angular fisheye looking up with -vh 180 -vv 180: the
    /// centre is the zenith, the top edge north (-vu 0 1 0), and the right
    /// edge `vd × vu` = west: the sky as seen from below.
    #[test]
    fn angular_fisheye_rays_follow_radiance() {
        let v = parse_view("VIEW= -vta -vp 0 0 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180").unwrap();
        let (w, h) = (128, 128);
        let zen = v.ray(64.0, 64.0, w, h).unwrap();
        assert!((zen - Vector3::z()).norm() < 1e-12);
        let west = v.ray(128.0, 64.0, w, h).unwrap();
        assert!((west + Vector3::x()).norm() < 1e-12, "{west:?}");
        let north = v.ray(64.0, 0.0, w, h).unwrap();
        assert!((north - Vector3::y()).norm() < 1e-12, "{north:?}");
        // 45° from the zenith a quarter of the width from the centre.
        let d = v.ray(96.0, 64.0, w, h).unwrap();
        assert!((d.z.acos().to_degrees() - 45.0).abs() < 1e-9);
        // A corner is 127° from the zenith: below the horizon.
        let corner = v.ray(0.0, 0.0, w, h).unwrap();
        assert!((corner.z.acos().to_degrees() - 90.0 * 2f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn hemispherical_fisheye_rays_follow_radiance() {
        let v = parse_view("-vth -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180").unwrap();
        let d = v.ray(96.0, 64.0, 128, 128).unwrap();
        // sin θ = 0.5 at a quarter of the width.
        assert!((d.z.acos().to_degrees() - 30.0).abs() < 1e-9);
        assert!(v.ray(0.0, 0.0, 128, 128).is_none());
    }

    #[test]
    fn perspective_views_are_refused_with_the_reason() {
        let e = parse_view("-vtv -vd 0 0 1 -vu 0 1 0 -vh 60 -vv 60").unwrap_err();
        assert!(e.contains("-vta"), "{e}");
        let e = parse_view("-vp 0 0 0 -vd 0 0 1").unwrap_err();
        assert!(e.contains("no view type"), "{e}");
    }
}
