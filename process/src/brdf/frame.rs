//! The local shading frame every model here is written in: the normal is +z,
//! the material's tangent +x, and the bitangent +y = z × x (right-handed).
//! A Ward lobe's orientation γ then turns its principal axes about z, away
//! from the tangent.
//!
//! Directions are unit vectors pointing away from the surface: `wi` toward
//! the light, `wo` toward the viewer. In the local frame, a direction's z
//! component is the cosine of its angle to the normal.

use nalgebra::Vector3;

use super::error::BrdfError;

/// A direction whose local z (cos θ) is at most this counts as at or below
/// the horizon, where every BRDF here is zero. The Ward forms grow without
/// bound as cos θ → 0 (the 1992 form as 1/√cos θ, Dür's as 1/cos θ); the
/// floor keeps them finite (below about 1e60 sr⁻¹ for α ≥ [`super::MIN_ALPHA`])
/// and costs only the directions within 6e-11° of the horizon.
pub const HORIZON_COS: f64 = 1e-12;

/// Whether the local direction `w` is strictly above the horizon (false for NaN).
pub(crate) fn above_horizon(w: &Vector3<f64>) -> bool {
    w.z > HORIZON_COS
}

/// Below this fraction of the preferred tangent's length left after removing
/// its normal component, the tangent counts as parallel to the normal and the
/// frame falls back to a tangent of its own choosing.
const PARALLEL_FRACTION: f64 = 1e-9;

/// An orthonormal frame at a surface point: `normal`, `tangent` and
/// `bitangent = normal × tangent`, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    /// Unit normal: the local +z.
    pub normal: Vector3<f64>,
    /// Unit tangent, perpendicular to the normal: the local +x.
    pub tangent: Vector3<f64>,
    /// Unit bitangent, `normal × tangent`: the local +y.
    pub bitangent: Vector3<f64>,
}

impl ShadingFrame {
    /// The frame with normal `normal` (any length) and the tangent nearest to
    /// `preferred_tangent` (Gram–Schmidt: its component along the normal is
    /// removed). When the preferred tangent is zero, not finite, or parallel
    /// to the normal, the tangent is built from the world axis least aligned
    /// with the normal instead, so the frame is never NaN.
    ///
    /// Errors: [`BrdfError::InvalidNormal`] when the normal is zero or not finite.
    pub fn new(normal: Vector3<f64>, preferred_tangent: Vector3<f64>) -> Result<ShadingFrame, BrdfError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(BrdfError::InvalidNormal {
                normal: [normal.x, normal.y, normal.z],
            });
        }
        let n = normal / len;
        let tangent = orthogonal_part(n, preferred_tangent).unwrap_or_else(|| fallback_tangent(n));
        Ok(ShadingFrame {
            normal: n,
            tangent,
            bitangent: n.cross(&tangent),
        })
    }

    /// A world direction in local coordinates `(v·t, v·b, v·n)`.
    pub fn to_local(&self, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(v.dot(&self.tangent), v.dot(&self.bitangent), v.dot(&self.normal))
    }

    /// A local direction in world coordinates `x t + y b + z n`.
    pub fn to_world(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

/// The unit part of `t` perpendicular to the unit vector `n`, or `None` when
/// `t` is zero, not finite, or (nearly) parallel to `n`.
fn orthogonal_part(n: Vector3<f64>, t: Vector3<f64>) -> Option<Vector3<f64>> {
    let t_len = t.norm();
    if !(t_len.is_finite() && t_len > 0.0) {
        return None;
    }
    let perp = t - n * n.dot(&t);
    let perp_len = perp.norm();
    (perp_len > PARALLEL_FRACTION * t_len).then(|| perp / perp_len)
}

/// A unit tangent for `n` from the world axis least aligned with it (its
/// smallest component), which is at least 54.7° away from `n`.
fn fallback_tangent(n: Vector3<f64>) -> Vector3<f64> {
    let a = n.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        Vector3::x()
    } else if a.y <= a.z {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let perp = axis - n * n.dot(&axis);
    perp / perp.norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(f: &ShadingFrame) {
        for (a, b, expected) in [
            (f.normal, f.normal, 1.0),
            (f.tangent, f.tangent, 1.0),
            (f.bitangent, f.bitangent, 1.0),
            (f.normal, f.tangent, 0.0),
            (f.normal, f.bitangent, 0.0),
            (f.tangent, f.bitangent, 0.0),
        ] {
            assert!((a.dot(&b) - expected).abs() < 1e-14, "{f:?}");
        }
        // Right-handed: t × b = n.
        assert!((f.tangent.cross(&f.bitangent) - f.normal).norm() < 1e-14);
    }

    #[test]
    fn gram_schmidt_keeps_the_preferred_tangent_in_its_plane() {
        let f = ShadingFrame::new(Vector3::new(0.0, 0.0, 2.0), Vector3::new(1.0, 0.0, 0.5)).unwrap();
        assert_orthonormal(&f);
        assert!((f.tangent - Vector3::x()).norm() < 1e-15);
        assert!((f.bitangent - Vector3::y()).norm() < 1e-15);
    }

    #[test]
    fn parallel_zero_or_nan_tangents_fall_back_without_nan() {
        let n = Vector3::new(0.3, -0.4, 0.866);
        for t in [
            n,
            -n * 3.0,
            Vector3::zeros(),
            Vector3::new(f64::NAN, 0.0, 1.0),
            n + Vector3::new(1e-13, 0.0, 0.0),
        ] {
            let f = ShadingFrame::new(n, t).unwrap();
            assert_orthonormal(&f);
        }
    }

    #[test]
    fn to_local_and_to_world_are_inverse() {
        let f = ShadingFrame::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.0, 1.0, 0.0)).unwrap();
        let v = Vector3::new(-0.2, 0.7, 0.4);
        assert!((f.to_world(&f.to_local(&v)) - v).norm() < 1e-15);
        assert!((f.to_local(&f.normal) - Vector3::z()).norm() < 1e-15);
    }

    #[test]
    fn a_zero_or_nan_normal_is_a_typed_error() {
        for n in [
            Vector3::zeros(),
            Vector3::new(f64::NAN, 0.0, 1.0),
            Vector3::new(f64::INFINITY, 0.0, 0.0),
        ] {
            assert!(matches!(
                ShadingFrame::new(n, Vector3::x()),
                Err(BrdfError::InvalidNormal { .. })
            ));
        }
    }
}
