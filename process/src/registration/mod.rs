//! Camera pose from targets (thesis §3.3): where a photograph was taken
//! from, found from targets whose world positions are surveyed.
//!
//! - [`correspondence`]: an image point paired with its surveyed world point.
//! - [`camera_pose`]: a camera's place and orientation in the world frame.
//! - [`p3p`]: the minimal solver, three points to up to four poses
//!   (Lambda Twist, through the `lambda-twist` crate).
//! - [`consensus`]: RANSAC over the minimal solver, so a false or moved
//!   target cannot pull the pose.
//! - [`refine`]: Levenberg–Marquardt on all six parameters over the
//!   reprojection error through the camera's distortion model (thesis
//!   §3.3.3), and the pose's covariance from the Jacobian.
//! - [`verdict`]: whether the pose is to be trusted: `ok`, `poor` or
//!   `failed`, each with its figures.
//! - the surveyed targets file (`targets.ron`) and the world corners of
//!   each coded target are `campanile_config::targets`.
//! - [`apriltag`]: coded targets (AprilTag, family tag36h11) found in a
//!   photograph, through the pure-Rust `kornia-apriltag` crate, and the
//!   tags' bit patterns for the simulator to paint.
//! - [`solve`]: the whole chain, correspondences to a judged pose.
//! - [`mount`]: the head's mount calibration from photographs registered
//!   at known head readings.
//! - the thesis's own targets, white circles without identity (§3.3.1–
//!   §3.3.3): [`circle_detect`] finds them (template sweep at several
//!   scales, then an [`ellipse`] fit), [`circle_search`] finds their
//!   correspondences by search over pairs of ellipse constraints and
//!   registers the photograph through [`solve`].
//!
//! Camera frame as in [`crate::pose`]: x right, y down, z forward; world
//! frame x east, y north, z up, metres.

pub mod apriltag;
pub mod camera_pose;
pub mod circle_detect;
pub mod circle_search;
pub mod consensus;
pub mod correspondence;
pub mod ellipse;
pub mod mount;
pub mod p3p;
pub mod refine;
pub mod solve;
pub mod verdict;

pub use camera_pose::CameraPose;
pub use correspondence::Correspondence;
pub use solve::{Registration, RegistrationSettings, register};
pub use verdict::{Quality, QualityLimits, Verdict};
