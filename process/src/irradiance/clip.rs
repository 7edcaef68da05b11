//! Clipping a spherical polygon by a great circle (Appendix B: "each
//! triangle defines a plane and only the part of the sky which is on the
//! correct side of this plane can be seen by the triangle"):
//! Sutherland–Hodgman on the sphere, keeping the side `n · v ≥ 0`.
//!
//! - A crossing edge is cut where its great arc meets the circle:
//!   `p = normalize(|n · b| a + |n · a| b)`, a positive combination of `a`
//!   and `b`, so `p` lies on the minor arc.
//! - A vertex within [`ON_PLANE`] of the plane counts as on it: it is kept,
//!   once, and creates no intersection.
//! - Two consecutive output vertices on the circle that are (nearly)
//!   antipodal get the circle's midpoint `normalize(n × a)` between them,
//!   which is on the interior side, so the new edge follows the circle.
//! - Nothing left, fewer than three distinct vertices, or a sliver below
//!   [`SLIVER_SR`]: no polygon.

use nalgebra::Vector3;

use super::spherical_polygon::{SphericalPolygon, SphericalPolygonError, is_antipodal};

/// Distance from the plane (`|n · v|`) below which a vertex is on it.
pub const ON_PLANE: f64 = 1e-14;

/// Polygons with a smaller solid angle (sr) are dropped as slivers.
pub const SLIVER_SR: f64 = 1e-12;

/// The part of `polygon` on the side `normal · v ≥ 0` of the plane through
/// the origin with normal `normal` (normalized here); `Ok(None)` when
/// nothing (or only a sliver) is left.
pub fn clip_to_hemisphere(
    polygon: &SphericalPolygon,
    normal: &Vector3<f64>,
) -> Result<Option<SphericalPolygon>, SphericalPolygonError> {
    let len = normal.norm();
    if !len.is_finite() || len == 0.0 {
        return Err(SphericalPolygonError::BadNormal {
            normal: [normal.x, normal.y, normal.z],
        });
    }
    let n = normal / len;
    let vs = polygon.vertices();
    let side = |v: &Vector3<f64>| {
        let d = n.dot(v);
        if d.abs() <= ON_PLANE { 0.0 } else { d }
    };
    if vs.iter().all(|v| side(v) == 0.0) {
        // Every vertex on the circle: the polygon is the hemisphere on the
        // side its orientation gives, kept if that is the normal's side.
        let kept = polygon.vector_flux().dot(&n) > 0.0;
        return Ok(kept.then(|| polygon.clone()));
    }
    if vs.iter().all(|v| side(v) >= 0.0) {
        return Ok(Some(polygon.clone()));
    }
    // Each output vertex with whether it lies on the circle.
    let mut out: Vec<(Vector3<f64>, bool)> = Vec::with_capacity(vs.len() + 2);
    for i in 0..vs.len() {
        let (a, b) = (vs[i], vs[(i + 1) % vs.len()]);
        let (da, db) = (side(&a), side(&b));
        if da >= 0.0 {
            out.push((a, da == 0.0));
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let p = a * db.abs() + b * da.abs();
            let pn = p.norm();
            if pn > 0.0 {
                out.push((p / pn, true));
            }
        }
    }
    // Drop repeated vertices (cyclically).
    let mut distinct: Vec<(Vector3<f64>, bool)> = Vec::with_capacity(out.len());
    for (v, on) in out {
        if distinct.last().is_none_or(|(w, _)| (v - w).norm() > 1e-15) {
            distinct.push((v, on));
        }
    }
    while distinct.len() > 1 && (distinct[0].0 - distinct[distinct.len() - 1].0).norm() <= 1e-15 {
        distinct.pop();
    }
    if distinct.len() < 3 {
        return Ok(None);
    }
    // Antipodal pairs on the circle: follow the circle through its midpoint.
    let mut vertices = Vec::with_capacity(distinct.len() + 1);
    for i in 0..distinct.len() {
        let (a, a_on) = distinct[i];
        let (b, b_on) = distinct[(i + 1) % distinct.len()];
        vertices.push(a);
        if a_on && b_on && is_antipodal(&a, &b) {
            vertices.push(n.cross(&a).normalize());
        }
    }
    let clipped = SphericalPolygon::new(vertices)?;
    if clipped.solid_angle() < SLIVER_SR {
        return Ok(None);
    }
    Ok(Some(clipped))
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    fn hemisphere() -> SphericalPolygon {
        SphericalPolygon::new(vec![
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
            v(-1.0, 0.0, 0.0),
            v(0.0, -1.0, 0.0),
        ])
        .unwrap()
    }

    #[test]
    fn tilted_plane_clips_the_sky_to_its_view_factor() {
        // The sky seen by a plane tilted by β: F·n = π (1 + cos β) / 2.
        for beta_deg in [0.0_f64, 10.0, 45.0, 90.0, 135.0, 179.0] {
            let beta = beta_deg.to_radians();
            let n = v(beta.sin(), 0.0, beta.cos());
            let e = match clip_to_hemisphere(&hemisphere(), &n).unwrap() {
                Some(p) => p.vector_flux().dot(&n),
                None => 0.0,
            };
            let exact = PI * (1.0 + beta.cos()) / 2.0;
            assert!((e - exact).abs() < 1e-12, "β {beta_deg}: {e} vs {exact}");
        }
    }

    #[test]
    fn facing_the_ground_leaves_nothing() {
        assert_eq!(clip_to_hemisphere(&hemisphere(), &v(0.0, 0.0, -1.0)).unwrap(), None);
    }

    #[test]
    fn vertices_on_the_plane_are_kept_once() {
        // The octant clipped by x = 0 keeps the edge y–z on the plane; by
        // x = y it is halved through the on-plane vertex z.
        let octant = SphericalPolygon::triangle(v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)).unwrap();
        let kept = clip_to_hemisphere(&octant, &v(1.0, 0.0, 0.0)).unwrap().unwrap();
        assert_eq!(kept.vertices().len(), 3);
        let gone = clip_to_hemisphere(&octant, &v(-1.0, 0.0, 0.0)).unwrap();
        assert_eq!(gone, None, "only the edge on the plane remains");
        let half = clip_to_hemisphere(&octant, &v(1.0, -1.0, 0.0)).unwrap().unwrap();
        assert_eq!(half.vertices().len(), 3, "{:?}", half.vertices());
        assert!((half.solid_angle() - PI / 4.0).abs() < 1e-14);
        assert!((half.vector_flux().z - PI / 8.0).abs() < 1e-14);
    }

    #[test]
    fn bad_normals_are_refused() {
        assert!(matches!(
            clip_to_hemisphere(&hemisphere(), &Vector3::zeros()),
            Err(SphericalPolygonError::BadNormal { .. })
        ));
        assert!(matches!(
            clip_to_hemisphere(&hemisphere(), &v(f64::NAN, 0.0, 1.0)),
            Err(SphericalPolygonError::BadNormal { .. })
        ));
    }
}
