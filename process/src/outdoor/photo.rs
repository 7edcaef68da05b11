//! The solver's inputs as plain data: posed radiance photographs and the
//! illumination at each time. The simulator and a processed capture
//! session both produce these.

use chrono::{DateTime, Utc};

use crate::camera::image::RadianceImage;
use crate::render::{CameraRig, Sky};

/// One HDR radiance photograph of the scene with its pose and time.
#[derive(Debug, Clone)]
pub struct Photo {
    /// A name for diagnostics (file or session step).
    pub label: String,
    /// Linear radiance, W·m⁻²·sr⁻¹ per channel.
    pub image: RadianceImage,
    /// The camera that took it (intrinsics, mount, head angles, position).
    pub rig: CameraRig,
    /// When it was taken, UTC.
    pub time: DateTime<Utc>,
    /// Valid pixels (`true` = use), row-major, `width · height`; `None`: all.
    pub mask: Option<Vec<bool>>,
}

/// The light at one time: the sky (and its solar disc, through
/// [`Sky::sun`]). The environment is the scene's non-target surfaces, lit
/// by this sky (see [`super::cell_irradiance`]).
#[derive(Clone, Copy)]
pub struct Illumination<'a> {
    /// The time it describes.
    pub time: DateTime<Utc>,
    /// Sky radiance and the solar disc (direction, angular radius, radiance
    /// per channel). A fitted eq. (5.9) sky becomes one through
    /// [`crate::sky::Daylight`].
    pub sky: &'a dyn Sky,
}

impl std::fmt::Debug for Illumination<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Illumination")
            .field("time", &self.time)
            .field("sun", &self.sky.sun())
            .finish()
    }
}
