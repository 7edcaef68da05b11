//! A room session's merged frames as inverse global illumination takes
//! them (thesis §4.7.2): each HDR map resampled into a rectified pinhole
//! view (no distortion, level to the camera's own axes), with a mask of
//! the pixels that can be trusted; and each bulb cut out of the views that
//! see it, for triangulation (§4.7.2: "the positions of the light sources
//! were recovered by triangulation from their images").
//!
//! # Rectification
//!
//! The rectified camera sits where the head's camera stood and looks along
//! its optical axis, with its own `up` (the mount's level offsets kept).
//! Its focal length is the station's, scaled by `scale`; its principal
//! point is the image centre. Each rectified pixel is the box average of
//! `n × n` sub-samples (`n = ⌈1/scale⌉`), each a bilinear tap of the merged
//! map at the point the distorted pinhole (`r' = r (1 + k1 r² + k2 r⁴)`)
//! images that direction at. Averaging radiance is linear, so a smaller
//! rectified image is still radiance (unlike an 8-bit image resampled
//! before calibration, which the HDR stage refuses). A rectified pixel is
//! masked out when any of its taps falls outside the frame or on a pixel
//! clipped or underexposed in a channel (the merge's mask).

use nalgebra::Vector3;

use super::MergedGroup;
use crate::camera::image::RadianceImage;
use crate::igi::ViewCamera;
use crate::pose::{HeadPose, Mount, Pinhole};

/// A merged frame resampled into a rectified pinhole view.
#[derive(Debug, Clone)]
pub struct RectifiedView {
    /// The rectified camera.
    pub camera: ViewCamera,
    /// Radiance, in the merged map's units.
    pub image: RadianceImage,
    /// Per pixel, `true` where every tap was valid.
    pub valid: Vec<bool>,
}

impl RectifiedView {
    /// The fraction of valid pixels.
    pub fn valid_fraction(&self) -> f64 {
        self.valid.iter().filter(|v| **v).count() as f64 / self.valid.len().max(1) as f64
    }
}

/// The rectified camera of a frame taken with `pinhole` (at `width` ×
/// `height`) on the head at `head` standing at `position_m`, scaled by `scale`.
pub fn rectified_camera(
    pinhole: &Pinhole,
    (width, height): (usize, usize),
    mount: &Mount,
    head: HeadPose,
    position_m: [f64; 3],
    scale: f64,
) -> ViewCamera {
    let oriented = mount.at(head);
    let look = oriented.to_world([0.0, 0.0, 1.0]);
    let down = oriented.to_world([0.0, 1.0, 0.0]);
    let (w, h) = scaled((width, height), scale);
    ViewCamera {
        position: Vector3::from(position_m),
        look: Vector3::from(look),
        up: -Vector3::from(down),
        // The vertical field of view of the undistorted pinhole over the
        // full frame height; scaling keeps the angle.
        vfov_rad: 2.0 * (height as f64 / 2.0 / pinhole.focal_px).atan(),
        width: w,
        height: h,
    }
}

fn scaled((width, height): (usize, usize), scale: f64) -> (usize, usize) {
    let s = |n: usize| ((n as f64 * scale).round() as usize).max(1);
    (s(width), s(height))
}

/// Bilinear tap of `map` at pixel point `(u, v)` (pixel centres at
/// half-integers); `None` outside the frame or where a tap is masked.
fn tap(map: &crate::hdr::merge::RadianceMap, u: f64, v: f64) -> Option<[f64; 3]> {
    let (x, y) = (u - 0.5, v - 0.5);
    if !(x >= 0.0 && y >= 0.0) {
        return None;
    }
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = (x0 + 1, y0 + 1);
    if x1 >= map.width || y1 >= map.height {
        return None;
    }
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let mut out = [0.0; 3];
    for (xx, yy, wgt) in [
        (x0, y0, (1.0 - fx) * (1.0 - fy)),
        (x1, y0, fx * (1.0 - fy)),
        (x0, y1, (1.0 - fx) * fy),
        (x1, y1, fx * fy),
    ] {
        let p = yy * map.width + xx;
        if !map.is_valid(p) {
            return None;
        }
        for (c, o) in out.iter_mut().enumerate() {
            *o += wgt * f64::from(map.rgb[p * 3 + c]);
        }
    }
    Some(out)
}

