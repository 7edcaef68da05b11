//! Typed errors of the inverse global illumination solver: each names the
//! view, pixel, light or option at fault, its value, and what was expected.

use crate::render::SceneError;

/// Everything that can stop [`super::recover`].
#[derive(Debug, thiserror::Error)]
pub enum IgiError {
    /// The scene has no triangles.
    #[error("the scene geometry has no triangles: expected at least one surface")]
    NoGeometry,
    /// The triangles do not form a valid scene.
    #[error("geometry: {0}")]
    Scene(#[from] SceneError),
    /// A camera parameter is out of range.
    #[error("view {view:?}: camera {field} = {value}: expected {expected}")]
    Camera {
        /// The view's name.
        view: String,
        /// Which field.
        field: &'static str,
        /// The value, printed.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// The image does not have the camera's size.
    #[error(
        "view {view:?}: the image is {got_width}x{got_height} (with {got_values} values) but the camera is {width}x{height}: expected width x height x 3 values"
    )]
    ImageSize {
        /// The view's name.
        view: String,
        /// Image width.
        got_width: usize,
        /// Image height.
        got_height: usize,
        /// Values in the image buffer.
        got_values: usize,
        /// Camera width.
        width: usize,
        /// Camera height.
        height: usize,
    },
    /// The mask does not have one entry per pixel.
    #[error("view {view:?}: the mask has {got} entries: expected {expected} (width x height)")]
    MaskSize {
        /// The view's name.
        view: String,
        /// Entries in the mask.
        got: usize,
        /// Pixels in the image.
        expected: usize,
    },
    /// A radiance that is negative or not finite, on a pixel not masked out.
    #[error(
        "view {view:?}, pixel ({x}, {y}), channel {channel}: radiance {value}: expected a finite value >= 0 (mask the pixel out if it is invalid)"
    )]
    Radiance {
        /// The view's name.
        view: String,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// Colour channel.
        channel: usize,
        /// The value.
        value: f32,
    },
    /// A light with a bad position, radius or intensity.
    #[error("light {index}: {field} = {value}: expected {expected}")]
    Light {
        /// Index of the light.
        index: usize,
        /// Which field.
        field: &'static str,
        /// The value, printed.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A solver option out of range.
    #[error("option {name} = {value}: expected {expected}")]
    Option {
        /// The option.
        name: &'static str,
        /// The value, printed.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
}
