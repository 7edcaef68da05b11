//! Coded targets: AprilTags of family tag36h11 found in a photograph by
//! the pure-Rust `kornia-apriltag` crate (no system library), and each
//! tag's bit pattern, from the same crate's code table, for the simulator
//! to paint. A tag's identity is its code, so matching it to the survey
//! needs no search: its four corners pair with the surveyed corners.

use kornia_apriltag::family::{TagFamily, TagFamilyKind};
use kornia_apriltag::{AprilTagDecoder, DecodeTagsConfig};
use kornia_image::{Image, ImageSize};

use super::correspondence::Correspondence;

/// Why tags could not be looked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TagError {
    /// The detector refused the image or its settings.
    #[error("AprilTag detector: {0}")]
    Detector(String),
    /// The image's buffer does not match its size.
    #[error("a {width} × {height} gray image needs {} bytes, got {len}", width * height)]
    Size {
        /// Width, pixels.
        width: usize,
        /// Height, pixels.
        height: usize,
        /// Bytes given.
        len: usize,
    },
}

/// A tag found in a photograph.
#[derive(Debug, Clone, PartialEq)]
pub struct TagDetection {
    /// The tag's id in tag36h11.
    pub id: u32,
    /// The black square's corners in the image, pixels (centres at
    /// half-integers), in the order top-left, top-right, bottom-right,
    /// bottom-left of the tag as printed (the order of
    /// `campanile_config::targets::Target::corners_m`).
    pub corners_px: [(f64, f64); 4],
    /// Bits corrected to reach the code.
    pub hamming: u8,
    /// The decoder's decision margin (higher is surer).
    pub margin: f32,
}

/// Finds tag36h11 tags in 8-bit gray images of one size.
pub struct TagDetector {
    decoder: AprilTagDecoder,
    width: usize,
    height: usize,
}

impl std::fmt::Debug for TagDetector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TagDetector")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl TagDetector {
    /// A detector for `width` × `height` images, with the crate's defaults:
    /// quads are segmented at half resolution, then their edges refined
    /// and the bits decoded at full resolution. (Segmenting at full
    /// resolution found fewer tags in the simulator's noisy photos: 4 of
    /// 7 where half resolution found 6.)
    pub fn new(width: usize, height: usize) -> Result<TagDetector, TagError> {
        let config =
            DecodeTagsConfig::new(vec![TagFamilyKind::Tag36H11]).map_err(|e| TagError::Detector(e.to_string()))?;
        let decoder =
            AprilTagDecoder::new(config, ImageSize { width, height }).map_err(|e| TagError::Detector(e.to_string()))?;
        Ok(TagDetector { decoder, width, height })
    }

    /// The image size this detector takes.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The tags in `gray` (row-major, `width × height` bytes), one per id:
    /// when an id is decoded twice, the one with the larger margin.
    pub fn detect(&mut self, gray: &[u8]) -> Result<Vec<TagDetection>, TagError> {
        if gray.len() != self.width * self.height {
            return Err(TagError::Size {
                width: self.width,
                height: self.height,
                len: gray.len(),
            });
        }
        let image = Image::<u8, 1>::new(
            ImageSize {
                width: self.width,
                height: self.height,
            },
            gray.to_vec(),
        )
        .map_err(|e| TagError::Detector(e.to_string()))?;
        self.decoder.clear();
        let found = self
            .decoder
            .decode(&image)
            .map_err(|e| TagError::Detector(e.to_string()))?;
        let mut out: Vec<TagDetection> = Vec::new();
        for d in found {
            let c = d.quad.corners;
            let corner = |i: usize| (f64::from(c[i].x), f64::from(c[i].y));
            let det = TagDetection {
                id: u32::from(d.id),
                corners_px: CORNER_ORDER.map(corner),
                hamming: d.hamming,
                margin: d.decision_margin,
            };
            if !det.corners_px.iter().all(|(u, v)| u.is_finite() && v.is_finite()) {
                continue;
            }
            match out.iter_mut().find(|o| o.id == det.id) {
                Some(o) if o.margin < det.margin => *o = det,
                Some(_) => {}
                None => out.push(det),
            }
        }
        out.sort_by_key(|d| d.id);
        Ok(out)
    }
}

