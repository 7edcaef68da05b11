//! §3.5 step 4: the item buffer of a view, the id of the nearest original
//! triangle at each pixel centre, cast with the renderer's hierarchy (the
//! thesis rendered ids with a hardware Z-buffer; one ray per pixel samples
//! the same thing).

use geo::{Distance, Euclidean, Point, Polygon};
use rayon::prelude::*;

use super::fragment::Model;
use super::view::PinholeView;

/// Nearest triangle per pixel, row-major; `u32::MAX` where nothing is hit.
#[derive(Debug, Clone, PartialEq)]
pub struct ItemBuffer {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Ids.
    pub ids: Vec<u32>,
}

/// No triangle at this pixel.
pub const NONE: u32 = u32::MAX;

/// Pixels within this distance (px) of a polygon count as covered by it:
/// conservative scan conversion, so that no occluder is missed at a pixel
/// the polygon only grazes.
pub const CONSERVATIVE_PX: f64 = 0.75;

impl ItemBuffer {
    /// Casts one ray per pixel centre of `view` into `model`.
    pub fn render(model: &Model, view: &PinholeView) -> ItemBuffer {
        let (w, h) = (view.width, view.height);
        let ids = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let ray = view.ray((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
                model
                    .accel
                    .nearest(&model.triangles, &ray, 0.0, f64::INFINITY)
                    .map_or(NONE, |hit| hit.triangle as u32)
            })
            .collect();
        ItemBuffer {
            width: w,
            height: h,
            ids,
        }
    }

    /// The ids at the pixels that image polygon `p` covers conservatively
    /// (§3.5 step 5), sorted and unique.
    pub fn ids_under(&self, p: &Polygon<f64>) -> Vec<u32> {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for c in &p.exterior().0 {
            x0 = x0.min(c.x);
            y0 = y0.min(c.y);
            x1 = x1.max(c.x);
            y1 = y1.max(c.y);
        }
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n.saturating_sub(1));
        let (px0, px1) = (clamp(x0 - 1.0, self.width), clamp(x1 + 1.0, self.width));
        let (py0, py1) = (clamp(y0 - 1.0, self.height), clamp(y1 + 1.0, self.height));
        let mut out = Vec::new();
        for py in py0..=py1 {
            for px in px0..=px1 {
                let id = self.ids[py * self.width + px];
                if id == NONE || out.contains(&id) {
                    continue;
                }
                let centre = Point::new(px as f64 + 0.5, py as f64 + 0.5);
                if Euclidean.distance(&centre, p) <= CONSERVATIVE_PX {
                    out.push(id);
                }
            }
        }
        out.sort_unstable();
        out
    }
}
