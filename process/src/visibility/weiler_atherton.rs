//! The comparison algorithm of Tables 3.2–3.3: Weiler–Atherton hidden
//! surface removal by polygon area sorting, applied at each view in turn to
//! the previous view's output (§3.5).
//!
//! At a view, the front-most remaining polygon (nearest vertex depth; if a
//! polygon it overlaps is in front of it at an interior point of the
//! overlap, that one instead, as in Weiler and Atherton's recursive step)
//! is visible, and clips every remaining polygon its image overlaps into
//! the part inside its image (hidden) and the parts outside (still in the
//! running) — *deep clipping*: polygons already hidden by another are cut
//! again. Back-facing triangles (an open model's panels seen from behind)
//! clip what is behind them but are not output at that view. Pieces below the size threshold are not cut; they are labelled by
//! their larger part.

use geo::{Area, BooleanOps, Polygon};

use super::fragment::{Fragment, Model};
use super::hybrid::occludes;
use super::image_clip::{area, clean, negligible};
use super::view::PinholeView;
use super::{Fragmentation, VisibilityError};

/// A polygon still in the running at a view: a fragment, or a back-facing
/// triangle that only hides (`fragment: None`).
struct Entry {
    triangle: usize,
    fragment: Option<Fragment>,
    image: Polygon<f64>,
    depth: f64,
}

fn nearest_depth(model: &Model, view: &PinholeView, f: &Fragment) -> f64 {
    let frame = &model.frames[f.triangle];
    f.shape
        .exterior()
        .0
        .iter()
        .map(|c| view.camera(&frame.world(*c)).z)
        .fold(f64::INFINITY, f64::min)
}

/// Fragments of `model` each wholly visible or hidden in every one of
/// `views`, by repeated Weiler–Atherton; pieces below `threshold_m2` are not
/// subdivided.
pub fn weiler_atherton(
    model: &Model,
    views: &[PinholeView],
    threshold_m2: f64,
) -> Result<Fragmentation, VisibilityError> {
    if !(threshold_m2.is_finite() && threshold_m2 >= 0.0) {
        return Err(VisibilityError::BadThreshold(threshold_m2));
    }
    let mut frags = model.whole_fragments(views.len());
    let (mut clips, mut small_mixed) = (0, 0);
    for (vi, view) in views.iter().enumerate() {
        let mut next = Vec::with_capacity(frags.len());
        let mut active: Vec<Entry> = Vec::new();
        for frag in frags {
            let (inside, outside) = model.split_by_frustum(frag, view);
            next.extend(outside);
            for (g, img) in inside {
                let depth = nearest_depth(model, view, &g);
                active.push(Entry {
                    triangle: g.triangle,
                    fragment: Some(g),
                    image: img,
                    depth,
                });
            }
        }
        // Back-facing triangles of an open model (a board seen from behind)
        // hide what is behind them: they clip, but are not output here.
        for t in (0..model.triangles.len()).filter(|&t| !model.front_facing(t, view)) {
            if let Some(image) = model.occluder_image(t, view) {
                let depth = image
                    .exterior()
                    .0
                    .iter()
                    .filter_map(|c| model.frames[t].ray_distance(view, [c.x, c.y]))
                    .fold(f64::INFINITY, f64::min);
                active.push(Entry {
                    triangle: t,
                    fragment: None,
                    image,
                    depth,
                });
            }
        }
        while !active.is_empty() {
            let mut i = (0..active.len())
                .min_by(|&a, &b| active[a].depth.total_cmp(&active[b].depth))
                .expect("non-empty");
            // Weiler–Atherton's recursion: a polygon in front of the chosen
            // one (over their overlap) becomes the clip polygon instead.
            let mut tried = vec![i];
            while let Some(j) = (0..active.len()).find(|&j| {
                !tried.contains(&j)
                    && occludes(
                        model,
                        view,
                        active[j].triangle,
                        &active[j].image,
                        active[i].triangle,
                        &active[i].image,
                    )
            }) {
                i = j;
                tried.push(j);
            }
            let p = active.swap_remove(i);
            if let Some(mut f) = p.fragment {
                f.visible[vi] = true;
                next.push(f);
            }
            let mut remaining = Vec::with_capacity(active.len());
            for q in active.drain(..) {
                let Some(mut g) = q.fragment else {
                    remaining.push(q);
                    continue;
                };
                if !occludes(model, view, p.triangle, &p.image, q.triangle, &q.image) {
                    remaining.push(Entry { fragment: Some(g), ..q });
                    continue;
                }
                clips += 1;
                let q_area = q.image.unsigned_area();
                let inner = clean(q.image.intersection(&p.image), q_area);
                let outer = clean(q.image.difference(&p.image), q_area);
                let (ai, ao) = (area(&inner), area(&outer));
                if negligible(ao, q_area) {
                    g.visible[vi] = false;
                    next.push(g);
                } else if g.area() < threshold_m2 {
                    if !g.mixed {
                        small_mixed += 1;
                    }
                    g.mixed = true;
                    if ai >= ao {
                        g.visible[vi] = false;
                        next.push(g);
                    } else {
                        remaining.push(Entry { fragment: Some(g), ..q });
                    }
                } else {
                    let frame = &model.frames[q.triangle];
                    for piece in inner.0 {
                        if let Some(shape) = frame.from_image(view, &piece) {
                            let mut visible = g.visible.clone();
                            visible[vi] = false;
                            next.push(Fragment {
                                triangle: q.triangle,
                                shape,
                                visible,
                                mixed: g.mixed,
                            });
                        }
                    }
                    for piece in outer.0 {
                        if let Some(shape) = frame.from_image(view, &piece) {
                            let f = Fragment {
                                triangle: q.triangle,
                                shape,
                                visible: g.visible.clone(),
                                mixed: g.mixed,
                            };
                            let depth = nearest_depth(model, view, &f);
                            remaining.push(Entry {
                                triangle: q.triangle,
                                fragment: Some(f),
                                image: piece,
                                depth,
                            });
                        }
                    }
                }
            }
            active = remaining;
        }
        frags = next;
    }
    Ok(Fragmentation {
        fragments: frags,
        clips,
        small_mixed,
    })
}
