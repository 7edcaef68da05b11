//! A fixed sky camera calibrated by the sun: from one day's sun centroids
//! and the ephemeris, the camera's orientation (three angles) and its lens
//! (focal length and radial terms of its projection, and optionally the
//! principal point), by Levenberg–Marquardt on the centroids' pixel
//! residuals, with the parameters' covariance from the Jacobian, the
//! residual in degrees and a quality verdict.
//!
//! **Model.** A sun shot at time `t` sees the sun's apparent direction
//! `s(t)` (NREL SPA, refraction included: [`crate::sun::sun_position`]).
//! The camera is on the station's head, held at one pose, so its
//! orientation is the mount calibration's: the azimuth at pan 0, and the
//! base's roll (about north) and pitch (about east) — three angles that
//! turn the camera freely for small tilts, whatever the pose (for a camera
//! at the zenith, the azimuth turns it about its axis and roll and pitch
//! tilt the axis). The tilt zero is held: at a fixed pose it only repeats
//! what roll and pitch do. The sun is imaged at
//! `project(mount.to_camera(head, s(t)))` ([`crate::pose::Pinhole`]: a
//! pinhole or a fisheye with radial terms `r (1 + k1 r² + k2 r⁴)`).
//!
//! **What one day identifies.** The day's track is a curve on the sky,
//! the small circle of the sun's declination, seen from θ_min (noon's
//! angle off the axis) to the horizon. Along it every shot is a known
//! direction, so the three angles are fixed by the track's shape and
//! timing; the lens's radial function r(θ) is sampled only on
//! [θ_min, θ_max], so `f`, `k1` (and `k2`) are fixed there and extrapolated
//! inside θ_min. The principal point is, to first order, the image of a
//! tilt of the axis: it is identifiable only through how that shift varies
//! with θ, so its correlation with the roll and pitch is near 1 and it is
//! held at its configured value unless asked for
//! ([`CalibrationOptions::fit_principal_point`]); the report gives every
//! pair's correlation, so what a day could not separate is measured, not
//! assumed. A track only near the horizon (a winter day at high latitude)
//! samples one θ: `f` and `k1` then trade against each other exactly and
//! the verdict says ill-conditioned.
//!
//! **Robustness.** Clouded or flared shots move a centroid far from the
//! track: the fit is first made with Huber weights (a pixel's scale), then
//! every shot whose residual exceeds `max(5 × 1.4826 × median residual,
//! CalibrationOptions::reject_floor_px)` is rejected (reported by time and
//! residual) and the inliers refitted. The fit starts from the nominal
//! orientation, its azimuth also tried every 30° so that a camera set
//! with an unknown north still converges.

mod fit;
mod report;

pub use fit::{
    CalibrationError, CalibrationOptions, FitParameter, Rejected, SkyCameraCalibration, SkyCameraModel, SunSighting,
    calibrate_sky_camera, direction_error_deg,
};
pub use report::calibration_report;
