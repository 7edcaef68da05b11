//! A picture of a segmentation, for the report page: every point in its
//! group's colour ([`crate::segmentation_ply::group_colour`]), unassigned
//! points grey, no return black.
//!
//! An organised scan is drawn as its own range image (row 0 at the top,
//! column 0 at the left), which is how the scanner saw it and how the
//! thesis shows its segmentations (Figs. 2.3–2.5). An unorganised cloud is
//! drawn from above (x to the right, y up the page), each point a pixel,
//! the highest point of a pixel winning.

use image::{Rgb, RgbImage};
use nalgebra::Vector3;

use crate::cloud::Scan;
use crate::segmentation::UNASSIGNED;
use crate::segmentation_ply::group_colour;

/// Colour of an unassigned point.
const UNASSIGNED_COLOUR: [u8; 3] = [128, 128, 128];
/// Longest side of a view of an unorganised cloud, pixels.
const MAX_SIDE: u32 = 1024;

fn colour(label: u32) -> Rgb<u8> {
    Rgb(if label == UNASSIGNED {
        UNASSIGNED_COLOUR
    } else {
        group_colour(label)
    })
}

/// The view of `scan` with each point's group `labels` (one per point).
/// `None` for an empty scan or when `labels` does not match the scan.
pub fn group_view(scan: &Scan, labels: &[u32]) -> Option<RgbImage> {
    if scan.is_empty() || labels.len() != scan.len() {
        return None;
    }
    if let Some(grid) = &scan.grid {
        let mut img = RgbImage::new(grid.cols as u32, grid.rows as u32);
        for row in 0..grid.rows {
            for col in 0..grid.cols {
                if let Some(p) = grid.point_at(row, col) {
                    img.put_pixel(col as u32, row as u32, colour(labels[p]));
                }
            }
        }
        return Some(img);
    }
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for p in &scan.positions {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let span = (hi.x - lo.x).max(hi.y - lo.y).max(1e-9);
    let scale = f64::from(MAX_SIDE - 1) / span;
    let w = ((hi.x - lo.x) * scale) as u32 + 1;
    let h = ((hi.y - lo.y) * scale) as u32 + 1;
    let mut img = RgbImage::new(w, h);
    let mut top = vec![f64::NEG_INFINITY; (w * h) as usize];
    for (p, &label) in scan.positions.iter().zip(labels) {
        let x = ((p.x - lo.x) * scale) as u32;
        let y = h - 1 - ((p.y - lo.y) * scale) as u32;
        let i = (y * w + x) as usize;
        if p.z > top[i] {
            top[i] = p.z;
            img.put_pixel(x, y, colour(label));
        }
    }
    Some(img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::{NO_RETURN, RangeGrid};

    #[test]
    fn an_organised_scan_is_drawn_as_its_grid() {
        let mut scan = Scan::from_positions("s", vec![Vector3::zeros(), Vector3::x(), Vector3::y()]);
        scan.grid = Some(RangeGrid {
            rows: 2,
            cols: 2,
            cells: vec![0, NO_RETURN, 1, 2],
        });
        let img = group_view(&scan, &[0, 1, UNASSIGNED]).unwrap();
        assert_eq!(img.dimensions(), (2, 2));
        assert_eq!(img.get_pixel(0, 0).0, group_colour(0));
        assert_eq!(img.get_pixel(1, 0).0, [0, 0, 0]);
        assert_eq!(img.get_pixel(0, 1).0, group_colour(1));
        assert_eq!(img.get_pixel(1, 1).0, UNASSIGNED_COLOUR);
        assert!(group_view(&scan, &[0, 1]).is_none());
    }

    #[test]
    fn an_unorganised_cloud_is_drawn_from_above_highest_point_first() {
        // Two points over one pixel (the lower one later), one at the far corner.
        let scan = Scan::from_positions(
            "s",
            vec![
                Vector3::new(0.0, 0.0, 1.0),
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(2.0, 1.0, 0.0),
            ],
        );
        let img = group_view(&scan, &[3, 4, 5]).unwrap();
        // 2 m by 1 m at 1023 px per 2 m: 511.5 px, so rows 0..=511.
        assert_eq!(img.dimensions(), (MAX_SIDE, 512));
        // (0, 0) is the bottom-left pixel: the higher point's group.
        assert_eq!(img.get_pixel(0, img.height() - 1).0, group_colour(3));
        assert_eq!(img.get_pixel(MAX_SIDE - 1, 0).0, group_colour(5));
    }
}
