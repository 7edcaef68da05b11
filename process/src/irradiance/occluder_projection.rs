//! Occluders projected onto the sphere of directions, Appendix B: the part
//! of a sky patch that the scene leaves open, exactly.
//!
//! Seen from the receiving point `P`, each scene triangle covers a spherical
//! polygon whose edges are great-circle arcs (a segment and `P` span a
//! plane). For a sky patch (a spherical triangle `abc`, less than a
//! hemisphere) each occluder is first cut to the patch's cone (the three
//! half-spaces `d · (a × b) ≥ 0`, `d · (b × c) ≥ 0`, `d · (c × a) ≥ 0`
//! through `P`), then mapped by the gnomonic projection about the patch's
//! axis, which sends great circles to straight lines: the open part of the
//! patch is the planar triangle minus the union of the occluders' images
//! (polygon Boolean operations), and mapping its rings back to the sphere
//! gives spherical polygons whose vector flux eq. (B.1) sums exactly.
//!
//! So a silhouette is where it is, whatever the subdivision depth (the
//! shadow-ray method of [`super::sky`] finds it only to the depth limit);
//! patches are split only for the sky's radiance.
//!
//! Triangles whose plane passes through `P` (the receiver's own face and
//! its coplanar neighbours, a wall meeting the ground at `P`) cover no
//! solid angle and are skipped.

use geo::{Area, BooleanOps, Coord, LineString, Polygon};
use nalgebra::Vector3;

use super::spherical_polygon::{edge_flux, triangle_flux};
use crate::render::Scene;
use crate::visibility::image_clip::{clean, union_all};

/// One occluder: its corners relative to `P`, cut to the upper hemisphere
/// of the receiver, and a cone around it for culling.
#[derive(Debug, Clone)]
struct Occluder {
    corners: Vec<Vector3<f64>>,
    axis: Vector3<f64>,
    /// Cosine of the cone's half-angle.
    cos_radius: f64,
}

/// The scene's triangles as seen from one point.
#[derive(Debug, Clone)]
pub struct ProjectedOccluders {
    occluders: Vec<Occluder>,
}

/// Keeps the part of polygon `poly` (points relative to `P`) where `d · m ≥ 0`.
pub(crate) fn clip(poly: &[Vector3<f64>], m: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (sp, sq) = (p.dot(m), q.dot(m));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            out.push(p + (q - p) * (sp / (sp - sq)));
        }
    }
    out
}

/// The cone (axis, cosine of half-angle) around unit directions `ds`.
fn cone(ds: impl Iterator<Item = Vector3<f64>> + Clone) -> Option<(Vector3<f64>, f64)> {
    let axis = ds.clone().fold(Vector3::zeros(), |s, d| s + d).try_normalize(1e-300)?;
    let cos = ds.map(|d| d.dot(&axis)).fold(1.0, f64::min);
    Some((axis, cos))
}

impl ProjectedOccluders {
    /// The triangles of `scene` seen from `apex` above the plane of unit normal `normal`.
    pub fn new(scene: &Scene, apex: &Vector3<f64>, normal: &Vector3<f64>) -> ProjectedOccluders {
        let scale = 1.0 + apex.norm();
        let occluders = scene
            .triangles()
            .iter()
            .filter(|t| t.normal.dot(&(apex - t.vertices[0])).abs() > 1e-12 * scale)
            .filter_map(|t| {
                let corners = clip(&t.vertices.map(|v| v - apex), normal);
                if corners.len() < 3 {
                    return None;
                }
                let units = corners.iter().filter_map(|d| d.try_normalize(1e-300));
                let (axis, cos_radius) = cone(units)?;
                Some(Occluder {
                    corners,
                    axis,
                    cos_radius,
                })
            })
            .collect();
        ProjectedOccluders { occluders }
    }

    /// How many scene triangles reach above the receiver's tangent plane.
    pub fn len(&self) -> usize {
        self.occluders.len()
    }

    /// Whether no triangle does.
    pub fn is_empty(&self) -> bool {
        self.occluders.is_empty()
    }

    /// The vector flux (eq. B.1) of the part of the spherical triangle `abc`
    /// (unit vectors, counter-clockwise seen from outside, less than a
    /// hemisphere) that no occluder covers, and whether an occluder covers
    /// part of it (`false`: the flux is the whole patch's).
    pub fn open_flux(&self, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> (Vector3<f64>, bool) {
        let Some((axis, cos_r)) = cone([*a, *b, *c].into_iter()) else {
            return (triangle_flux(a, b, c), false);
        };
        // Cones overlap when the angle between axes is below the sum of half-angles.
        let patch_r = cos_r.clamp(-1.0, 1.0).acos();
        let planes = [a.cross(b), b.cross(c), c.cross(a)];
        let e1 = axis
            .cross(&if axis.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() })
            .normalize();
        let e2 = axis.cross(&e1);
        let gnomonic = |d: &Vector3<f64>| {
            let z = d.dot(&axis);
            Coord {
                x: d.dot(&e1) / z,
                y: d.dot(&e2) / z,
            }
        };
        let mut pieces = Vec::new();
        for o in &self.occluders {
            let between = o.axis.dot(&axis).clamp(-1.0, 1.0).acos();
            if between > patch_r + o.cos_radius.clamp(-1.0, 1.0).acos() + 1e-12 {
                continue;
            }
            let mut poly = o.corners.clone();
            for m in &planes {
                poly = clip(&poly, m);
                if poly.len() < 3 {
                    break;
                }
            }
            // Corners at P itself (no direction) cannot be projected: such a
            // triangle's plane passes through P and was skipped, so only a
            // rounding remnant of zero area is left.
            if poly.len() < 3 || poly.iter().any(|d| d.dot(&axis) <= 0.0) {
                continue;
            }
            let ring: Vec<Coord<f64>> = poly.iter().map(gnomonic).collect();
            let p = Polygon::new(LineString::from(ring), vec![]);
            if p.unsigned_area() > 0.0 {
                pieces.push(p);
            }
        }
        if pieces.is_empty() {
            return (triangle_flux(a, b, c), false);
        }
        let patch = Polygon::new(LineString::from(vec![gnomonic(a), gnomonic(b), gnomonic(c)]), vec![]);
        let open = clean(patch.difference(&union_all(&pieces)), patch.unsigned_area());
        let back = |q: &Coord<f64>| (e1 * q.x + e2 * q.y + axis).normalize();
        let ring_flux = |ring: &LineString<f64>| {
            // Counter-clockwise in (e1, e2) is counter-clockwise seen from
            // outside, e1 × e2 being the axis.
            let mut pts: Vec<Vector3<f64>> = ring.0.iter().map(back).collect();
            if pts.len() > 1 && pts.first() == pts.last() {
                pts.pop();
            }
            let signed: f64 = (0..ring.0.len().saturating_sub(1))
                .map(|i| ring.0[i].x * ring.0[i + 1].y - ring.0[i + 1].x * ring.0[i].y)
                .sum();
            if signed < 0.0 {
                pts.reverse();
            }
            (0..pts.len())
                .map(|i| edge_flux(&pts[i], &pts[(i + 1) % pts.len()]))
                .sum::<Vector3<f64>>()
        };
        let flux = open
            .0
            .iter()
            .map(|p| ring_flux(p.exterior()) - p.interiors().iter().map(ring_flux).sum::<Vector3<f64>>())
            .sum();
        (flux, true)
    }
}
