//! The photographs of `campanile outdoor recover|render` (README:
//! "Outdoor files"): calibrated cameras, as the IGI scene file gives them
//! (position, look, up and a field of view, or a RADIANCE view string), and
//! photos, each one camera at one time with an HDR radiance image (OpenEXR,
//! RADIANCE RGBE, PFM) and an optional 8-bit PNG mask. Paths are relative
//! to the file. For `outdoor render`, a photo without an image is a view to
//! render; with one, the render is compared with it.
//!
//! ```ron
//! OutdoorPhotos(
//!     cameras: [
//!         (name: "south", radiance_view: "-vtv -vp 0 -30 1.6 -vd 0 1 0.25 -vu 0 0 1 -vh 60 -vv 41.6",
//!          width: 96, height: 64),
//!         (name: "east", position_m: (30.0, 0.0, 1.6), look: (-1.0, 0.0, 0.2), up: (0.0, 0.0, 1.0),
//!          vfov_deg: 40.0, width: 96, height: 64),
//!     ],
//!     photos: [
//!         (camera: "south", time: "2026-06-21T08:00:00Z", image: "south-0800.hdr"),
//!         (camera: "east", time: "2026-06-21T08:00:00Z", image: "east-0800.exr", mask: "east-mask.png"),
//!     ],
//! )
//! ```

use std::path::{Path, PathBuf};

use chrono::{DateTime, Utc};
use serde::Deserialize;

use super::photo::Photo;
use crate::camera::image::RadianceImage;
use crate::igi::scene_file::{CameraEntry, SceneFileError, read_mask, read_ron_file, view_camera};
use crate::radiance_file::read_radiance_image;
use crate::render::CameraRig;

/// One photograph.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhotoEntry {
    /// The camera that took it (a name in `cameras`).
    pub camera: String,
    /// When, UTC (RFC 3339, e.g. `"2026-06-21T08:00:00Z"`).
    pub time: DateTime<Utc>,
    /// The HDR radiance image, W·m⁻²·sr⁻¹ per channel.
    #[serde(default)]
    pub image: Option<PathBuf>,
    /// An 8-bit PNG mask of the image's size: non-zero pixels are used.
    #[serde(default)]
    pub mask: Option<PathBuf>,
}

/// The file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutdoorPhotos {
    /// Cameras.
    pub cameras: Vec<CameraEntry>,
    /// Photographs.
    pub photos: Vec<PhotoEntry>,
}

/// A photo entry, read: its camera as a rig, and its image if it has one.
#[derive(Debug, Clone)]
pub struct PosedView {
    /// `camera@time`, for diagnostics and file names.
    pub label: String,
    /// The camera's name.
    pub camera: String,
    /// The camera.
    pub rig: CameraRig,
    /// When.
    pub time: DateTime<Utc>,
    /// The radiance image, if given.
    pub image: Option<RadianceImage>,
    /// Valid pixels: the mask's non-zero pixels that hold finite,
    /// non-negative radiance in every channel.
    pub mask: Option<Vec<bool>>,
    /// Pixels of the image with a non-finite or negative channel (left out).
    pub bad_pixels: usize,
}

impl PosedView {
    /// The solver's photo; `None` without an image.
    pub fn photo(&self) -> Option<Photo> {
        Some(Photo {
            label: self.label.clone(),
            image: self.image.clone()?,
            rig: self.rig,
            time: self.time,
            mask: self.mask.clone(),
        })
    }
}

/// Reads the photographs file at `path`, its cameras and images.
pub fn load_photos(path: &Path) -> Result<Vec<PosedView>, SceneFileError> {
    let file: OutdoorPhotos = read_ron_file(path, "the OutdoorPhotos format of the README, \"Outdoor files\"")?;
    let base = path.parent().unwrap_or(Path::new("."));
    let field = |field: String, value: String, expected: &str| SceneFileError::Field {
        path: path.to_path_buf(),
        field,
        value,
        expected: expected.to_string(),
    };
    if file.photos.is_empty() {
        return Err(field("photos".into(), "[]".into(), "at least one photo"));
    }
    let mut cameras: Vec<(String, CameraRig)> = Vec::new();
    for (i, c) in file.cameras.iter().enumerate() {
        if cameras.iter().any(|(n, _)| n == &c.name) {
            return Err(field(
                format!("cameras[{i}].name"),
                format!("{:?}", c.name),
                "a name no other camera has",
            ));
        }
        let first_image = file
            .photos
            .iter()
            .filter(|p| p.camera == c.name)
            .find_map(|p| p.image.as_ref())
            .map(|f| base.join(f));
        let view = view_camera(path, &format!("cameras[{i}]"), c, first_image.as_deref())?;
        let rig = CameraRig::look_at(
            view.position,
            view.look,
            view.up,
            view.vfov_rad,
            view.width,
            view.height,
        )
        .ok_or_else(|| {
            field(
                format!("cameras[{i}]"),
                format!("{:?}", c.name),
                "a camera with a non-zero look direction and an up hint not parallel to it",
            )
        })?;
        cameras.push((c.name.clone(), rig));
    }
    let mut views = Vec::new();
    for (i, p) in file.photos.iter().enumerate() {
        let rig = cameras
            .iter()
            .find(|(n, _)| n == &p.camera)
            .map(|(_, r)| *r)
            .ok_or_else(|| {
                field(
                    format!("photos[{i}].camera"),
                    format!("{:?}", p.camera),
                    &format!(
                        "a camera named in cameras (there are: {})",
                        cameras.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ")
                    ),
                )
            })?;
        let label = format!("{}@{}", p.camera, p.time.format("%Y-%m-%dT%H:%M:%SZ"));
        if views.iter().any(|v: &PosedView| v.label == label) {
            return Err(field(
                format!("photos[{i}]"),
                label,
                "one photo per camera and time (this camera has another at this time)",
            ));
        }
        let image = match &p.image {
            None => None,
            Some(f) => {
                let full = base.join(f);
                let img = read_radiance_image(&full)
                    .map_err(|e| SceneFileError::File {
                        path: full.clone(),
                        message: e.message,
                    })?
                    .image;
                if img.width != rig.width || img.height != rig.height {
                    return Err(field(
                        format!("photos[{i}].image"),
                        format!("{} ({}x{})", full.display(), img.width, img.height),
                        &format!("an image of the camera's size {}x{}", rig.width, rig.height),
                    ));
                }
                Some(img)
            }
        };
        let given_mask = match &p.mask {
            None => None,
            Some(_) if image.is_none() => {
                return Err(field(
                    format!("photos[{i}].mask"),
                    "given".into(),
                    "no mask without an image (a mask selects the image's pixels)",
                ));
            }
            Some(m) => Some(read_mask(
                path,
                format!("photos[{i}].mask"),
                &base.join(m),
                rig.width,
                rig.height,
            )?),
        };
        let (mask, bad_pixels) = match &image {
            None => (None, 0),
            Some(img) => {
                let good: Vec<bool> = img
                    .data
                    .chunks_exact(3)
                    .map(|px| px.iter().all(|v| v.is_finite() && *v >= 0.0))
                    .collect();
                let bad = good.iter().filter(|g| !**g).count();
                match given_mask {
                    Some(m) => (Some(m.iter().zip(&good).map(|(a, b)| *a && *b).collect()), bad),
                    None if bad > 0 => (Some(good), bad),
                    None => (None, 0),
                }
            }
        };
        views.push(PosedView {
            label,
            camera: p.camera.clone(),
            rig,
            time: p.time,
            image,
            mask,
            bad_pixels,
        });
    }
    Ok(views)
}
