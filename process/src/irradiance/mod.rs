//! Irradiance at a surface point from the sky, the sun and the environment,
//! thesis §5.4 and Appendix B.
//!
//! - [`spherical_polygon`]: spherical polygons, their solid angle and their
//!   vector flux, eq. (B.1).
//! - [`clip`]: clipping a spherical polygon by the receiver's tangent plane.
//! - [`sky`]: sky irradiance by adaptive subdivision of the clipped sky
//!   (Appendix B), with occluders by shadow rays.
//! - [`region`]: environment regions of uniform radiance, no subdivision.
//! - [`sun`]: the solar disc, with penumbra.
//! - [`occluder_projection`]: the scene's triangles projected onto the
//!   sphere of directions and cut out of each sky patch exactly (App. B);
//!   [`sky::Occlusion`] chooses it or shadow rays.
//! - [`form_factor`]: point-to-patch form factors (Lambert's formula, eq. B.1
//!   over π) and hierarchical links under a solid-angle threshold (§4.5).
//! - [`reference`]: an independent quadrature the tests and benchmark check against.
//!
//! Not yet: light reflected by the occluders themselves (§5.4, [83]) is
//! gathered by the outdoor solver's bounce, not here.

pub mod clip;
pub mod form_factor;
pub mod occluder_projection;
pub mod reference;
pub mod region;
pub mod sky;
pub mod spherical_polygon;
pub mod sun;

use nalgebra::Vector3;
use thiserror::Error;

pub use clip::clip_to_hemisphere;
pub use reference::{ReferenceGrid, reference_sky_irradiance};
pub use region::{environment_irradiance, region_irradiance};
pub use sky::{Occlusion, SkyIrradiance, SkySubdivision, sky_irradiance, sky_irradiance_with};
pub use spherical_polygon::{SphericalPolygon, SphericalPolygonError};
pub use sun::{SunIrradiance, sun_irradiance};

/// Why an irradiance could not be computed.
#[derive(Debug, Error, PartialEq)]
pub enum IrradianceError {
    /// The surface normal (or the sun's direction) is zero or not finite.
    #[error("direction {direction:?} is zero or not finite")]
    BadDirection {
        /// The value given.
        direction: [f64; 3],
    },
    /// The point is not finite.
    #[error("point {point:?} is not finite")]
    BadPoint {
        /// The value given.
        point: [f64; 3],
    },
    /// The subdivision tolerance is negative or not finite.
    #[error("subdivision tolerance {tolerance} must be finite and ≥ 0")]
    BadTolerance {
        /// The value given.
        tolerance: f64,
    },
    /// The depth limit is beyond what can be computed.
    #[error("subdivision depth {depth} exceeds the limit {limit}")]
    DepthTooLarge {
        /// The value given.
        depth: u32,
        /// The largest allowed.
        limit: u32,
    },
    /// The solar disc's angular radius is not in [0, π/2).
    #[error("solar disc angular radius {angular_radius_rad} rad is not in [0, π/2)")]
    BadDisc {
        /// The value given.
        angular_radius_rad: f64,
    },
    /// A spherical polygon was unusable.
    #[error(transparent)]
    Polygon(#[from] SphericalPolygonError),
}

/// `v` normalized, or an error if it names no direction.
fn unit_normal(v: &Vector3<f64>) -> Result<Vector3<f64>, IrradianceError> {
    let len = v.norm();
    if len.is_finite() && len > 0.0 {
        Ok(v / len)
    } else {
        Err(IrradianceError::BadDirection {
            direction: [v.x, v.y, v.z],
        })
    }
}