/// `group` resampled into its rectified view at `scale` (module doc).
pub fn rectify(group: &MergedGroup, mount: &Mount, scale: f64) -> RectifiedView {
    let map = &group.map;
    let camera = rectified_camera(
        &group.pinhole,
        (map.width, map.height),
        mount,
        group.head,
        group.position_m,
        scale,
    );
    let n = (1.0 / scale).ceil().max(1.0) as usize;
    let (w, h) = (camera.width, camera.height);
    let mut data = vec![0f32; w * h * 3];
    let mut valid = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0; 3];
            let mut ok = true;
            'taps: for j in 0..n {
                for i in 0..n {
                    let (px, py) = (
                        x as f64 + (i as f64 + 0.5) / n as f64,
                        y as f64 + (j as f64 + 0.5) / n as f64,
                    );
                    let d = camera.direction(px, py);
                    let c = mount.to_camera(group.head, [d.x, d.y, d.z]);
                    let Some(l) = group.pinhole.project(c).and_then(|(u, v)| tap(map, u, v)) else {
                        ok = false;
                        break 'taps;
                    };
                    (0..3).for_each(|k| sum[k] += l[k]);
                }
            }
            if ok {
                let k = y * w + x;
                valid[k] = true;
                for c in 0..3 {
                    data[k * 3 + c] = (sum[c] / (n * n) as f64) as f32;
                }
            }
        }
    }
    RectifiedView {
        camera,
        image: RadianceImage {
            width: w,
            height: h,
            data,
        },
        valid,
    }
}

