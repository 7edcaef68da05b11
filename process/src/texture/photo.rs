//! A registered photograph: its radiance and the camera that took it.

use nalgebra::Vector3;

use super::TextureError;
use crate::camera::image::RadianceImage;
use crate::pose::Pinhole;
use crate::registration::CameraPose;
use crate::render::CameraRig;

/// One photograph to texture from.
#[derive(Debug, Clone)]
pub struct TexturePhoto {
    /// A name for reports (the pose's name).
    pub label: String,
    /// Linear radiance, W·m⁻²·sr⁻¹ per channel (or relative units, the
    /// same for every photo).
    pub image: RadianceImage,
    /// The camera: intrinsics with distortion, orientation and position.
    pub rig: CameraRig,
}

impl TexturePhoto {
    /// A photograph taken from `pose` through `pinhole` (for the image's size).
    pub fn new(label: &str, image: RadianceImage, pose: &CameraPose, pinhole: Pinhole) -> Result<Self, TextureError> {
        let bad = |what: String| TextureError::BadPhoto {
            photo: label.to_string(),
            what,
        };
        if image.width == 0 || image.height == 0 || image.data.len() != image.width * image.height * 3 {
            return Err(bad(format!(
                "{} × {} image holds {} values, expected width · height · 3 > 0",
                image.width,
                image.height,
                image.data.len()
            )));
        }
        let m = pose.rotation.matrix();
        let (down, forward) = (m.row(1).transpose(), m.row(2).transpose());
        let mut rig = CameraRig::look_at(pose.centre, forward, -down, 1.0, image.width, image.height)
            .ok_or_else(|| bad(format!("degenerate camera orientation {:?}", pose.rotation)))?;
        rig.pinhole = pinhole;
        Ok(TexturePhoto {
            label: label.to_string(),
            image,
            rig,
        })
    }

    /// Bilinear radiance at image point `(u, v)` (pixel centres at half
    /// integers), or `None` outside the pixel centres' hull or at a
    /// non-finite or negative value.
    pub fn sample(&self, u: f64, v: f64) -> Option<[f64; 3]> {
        self.sample_where(u, v, &|_| true)
    }

    /// [`TexturePhoto::sample`], or `None` when any of the four pixels it
    /// interpolates (row-major index) fails `accept`.
    pub fn sample_where(&self, u: f64, v: f64, accept: &dyn Fn(usize) -> bool) -> Option<[f64; 3]> {
        let (w, h) = (self.image.width, self.image.height);
        let (x, y) = (u - 0.5, v - 0.5);
        if !(x >= 0.0 && y >= 0.0 && x <= (w - 1) as f64 && y <= (h - 1) as f64) {
            return None;
        }
        let (x0, y0) = (
            (x.floor() as usize).min(w.saturating_sub(2)),
            (y.floor() as usize).min(h.saturating_sub(2)),
        );
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        if ![(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            .iter()
            .all(|&(xx, yy)| accept(yy * w + xx))
        {
            return None;
        }
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let at = |xx: usize, yy: usize| f64::from(self.image.data[(yy * w + xx) * 3 + c]);
            let (a, b, cc, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
            if !(a.is_finite() && b.is_finite() && cc.is_finite() && d.is_finite()) || a.min(b).min(cc).min(d) < 0.0 {
                return None;
            }
            *o = (a * (1.0 - fx) + b * fx) * (1.0 - fy) + (cc * (1.0 - fx) + d * fx) * fy;
        }
        Some(out)
    }
}

/// The pose at `position` whose optical axis has azimuth `azimuth_deg`
/// (from north through east) and elevation `elevation_deg`, rolled
/// `roll_deg` about the axis (as [`CameraPose::roll_deg`] measures it: the
/// form of a scene file's `poses` plus `campanile register`'s roll).
/// `None` for a vertical axis with a roll (no level reference).
pub fn pose_from_angles(
    position: Vector3<f64>,
    azimuth_deg: f64,
    elevation_deg: f64,
    roll_deg: f64,
) -> Option<CameraPose> {
    // Straight up or down the level right vector (the axis × up) vanishes.
    (elevation_deg.to_radians().cos() > 1e-9)
        .then(|| CameraPose::from_angles(azimuth_deg, elevation_deg, roll_deg, position))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pose from angles gives back its angles, and the photo's rig
    /// projects world points where the pose and the pinhole do.
    #[test]
    fn angles_round_trip_and_the_rig_projects_like_the_pose() {
        let pose = pose_from_angles(Vector3::new(1.0, -2.0, 1.5), 35.0, 12.0, -7.0).unwrap();
        assert!((pose.azimuth_deg() - 35.0).abs() < 1e-9);
        assert!((pose.elevation_deg() - 12.0).abs() < 1e-9);
        assert!((pose.roll_deg() + 7.0).abs() < 1e-9);
        let pinhole = Pinhole {
            focal_px: 300.0,
            principal_px: (161.0, 118.0),
            k1: -0.05,
            k2: 0.01,
            projection: crate::pose::Projection::Pinhole,
        };
        let image = RadianceImage {
            width: 320,
            height: 240,
            data: vec![1.0; 320 * 240 * 3],
        };
        let photo = TexturePhoto::new("p", image, &pose, pinhole).unwrap();
        for p in [Vector3::new(5.0, 4.0, 2.5), Vector3::new(2.0, 6.0, 0.0)] {
            let a = pose.project(&pinhole, &p).unwrap();
            let b = photo.rig.project(&p).unwrap();
            assert!((a.0 - b.0).abs() < 1e-8 && (a.1 - b.1).abs() < 1e-8, "{a:?} {b:?}");
        }
        // Bilinear sampling inside; none outside the pixel centres.
        assert_eq!(photo.sample(10.0, 10.0), Some([1.0; 3]));
        assert_eq!(photo.sample(0.2, 10.0), None);
        assert!(pose_from_angles(Vector3::zeros(), 0.0, 90.0, 0.0).is_none());
    }
}
