//! A RADIANCE view string (`-vtv -vp x y z -vd dx dy dz -vu ux uy uz -vh H
//! -vv V`, as `rpict`, `rvu` and `vwrite` print it, or a picture header's
//! `VIEW=` line) turned into a [`ViewCamera`] for a picture's size.
//!
//! RADIANCE's conventions match [`ViewCamera`]'s: right = `-vd` × `-vu`,
//! `-vu` only a hint, `-vh`/`-vv` the full angles across the picture's width
//! and height, pixel centres at `(x + 0.5) / width`. Defaults are RADIANCE's
//! (`-vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45`); later options win.
//! Only perspective views (`-vtv`) without shift, lift or clipping are
//! supported.
//!
//! rpict keeps pixels square (`-pa 1`): given `-x W -y H` it shrinks one
//! of them so that the picture has the view's aspect (`normaspect`), rounding
//! to the nearest pixel. The picture's `-vh`/`-vv` therefore agree with its
//! size only to within half a pixel; [`RadianceView::camera`] takes the
//! square-pixel field of view that splits that rounding between the two axes
//! (at most a quarter pixel at the edges) and refuses a size the view cannot
//! have come from.

use nalgebra::Vector3;

use super::camera::ViewCamera;

/// A parsed perspective RADIANCE view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadianceView {
    /// `-vp`: the view point.
    pub vp: Vector3<f64>,
    /// `-vd`: the view direction (any length).
    pub vd: Vector3<f64>,
    /// `-vu`: the up hint.
    pub vu: Vector3<f64>,
    /// `-vh`: the horizontal angle, degrees.
    pub vh_deg: f64,
    /// `-vv`: the vertical angle, degrees.
    pub vv_deg: f64,
}

impl Default for RadianceView {
    fn default() -> Self {
        RadianceView {
            vp: Vector3::zeros(),
            vd: Vector3::y(),
            vu: Vector3::z(),
            vh_deg: 45.0,
            vv_deg: 45.0,
        }
    }
}

/// The picture size rpict makes from `-x width -y height` for a view of
/// horizontal and vertical angles `vh_deg`, `vv_deg` (square pixels,
/// RADIANCE's `normaspect`): one of the two shrinks.
pub fn rpict_size(vh_deg: f64, vv_deg: f64, width: usize, height: usize) -> (usize, usize) {
    let va = (0.5 * vv_deg.to_radians()).tan() / (0.5 * vh_deg.to_radians()).tan();
    let (w, h) = (width as f64, height as f64);
    if va * w > h {
        ((h / va + 0.5) as usize, height)
    } else {
        (width, (w * va + 0.5) as usize)
    }
}

