//! The thesis's hybrid visibility algorithm (§3.5): image-space candidate
//! occluders from an item buffer, object-space confirmation and clipping,
//! shallow clipping and a size threshold.

use geo::{Area, BooleanOps, Polygon};

use super::fragment::{Fragment, Model};
use super::image_clip::{area, boxes_overlap, clean, interior_point, negligible, union_all};
use super::item_buffer::ItemBuffer;
use super::view::PinholeView;
use super::{Fragmentation, VisibilityError};

/// Whether original triangle `a` (image polygon `a_img`) occludes part of
/// fragment image `b_img` of triangle `b` in `view`: their images overlap
/// and, at an interior point of the overlap, `a` is nearer.
pub fn occludes(
    model: &Model,
    view: &PinholeView,
    a: usize,
    a_img: &Polygon<f64>,
    b: usize,
    b_img: &Polygon<f64>,
) -> bool {
    if !boxes_overlap(a_img, b_img) {
        return false;
    }
    let overlap = clean(
        b_img.intersection(a_img),
        b_img.unsigned_area().min(a_img.unsigned_area()),
    );
    let Some(largest) = overlap
        .0
        .iter()
        .max_by(|p, q| p.unsigned_area().total_cmp(&q.unsigned_area()))
    else {
        return false;
    };
    let Some(xy) = interior_point(largest) else {
        return false;
    };
    match (
        model.frames[a].ray_distance(view, xy),
        model.frames[b].ray_distance(view, xy),
    ) {
        (Some(ta), Some(tb)) => ta < tb * (1.0 - 1e-9),
        _ => false,
    }
}

/// Fragments of `model` each wholly visible or hidden in every one of
/// `views`; pieces of area below `threshold_m2` are not subdivided.
pub fn hybrid(model: &Model, views: &[PinholeView], threshold_m2: f64) -> Result<Fragmentation, VisibilityError> {
    if !(threshold_m2.is_finite() && threshold_m2 >= 0.0) {
        return Err(VisibilityError::BadThreshold(threshold_m2));
    }
    let mut frags = model.whole_fragments(views.len());
    let (mut clips, mut small_mixed) = (0, 0);
    for (vi, view) in views.iter().enumerate() {
        let buffer = ItemBuffer::render(model, view);
        let occluder: Vec<Option<Polygon<f64>>> = (0..model.triangles.len())
            .map(|t| model.occluder_image(t, view))
            .collect();
        let mut next = Vec::with_capacity(frags.len());
        for frag in frags {
            let (inside, outside) = model.split_by_frustum(frag, view);
            next.extend(outside);
            for (mut g, img) in inside {
                let occluders: Vec<Polygon<f64>> = buffer
                    .ids_under(&img)
                    .into_iter()
                    .map(|a| a as usize)
                    .filter(|&a| a != g.triangle)
                    .filter_map(|a| {
                        let a_img = occluder[a].as_ref()?;
                        occludes(model, view, a, a_img, g.triangle, &img).then(|| a_img.clone())
                    })
                    .collect();
                if occluders.is_empty() {
                    g.visible[vi] = true;
                    next.push(g);
                    continue;
                }
                clips += 1;
                let union = union_all(&occluders);
                let img_area = img.unsigned_area();
                let hidden = clean(img.intersection(&union), img_area);
                let seen = clean(img.difference(&union), img_area);
                let (ah, av) = (area(&hidden), area(&seen));
                if negligible(ah, img_area) || negligible(av, img_area) {
                    // Wholly visible or wholly hidden: left intact (shallow clipping).
                    g.visible[vi] = negligible(ah, img_area);
                    next.push(g);
                } else if g.area() < threshold_m2 {
                    g.visible[vi] = av >= ah;
                    g.mixed = true;
                    small_mixed += 1;
                    next.push(g);
                } else {
                    let frame = &model.frames[g.triangle];
                    for (pieces, label) in [(seen, true), (hidden, false)] {
                        for p in pieces.0 {
                            if let Some(shape) = frame.from_image(view, &p) {
                                let mut visible = g.visible.clone();
                                visible[vi] = label;
                                next.push(Fragment {
                                    triangle: g.triangle,
                                    shape,
                                    visible,
                                    mixed: g.mixed,
                                });
                            }
                        }
                    }
                }
            }
        }
        frags = next;
    }
    Ok(Fragmentation {
        fragments: frags,
        clips,
        small_mixed,
    })
}
