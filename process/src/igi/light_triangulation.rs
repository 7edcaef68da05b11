//! Light sources from HDR images of their bulbs (thesis §4.7.2: "the
//! positions of the light sources were recovered by triangulation from
//! their images"): in each calibrated view, the bulb is the connected
//! set of pixels brighter than half the brightest; its radiance-weighted
//! centroid defines a ray; the rays of ≥ 2 views meet, in the
//! least-squares sense, at the bulb's centre. The bulb's solid angle in
//! each view (its pixel count times each pixel's solid angle) and the
//! distance give its radius. Its radiant intensity comes from the light
//! it sends into each view: Σ L Ω over the bulb and a margin of
//! [`BULB_MARGIN_PX`] pixels around it (less the background just outside),
//! times the distance squared (a uniform sphere of radiance L and radius r
//! has intensity L π r² in every direction and subtends π r² / D²).
//!
//! Half the peak, and a margin for the flux, because a bulb's image is
//! blurred (optics, pixel integration, resampling into rectified views):
//! the area inside the half-maximum contour of a blurred disc is its true
//! area to first order, and the margin keeps the blurred edge's light.

use nalgebra::{Matrix3, Vector3};

use super::camera::ViewCamera;
use super::input::IgiLight;
use crate::camera::image::RadianceImage;

/// One HDR image of a bulb.
#[derive(Debug, Clone)]
pub struct BulbImage<'a> {
    /// Name, for diagnostics.
    pub name: &'a str,
    /// The calibrated camera.
    pub camera: ViewCamera,
    /// Its radiance image.
    pub image: &'a RadianceImage,
}

/// A bulb seen in one image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BulbSighting {
    /// Radiance-weighted centroid, pixels.
    pub centroid_px: (f64, f64),
    /// Pixels in the bulb.
    pub pixels: usize,
    /// Solid angle of the bulb, steradians.
    pub solid_angle_sr: f64,
    /// Mean radiance of the bulb's pixels per channel: the flux below
    /// over the bulb's solid angle.
    pub radiance: [f64; 3],
    /// Σ (L − background) Ω over the bulb and its margin, per channel
    /// (W·m⁻² at the camera: the bulb's irradiance there).
    pub flux: [f64; 3],
}

/// A triangulated light and its diagnostics.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangulatedLight {
    /// The light as the solver takes it.
    pub light: IgiLight,
    /// Per image, the bulb seen.
    pub sightings: Vec<BulbSighting>,
    /// Root-mean-square distance of the centre from the rays, metres.
    pub ray_rms_m: f64,
}

/// Why a bulb could not be triangulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TriangulationError {
    /// Fewer than two images.
    #[error("light {light:?}: {got} image(s) of the bulb: expected at least 2 calibrated views")]
    TooFewViews {
        /// The light's name.
        light: String,
        /// Images given.
        got: usize,
    },
    /// No bulb in an image.
    #[error(
        "light {light:?}, image {image:?}: {reason}: expected a bulb brighter than everything else, away from the image border"
    )]
    NoBulb {
        /// The light's name.
        light: String,
        /// The image's name.
        image: String,
        /// What was found instead.
        reason: String,
    },
    /// The rays are (nearly) parallel.
    #[error(
        "light {light:?}: the views' rays toward the bulb are nearly parallel (condition {condition:.3e}): expected views from different positions"
    )]
    Parallel {
        /// The light's name.
        light: String,
        /// Smallest over largest eigenvalue of the normal matrix.
        condition: f64,
    },
}

/// Pixels above this fraction of the brightest pixel's mean-channel
/// radiance are the bulb (half maximum: see the module doc).
pub const BULB_THRESHOLD: f64 = 0.5;

/// Pixels around the bulb whose light is counted in its intensity.
pub const BULB_MARGIN_PX: usize = 2;

/// Width of the ring beyond the margin whose mean is the background.
const BACKGROUND_RING_PX: usize = 2;

/// The solid angle of pixel `(x, y)` of `camera` (pinhole: the pixel's
/// area on the unit image plane times cos³ of its angle off axis).
pub fn pixel_solid_angle(camera: &ViewCamera, x: usize, y: usize) -> f64 {
    let t = (0.5 * camera.vfov_rad).tan();
    let side = 2.0 * t / camera.height as f64;
    let cos = camera
        .direction(x as f64 + 0.5, y as f64 + 0.5)
        .dot(&camera.look.normalize());
    side * side * cos.powi(3)
}

