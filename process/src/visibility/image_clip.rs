//! Polygon operations shared by the two algorithms: half-plane and
//! image-rectangle clipping, unions, areas and interior points, on the
//! `geo` crate's f64 Boolean operations.

use geo::{Area, BooleanOps, Coord, InteriorPoint, LineString, MultiPolygon, Polygon};

/// Pieces smaller than this fraction of the polygon they were cut from
/// are rounding slivers of a Boolean operation, and dropped. (The `geo`
/// crate's Boolean operations snap to an integer grid of about 1e-8 of the
/// operands' extent, so a cut can leave slivers of that width.)
pub const SLIVER: f64 = 1e-7;

/// Whether area `a` is a sliver of a polygon of area `subject`.
pub fn negligible(a: f64, subject: f64) -> bool {
    a <= SLIVER * subject
}

/// The part of `p` where `a x + b y + c ≥ 0`, and the rest.
pub fn split_half_plane(p: &Polygon<f64>, [a, b, c]: [f64; 3]) -> (MultiPolygon<f64>, MultiPolygon<f64>) {
    let side = |q: &Coord<f64>| a * q.x + b * q.y + c;
    let ext = &p.exterior().0;
    if ext.iter().all(|q| side(q) >= 0.0) {
        return (MultiPolygon(vec![p.clone()]), MultiPolygon(vec![]));
    }
    if ext.iter().all(|q| side(q) <= 0.0) {
        return (MultiPolygon(vec![]), MultiPolygon(vec![p.clone()]));
    }
    // The half-plane within the polygon's bounding box (enlarged), clipped
    // Sutherland–Hodgman style: a convex polygon.
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for q in ext {
        x0 = x0.min(q.x);
        y0 = y0.min(q.y);
        x1 = x1.max(q.x);
        y1 = y1.max(q.y);
    }
    let m = 1.0 + (x1 - x0).max(y1 - y0);
    let boxed = [
        Coord { x: x0 - m, y: y0 - m },
        Coord { x: x1 + m, y: y0 - m },
        Coord { x: x1 + m, y: y1 + m },
        Coord { x: x0 - m, y: y1 + m },
    ];
    let mut half = Vec::new();
    for i in 0..4 {
        let (p0, p1) = (boxed[i], boxed[(i + 1) % 4]);
        let (s0, s1) = (side(&p0), side(&p1));
        if s0 >= 0.0 {
            half.push(p0);
        }
        if (s0 >= 0.0) != (s1 >= 0.0) {
            let t = s0 / (s0 - s1);
            half.push(Coord {
                x: p0.x + t * (p1.x - p0.x),
                y: p0.y + t * (p1.y - p0.y),
            });
        }
    }
    let half = Polygon::new(LineString::from(half), vec![]);
    let a = p.unsigned_area();
    (clean(p.intersection(&half), a), clean(p.difference(&half), a))
}

/// `m`, cut from a polygon of area `subject`, without its slivers.
pub fn clean(m: MultiPolygon<f64>, subject: f64) -> MultiPolygon<f64> {
    MultiPolygon(
        m.0.into_iter()
            .filter(|p| !negligible(p.unsigned_area(), subject))
            .collect(),
    )
}

/// Area of `m`.
pub fn area(m: &MultiPolygon<f64>) -> f64 {
    m.0.iter().map(|p| p.unsigned_area()).sum()
}

/// A point strictly inside `p` (not its centroid, which a concave polygon
/// may not contain).
pub fn interior_point(p: &Polygon<f64>) -> Option<[f64; 2]> {
    p.interior_point().map(|q| [q.x(), q.y()])
}

/// The union of `polys`.
pub fn union_all(polys: &[Polygon<f64>]) -> MultiPolygon<f64> {
    let mut acc = MultiPolygon(vec![]);
    for p in polys {
        acc = if acc.0.is_empty() {
            MultiPolygon(vec![p.clone()])
        } else {
            acc.union(p)
        };
    }
    let total = polys.iter().map(|p| p.unsigned_area()).sum();
    clean(acc, total)
}

/// Whether the bounding boxes of `a` and `b` overlap (a cheap test before a
/// Boolean operation).
pub fn boxes_overlap(a: &Polygon<f64>, b: &Polygon<f64>) -> bool {
    use geo::BoundingRect;
    match (a.bounding_rect(), b.bounding_rect()) {
        (Some(p), Some(q)) => {
            p.min().x < q.max().x && q.min().x < p.max().x && p.min().y < q.max().y && q.min().y < p.max().y
        }
        _ => false,
    }
}