/// Which of kornia-apriltag's corners is our top-left, top-right,
/// bottom-right, bottom-left: it lists top-right, bottom-right,
/// bottom-left, top-left of the printed tag. Its pixel coordinates, like
/// ours, put pixel centres at half-integers (both checked against
/// projected corners in this module's tests).
const CORNER_ORDER: [usize; 4] = [3, 0, 1, 2];

/// The printed pattern of tag36h11 tag `id`: `total_width` × `total_width`
/// cells, row-major from the top-left, `true` for white: a one-cell white
/// frame, a one-cell black border, and the 6 × 6 code cells (the C
/// library's `apriltag_to_image`). `None` for an id the family lacks.
pub fn tag36h11_cells(id: u32) -> Option<(usize, Vec<bool>)> {
    let family = TagFamily::tag36_h11().ok()?;
    let code = *family.code_data.get(id as usize)?;
    let w = family.total_width;
    let mut cells = vec![false; w * w];
    let white_width = family.width_at_border + if family.reversed_border { 0 } else { 2 };
    let white_start = (w - white_width) / 2;
    for i in 0..white_width {
        for (x, y) in [
            (white_start + i, white_start),
            (white_start + i, white_start + white_width - 1),
            (white_start, white_start + i),
            (white_start + white_width - 1, white_start + i),
        ] {
            cells[y * w + x] = true;
        }
    }
    let border_start = (w - family.width_at_border) / 2;
    for i in 0..family.nbits {
        if code & (1usize << (family.nbits - i - 1)) != 0 {
            let x = family.bit_x[i] as usize + border_start;
            let y = family.bit_y[i] as usize + border_start;
            cells[y * w + x] = true;
        }
    }
    Some((w, cells))
}

/// Cells of the black square's side in tag36h11 (the `size_m` of a target
/// spans this many cells; the white frame adds one on each side).
pub const TAG36H11_BORDER_CELLS: usize = 8;

/// The correspondences of `detections` with the surveyed `targets`: the
/// four corners of every detected tag that the survey lists. Tags the
/// survey lacks are returned apart (their ids), for the report.
pub fn correspondences(
    detections: &[TagDetection],
    targets: &[campanile_config::targets::Target],
) -> (Vec<Correspondence>, Vec<u32>) {
    let mut points = Vec::new();
    let mut unknown = Vec::new();
    for d in detections {
        match targets.iter().find(|t| t.id == d.id) {
            Some(t) => {
                for (pixel, world) in d.corners_px.iter().zip(t.corners_m()) {
                    points.push(Correspondence {
                        target: d.id,
                        pixel: *pixel,
                        world,
                    });
                }
            }
            None => unknown.push(d.id),
        }
    }
    (points, unknown)
}