/// The bulb in one image: the 8-connected set of pixels around the
/// brightest one above [`BULB_THRESHOLD`] of it.
pub fn sighting(light: &str, view: &BulbImage) -> Result<BulbSighting, TriangulationError> {
    let img = view.image;
    let (w, h) = (img.width, img.height);
    let no_bulb = |reason: String| TriangulationError::NoBulb {
        light: light.to_string(),
        image: view.name.to_string(),
        reason,
    };
    if w == 0 || h == 0 || img.data.len() != w * h * 3 || view.camera.width != w || view.camera.height != h {
        return Err(no_bulb(format!(
            "the image is {w}x{h} with {} values but the camera is {}x{}",
            img.data.len(),
            view.camera.width,
            view.camera.height
        )));
    }
    let lum = |i: usize| -> f64 { (0..3).map(|c| f64::from(img.data[i * 3 + c])).sum::<f64>() / 3.0 };
    let mut best = (0usize, f64::NEG_INFINITY);
    for i in 0..w * h {
        let l = lum(i);
        if !l.is_finite() {
            return Err(no_bulb(format!("pixel ({}, {}) has radiance {l}", i % w, i / w)));
        }
        if l > best.1 {
            best = (i, l);
        }
    }
    if best.1 <= 0.0 {
        return Err(no_bulb("the image is black".into()));
    }
    let threshold = BULB_THRESHOLD * best.1;
    let mut inside = vec![false; w * h];
    let mut stack = vec![best.0];
    inside[best.0] = true;
    let (mut sx, mut sy, mut sw, mut omega) = (0.0, 0.0, 0.0, 0.0);
    let mut count = 0usize;
    let mut touches_border = false;
    while let Some(i) = stack.pop() {
        let (x, y) = (i % w, i / w);
        let l = lum(i);
        sx += l * (x as f64 + 0.5);
        sy += l * (y as f64 + 0.5);
        sw += l;
        omega += pixel_solid_angle(&view.camera, x, y);
        count += 1;
        touches_border |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if !inside[j] && lum(j) >= threshold {
                    inside[j] = true;
                    stack.push(j);
                }
            }
        }
    }
    if count < 3 {
        return Err(no_bulb(format!(
            "the brightest blob has {count} pixel(s) (too small to measure its size)"
        )));
    }
    // Chebyshev distance of every pixel from the blob, up to margin + ring.
    let reach = BULB_MARGIN_PX + BACKGROUND_RING_PX;
    let mut dist = vec![usize::MAX; w * h];
    let mut frontier: Vec<usize> = (0..w * h).filter(|&i| inside[i]).collect();
    frontier.iter().for_each(|&i| dist[i] = 0);
    for d in 1..=reach {
        let mut next = Vec::new();
        for &i in &frontier {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        touches_border = true;
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if dist[j] == usize::MAX {
                        dist[j] = d;
                        next.push(j);
                    }
                }
            }
        }
        frontier = next;
    }
    if touches_border {
        return Err(no_bulb(format!(
            "the brightest blob comes within {reach} pixels of the image border (its margin and background would be cut)"
        )));
    }
    let (mut bg, mut bg_n) = ([0.0; 3], 0usize);
    for i in (0..w * h).filter(|&i| dist[i] > BULB_MARGIN_PX && dist[i] <= reach) {
        for (c, b) in bg.iter_mut().enumerate() {
            *b += f64::from(img.data[i * 3 + c]);
        }
        bg_n += 1;
    }
    let bg = bg.map(|b| b / bg_n.max(1) as f64);
    let mut flux = [0.0; 3];
    for i in (0..w * h).filter(|&i| dist[i] <= BULB_MARGIN_PX) {
        let o = pixel_solid_angle(&view.camera, i % w, i / w);
        for (c, f) in flux.iter_mut().enumerate() {
            *f += (f64::from(img.data[i * 3 + c]) - bg[c]) * o;
        }
    }
    Ok(BulbSighting {
        centroid_px: (sx / sw, sy / sw),
        pixels: count,
        solid_angle_sr: omega,
        radiance: flux.map(|f| f / omega),
        flux,
    })
}