impl RadianceView {
    /// Parses a view string; an optional leading `rvu`, `rpict`, `rview`
    /// or `VIEW=` is skipped. The error says which option and what was
    /// expected.
    pub fn parse(text: &str) -> Result<RadianceView, String> {
        let mut tokens: Vec<&str> = text.split_whitespace().collect();
        if let Some(first) = tokens.first_mut()
            && let Some(rest) = first.strip_prefix("VIEW=")
        {
            *first = rest;
        }
        let mut tokens = tokens.into_iter().filter(|t| !t.is_empty()).peekable();
        if tokens.peek().is_some_and(|t| matches!(*t, "rvu" | "rpict" | "rview")) {
            tokens.next();
        }
        let mut v = RadianceView::default();
        while let Some(opt) = tokens.next() {
            let mut number = |what: &str| -> Result<f64, String> {
                let t = tokens
                    .next()
                    .ok_or_else(|| format!("{opt} needs {what}: the view string ends"))?;
                t.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("{opt} {t}: expected {what}"))
            };
            match opt {
                // RADIANCE's default type.
                "-vtv" => {}
                "-vth" | "-vta" | "-vtl" | "-vts" | "-vtc" => {
                    return Err(format!(
                        "view type {opt}: only perspective views (-vtv) are supported, not {}",
                        match opt {
                            "-vth" => "hemispherical fisheye",
                            "-vta" => "angular fisheye",
                            "-vtl" => "parallel",
                            "-vts" => "planisphere",
                            _ => "cylindrical panorama",
                        }
                    ));
                }
                "-vp" | "-vd" | "-vu" => {
                    let mut p = [0.0; 3];
                    for c in &mut p {
                        *c = number("three numbers")?;
                    }
                    let p = Vector3::from(p);
                    match opt {
                        "-vp" => v.vp = p,
                        "-vd" => v.vd = p,
                        _ => v.vu = p,
                    }
                }
                "-vh" => v.vh_deg = number("an angle in degrees")?,
                "-vv" => v.vv_deg = number("an angle in degrees")?,
                "-vs" | "-vl" | "-vo" | "-va" => {
                    let x = number("a number")?;
                    if x != 0.0 {
                        return Err(format!(
                            "{opt} {x}: expected 0 ({} is not supported)",
                            if matches!(opt, "-vs" | "-vl") {
                                "a shifted or lifted view"
                            } else {
                                "a clipping plane"
                            }
                        ));
                    }
                }
                "-vf" => {
                    return Err(
                        "-vf (a view file): expected the view's options themselves (e.g. the VIEW= line of the file)"
                            .into(),
                    );
                }
                _ if opt.starts_with("-vt") => {
                    return Err(format!("view type {opt}: expected -vtv (perspective)"));
                }
                _ => {
                    return Err(format!(
                        "option {opt:?}: expected a RADIANCE view option (-vtv -vp -vd -vu -vh -vv, or -vs -vl -vo -va 0)"
                    ));
                }
            }
        }
        if v.vd.norm() == 0.0 {
            return Err(format!(
                "-vd {} {} {}: expected a non-zero direction",
                v.vd.x, v.vd.y, v.vd.z
            ));
        }
        if v.vd.normalize().cross(&v.vu).norm() < 1e-9 * v.vu.norm().max(1e-300) {
            return Err(format!(
                "-vu {} {} {}: expected an up direction not parallel to -vd",
                v.vu.x, v.vu.y, v.vu.z
            ));
        }
        for (opt, a) in [("-vh", v.vh_deg), ("-vv", v.vv_deg)] {
            if !(a > 0.0 && a < 180.0) {
                return Err(format!("{opt} {a}: expected a perspective angle in (0, 180) degrees"));
            }
        }
        Ok(v)
    }

    /// The square-pixel camera of this view for a `width` × `height`
    /// picture. Refused when the view's aspect and the picture's differ by
    /// more than rpict's rounding (a camera error over half a pixel at an
    /// edge): the message gives the size rpict would make.
    pub fn camera(&self, width: usize, height: usize) -> Result<ViewCamera, String> {
        if width == 0 || height == 0 {
            return Err(format!("{width}x{height}: expected at least 1x1 pixels"));
        }
        let th = (0.5 * self.vh_deg.to_radians()).tan();
        let tv = (0.5 * self.vv_deg.to_radians()).tan();
        let (w, h) = (width as f64, height as f64);
        // tan(vfov/2) = t: vertical edge error (h/2)(t/tv − 1), horizontal
        // (w/2)(t·w/(h·th) − 1). Equal and opposite at the t that
        // minimizes the larger.
        let t = (h + w) / (h / tv + w * w / (h * th));
        let edge = ((0.5 * h * (t / tv - 1.0)).abs()).max((0.5 * w * (t * w / (h * th) - 1.0)).abs());
        if edge > 0.5 {
            let (rw, rh) = rpict_size(self.vh_deg, self.vv_deg, width, height);
            return Err(format!(
                "-vh {} -vv {} on a {width}x{height} picture: the view's aspect ({:.4}) is not the picture's ({:.4}) \
                 (square pixels would be off by {edge:.2} px at the edges); expected the size rpict writes for \
                 this view (rpict -x {width} -y {height} makes {rw}x{rh}) or -vh/-vv matching the picture",
                self.vh_deg,
                self.vv_deg,
                th / tv,
                w / h
            ));
        }
        Ok(ViewCamera {
            position: self.vp,
            look: self.vd,
            up: self.vu,
            vfov_rad: 2.0 * t.atan(),
            width,
            height,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiance_file::read_radiance_image;
    use std::path::Path;

    fn fixtures() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../validation/radiance-inputs/fixtures")
    }

    #[test]
    fn view_strings_parse_with_radiance_defaults_and_prefixes() {
        let v = RadianceView::parse("VIEW= -vtv -vp 1 2 3 -vd 0 2 0 -vh 60 -vo 0 -va 0 -vs 0 -vl 0").unwrap();
        assert_eq!(v.vp, Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(v.vd, Vector3::new(0.0, 2.0, 0.0));
        assert_eq!((v.vu, v.vh_deg, v.vv_deg), (Vector3::z(), 60.0, 45.0));
        let v = RadianceView::parse("rpict -vv 30 -vh 40 -vh 50").unwrap();
        assert_eq!((v.vh_deg, v.vv_deg), (50.0, 30.0));
        assert_eq!(RadianceView::parse("VIEW=-vtv").unwrap(), RadianceView::default());
        for (text, want) in [
            (
                "-vth -vh 180",
                "only perspective views (-vtv) are supported, not hemispherical fisheye",
            ),
            ("-vtl", "parallel"),
            ("-vs 0.5", "-vs 0.5: expected 0"),
            ("-vo 1", "-vo 1: expected 0 (a clipping plane"),
            ("-vp 1 2", "-vp needs three numbers"),
            ("-vh wide", "-vh wide: expected an angle"),
            ("-vh 180", "-vh 180: expected a perspective angle in (0, 180)"),
            ("-vd 0 0 1", "-vu 0 0 1: expected an up direction not parallel to -vd"),
            ("-ab 2", "option \"-ab\": expected a RADIANCE view option"),
        ] {
            let e = RadianceView::parse(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
    }

    #[test]
    fn rpict_size_follows_normaspect() {
        // Checked with rpict/vwrays -d (RADIANCE 6.0a): 48x48 at -vh 60 -vv 40
        // makes 48x30; 384x384 at -vh 60 -vv 39.71 makes 384x240.
        assert_eq!(rpict_size(60.0, 40.0, 48, 48), (48, 30));
        assert_eq!(rpict_size(60.0, 39.71, 384, 384), (384, 240));
        assert_eq!(rpict_size(40.0, 60.0, 48, 48), (30, 48));
    }

    #[test]
    fn camera_rays_match_vwrays_within_a_tenth_of_a_pixel() {
        // vwrays -i on a view whose -vh 60 -vv 40 are 48x30 only after
        // rpict's rounding (48 · tan 20° / tan 30° = 30.26 rows).
        let text = std::fs::read_to_string(fixtures().join("vwrays-48x30.txt")).unwrap();
        let view = text.lines().find_map(|l| l.strip_prefix("view ")).unwrap();
        let cam = RadianceView::parse(view).unwrap().camera(48, 30).unwrap();
        let mut worst = 0.0f64;
        let mut n = 0;
        for l in text.lines().filter(|l| !l.starts_with('#') && !l.starts_with("view")) {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            assert_eq!(Vector3::new(v[2], v[3], v[4]), cam.position);
            // vwrays counts y from the bottom.
            let d = Vector3::new(v[5], v[6], v[7]);
            let (px, py) = cam.project(&(cam.position + d)).unwrap();
            let (wx, wy) = (v[0] + 0.5, 30.0 - v[1] - 0.5);
            worst = worst.max((px - wx).abs()).max((py - wy).abs());
            n += 1;
        }
        assert_eq!(n, 7);
        // Measured 0.078 px; 0.20 px at the left and right edges if -vv
        // alone set the field of view.
        eprintln!("vwrays: worst {worst:.3} px");
        assert!(worst < 0.1, "{worst} px");
    }

    #[test]
    fn camera_projects_the_sphere_where_rpict_rendered_it() {
        // A light sphere rendered by rpict asked for 384x384 with -vh 60
        // -vv 39.71 (it made 384x240), box-filtered 8x8 by pfilt to 48x30:
        // its radiance-weighted centroid against Campanile's projection of
        // its centre, the camera taken from the picture's VIEW= line.
        let f = read_radiance_image(&fixtures().join("sphere-48x30.hdr")).unwrap();
        let cam = RadianceView::parse(&f.view.unwrap())
            .unwrap()
            .camera(f.image.width, f.image.height)
            .unwrap();
        let text = std::fs::read_to_string(fixtures().join("sphere.txt")).unwrap();
        let c: Vec<f64> = text
            .lines()
            .find_map(|l| l.strip_prefix("centre "))
            .unwrap()
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        let (px, py) = cam.project(&Vector3::new(c[0], c[1], c[2])).unwrap();
        let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
        for y in 0..f.image.height {
            for x in 0..f.image.width {
                let v = f64::from(f.image.radiance(x, y, 0));
                sx += v * (x as f64 + 0.5);
                sy += v * (y as f64 + 0.5);
                s += v;
            }
        }
        let (cx, cy) = (sx / s, sy / s);
        eprintln!("sphere: projected ({px:.3}, {py:.3}), rendered centroid ({cx:.3}, {cy:.3})");
        assert!(
            (px - cx).abs() < 0.3 && (py - cy).abs() < 0.3,
            "({px}, {py}) vs ({cx}, {cy})"
        );
        // Off-centre on both axes, so a flipped axis would miss by pixels.
        assert!((cx - 24.0).abs() > 3.0 && (cy - 15.0).abs() > 3.0, "({cx}, {cy})");
    }

    #[test]
    fn a_picture_size_the_view_cannot_have_made_is_refused() {
        let v = RadianceView::parse("-vh 60 -vv 60").unwrap();
        let e = v.camera(48, 30).unwrap_err();
        assert!(e.contains("rpict -x 48 -y 30 makes 30x30"), "{e}");
        // The view's own aspect is accepted; vfov is then the view's -vv.
        let cam = v.camera(48, 48).unwrap();
        assert!((cam.vfov_rad.to_degrees() - 60.0).abs() < 1e-9);
    }
}
