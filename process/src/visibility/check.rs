//! The accuracy check of a fragmentation: brute-force ray casting at four
//! sub-pixel points per pixel (at the quarter points, not the item buffer's
//! pixel centres), walking each ray through every surface it crosses. The
//! first surface is visible and every later one hidden; a fragment whose
//! label disagrees at the point is misclassified there.

use geo::{Intersects, Point};
use rayon::prelude::*;

use super::fragment::{Fragment, Model};
use super::view::PinholeView;

/// Counts of ray–surface points, per view or in total.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Misclassification {
    /// Surface points checked (every crossing of every ray).
    pub points: usize,
    /// Points whose fragment's label is wrong.
    pub wrong: usize,
    /// Of those, points on fragments left whole below the size threshold.
    pub wrong_in_mixed: usize,
    /// Points in no fragment (rounding slivers dropped by clipping).
    pub unlocated: usize,
}

impl Misclassification {
    /// Misclassified fraction of the points (0 when there are none).
    pub fn fraction(&self) -> f64 {
        if self.points == 0 {
            0.0
        } else {
            self.wrong as f64 / self.points as f64
        }
    }

    fn add(mut self, o: Misclassification) -> Misclassification {
        self.points += o.points;
        self.wrong += o.wrong;
        self.wrong_in_mixed += o.wrong_in_mixed;
        self.unlocated += o.unlocated;
        self
    }
}

/// Most surfaces one ray is followed through.
const MAX_CROSSINGS: usize = 64;

/// Checks `fragments` against ray casting in each of `views`; one entry per view.
pub fn misclassified(model: &Model, fragments: &[Fragment], views: &[PinholeView]) -> Vec<Misclassification> {
    let mut by_triangle: Vec<Vec<usize>> = vec![Vec::new(); model.triangles.len()];
    for (i, f) in fragments.iter().enumerate() {
        by_triangle[f.triangle].push(i);
    }
    views
        .iter()
        .enumerate()
        .map(|(vi, view)| {
            (0..view.width * view.height * 4)
                .into_par_iter()
                .map(|s| {
                    let (pixel, sub) = (s / 4, s % 4);
                    let x = (pixel % view.width) as f64 + 0.25 + 0.5 * (sub % 2) as f64;
                    let y = (pixel / view.width) as f64 + 0.25 + 0.5 * (sub / 2) as f64;
                    check_ray(model, fragments, &by_triangle, vi, view, x, y)
                })
                .reduce(Misclassification::default, Misclassification::add)
        })
        .collect()
}

fn check_ray(
    model: &Model,
    fragments: &[Fragment],
    by_triangle: &[Vec<usize>],
    vi: usize,
    view: &PinholeView,
    x: f64,
    y: f64,
) -> Misclassification {
    let mut m = Misclassification::default();
    let ray = view.ray(x, y);
    let mut t_min = 0.0;
    for crossing in 0..MAX_CROSSINGS {
        let Some(hit) = model.accel.nearest(&model.triangles, &ray, t_min, f64::INFINITY) else {
            break;
        };
        t_min = hit.t + 1e-9 * (1.0 + hit.t);
        let frame = &model.frames[hit.triangle];
        let c = frame.local(&(ray.origin + ray.direction * hit.t));
        let point = Point::new(c.x, c.y);
        m.points += 1;
        let expected = crossing == 0 && model.front_facing(hit.triangle, view);
        match by_triangle[hit.triangle]
            .iter()
            .find(|&&i| fragments[i].shape.intersects(&point))
        {
            None => m.unlocated += 1,
            Some(&i) if fragments[i].visible[vi] != expected => {
                m.wrong += 1;
                if fragments[i].mixed {
                    m.wrong_in_mixed += 1;
                }
            }
            Some(_) => {}
        }
    }
    m
}

/// The sum over views.
pub fn total(per_view: &[Misclassification]) -> Misclassification {
    per_view
        .iter()
        .copied()
        .fold(Misclassification::default(), Misclassification::add)
}
