//! Which parts of a polygon model each photograph sees, thesis §3.5.
//!
//! The model's triangles are cut into *fragments*: planar pieces, each
//! either wholly visible or wholly hidden in every photograph, with the list
//! of photographs that see it. Two algorithms produce them:
//!
//! - [`hybrid`]: the thesis's algorithm (§3.5, steps 1–7). An item buffer of
//!   the *original* triangles per view finds, for each fragment, the
//!   candidate occluders among the ids its pixels show (conservative: every
//!   pixel within 0.75 px of the fragment counts); each candidate is checked
//!   in object space (overlap and depth at an interior point of the
//!   overlap); the fragment is then clipped by the true occluders only
//!   (*shallow clipping*: a fragment wholly hidden is left intact, and
//!   nothing behind it is touched), unless its area is below the size
//!   threshold, in which case it keeps the majority label.
//! - [`weiler_atherton`]: the comparison of Tables 3.2–3.3, hidden-surface
//!   removal by polygon area sorting (Weiler and Atherton 1977) applied at
//!   each view in turn to the previous view's output: the front-most polygon
//!   clips *every* polygon it overlaps, hidden or not (*deep clipping*).
//!
//! Both first split fragments by the view frustum (step 3: "clip the
//! polygons against all image boundaries"), so their counts compare like
//! for like; [`check`] measures how many pixels' surface points a
//! fragmentation labels wrongly, against brute-force per-pixel ray casting
//! with the same [`crate::render::accel::Accel`] the renderer uses.
//!
//! Clipping happens in the image plane, where a pinhole's projection maps
//! the planes of the model to lines (a projective map), so polygon Boolean
//! operations there (the `geo` crate's, on f64) are exact up to rounding,
//! and each piece maps back onto its triangle's plane by ray–plane
//! intersection. Fragments are stored in their triangle's plane coordinates.
//!
//! Assumed: triangles do not interpenetrate (step 2 of §3.5, splitting
//! intersecting polygons, is not implemented; the example scenes have
//! none), and the photographs are undistorted pinhole images.

pub mod check;
pub mod fragment;
pub mod hybrid;
pub mod image_clip;
pub mod item_buffer;
pub mod view;
pub mod weiler_atherton;

pub use check::{Misclassification, misclassified};
pub use fragment::{Fragment, Model};
pub use hybrid::hybrid;
pub use view::PinholeView;
pub use weiler_atherton::weiler_atherton;

/// Why visibility could not be computed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum VisibilityError {
    /// A camera field is out of range.
    #[error("view {view}: {field} = {value}, expected {expected}")]
    BadView {
        /// The view's name.
        view: String,
        /// The field.
        field: &'static str,
        /// The value given.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The model has no triangles.
    #[error("the model has no triangles")]
    EmptyModel,
    /// The size threshold is negative or not finite.
    #[error("size threshold {0} m² must be finite and ≥ 0")]
    BadThreshold(f64),
}

/// What a fragmentation produced, for Tables 3.2–3.3.
#[derive(Debug, Clone)]
pub struct Fragmentation {
    /// The fragments.
    pub fragments: Vec<Fragment>,
    /// Object-space clip operations done (a Boolean operation of one
    /// fragment against its occluders counts once).
    pub clips: usize,
    /// Fragments left below the size threshold with a mixed visibility
    /// (labelled by the larger part).
    pub small_mixed: usize,
}

#[cfg(test)]
mod tests;
