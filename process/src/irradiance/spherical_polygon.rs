//! Spherical polygons on the unit sphere: their solid angle and their
//! vector flux, eq. (B.1) of Appendix B generalized to n edges.
//!
//! Orientation: vertices run counter-clockwise seen from outside the sphere,
//! so the interior lies to the left of each edge, on the side `(a × b) · v > 0`
//! of each edge `a → b`. The thesis writes eq. (B.1) with `Π_AB =
//! normalize(−(OA × OB))`, i.e. for the clockwise order; with our order the
//! minus sign goes away and
//!
//! `F = Σᵢ (θᵢ / 2) · normalize(vᵢ × vᵢ₊₁)`, `θᵢ = atan2(|vᵢ × vᵢ₊₁|, vᵢ · vᵢ₊₁)`,
//!
//! is `∫ ω dω` over the polygon: for a polygon above the plane of unit
//! normal `n`, `F · n` is the irradiance it gives under unit radiance (the
//! whole upper hemisphere gives `F · z = π`).
//!
//! Edges: a zero-length edge (repeated vertex) contributes nothing. An edge
//! between (nearly) antipodal vertices has no defined great circle; the
//! constructor refuses it with [`SphericalPolygonError::AntipodalEdge`], and
//! the caller must add a vertex on the arc it means (the clipper does this
//! itself for the arcs it creates on the clipping circle).

use nalgebra::Vector3;
use thiserror::Error;

/// An edge whose `|a × b|` is below this while `a · b < 0` (an arc longer
/// than `π − 1e-9` rad) is treated as antipodal: its great circle is
/// undefined to working precision.
pub const ANTIPODAL_SIN: f64 = 1e-9;

/// Why a list of directions is not a usable spherical polygon.
#[derive(Debug, Error, PartialEq)]
pub enum SphericalPolygonError {
    /// Fewer than three vertices.
    #[error("a spherical polygon needs at least 3 vertices, got {count}")]
    TooFewVertices {
        /// Vertices given.
        count: usize,
    },
    /// A vertex is zero or not finite, so it names no direction.
    #[error("vertex {index} is not a direction: {vertex:?}")]
    NotADirection {
        /// Index of the vertex.
        index: usize,
        /// Its value.
        vertex: [f64; 3],
    },
    /// Vertices `index` and `index + 1` are (nearly) antipodal: the edge's
    /// great circle is undefined. Add a vertex on the intended arc.
    #[error("edge {index} joins nearly antipodal vertices; add a vertex on the intended arc")]
    AntipodalEdge {
        /// Index of the edge's first vertex.
        index: usize,
    },
    /// A plane normal is zero or not finite.
    #[error("plane normal {normal:?} is not a direction")]
    BadNormal {
        /// The normal given.
        normal: [f64; 3],
    },
}

/// A spherical polygon: unit-vector vertices, counter-clockwise seen from
/// outside, edges along minor great arcs shorter than π.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalPolygon {
    vertices: Vec<Vector3<f64>>,
}

impl SphericalPolygon {
    /// A polygon from directions (normalized here). Refuses fewer than three
    /// vertices, non-directions and antipodal edges.
    pub fn new(vertices: Vec<Vector3<f64>>) -> Result<SphericalPolygon, SphericalPolygonError> {
        if vertices.len() < 3 {
            return Err(SphericalPolygonError::TooFewVertices { count: vertices.len() });
        }
        let mut unit = Vec::with_capacity(vertices.len());
        for (index, v) in vertices.iter().enumerate() {
            let norm = v.norm();
            if !norm.is_finite() || norm == 0.0 {
                return Err(SphericalPolygonError::NotADirection {
                    index,
                    vertex: [v.x, v.y, v.z],
                });
            }
            unit.push(v / norm);
        }
        for index in 0..unit.len() {
            let (a, b) = (unit[index], unit[(index + 1) % unit.len()]);
            if is_antipodal(&a, &b) {
                return Err(SphericalPolygonError::AntipodalEdge { index });
            }
        }
        Ok(SphericalPolygon { vertices: unit })
    }

    /// A polygon from vertices already known to be unit, with no antipodal edge.
    pub(crate) fn from_unit_unchecked(vertices: Vec<Vector3<f64>>) -> SphericalPolygon {
        SphericalPolygon { vertices }
    }