/// A synthetic photograph of tags for tests: each pixel the mean of 4 × 4
/// samples of the printed pattern (white 230, black 20) on a grey (100)
/// background, seen through `pinhole` at `pose`.
#[cfg(test)]
pub(crate) fn synthetic_photo(
    pinhole: &crate::pose::Pinhole,
    pose: &super::CameraPose,
    targets: &[campanile_config::targets::Target],
    (width, height): (usize, usize),
) -> Vec<u8> {
    use nalgebra::Vector3;
    let patterns: Vec<(usize, Vec<bool>)> = targets
        .iter()
        .map(|t| tag36h11_cells(t.id).expect("a tag36h11 id"))
        .collect();
    let mut out = vec![0u8; width * height];
    let r_inv = pose.rotation.inverse();
    for y in 0..height {
        for x in 0..width {
            let mut sum = 0.0f64;
            for sy in 0..4 {
                for sx in 0..4 {
                    let (u, v) = (x as f64 + (sx as f64 + 0.5) / 4.0, y as f64 + (sy as f64 + 0.5) / 4.0);
                    let d = pinhole.unproject(u, v).expect("inside the lens");
                    let dir = r_inv * Vector3::new(d[0], d[1], d[2]);
                    let mut best = (f64::INFINITY, 100.0);
                    for (t, (w, cells)) in targets.iter().zip(&patterns) {
                        let [r, up, n] = t.axes().map(Vector3::from);
                        let c = Vector3::new(t.centre_m.0, t.centre_m.1, t.centre_m.2);
                        let denom = dir.dot(&n);
                        if denom.abs() < 1e-12 {
                            continue;
                        }
                        let s = (c - pose.centre).dot(&n) / denom;
                        if s <= 0.0 || s >= best.0 {
                            continue;
                        }
                        let p = pose.centre + dir * s - c;
                        let cell = t.size_m / TAG36H11_BORDER_CELLS as f64;
                        let (a, b) = (p.dot(&r) / cell + *w as f64 / 2.0, -p.dot(&up) / cell + *w as f64 / 2.0);
                        // A plate one cell wider than the pattern on each side, white.
                        if a < -1.0 || b < -1.0 || a >= *w as f64 + 1.0 || b >= *w as f64 + 1.0 {
                            continue;
                        }
                        let inside = a >= 0.0 && b >= 0.0 && a < *w as f64 && b < *w as f64;
                        let white = !inside || cells[b as usize * w + a as usize];
                        best = (s, if white { 230.0 } else { 20.0 });
                    }
                    sum += best.1;
                }
            }
            out[y * width + x] = (sum / 16.0).round() as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::Pinhole;
    use crate::registration::CameraPose;
    use campanile_config::targets::Target;
    use nalgebra::Vector3;

    #[test]
    fn tag_zero_has_the_frame_border_and_code_of_the_family() {
        let (w, cells) = tag36h11_cells(0).expect("id 0");
        assert_eq!(w, 10);
        // White frame, black border.
        assert!((0..10).all(|i| cells[i] && cells[90 + i] && cells[i * 10] && cells[i * 10 + 9]));
        assert!((1..9).all(|i| !cells[10 + i] && !cells[80 + i] && !cells[i * 10 + 1] && !cells[i * 10 + 8]));
        // 0x0000000d7e00984b has 17 bits set.
        let data_white = (2..8)
            .flat_map(|y| (2..8).map(move |x| (x, y)))
            .filter(|(x, y)| cells[y * 10 + x])
            .count();
        assert_eq!(data_white, 0x0000_000d_7e00_984b_u64.count_ones() as usize);
        assert!(tag36h11_cells(587).is_none());
    }

    #[test]
    fn detected_corners_land_on_the_projected_survey_corners() {
        let pinhole = Pinhole {
            focal_px: 700.0,
            principal_px: (320.0, 240.0),
            k1: -0.05,
            k2: 0.01,
            projection: campanile_config::camera::Projection::Pinhole,
        };
        // Facing north at a wall 4 m away, turned 20° and rolled 8°.
        let (a, r) = (20f64.to_radians(), 8f64.to_radians());
        let forward = Vector3::new(a.sin(), a.cos(), 0.0);
        let level_right = forward.cross(&Vector3::z()).normalize();
        let level_down = forward.cross(&level_right);
        let right = level_right * r.cos() + level_down * r.sin();
        let pose = CameraPose::from_axes(right, forward.cross(&right), forward, Vector3::new(-1.0, -4.0, 1.5));
        let targets: Vec<Target> = [(5, -0.6, 1.8), (17, 0.2, 1.2), (230, 0.7, 2.0)]
            .into_iter()
            .map(|(id, x, z)| Target {
                id,
                centre_m: (x, 0.0, z),
                normal: (0.0, -1.0, 0.0),
                up: None,
                size_m: 0.3,
            })
            .collect();
        let photo = synthetic_photo(&pinhole, &pose, &targets, (640, 480));
        let mut detector = TagDetector::new(640, 480).expect("detector");
        let found = detector.detect(&photo).expect("detects");
        let ids: Vec<u32> = found.iter().map(|d| d.id).collect();
        assert_eq!(ids, [5, 17, 230]);
        for (d, t) in found.iter().zip(&targets) {
            for (px, w) in d.corners_px.iter().zip(t.corners_m()) {
                let (u, v) = pose.project(&pinhole, &Vector3::from(w)).expect("in view");
                let err = (px.0 - u).hypot(px.1 - v);
                assert!(
                    err < 0.15,
                    "tag {} corner {px:?} vs projected ({u:.2}, {v:.2}): {err:.2} px",
                    t.id
                );
            }
        }
    }
}