/// Triangulates one light from `views` (module doc).
pub fn triangulate(light: &str, views: &[BulbImage]) -> Result<TriangulatedLight, TriangulationError> {
    if views.len() < 2 {
        return Err(TriangulationError::TooFewViews {
            light: light.to_string(),
            got: views.len(),
        });
    }
    let sightings: Vec<BulbSighting> = views.iter().map(|v| sighting(light, v)).collect::<Result<_, _>>()?;
    // Least-squares point nearest all rays: Σ (I − d dᵀ) p = Σ (I − d dᵀ) o.
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    let rays: Vec<(Vector3<f64>, Vector3<f64>)> = views
        .iter()
        .zip(&sightings)
        .map(|(v, s)| (v.camera.position, v.camera.direction(s.centroid_px.0, s.centroid_px.1)))
        .collect();
    for (o, d) in &rays {
        let m = Matrix3::identity() - d * d.transpose();
        a += m;
        b += m * o;
    }
    let eig = a.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    let condition = lo / hi;
    if condition.is_nan() || condition <= 1e-6 {
        return Err(TriangulationError::Parallel {
            light: light.to_string(),
            condition,
        });
    }
    let Some(p) = a.lu().solve(&b) else {
        return Err(TriangulationError::Parallel {
            light: light.to_string(),
            condition,
        });
    };
    let ray_rms_m = (rays
        .iter()
        .map(|(o, d)| {
            let v = p - o;
            (v - d * v.dot(d)).norm_squared()
        })
        .sum::<f64>()
        / rays.len() as f64)
        .sqrt();
    // Radius: a sphere at distance D subtends 2π(1 − cos θ) with sin θ = r / D.
    // Weighted by pixel count (larger discs are measured better).
    // Intensity: each view's flux times its distance squared, weighted alike.
    let (mut rw, mut r_sum) = (0.0, 0.0);
    let mut intensity = [0.0; 3];
    for ((o, _), s) in rays.iter().zip(&sightings) {
        let dist = (p - o).norm();
        let cos = (1.0 - s.solid_angle_sr / std::f64::consts::TAU).clamp(-1.0, 1.0);
        let r = dist * (1.0 - cos * cos).sqrt();
        let wgt = s.pixels as f64;
        r_sum += wgt * r;
        rw += wgt;
        for c in 0..3 {
            intensity[c] += wgt * s.flux[c] * dist * dist;
        }
    }
    let radius = r_sum / rw;
    Ok(TriangulatedLight {
        light: IgiLight {
            position: p,
            radius,
            intensity: intensity.map(|v| v / rw),
        },
        sightings,
        ray_rms_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An analytic image of a uniform sphere of radiance `l` (pixel centres
    /// inside the disc), on a black background.
    fn bulb_image(camera: &ViewCamera, centre: Vector3<f64>, radius: f64, l: [f32; 3]) -> RadianceImage {
        let mut data = vec![0f32; camera.width * camera.height * 3];
        for y in 0..camera.height {
            for x in 0..camera.width {
                let d = camera.direction(x as f64 + 0.5, y as f64 + 0.5);
                let v = centre - camera.position;
                let miss = (v - d * v.dot(&d)).norm();
                if v.dot(&d) > 0.0 && miss < radius {
                    data[(y * camera.width + x) * 3..][..3].copy_from_slice(&l);
                }
            }
        }
        RadianceImage {
            width: camera.width,
            height: camera.height,
            data,
        }
    }

    fn bulb_views<'a>(cams: &[ViewCamera], images: &'a [RadianceImage]) -> Vec<BulbImage<'a>> {
        cams.iter()
            .zip(images)
            .map(|(c, i)| BulbImage {
                name: "v",
                camera: *c,
                image: i,
            })
            .collect()
    }

    #[test]
    fn a_bulb_seen_from_three_views_is_found_within_a_millimetre() {
        let centre = Vector3::new(1.0, 1.0, 2.6);
        let radius = 0.05;
        let l = [380.0f32, 350.0, 300.0];
        let cams: Vec<ViewCamera> = [
            Vector3::new(0.5, 0.5, 1.6),
            Vector3::new(4.5, 0.5, 1.6),
            Vector3::new(2.5, 3.7, 1.6),
        ]
        .iter()
        .map(|p| ViewCamera {
            position: *p,
            // Off-centre aim: the bulb is not at the image centre.
            look: centre - p + Vector3::new(0.02, -0.015, 0.01),
            up: Vector3::z(),
            vfov_rad: 8f64.to_radians(),
            width: 96,
            height: 96,
        })
        .collect();
        let images: Vec<RadianceImage> = cams.iter().map(|c| bulb_image(c, centre, radius, l)).collect();
        let views = bulb_views(&cams, &images);
        let t = triangulate("lamp", &views).unwrap();
        let err_mm = (t.light.position - centre).norm() * 1e3;
        eprintln!(
            "position {err_mm:.3} mm, radius {:.4} m, intensity {:?}",
            t.light.radius, t.light.intensity
        );
        assert!(err_mm < 1.0, "position off by {err_mm:.3} mm");
        assert!(
            (t.light.radius / radius - 1.0).abs() < 0.03,
            "radius {}",
            t.light.radius
        );
        let truth = l.map(|v| f64::from(v) * std::f64::consts::PI * radius * radius);
        for c in 0..3 {
            assert!(
                (t.light.intensity[c] / truth[c] - 1.0).abs() < 0.06,
                "{:?}",
                t.light.intensity
            );
        }
        // One view is not enough; a black image has no bulb.
        assert!(matches!(
            triangulate("lamp", &views[..1]),
            Err(TriangulationError::TooFewViews { got: 1, .. })
        ));
        let black = RadianceImage {
            width: 96,
            height: 96,
            data: vec![0.0; 96 * 96 * 3],
        };
        let mut bad = views.clone();
        bad[1].image = &black;
        let e = triangulate("lamp", &bad).unwrap_err();
        assert!(e.to_string().contains("black"), "{e}");
    }

    /// The same bulb seen small (87 and 5 px) and blurred by a 3×3 box (as
    /// resampling into a rectified view blurs it), on a lit ceiling of
    /// radiance 0.3: against the same views unblurred on black, the
    /// half-maximum area keeps the radius within 5 % and the flux with its
    /// margin keeps the intensity within 0.5 %. (The unblurred small discs
    /// themselves differ from π r² L by their pixelation, a few percent.)
    #[test]
    fn a_small_blurred_bulb_on_a_lit_background_keeps_its_intensity() {
        let centre = Vector3::new(1.0, 1.0, 2.6);
        let radius = 0.05;
        let l = [380.0f32, 350.0, 300.0];
        let cams: Vec<ViewCamera> = [Vector3::new(0.5, 0.5, 1.6), Vector3::new(4.5, 0.5, 1.6)]
            .iter()
            .map(|p| ViewCamera {
                position: *p,
                look: centre - p + Vector3::new(0.03, -0.02, 0.01),
                up: Vector3::z(),
                vfov_rad: 40f64.to_radians(),
                width: 96,
                height: 96,
            })
            .collect();
        let sharp_images: Vec<RadianceImage> = cams.iter().map(|c| bulb_image(c, centre, radius, l)).collect();
        let images: Vec<RadianceImage> = sharp_images
            .iter()
            .map(|sharp| {
                let (w, h) = (sharp.width, sharp.height);
                let mut data = vec![0f32; w * h * 3];
                for y in 1..h - 1 {
                    for x in 1..w - 1 {
                        for ch in 0..3 {
                            let mut s = 0.0;
                            for dy in 0..3 {
                                for dx in 0..3 {
                                    let v = sharp.data[((y + dy - 1) * w + x + dx - 1) * 3 + ch];
                                    s += if v > 0.0 { v } else { 0.3 };
                                }
                            }
                            data[(y * w + x) * 3 + ch] = s / 9.0;
                        }
                    }
                }
                RadianceImage {
                    width: w,
                    height: h,
                    data,
                }
            })
            .collect();
        let views = bulb_views(&cams, &images);
        let t = triangulate("lamp", &views).unwrap();
        let sharp_views = bulb_views(&cams, &sharp_images);
        let sharp = triangulate("lamp", &sharp_views).unwrap();
        let err_mm = (t.light.position - centre).norm() * 1e3;
        let truth = sharp.light.intensity;
        let worst = (0..3)
            .map(|c| (t.light.intensity[c] / truth[c] - 1.0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "blurred: position {err_mm:.2} mm, radius {:.4} m, intensity worst {:.2} %, pixels {:?}",
            t.light.radius,
            100.0 * worst,
            t.sightings.iter().map(|s| s.pixels).collect::<Vec<_>>()
        );
        assert!(err_mm < 5.0, "position off by {err_mm:.2} mm");
        assert!(
            (t.light.radius / radius - 1.0).abs() < 0.05,
            "radius {}",
            t.light.radius
        );
        assert!(worst < 0.005, "intensity {:?} against {truth:?}", t.light.intensity);
    }
}