    /// The spherical triangle `abc` (counter-clockwise seen from outside).
    pub fn triangle(
        a: Vector3<f64>,
        b: Vector3<f64>,
        c: Vector3<f64>,
    ) -> Result<SphericalPolygon, SphericalPolygonError> {
        SphericalPolygon::new(vec![a, b, c])
    }

    /// The unit vertices.
    pub fn vertices(&self) -> &[Vector3<f64>] {
        &self.vertices
    }

    /// Solid angle, sr.
    ///
    /// When every vertex lies well inside the hemisphere about the mean
    /// vertex direction `m`, the sum of the signed triangle solid angles
    /// `(m, vᵢ, vᵢ₊₁)` by the Van Oosterom–Strackee formula
    /// `2 atan2(m · (a × b), 1 + m · a + a · b + b · m)`, which keeps its
    /// relative precision down to the smallest polygons. Otherwise (polygons
    /// as large as a hemisphere) Gauss–Bonnet: `2π − Σ` turning angles.
    pub fn solid_angle(&self) -> f64 {
        let n = self.vertices.len();
        let s: Vector3<f64> = self.vertices.iter().sum();
        let sn = s.norm();
        if sn > 1e-3 * n as f64 {
            let m = s / sn;
            if self.vertices.iter().all(|v| m.dot(v) > 0.1) {
                return (0..n)
                    .map(|i| triangle_solid_angle(&m, &self.vertices[i], &self.vertices[(i + 1) % n]))
                    .sum();
            }
        }
        self.gauss_bonnet_solid_angle()
    }

    /// `2π − Σ` exterior (turning) angles between consecutive edges' great
    /// circles, skipping zero-length edges.
    fn gauss_bonnet_solid_angle(&self) -> f64 {
        let n = self.vertices.len();
        let edges: Vec<(Vector3<f64>, Vector3<f64>)> = (0..n)
            .filter_map(|i| {
                let (a, b) = (self.vertices[i], self.vertices[(i + 1) % n]);
                let c = a.cross(&b);
                let len = c.norm();
                (len > 0.0).then(|| (a, c / len))
            })
            .collect();
        if edges.len() < 2 {
            return 0.0;
        }
        let turning: f64 = (0..edges.len())
            .map(|k| {
                let prev = edges[(k + edges.len() - 1) % edges.len()].1;
                let (start, next) = edges[k];
                start.dot(&prev.cross(&next)).atan2(prev.dot(&next))
            })
            .sum();
        std::f64::consts::TAU - turning
    }

    /// The vector flux `F = ∫ ω dω` of the polygon under unit radiance,
    /// eq. (B.1) summed over all edges (see the module documentation for
    /// the orientation). For a polygon above the plane of unit normal `n`,
    /// `F · n` is its irradiance per unit radiance.
    pub fn vector_flux(&self) -> Vector3<f64> {
        let n = self.vertices.len();
        (0..n)
            .map(|i| edge_flux(&self.vertices[i], &self.vertices[(i + 1) % n]))
            .sum()
    }

    /// The mean direction of the polygon, `normalize(F)` (its first moment);
    /// `None` if the flux vanishes (e.g. a whole sphere).
    pub fn centroid(&self) -> Option<Vector3<f64>> {
        let f = self.vector_flux();
        let len = f.norm();
        (len > 0.0 && len.is_finite()).then(|| f / len)
    }
}

/// Whether the edge `a → b` (unit vectors) is too close to antipodal for its
/// great circle to be known.
pub fn is_antipodal(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    a.dot(b) < 0.0 && a.cross(b).norm() < ANTIPODAL_SIN
}

/// The length of the great arc between unit vectors, radians:
/// `atan2(|a × b|, a · b)`, exact to rounding at 0 and near π, where an
/// arccos of the dot product loses half its digits.
pub fn edge_angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(&(b - a)).norm().atan2(a.dot(b))
}