/// The part of `view` within `window_m` of `center` (a bulb's approximate
/// position, e.g. from the station's configuration) as seen from the
/// camera, everything else black: one bulb's image among several lit at
/// once. `None` when the centre is behind the camera, when a bulb of
/// radius `bulb_m` there, with the margin and background ring that
/// triangulation measures, would reach the image border, or when a pixel inside the window is not
/// valid (a bulb clipped in every exposure cannot be measured).
pub fn bulb_window(view: &RectifiedView, center: &Vector3<f64>, bulb_m: f64, window_m: f64) -> Option<RadianceImage> {
    let cam = &view.camera;
    let (cx, cy) = cam.project(center)?;
    let distance = (center - cam.position).norm();
    let focal = cam.height as f64 / 2.0 / (cam.vfov_rad / 2.0).tan();
    // The bulb, the margin and background ring the triangulation measures, and a pixel.
    let bulb_px = focal * bulb_m / distance + crate::igi::light_triangulation::BULB_MARGIN_PX as f64 + 3.0;
    if !(cx - bulb_px >= 0.0
        && cy - bulb_px >= 0.0
        && cx + bulb_px <= cam.width as f64
        && cy + bulb_px <= cam.height as f64)
    {
        return None;
    }
    let r_px = focal * window_m / distance;
    let mut data = vec![0f32; view.image.data.len()];
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            if dx * dx + dy * dy > r_px * r_px {
                continue;
            }
            let k = y * cam.width + x;
            if !view.valid[k] {
                return None;
            }
            data[k * 3..k * 3 + 3].copy_from_slice(&view.image.data[k * 3..k * 3 + 3]);
        }
    }
    Some(RadianceImage {
        width: cam.width,
        height: cam.height,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::merge::RadianceMap;
    use crate::pipeline::Purpose;

    /// A map whose radiance at each pixel is a known function of the
    /// world direction it sees, through a distorted pinhole on a tilted
    /// mount: the rectified view must see the same function of direction.
    fn direction_coded_group(scale_check: f64) -> (MergedGroup, Mount, f64) {
        let pinhole = Pinhole {
            focal_px: 221.7,
            principal_px: (130.0, 95.0),
            k1: -0.05,
            k2: 0.01,
            projection: crate::pose::Projection::Pinhole,
        };
        let mount = Mount {
            pan_zero_azimuth_rad: 0.0,
            tilt_zero_rad: 0.0,
            roll_rad: 0.15f64.to_radians(),
            pitch_rad: -0.1f64.to_radians(),
        };
        let head = HeadPose {
            pan_rad: 0.7,
            tilt_rad: 0.3,
        };
        let (w, h) = (256, 192);
        let f = |d: [f64; 3]| [1.0 + d[0], 2.0 + d[1], 3.0 + d[2]];
        let mut rgb = vec![0f32; w * h * 3];
        for y in 0..h {
            for x in 0..w {
                let c = pinhole.unproject(x as f64 + 0.5, y as f64 + 0.5).unwrap();
                let d = mount.to_world(head, c);
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let v = f([d[0] / n, d[1] / n, d[2] / n]);
                for k in 0..3 {
                    rgb[(y * w + x) * 3 + k] = v[k] as f32;
                }
            }
        }
        let group = MergedGroup {
            key: "g".into(),
            occurrence: "o".into(),
            held_out: false,
            purpose: Purpose::View { pose: "p".into() },
            time: chrono::DateTime::UNIX_EPOCH,
            head,
            held_by: None,
            position_m: [1.0, 2.0, 1.5],
            pinhole,
            zoom: false,
            map: RadianceMap {
                width: w,
                height: h,
                rgb,
                variance: vec![0.0; w * h * 3],
                mask: vec![0; w * h],
            },
        };
        (group, mount, scale_check)
    }

    /// The rectified view sees the coded function of direction to the
    /// accuracy of bilinear interpolation (a smooth function: 1e-4), at
    /// full and half scale; the outermost pixels, whose taps leave the
    /// distorted frame, are masked rather than extrapolated.
    #[test]
    fn rectified_pixels_see_their_directions() {
        for scale in [1.0, 0.5] {
            let (group, mount, _) = direction_coded_group(scale);
            let view = rectify(&group, &mount, scale);
            assert_eq!(view.camera.width, (256.0 * scale) as usize);
            let mut worst = 0.0f64;
            let mut checked = 0;
            for y in 0..view.camera.height {
                for x in 0..view.camera.width {
                    let k = y * view.camera.width + x;
                    if !view.valid[k] {
                        continue;
                    }
                    checked += 1;
                    // The box average of the function over the pixel is
                    // the function at the centre to second order.
                    let d = view.camera.direction(x as f64 + 0.5, y as f64 + 0.5);
                    let want = [1.0 + d.x, 2.0 + d.y, 3.0 + d.z];
                    for (c, w) in want.iter().enumerate() {
                        worst = worst.max((f64::from(view.image.data[k * 3 + c]) - w).abs());
                    }
                }
            }
            assert!(
                checked > 10_000 * (scale * scale) as usize,
                "scale {scale}: {checked} pixels checked"
            );
            assert!(worst < 1e-4, "scale {scale}: worst {worst}");
            // Barrel distortion at the same focal length: the rectified
            // frame is within the distorted one except at the far corners
            // (principal point off-centre by (2, −1) px).
            let f = view.valid_fraction();
            assert!(f > 0.97 && f <= 1.0, "scale {scale}: valid fraction {f}");
        }
    }

    /// A clipped pixel of the merge masks every rectified pixel that taps it.
    #[test]
    fn clipped_pixels_are_masked() {
        let (mut group, mount, _) = direction_coded_group(1.0);
        let p = 96 * 256 + 130;
        group.map.mask[p] = crate::hdr::merge::MASK_SATURATED;
        let view = rectify(&group, &mount, 1.0);
        let masked = view.valid.iter().filter(|v| !**v).count();
        let baseline = rectify(&direction_coded_group(1.0).0, &mount, 1.0)
            .valid
            .iter()
            .filter(|v| !**v)
            .count();
        assert!(
            (1..=9).contains(&(masked - baseline)),
            "one clipped source pixel masks 1–9 rectified pixels, got {}",
            masked - baseline
        );
    }

    /// A bulb window keeps the disc around the prior and blacks out the rest.
    #[test]
    fn bulb_window_keeps_only_the_disc() {
        let (group, mount, _) = direction_coded_group(1.0);
        let view = rectify(&group, &mount, 1.0);
        let ahead = view.camera.position + view.camera.look.normalize() * 2.0;
        let img = bulb_window(&view, &ahead, 0.05, 0.1).expect("in view");
        let kept = (0..img.width * img.height).filter(|k| img.data[k * 3] != 0.0).count();
        // A 0.1 m radius at 2 m is 0.05 rad; in pixels f · 0.05.
        let focal = view.camera.height as f64 / 2.0 / (view.camera.vfov_rad / 2.0).tan();
        let expected = std::f64::consts::PI * (focal * 0.05).powi(2);
        assert!(
            (kept as f64 / expected - 1.0).abs() < 0.05,
            "kept {kept} pixels, expected about {expected:.0}"
        );
        let behind = view.camera.position - view.camera.look.normalize() * 2.0;
        assert!(bulb_window(&view, &behind, 0.05, 0.1).is_none());
        // A bulb at the image's edge would be cut: refused.
        let edge = view.camera.position + view.camera.direction(1.0, 96.0) * 2.0;
        assert!(bulb_window(&view, &edge, 0.05, 0.1).is_none());
    }
}