/// One edge's term of eq. (B.1): `(θ / 2) · normalize(a × b)`, zero for a
/// zero-length edge. `a × b` is taken as `a × (b − a)`: for a short edge the
/// difference is exact and the normal keeps full relative precision, where
/// the plain cross product of two nearly equal vectors would leave an
/// absolute error of ε in every term and a relative error of ε / Ω in the
/// flux of a polygon of solid angle Ω.
pub fn edge_flux(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector3<f64> {
    let c = a.cross(&(b - a));
    let sin = c.norm();
    if sin == 0.0 {
        return Vector3::zeros();
    }
    let theta = sin.atan2(a.dot(b));
    c * (0.5 * theta / sin)
}

/// The vector flux of the spherical triangle `abc` (unit vectors,
/// counter-clockwise seen from outside): eq. (B.1) itself.
pub fn triangle_flux(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> Vector3<f64> {
    edge_flux(a, b) + edge_flux(b, c) + edge_flux(c, a)
}

/// The signed solid angle of the spherical triangle `abc` (unit vectors),
/// Van Oosterom–Strackee: `2 atan2(a · (b × c), 1 + a · b + b · c + c · a)`;
/// positive when `abc` is counter-clockwise seen from outside. The triple
/// product is taken as `a · ((b − a) × (c − a))`, which keeps its relative
/// precision for tiny triangles (the plain form loses it as `ε / Ω`).
pub fn triangle_solid_angle(a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> f64 {
    let triple = a.dot(&(b - a).cross(&(c - a)));
    let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * triple.atan2(denominator)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, PI};

    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    /// The regular n-gon inscribed in the circle of angular radius `delta`
    /// about +z, counter-clockwise seen from above.
    fn regular(n: usize, delta: f64) -> SphericalPolygon {
        let (s, c) = delta.sin_cos();
        let vertices = (0..n)
            .map(|i| {
                let phi = std::f64::consts::TAU * i as f64 / n as f64;
                v(s * phi.cos(), s * phi.sin(), c)
            })
            .collect();
        SphericalPolygon::new(vertices).unwrap()
    }

    /// Richardson extrapolation of an n-gon quantity to the cap: the
    /// inscribed polygon's error is a series in 1/n², so `(4 q(2n) − q(n)) / 3`
    /// leaves O(1/n⁴).
    fn richardson(q: impl Fn(usize) -> f64, n: usize) -> f64 {
        (4.0 * q(2 * n) - q(n)) / 3.0
    }

    #[test]
    fn whole_upper_hemisphere_has_flux_pi_and_solid_angle_two_pi() {
        let h = SphericalPolygon::new(vec![
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
            v(-1.0, 0.0, 0.0),
            v(0.0, -1.0, 0.0),
        ])
        .unwrap();
        let f = h.vector_flux();
        assert!((f.z - PI).abs() < 1e-12, "{f:?}");
        assert!(f.x.abs() < 1e-12 && f.y.abs() < 1e-12);
        assert!((h.solid_angle() - 2.0 * PI).abs() < 1e-12, "{}", h.solid_angle());
    }

    #[test]
    fn octant_has_solid_angle_half_pi_and_flux_quarter_pi_per_axis() {
        // ∫ over the octant of ω dω: each component is π/4.
        let o = SphericalPolygon::triangle(v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)).unwrap();
        assert!((o.solid_angle() - FRAC_PI_2).abs() < 1e-14);
        assert!((o.gauss_bonnet_solid_angle() - FRAC_PI_2).abs() < 1e-14);
        let f = o.vector_flux();
        for c in [f.x, f.y, f.z] {
            assert!((c - PI / 4.0).abs() < 1e-14, "{f:?}");
        }
    }

    #[test]
    fn cap_flux_is_pi_sin_squared_delta() {
        // Cap of half-angle δ about the normal: F·z = π sin²δ, Ω = 4π sin²(δ/2).
        for delta in [0.3_f64, 1.2] {
            let flux = richardson(|n| regular(n, delta).vector_flux().z, 1024);
            let exact = PI * delta.sin().powi(2);
            assert!(((flux - exact) / exact).abs() < 1e-10, "δ {delta}: {flux} vs {exact}");
            let omega = richardson(|n| regular(n, delta).solid_angle(), 1024);
            let exact = 4.0 * PI * (delta / 2.0).sin().powi(2);
            assert!(((omega - exact) / exact).abs() < 1e-10, "δ {delta}: {omega} vs {exact}");
        }
    }

    #[test]
    fn polygons_below_a_microsteradian_keep_their_digits() {
        // A cap of δ = 5e-4 rad (7.9e-7 sr): flux and solid angle to 1e-9 relative.
        let delta = 5e-4_f64;
        let omega = richardson(|n| regular(n, delta).solid_angle(), 1024);
        let exact_omega = 4.0 * PI * (delta / 2.0).sin().powi(2);
        assert!(exact_omega < 1e-6);
        assert!(
            ((omega - exact_omega) / exact_omega).abs() < 1e-9,
            "{omega} vs {exact_omega}"
        );
        let flux = richardson(|n| regular(n, delta).vector_flux().z, 1024);
        let exact_flux = PI * delta.sin().powi(2);
        assert!(
            ((flux - exact_flux) / exact_flux).abs() < 1e-9,
            "{flux} vs {exact_flux}"
        );
        // A triangle of ~1e-10 sr far from any axis: F = Ω · centroid to 1e-9 relative
        // (the difference is O(Ω) relative, 1e-10 here).
        let c = v(0.3, -0.5, 0.8).normalize();
        let e1 = c.cross(&Vector3::z()).normalize();
        let e2 = c.cross(&e1);
        let s = 1.5e-5;
        let t = SphericalPolygon::triangle(
            c + e1 * s,
            c + (e2 * 0.866 - e1 * 0.5) * s,
            c - (e2 * 0.866 + e1 * 0.5) * s,
        )
        .unwrap();
        let omega = t.solid_angle();
        assert!(omega > 0.0 && omega < 1e-9, "{omega}");
        let f = t.vector_flux();
        assert!(f.iter().all(|x| x.is_finite()));
        let dir = (t.vertices()[0] + t.vertices()[1] + t.vertices()[2]).normalize();
        assert!(
            (f - dir * omega).norm() / omega < 1e-9,
            "{}",
            (f - dir * omega).norm() / omega
        );
    }

    #[test]
    fn zero_and_near_straight_edges_give_the_exact_wedge() {
        // B → A along the equator through −y (an arc of π − 2h), then the pole:
        // the upper hemisphere's wedge of azimuths [−π/2 − (π/2 − h), −π/2 + (π/2 − h)].
        for h in [1e-7_f64, 1e-3] {
            let a = v(h.cos(), -h.sin(), 0.0);
            let b = v(-h.cos(), -h.sin(), 0.0);
            let z = v(0.0, 0.0, 1.0);
            // The repeated vertex is a zero-length (0°) edge.
            let wedge = SphericalPolygon::new(vec![b, a, a, z]).unwrap();
            let span = PI - 2.0 * h;
            let (phi1, phi2) = (-PI + h, -h);
            let f = wedge.vector_flux();
            assert!(f.iter().all(|x| x.is_finite()));
            assert!((f.z - span / 2.0).abs() < 1e-12, "{f:?}");
            assert!((f.x - PI / 4.0 * (phi2.sin() - phi1.sin())).abs() < 1e-12);
            assert!((f.y - PI / 4.0 * (phi1.cos() - phi2.cos())).abs() < 1e-12);
            assert!((wedge.solid_angle() - span).abs() < 1e-12, "{}", wedge.solid_angle());
            assert!((edge_angle(&b, &a) - span).abs() < 1e-15);
        }
        assert_eq!(edge_angle(&v(0.0, 0.0, 1.0), &v(0.0, 0.0, 1.0)), 0.0);
        assert_eq!(edge_flux(&v(0.0, 0.0, 1.0), &v(0.0, 0.0, 1.0)), Vector3::zeros());
    }

    #[test]
    fn bad_polygons_are_refused_with_typed_errors() {
        let z = v(0.0, 0.0, 1.0);
        assert_eq!(
            SphericalPolygon::new(vec![z, -z, v(1.0, 0.0, 0.0)]),
            Err(SphericalPolygonError::AntipodalEdge { index: 0 })
        );
        assert_eq!(
            SphericalPolygon::new(vec![z, v(1.0, 0.0, 0.0)]),
            Err(SphericalPolygonError::TooFewVertices { count: 2 })
        );
        assert!(matches!(
            SphericalPolygon::new(vec![z, v(f64::NAN, 0.0, 0.0), v(1.0, 0.0, 0.0)]),
            Err(SphericalPolygonError::NotADirection { index: 1, .. })
        ));
        assert!(matches!(
            SphericalPolygon::new(vec![z, Vector3::zeros(), v(1.0, 0.0, 0.0)]),
            Err(SphericalPolygonError::NotADirection { index: 1, .. })
        ));
    }
}
